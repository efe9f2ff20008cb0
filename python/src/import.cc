// import_log: real recordings into push logs or wrench-twist pairs, with import-log's
// options. A rejected file is in the summary, as in the tool; it does not raise.

#include <pybind11/stl.h>

#include "core.h"
#include "pipeline/import_options.h"

namespace slideid::python {
namespace po = boost::program_options;

namespace {

py::dict ImportLogs(const std::string& format, const std::vector<std::string>& files,
                    const std::string& out_dir, const py::kwargs& keywords) {
  po::options_description options, hidden;
  cli::AddImportOptions(&options, &hidden);
  options.add(hidden);
  std::vector<std::string> leading = {"--format=" + format, "--out=" + out_dir};
  for (const std::string& f : files) leading.push_back("--files=" + f);
  const po::variables_map vm =
      ParseKeywords("import_log", options, keywords, {"format", "out", "files"}, leading);
  const ImportRequest request = cli::ReadImportOptions(vm);
  ImportSummary summary;
  try {
    py::gil_scoped_release release;
    summary = ImportFiles(request);
  } catch (const std::runtime_error& e) {  // an output that cannot be written
    throw WriteFailure(e.what());
  }
  py::dict d;
  d["files"] = summary.files;
  d["accepted"] = summary.accepted;
  d["accepted_lines"] = summary.accepted_lines;
  d["rejections"] = summary.rejections;
  d["report_path"] = summary.report_path;
  return d;
}

}  // namespace

void BindImport(py::module_& m) {
  m.def("import_log", &ImportLogs, py::arg("format"), py::arg("files"), py::arg("out_dir"));
}

}  // namespace slideid::python
