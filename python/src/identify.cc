// identify: push logs (files or slideid.Log objects) or wrench-twist pair files, with the
// options of the identify tool, to the identify JSON and what goes with it.

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <sstream>

#include "core.h"
#include "io/log_check_report.h"
#include "io/result_json.h"
#include "pipeline/check_files.h"
#include "pipeline/identify_options.h"
#include "pipeline/report_files.h"

namespace slideid::python {
namespace po = boost::program_options;

namespace {

/// identify's options that are not about the fit: the files come as arguments, the output
/// is the result, --strict is the Python layer's, and a batch is a map of identify_file.
const std::vector<std::string> kNotKeywords = {"log",     "logs",   "json",  "residuals",
                                               "verbose", "strict", "batch", "jobs",
                                               "out",     "shard",  "check"};

/// Whether the keywords ask for a log to be read differently from how it was.
bool ChangesReading(const po::variables_map& vm) {
  for (const char* option :
       {"mass", "inertia", "com-height", "gravity", "regular-times", "missing-as-gaps"}) {
    if (vm.count(option)) return true;
  }
  return !vm["max-gap-ratio"].defaulted();
}

/// `log` read again from its text with `options` (slider overrides, largest gap, regular
/// times, dropouts), as the
/// file it makes would be read with them.
Trajectory Reread(const PushLogFile& file, const LogReadOptions& options, FileIdentifyResult* run) {
  const Trajectory& log = file.log;
  std::ostringstream text;
  WritePushLog(file, text);
  LogReadReport report;
  Trajectory again = ParsePushLog(text.str(), log.source, options, &report);
  again.source = log.source;
  run->warnings.insert(run->warnings.end(), report.warnings.begin(), report.warnings.end());
  for (const std::string& n : report.notes) run->notes.push_back(log.source + ": " + n);
  return again;
}

py::dict Residuals(const EstimateResult& result) {
  const size_t n = result.residuals.size();
  py::array_t<int> log(n), row(n);
  py::array_t<double> t(n), r0(n), r1(n), r2(n);
  py::array_t<bool> used(n);
  for (size_t k = 0; k < n; ++k) {
    const StepResidual& r = result.residuals[k];
    log.mutable_at(k) = r.log;
    row.mutable_at(k) = r.row;
    t.mutable_at(k) = r.t_s;
    r0.mutable_at(k) = r.value[0];
    r1.mutable_at(k) = r.value[1];
    r2.mutable_at(k) = r.value[2];
    used.mutable_at(k) = r.used;
  }
  py::dict out;
  out["log"] = log;
  out["row"] = row;
  out["t"] = t;
  out[py::str(result.residual_names[0])] = r0;
  out[py::str(result.residual_names[1])] = r1;
  out[py::str(result.residual_names[2])] = r2;
  out["used"] = used;
  return out;
}

py::object Truth(const std::optional<ReducedFriction>& truth) {
  if (!truth) return py::none();
  py::dict d;
  d["e_t_mu"] = truth->a;
  d["e_o_over_e_t"] = truth->b;
  d["e_r_over_e_t"] = truth->c;
  return d;
}

/// identify's keyword arguments read as its options are (TypeError, OptionError).
po::variables_map IdentifyKeywords(const py::kwargs& keywords) {
  po::options_description general, advanced;
  cli::AddIdentifyOptions(&general, &advanced);
  general.add(advanced);
  return ParseKeywords("identify", general, keywords, kNotKeywords);
}

/// Checks identify's keyword arguments without reading a log: what a map over many logs
/// does once before sending them out, since a bad option would fail every log.
void CheckIdentifyKeywords(const py::kwargs& keywords) {
  cli::ReadFileIdentifyOptions(IdentifyKeywords(keywords));
}

/// The logs a directory or a glob names, sorted, as identify --logs and --batch find them.
std::vector<std::string> LogFiles(const std::string& directory_or_glob) {
  return ExpandFiles(directory_or_glob);
}

/// Identifies `inputs`: all paths (as the identify tool does) or all LogHandles.
py::dict IdentifyInputs(const py::list& inputs, const py::kwargs& keywords) {
  const po::variables_map vm = IdentifyKeywords(keywords);
  const FileIdentifyOptions options = cli::ReadFileIdentifyOptions(vm);

  std::vector<std::string> paths;
  std::vector<LogPtr> handles;
  for (py::handle item : inputs) {
    if (py::isinstance<LogHandle>(item)) {
      handles.push_back(item.cast<LogPtr>());
    } else {
      paths.push_back(item.cast<std::string>());
    }
  }
  if (!paths.empty() && !handles.empty()) {
    throw std::invalid_argument(
        "identify: give paths or Log objects, not both (read the "
        "paths with read_log)");
  }
  FileIdentifyResult run;
  std::string what;
  // The readers' warnings, and those of them not yet issued (read_log issued its own).
  std::vector<std::string> warnings, fresh_warnings, notes;
  std::vector<Trajectory> read_logs;  // kept for the report
  if (handles.empty()) {
    what = paths.size() == 1 ? paths[0] : std::to_string(paths.size()) + " logs";
    {
      py::gil_scoped_release release;
      run = IdentifyFiles(paths, options);
    }
    warnings = fresh_warnings = run.warnings;
    notes = run.notes;
  } else {
    const bool reread = ChangesReading(vm);
    std::vector<Trajectory> logs;
    for (const LogPtr& h : handles) {
      if (reread) {
        FileIdentifyResult reading;
        logs.push_back(Reread(h->file, options.read, &reading));
        fresh_warnings.insert(fresh_warnings.end(), reading.warnings.begin(),
                              reading.warnings.end());
        notes.insert(notes.end(), reading.notes.begin(), reading.notes.end());
        continue;
      }
      logs.push_back(h->file.log);
      warnings.insert(warnings.end(), h->warnings.begin(), h->warnings.end());
      for (const std::string& n : h->notes) notes.push_back(h->file.log.source + ": " + n);
    }
    warnings.insert(warnings.end(), fresh_warnings.begin(), fresh_warnings.end());
    what = logs.size() == 1 ? (logs[0].source.empty() ? "the log" : logs[0].source)
                            : std::to_string(logs.size()) + " logs";
    py::gil_scoped_release release;
    if (vm.count("report")) read_logs = logs;  // the report shows them
    run = IdentifyReadLogs(std::move(logs), options);
  }
  if (vm.count("report")) {  // report=PATH: identify --report's page
    py::gil_scoped_release release;
    ReportInputs report = handles.empty() ? GatherIdentifyReport(paths, options, run)
                                          : GatherIdentifyReportOfLogs(read_logs, options, run);
    report.command_line = "slideid.identify(" + what + ", report=...)";
    report.timings = {{"the fit itself", run.result.seconds}};
    WriteHtmlReport(report, vm["report"].as<std::string>());
  }
  const EstimateResult& result = run.result;
  py::dict out;
  out["json"] = FormatJson(result);
  out["what"] = what;
  out["too_little_excitation"] = result.status == TerminationStatus::kTooLittleExcitation;
  out["failure"] = NumericalFailure(result);
  out["suspects"] = SuspectNames(result);
  out["suspect_summary"] = SuspectSummary(result);  // the warning, with counts when pooled
  out["residuals"] = Residuals(result);
  out["truth"] = Truth(run.truth);
  out["warnings"] = warnings;
  out["fresh_warnings"] = fresh_warnings;
  out["notes"] = notes;
  return out;
}

/// The pre-fit check of `inputs` (all paths or all LogHandles): one identify --check --json
/// line per log, with the readers' warnings. A path that cannot be read raises (bad input).
py::dict CheckInputs(const py::list& inputs, const py::kwargs& keywords) {
  const po::variables_map vm = IdentifyKeywords(keywords);
  if (vm["method"].as<std::string>() != "trajectory") {
    throw po::error("--check forecasts the trajectory fit: it does not go with --method " +
                    vm["method"].as<std::string>());
  }
  const FileIdentifyOptions options = cli::ReadFileIdentifyOptions(vm);
  std::vector<std::string> paths;
  std::vector<Trajectory> logs;
  for (py::handle item : inputs) {
    if (py::isinstance<LogHandle>(item)) {
      logs.push_back(item.cast<LogPtr>()->file.log);
    } else {
      paths.push_back(item.cast<std::string>());
    }
  }
  if (!paths.empty() && !logs.empty()) {
    throw std::invalid_argument("check: give paths or Log objects, not both");
  }
  std::vector<FileCheck> checks;
  {
    py::gil_scoped_release release;
    checks = logs.empty() ? CheckFiles(paths, options) : CheckReadLogs(logs, options);
  }
  std::vector<std::string> lines, warnings;
  for (const FileCheck& f : checks) {
    if (!f.check) throw FileError(f.error);
    lines.push_back(FormatCheckJson(*f.check));
    warnings.insert(warnings.end(), f.warnings.begin(), f.warnings.end());
  }
  py::dict out;
  out["json"] = lines;
  out["warnings"] = warnings;
  return out;
}

}  // namespace

void BindIdentify(py::module_& m) {
  m.def("check", &CheckInputs, py::arg("inputs"));
  m.def("identify", &IdentifyInputs, py::arg("inputs"));
  m.def("check_identify_options", &CheckIdentifyKeywords);
  m.def("log_files", &LogFiles, py::arg("directory_or_glob"));
}

}  // namespace slideid::python
