#include "pipeline/report_files.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "estimator/log_check.h"
#include "forward_model/number_format.h"
#include "forward_model/simulator.h"
#include "io/atomic_file.h"
#include "io/import_report_row.h"
#include "io/push_log.h"
#include "report/html_report.h"

namespace slideid {
namespace {

std::string FileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

// The value a replay uses: the estimate, or where the parameter was held.
double ReplayValue(const ParameterEstimate& p) {
  return std::isfinite(p.value) ? p.value : p.held_at;
}

// The check, the import report row: what every report shows of a log.
void Describe(const IdentifyOptions& options, const std::string& path, ReportLog* out) {
  try {
    out->check = CheckLog(out->log, options);
  } catch (const std::exception& e) {
    out->check_note = e.what();
  }
  out->import_report_path = ImportReportBeside(path);
  out->import_row = FindImportReportRow(out->import_report_path, out->name);
}

// Where a simulation that did not reach the end stopped, in words.
std::string StoppedNote(const char* what, const SimulationSummary& s, const Trajectory& t) {
  if (s.ok()) return "";
  return Printf("The %s stopped at t = %.3f s: %s (%s).", what,
                t.samples.empty() ? 0.0 : t.samples.back().t_s, ToString(s.status), s.message);
}

}  // namespace

namespace {

// identify's report of logs already read (each ReportLog's name, path and log set).
ReportInputs IdentifyReportOf(std::vector<ReportLog> logs, const FileIdentifyOptions& options,
                              const FileIdentifyResult& run, std::vector<std::string> warnings) {
  ReportInputs in;
  in.tool = "identify";
  in.version = SLIDEID_VERSION;
  in.result = run.result;
  in.truth = run.truth;
  in.warnings = run.warnings;
  in.warnings.insert(in.warnings.end(), warnings.begin(), warnings.end());
  const EstimateResult& r = run.result;
  if (options.identify.method == EstimatorMethod::kQuasiStatic) {
    in.warnings.push_back(
        "the quasi-static method fits wrench-twist pairs, not push logs: the "
        "report has no per-log section");
    return in;
  }
  // The fitted logs' order (the residuals' `log`): the pooled entries not skipped.
  std::vector<std::string> fitted;
  for (const LogResult& l : r.logs) {
    if (!l.skipped) fitted.push_back(l.name);
  }
  const ReducedFriction friction{ReplayValue(r.parameters[kA]), ReplayValue(r.parameters[kB]),
                                 ReplayValue(r.parameters[kC])};
  const bool replayable =
      std::isfinite(friction.a) && std::isfinite(friction.b) && std::isfinite(friction.c);
  for (ReportLog& l : logs) {
    if (fitted.empty()) {
      l.fit_index = 0;  // one log: the one fitted
    } else {
      const auto at = std::find(fitted.begin(), fitted.end(), l.name);
      l.fit_index = at == fitted.end() ? -1 : static_cast<int>(at - fitted.begin());
    }
    if (!replayable) {
      l.replay_note = "No replay: the fit gave no value to replay with.";
    } else if (l.log.samples.size() >= 2) {
      try {
        SimulationResult replay = ReplayLog(l.log, friction, options.identify.trajectory.substeps);
        l.replay_note = StoppedNote("replay", replay.summary, replay.trajectory);
        l.replay = std::move(replay.trajectory);
      } catch (const std::exception& e) {
        l.replay_note = std::string("No replay: ") + e.what();
      }
    }
    Describe(options.identify, l.path, &l);
    in.logs.push_back(std::move(l));
  }
  return in;
}

// A push log read from `path`, named in the page by its file name.
ReportLog FileReportLog(const std::string& path, Trajectory log) {
  ReportLog l;
  l.path = path;
  l.name = FileName(path);
  l.log = std::move(log);
  l.log.source = l.name;
  return l;
}

}  // namespace

ReportInputs GatherIdentifyReport(const std::vector<std::string>& paths,
                                  const FileIdentifyOptions& options,
                                  const FileIdentifyResult& run) {
  std::vector<ReportLog> logs;
  std::vector<std::string> warnings;
  if (options.identify.method != EstimatorMethod::kQuasiStatic) {
    // The logs the fit read, where it kept them: a log from a pipe (--log <(zcat ...))
    // cannot be read again, and a second read was empty, leaving the log out of the page
    // without a word.
    for (const auto& [path, log] : run.logs) logs.push_back(FileReportLog(path, log));
    if (run.logs.empty()) {
      for (const std::string& path : paths) {
        try {
          logs.push_back(FileReportLog(path, ReadPushLog(path, options.read)));
        } catch (const std::exception& e) {
          warnings.push_back("report: " + std::string(e.what()));
        }
      }
    }
  }
  return IdentifyReportOf(std::move(logs), options, run, warnings);
}

ReportInputs GatherIdentifyReportOfLogs(const std::vector<Trajectory>& logs,
                                        const FileIdentifyOptions& options,
                                        const FileIdentifyResult& run) {
  std::vector<ReportLog> entries;
  for (size_t k = 0; k < logs.size(); ++k) {
    ReportLog l;
    l.path = logs[k].source;
    // As IdentifyReadLogs names them.
    l.name = logs[k].source.empty() ? "log " + std::to_string(k + 1) : logs[k].source;
    l.log = logs[k];
    entries.push_back(std::move(l));
  }
  return IdentifyReportOf(std::move(entries), options, run, {});
}

ReportInputs GatherValidateReport(const std::vector<Trajectory>& logs,
                                  const ValidationOptions& options,
                                  const ValidationResult& result) {
  ReportInputs in;
  in.tool = "validate";
  in.version = SLIDEID_VERSION;
  in.validation = result;
  const MethodValidation* folds = nullptr;
  for (const MethodValidation& m : result.methods) {
    if (m.method == "folds") folds = &m;
  }
  for (const Trajectory& log : logs) {
    ReportLog l;
    l.path = log.source;
    l.name = FileName(log.source);
    l.log = log;
    const PushPrediction* push = nullptr;
    if (folds) {
      for (const PushPrediction& p : folds->pushes) {
        if (p.log == log.source || p.log == l.name) push = &p;
      }
    }
    if (!push) {
      l.prediction_note = "No prediction of its fold.";
    } else {
      try {
        const Prediction p = PredictPush(
            log, push->friction, std::optional<double>(push->mu_pusher), options.prediction);
        l.prediction_note = StoppedNote("prediction", p.summary, p.predicted);
        l.prediction = p.predicted;
      } catch (const std::exception& e) {
        l.prediction_note = std::string("No prediction: ") + e.what();
      }
    }
    Describe(options.identify, log.source, &l);
    in.logs.push_back(std::move(l));
  }
  return in;
}

void WriteHtmlReport(const ReportInputs& inputs, const std::string& path) {
  WriteFileAtomically(path, "the HTML report", RenderHtmlReport(inputs));
}

std::string QuotedCommandLine(int argc, const char* const* argv) {
  std::string line;
  for (int k = 0; k < argc; ++k) {
    const std::string arg = argv[k];
    const bool plain = !arg.empty() && std::all_of(arg.begin(), arg.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) ||
             std::string("-_./=:,+@%").find(c) != std::string::npos;
    });
    std::string quoted = "'";
    for (const char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    quoted += "'";
    line += (k ? " " : "") + (plain ? arg : quoted);
  }
  return line;
}

}  // namespace slideid
