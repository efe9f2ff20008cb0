#pragma once
// What the HTML report shows, gathered beforehand (pipeline/report_files.h reads the files,
// replays and checks the logs): plain data, so that report/ renders without touching a
// file, and a test can render a report made up in memory.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "estimator/estimate.h"
#include "estimator/log_check.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"
#include "prediction/validate.h"

namespace slideid {

/// One log of the run, with what was made of it.
struct ReportLog {
  std::string name;  ///< its file name: how the result, the check and validate name it
  std::string path;  ///< as given on the command line
  Trajectory log;    ///< as read
  /// Its index among the fitted logs of `ReportInputs::result` (the residuals' `log`); -1
  /// when it was not fitted (skipped).
  int fit_index = -1;
  /// identify: the log replayed from its first row under the logged forces with the
  /// estimates (held values where not identifiable), and how that went ("" when fine).
  std::optional<Trajectory> replay;
  std::string replay_note;
  /// validate: the push predicted by its fold's friction, and how that went.
  std::optional<Trajectory> prediction;
  std::string prediction_note;
  /// The check before fitting (estimator/log_check.h), or why there is none.
  std::optional<LogCheck> check;
  std::string check_note;
  /// Its row of the import report beside it (import-log's DIR/import_report.csv), as
  /// (column, cell) pairs; empty when it has none.
  std::vector<std::pair<std::string, std::string>> import_row;
  std::string import_report_path;
};

/// A step of the run and how long it took.
struct ReportTiming {
  std::string what;
  double seconds = 0;
};

/// Everything one report shows.
struct ReportInputs {
  std::string tool;          ///< "identify" or "validate"
  std::string command_line;  ///< as typed (each argument shell-quoted where needed)
  std::string version;       ///< the project's version (CMake's)
  std::vector<ReportTiming> timings;
  /// identify: the result, and the truth the logs record (simulated logs), when they agree.
  std::optional<EstimateResult> result;
  std::optional<ReducedFriction> truth;
  /// validate: the cross-validation.
  std::optional<ValidationResult> validation;
  std::vector<ReportLog> logs;
  std::vector<std::string> warnings;  ///< what the readers and the run warned of
};

}  // namespace slideid
