#pragma once
// Identification of files: read each (push logs, or wrench-twist pairs for the quasi-static
// method), skip the bad ones if asked, and identify them, pooled when there are several.
// What `identify` and the Python module's identify() do.

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"
#include "io/push_log.h"

namespace slideid {

/// How to read and identify.
struct FileIdentifyOptions {
  IdentifyOptions identify;
  LogReadOptions read;  ///< slider overrides and the largest gap
  /// A file that cannot be read, or that the method cannot use, is listed in result.logs
  /// as skipped (with the reason) instead of failing the whole run.
  bool skip_bad = false;
  /// Keep the push logs read in the result (FileIdentifyResult::logs), for a report drawn
  /// after the fit: a log from a pipe cannot be read a second time.
  bool keep_logs = false;
};

/// The identification and what the readers said.
struct FileIdentifyResult {
  EstimateResult result;
  /// The truth the files record (simulated logs), when they all record the same.
  std::optional<ReducedFriction> truth;
  std::vector<std::string> warnings;  ///< likely mistakes, each naming its file
  std::vector<std::string> notes;     ///< plain facts, each naming its file
  /// With keep_logs: each push log read, with its path (the skipped ones left out).
  std::vector<std::pair<std::string, Trajectory>> logs;
};

/// A file that fails the whole run: its message names it (LogError and friends already do).
class FileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads `paths` and identifies them. Throws FileError for a file that cannot be read
/// (unless options.skip_bad), or when no file is left; std::invalid_argument for invalid
/// options. What the files cannot tell is the result's status, as for Identify.
FileIdentifyResult IdentifyFiles(const std::vector<std::string>& paths,
                                 const FileIdentifyOptions& options);

/// Why `result` identifies nothing, or "" when it identifies something: the status too
/// little excitation (its message), or a converged fit of any method in which no friction
/// parameter is identifiable (their reasons, each once). The tools' exit 1, bad input
/// (README, "Exit codes"); a fit that did not converge is NumericalFailure's.
std::string NothingIdentified(const EstimateResult& result);
/// The same of a log's own fit within a pooled one ("" for a skipped log).
std::string NothingIdentified(const LogResult& log);

/// Why `result` must not be used (a numerical failure: no convergence, a non-finite
/// estimate), or "" when it may.
std::string NumericalFailure(const EstimateResult& result);

/// The names of the suspect estimates ("e_t_mu, force_bias_x_n"), or "".
std::string SuspectNames(const EstimateResult& result);

/// The warning about suspect estimates, "" when there is none: "suspect estimates (e_t_mu):
/// see their reasons", and for a pooled fit how many of its logs have suspect estimates of
/// their own ("...; of the 11 logs, 3 have suspect estimates of their own, 8 do not").
std::string SuspectSummary(const EstimateResult& result);

/// What IdentifyFiles does once push logs are read, for logs already in memory (the Python
/// module's): a log that cannot be pooled with the others (a dead force channel) is listed
/// as skipped (options.skip_bad) or fails the run with a FileError naming its source.
/// options.read is not used. Throws std::invalid_argument for invalid options or the
/// quasi-static method (it fits wrench-twist pairs, read from files).
FileIdentifyResult IdentifyReadLogs(std::vector<Trajectory> logs,
                                    const FileIdentifyOptions& options);

/// The files named by a directory (its files ending in `extension`), or by a glob pattern,
/// sorted; without the manifests our tools write beside their logs (truth.csv of
/// make-dataset, import_report.csv of import-log). Throws FileError when it names none.
std::vector<std::string> ExpandFiles(const std::string& directory_or_glob,
                                     const std::string& extension = ".csv");

}  // namespace slideid
