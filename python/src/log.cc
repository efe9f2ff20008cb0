// slideid.Log and its files: read_log, make_log (a log from arrays, read exactly as the file
// they make would be), write_log.

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <filesystem>
#include <sstream>

#include "core.h"
#include "io/push_log.h"
#include "pipeline/identify_options.h"

namespace slideid::python {
namespace po = boost::program_options;

namespace {

/// The keywords of read_log: identify's slider overrides and how rows are read (largest
/// gap, regular times, dropouts as gaps).
const std::vector<std::string> kReadKeywords = {"mass",           "inertia",       "com_height",
                                                "gravity",        "max_gap_ratio", "regular_times",
                                                "missing_as_gaps"};

LogReadOptions ReadOptionsFromKeywords(const std::string& function, const py::dict& keywords) {
  po::options_description general, advanced;
  cli::AddIdentifyOptions(&general, &advanced);
  general.add(advanced);
  for (const auto& [key, value] : keywords) {
    const std::string name = py::str(key).cast<std::string>();
    if (std::find(kReadKeywords.begin(), kReadKeywords.end(), name) == kReadKeywords.end()) {
      throw py::type_error(function + "() got an unexpected keyword argument '" + name + "'");
    }
  }
  return cli::ReadFileIdentifyOptions(ParseKeywords(function, general, keywords)).read;
}

std::string LogText(const PushLogFile& file) {
  std::ostringstream out;
  WritePushLog(file, out);
  return out.str();
}

/// Options that read back anything a log can hold: the text of a log in memory.
LogReadOptions AnyLog() {
  LogReadOptions o;
  o.require_slider_properties = false;
  o.max_gap_ratio = 0;
  return o;
}

py::dict Columns(const LogHandle& h) {
  const PushLogColumns columns = ColumnsOf(h.file.log);
  py::dict out;
  for (size_t c = 0; c < columns.names.size(); ++c) {
    const std::vector<double>& v = columns.values[c];
    out[py::str(columns.names[c])] =
        py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
  }
  if (!columns.mode.empty()) out["mode"] = py::cast(columns.mode);
  return out;
}

py::dict Metadata(const LogHandle& h) {
  const Trajectory& log = h.file.log;
  py::dict m;
  m["source"] = log.source;
  m["mass"] = log.slider.mass_kg;
  m["inertia"] = log.slider.inertia_kgm2;
  m["com_height"] = log.slider.com_height_m;
  m["gravity"] = log.slider.gravity_mps2;
  const std::string patch = PatchText(h.file);
  m["patch"] = patch.empty() ? py::object(py::none()) : py::object(py::str(patch));
  m["tip_radius"] =
      log.tip_radius_m ? py::object(py::float_(*log.tip_radius_m)) : py::object(py::none());
  if (log.true_friction) {
    const FrictionParameters& f = *log.true_friction;
    py::dict truth;
    truth["mu"] = f.mu;
    truth["e_t"] = f.e_t;
    truth["e_o"] = f.e_o;
    truth["e_r"] = f.e_r;
    m["truth"] = truth;
  } else {
    m["truth"] = py::none();
  }
  py::dict extra;
  for (const auto& [key, value] : h.file.extra_metadata) extra[py::str(key)] = value;
  m["extra"] = extra;
  return m;
}

LogPtr ReadLog(const std::string& path, const py::kwargs& keywords) {
  const LogReadOptions options = ReadOptionsFromKeywords("read_log", keywords);
  auto handle = std::make_shared<LogHandle>();
  LogReadReport report;
  {
    py::gil_scoped_release release;
    handle->file = ReadPushLogFile(path, options, &report);
  }
  handle->file.log.source = std::filesystem::path(path).filename().string();
  handle->warnings = report.warnings;
  handle->notes = report.notes;
  return handle;
}

LogPtr MakeLog(const py::dict& columns, const std::optional<std::vector<std::string>>& mode,
               const std::vector<std::pair<std::string, std::string>>& metadata,
               const std::string& source, const py::kwargs& keywords) {
  const LogReadOptions options = ReadOptionsFromKeywords("make_log", keywords);
  PushLogColumns table;
  for (const auto& [name, values] : columns) {
    table.names.push_back(py::str(name).cast<std::string>());
    const auto array =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
    if (!array || array.ndim() != 1) {
      throw std::invalid_argument("make_log: column '" + table.names.back() +
                                  "' is not a one-dimensional array of numbers");
    }
    table.values.emplace_back(array.data(), array.data() + array.size());
  }
  if (mode) table.mode = *mode;
  auto handle = std::make_shared<LogHandle>();
  LogReadReport report;
  handle->file = ParsePushLogColumns(table, metadata, source, options, &report);
  handle->file.log.source = source;
  handle->warnings = report.warnings;
  handle->notes = report.notes;
  return handle;
}

void WriteLog(const LogHandle& handle, const std::string& path) {
  py::gil_scoped_release release;
  try {
    WritePushLog(handle.file, path);
  } catch (const std::invalid_argument&) {
    throw;  // metadata a file cannot hold: bad input
  } catch (const std::runtime_error& e) {
    throw WriteFailure(e.what());
  }
}

}  // namespace

void BindLog(py::module_& m) {
  py::class_<LogHandle, LogPtr>(m, "LogHandle",
                                "A push log in memory (use slideid.Log, which wraps it).")
      .def_property_readonly("source", [](const LogHandle& h) { return h.file.log.source; })
      .def_property_readonly("rows", [](const LogHandle& h) { return h.file.log.samples.size(); })
      .def_readonly("warnings", &LogHandle::warnings)
      .def_readonly("notes", &LogHandle::notes)
      .def("columns", &Columns, "the columns write_log writes, as numpy arrays")
      .def("metadata", &Metadata, "slider properties, patch, truth and further metadata")
      .def(
          "text", [](const LogHandle& h) { return LogText(h.file); }, "the log as CSV text")
      .def(py::pickle(
          [](const LogHandle& h) {
            return py::make_tuple(LogText(h.file), h.file.log.source, h.warnings, h.notes);
          },
          [](const py::tuple& state) {
            auto h = std::make_shared<LogHandle>();
            const auto source = state[1].cast<std::string>();
            h->file = ParsePushLogFile(state[0].cast<std::string>(), source, AnyLog());
            h->file.log.source = source;
            h->warnings = state[2].cast<std::vector<std::string>>();
            h->notes = state[3].cast<std::vector<std::string>>();
            return h;
          }));
  m.def("read_log", &ReadLog, py::arg("path"));
  m.def("make_log", &MakeLog, py::arg("columns"), py::arg("mode"), py::arg("metadata"),
        py::arg("source"));
  m.def("write_log", &WriteLog, py::arg("log"), py::arg("path"));
}

}  // namespace slideid::python
