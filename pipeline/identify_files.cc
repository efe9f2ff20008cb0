#include "pipeline/identify_files.h"

#include <glob.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>

#include "estimator/identify.h"
#include "estimator/log_diagnostics.h"
#include "estimator/pooling.h"
#include "estimator/quasi_static_fit.h"
#include "io/wrench_twist_csv.h"

namespace slideid {
namespace {

// What make-dataset (truth.csv) and import-log (import_report.csv) write beside their logs,
// and the name every per-file import report ends with (pipeline/import_files.h).
const char* const kManifestNames[] = {"truth.csv", "import_report.csv"};
constexpr const char kReportSuffix[] = "_import_report.csv";

bool IsManifest(const std::string& name) {
  const std::string suffix = kReportSuffix;
  return std::find(std::begin(kManifestNames), std::end(kManifestNames), name) !=
             std::end(kManifestNames) ||
         (name.size() >= suffix.size() &&
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0);
}

std::vector<std::string> ExpandAllFiles(const std::string& directory_or_glob,
                                        const std::string& extension);

std::string FileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

LogResult Skipped(const std::string& path, const std::string& reason) {
  LogResult r;
  r.name = FileName(path);
  r.skipped = true;
  r.skip_reason = reason;
  return r;
}

// The truth every input records, or none when one lacks it or they differ.
template <typename Input>
std::optional<ReducedFriction> CommonTruth(const std::vector<Input>& inputs) {
  std::optional<ReducedFriction> truth;
  for (const Input& in : inputs) {
    if (!in.true_friction) return std::nullopt;
    const ReducedFriction t = ReducedFriction::From(*in.true_friction);
    if (truth && (truth->a != t.a || truth->b != t.b || truth->c != t.c)) return std::nullopt;
    truth = t;
  }
  return truth;
}

// A dead force channel cannot be pooled with the others: it would explain their motion with
// no force at all. Throws FileError naming the log `name`.
void CheckPoolable(const Trajectory& log, const std::string& name) {
  if (const auto dead = DiagnoseLog(log).dead_force_channel) throw FileError(name + ": " + *dead);
}

// Reads every file with `read`; a file that throws is skipped (skip_bad) or fails the run.
template <typename Input, typename Read>
std::vector<Input> ReadAll(const std::vector<std::string>& paths, bool skip_bad, Read read,
                           std::vector<LogResult>* skipped) {
  std::vector<Input> inputs;
  for (const std::string& path : paths) {
    try {
      inputs.push_back(read(path));
    } catch (const std::exception& e) {
      if (!skip_bad) throw FileError(e.what());
      skipped->push_back(Skipped(path, e.what()));
    }
  }
  if (inputs.empty()) {
    throw FileError(paths.empty() ? "no files to identify"
                                  : "every file was skipped: nothing left to identify");
  }
  return inputs;
}

void AppendSkipped(std::vector<LogResult> skipped, EstimateResult* result) {
  result->logs.insert(result->logs.end(), std::make_move_iterator(skipped.begin()),
                      std::make_move_iterator(skipped.end()));
}

// Why a log's own fit within a pooled one identifies nothing usable, or "": NothingIdentified,
// or a fit that did not converge (an inertia of 1e-300 overflows at its end).
std::string NothingOfItsOwn(const LogResult& log) {
  if (!log.skipped && log.status == TerminationStatus::kNoConvergence) {
    return "its fit did not converge";
  }
  return NothingIdentified(log);
}

// The logs of a pooled `result` that identify nothing on their own while another log does:
// when the pooled fit identifies nothing, they spoilt it (a heading of 1e17 rad whose rows
// all read the same outweighs a good log). Empty otherwise, and when no log identifies
// anything on its own (nothing to tell the spoilt from the spoiling).
std::vector<size_t> SpoilingLogs(const EstimateResult& result) {
  if (result.logs.size() < 2 || NothingIdentified(result).empty()) return {};
  std::vector<size_t> spoiling;
  for (size_t k = 0; k < result.logs.size(); ++k) {
    if (!NothingOfItsOwn(result.logs[k]).empty()) spoiling.push_back(k);
  }
  if (spoiling.size() == result.logs.size()) return {};
  return spoiling;
}

// Identify(logs), named `names`, as the pooling rule for logs that cannot be pooled has it
// (CheckPoolable): a log that spoilt a pooled fit (SpoilingLogs) fails the run with a
// FileError naming it and why, or with skip_bad is listed as skipped, with a warning, and
// the other logs are fitted again without it.
EstimateResult IdentifyWithoutSpoilingLogs(std::vector<Trajectory>* logs,
                                           std::vector<std::string>* names,
                                           const FileIdentifyOptions& options,
                                           std::vector<LogResult>* skipped,
                                           std::vector<std::string>* warnings) {
  EstimateResult result = Identify(*logs, options.identify);
  const std::vector<size_t> spoiling = SpoilingLogs(result);
  if (spoiling.empty()) return result;
  const std::string pooled = NothingIdentified(result);
  for (size_t k : spoiling) {
    const std::string own = NothingOfItsOwn(result.logs[k]);
    std::string why = "identifies nothing on its own (" + own +
                      "), and pooled with logs that do, it leaves the fit identifying nothing";
    if (pooled.find(own) == std::string::npos) why += " (" + pooled + ")";
    // The reader's warning on it, if any, is the likeliest cause; an error would lose it.
    const auto warned = std::find_if(warnings->begin(), warnings->end(), [&](const std::string& w) {
      return w.compare(0, (*names)[k].size() + 1, (*names)[k] + ":") == 0;
    });
    if (warned != warnings->end()) why += "; the reader warned: " + *warned;
    if (!options.skip_bad) {
      throw FileError((*names)[k] + ": " + why + ": leave it out, or skip it (--skip-bad)");
    }
    warnings->push_back((*names)[k] + ": skipped: " + why);
    skipped->push_back(Skipped((*names)[k], why));
  }
  for (auto k = spoiling.rbegin(); k != spoiling.rend(); ++k) {
    logs->erase(logs->begin() + static_cast<std::ptrdiff_t>(*k));
    names->erase(names->begin() + static_cast<std::ptrdiff_t>(*k));
  }
  return Identify(*logs, options.identify);
}

FileIdentifyResult IdentifyPushLogs(const std::vector<std::string>& paths,
                                    const FileIdentifyOptions& options) {
  FileIdentifyResult out;
  std::vector<LogResult> skipped;
  std::vector<std::string> read_paths;  // of the logs read, in order
  std::vector<Trajectory> logs = ReadAll<Trajectory>(
      paths, options.skip_bad,
      [&](const std::string& path) {
        LogReadReport report;
        Trajectory log = ReadPushLog(path, options.read, &report);
        log.source = FileName(path);
        for (const std::string& w : report.warnings) out.warnings.push_back(w);
        for (const std::string& n : report.notes) out.notes.push_back(path + ": " + n);
        if (paths.size() > 1) CheckPoolable(log, path);
        read_paths.push_back(path);
        return log;
      },
      &skipped);
  out.result = IdentifyWithoutSpoilingLogs(&logs, &read_paths, options, &skipped, &out.warnings);
  out.truth = CommonTruth(logs);  // of the logs fitted, without those that spoilt the pool
  AppendSkipped(std::move(skipped), &out.result);
  if (options.keep_logs) {
    for (std::size_t k = 0; k < logs.size(); ++k) {
      out.logs.emplace_back(read_paths[k], std::move(logs[k]));
    }
  }
  return out;
}

// Quasi-static: every file's pairs fitted on its own, and all pairs pooled (one slider:
// the files must share its weight).
FileIdentifyResult IdentifyPairFiles(const std::vector<std::string>& paths,
                                     const FileIdentifyOptions& options) {
  FileIdentifyResult out;
  std::vector<LogResult> skipped;
  std::vector<WrenchTwistData> files = ReadAll<WrenchTwistData>(
      paths, options.skip_bad,
      [&](const std::string& path) {
        WrenchTwistReadReport report;
        WrenchTwistData data = ReadWrenchTwistCsv(path, options.read.overrides, &report);
        data.source = FileName(path);
        for (const std::string& n : report.notes) out.notes.push_back(path + ": " + n);
        return data;
      },
      &skipped);
  out.truth = CommonTruth(files);
  try {
    out.result = EstimateQuasiStatic(files, options.identify);
  } catch (const std::invalid_argument& e) {  // names the file: too few pairs, weights, ...
    throw FileError(e.what());
  }
  AppendSkipped(std::move(skipped), &out.result);
  return out;
}

}  // namespace

namespace {

// NothingIdentified of a fit's status, message and parameters: a pooled fit's or a log's own.
std::string NothingIdentified(TerminationStatus status, const std::string& message,
                              const std::array<ParameterEstimate, 3>& parameters) {
  if (status == TerminationStatus::kTooLittleExcitation) return message;
  // A fit that did not converge is a numerical failure (exit 3) whatever it left identifiable.
  if (status == TerminationStatus::kNoConvergence) return "";
  std::vector<std::string> reasons;
  for (const ParameterEstimate& p : parameters) {
    if (p.identifiable) return "";
    if (std::find(reasons.begin(), reasons.end(), p.reason) == reasons.end()) {
      reasons.push_back(p.reason);
    }
  }
  std::string why = "no friction parameter is identifiable";
  for (size_t k = 0; k < reasons.size(); ++k) {
    if (!reasons[k].empty()) why += (k == 0 ? ": " : "; ") + reasons[k];
  }
  return why;
}

}  // namespace

std::string NothingIdentified(const EstimateResult& result) {
  return NothingIdentified(result.status, result.message, result.parameters);
}

std::string NothingIdentified(const LogResult& log) {
  return log.skipped ? "" : NothingIdentified(log.status, log.message, log.parameters);
}

std::string NumericalFailure(const EstimateResult& result) {
  const std::string fit = std::string("the ") + ToString(result.method) + " fit";
  if (!result.converged) return fit + " did not converge (" + result.message + ")";
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = result.parameters[i];
    if (p.identifiable && !(std::isfinite(p.value) && std::isfinite(p.stderr_value) &&
                            std::isfinite(p.ci95_lo) && std::isfinite(p.ci95_hi))) {
      return fit + " gave a non-finite " + ParameterName(i);
    }
  }
  return "";
}

std::string SuspectNames(const EstimateResult& result) {
  std::string names;
  for (int i = 0; i < 3; ++i) {
    if (result.parameters[i].verdict == Verdict::kSuspect) {
      names += (names.empty() ? "" : ", ") + std::string(ParameterName(i));
    }
  }
  for (const NuisanceEstimate& n : result.nuisance) {
    if (n.verdict == Verdict::kSuspect) names += (names.empty() ? "" : ", ") + n.name;
  }
  return names;
}

std::string SuspectSummary(const EstimateResult& result) {
  const std::string names = SuspectNames(result);
  if (names.empty()) return "";
  int fitted = 0, suspect = 0;
  for (const LogResult& log : result.logs) {
    if (log.skipped) continue;
    ++fitted;
    suspect +=
        std::any_of(log.parameters.begin(), log.parameters.end(),
                    [](const ParameterEstimate& p) { return p.verdict == Verdict::kSuspect; });
  }
  if (fitted == 0) return "suspect estimates (" + names + "): see their reasons";
  return "suspect estimates of the pooled fit (" + names + "): see their reasons; of the " +
         std::to_string(fitted) + " logs, " + std::to_string(suspect) +
         (suspect == 1 ? " has suspect estimates" : " have suspect estimates") + " of their own, " +
         std::to_string(fitted - suspect) + (fitted - suspect == 1 ? " does not" : " do not");
}

FileIdentifyResult IdentifyReadLogs(std::vector<Trajectory> logs,
                                    const FileIdentifyOptions& options) {
  std::string why;
  if (!options.identify.IsValid(&why)) throw std::invalid_argument(why);
  if (options.identify.method == EstimatorMethod::kQuasiStatic) {
    throw std::invalid_argument(
        "the quasi-static method fits wrench-twist pairs, read from "
        "files: give their paths, not push logs");
  }
  FileIdentifyResult out;
  std::vector<LogResult> skipped;
  std::vector<Trajectory> kept;
  std::vector<std::string> kept_names;
  for (size_t k = 0; k < logs.size(); ++k) {
    const std::string name =
        logs[k].source.empty() ? "log " + std::to_string(k + 1) : logs[k].source;
    try {
      if (logs.size() > 1) CheckPoolable(logs[k], name);
      kept.push_back(std::move(logs[k]));
      kept_names.push_back(name);
    } catch (const FileError& e) {
      if (!options.skip_bad) throw;
      skipped.push_back(Skipped(name, e.what()));
    }
  }
  if (kept.empty()) {
    throw FileError(logs.empty() ? "no logs to identify"
                                 : "every log was skipped: nothing left to identify");
  }
  out.result = IdentifyWithoutSpoilingLogs(&kept, &kept_names, options, &skipped, &out.warnings);
  out.truth = CommonTruth(kept);  // of the logs fitted, without those that spoilt the pool
  AppendSkipped(std::move(skipped), &out.result);
  return out;
}

FileIdentifyResult IdentifyFiles(const std::vector<std::string>& paths,
                                 const FileIdentifyOptions& options) {
  std::string why;
  if (!options.identify.IsValid(&why)) throw std::invalid_argument(why);
  if (options.identify.method == EstimatorMethod::kQuasiStatic) {
    return IdentifyPairFiles(paths, options);
  }
  return IdentifyPushLogs(paths, options);
}

std::vector<std::string> ExpandFiles(const std::string& directory_or_glob,
                                     const std::string& extension) {
  std::vector<std::string> files = ExpandAllFiles(directory_or_glob, extension);
  // The manifests our own tools write beside their logs are not logs.
  files.erase(std::remove_if(files.begin(), files.end(),
                             [](const std::string& f) { return IsManifest(FileName(f)); }),
              files.end());
  if (files.empty()) {
    throw FileError(directory_or_glob + ": names no " + extension +
                    " file other than manifests (a directory or a glob)");
  }
  return files;
}

namespace {

std::vector<std::string> ExpandAllFiles(const std::string& directory_or_glob,
                                        const std::string& extension) {
  std::vector<std::string> files;
  std::error_code ec;
  if (std::filesystem::is_directory(directory_or_glob, ec)) {
    for (const auto& entry : std::filesystem::directory_iterator(directory_or_glob, ec)) {
      if (entry.is_regular_file() && entry.path().extension() == extension) {
        files.push_back(entry.path().string());
      }
    }
    if (ec) throw FileError(directory_or_glob + ": cannot list the directory: " + ec.message());
  } else {
    glob_t matches{};
    if (glob(directory_or_glob.c_str(), 0, nullptr, &matches) == 0) {
      for (size_t i = 0; i < matches.gl_pathc; ++i) files.emplace_back(matches.gl_pathv[i]);
    }
    globfree(&matches);
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    throw FileError(directory_or_glob + ": names no " + extension +
                    " file (a directory or a glob)");
  }
  return files;
}

}  // namespace

}  // namespace slideid
