#pragma once
// Reading and writing push logs in the CSV format of docs/log-format.md.
// The reader uses fast-cpp-csv-parser; columns are found by name in any order.

#include <iosfwd>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "forward_model/trajectory.h"

namespace slideid {

/// Bad log: the message names the file, the line (1-based, counting comment lines) and,
/// where there is one, the column.
class LogError : public std::runtime_error {
 public:
  LogError(const std::string& file, int line, const std::string& column, const std::string& what);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& column() const { return column_; }

 private:
  std::string file_;
  int line_;
  std::string column_;
};

/// Known slider properties that override the log's metadata (command-line options).
struct SliderOverrides {
  std::optional<double> mass_kg, inertia_kgm2, com_height_m, gravity_mps2;
};

struct LogReadOptions {
  SliderOverrides overrides;
  /// Require mass and inertia (and com_height) to be known; identify needs them.
  bool require_slider_properties = true;
  /// An interval between rows longer than this many times the median interval is an error
  /// (the model holds the force across it: docs/robustness.md); 0 or less: no limit.
  double max_gap_ratio = 10.0;
  /// Put each run's rows on a regular grid (io/row_times.h), for a logger that samples
  /// regularly and stamps the rows on arrival; without it such times are warned of.
  bool regular_times = false;
  /// Drop a row with a missing cell (empty or NaN: a motion-capture dropout) and start a new
  /// run at the next row, as a gap marked `start` would, instead of failing on it.
  bool missing_as_gaps = false;
  /// With missing_as_gaps, a text whose rows were all dropped reads as a log without rows
  /// instead of an error: a stream read one row at a time (identify --follow).
  bool allow_no_rows = false;
};

/// What the reader noticed that is not an error.
struct LogReadReport {
  /// Likely mistakes, each "file:line: column 'c': what": absurd magnitudes (a unit
  /// error?), long gaps in t. Tools print them always.
  std::vector<std::string> warnings;
  /// Plain facts (unknown columns, unwrapped theta, velocities from poses, ...). Tools print
  /// them with --verbose.
  std::vector<std::string> notes;
  std::vector<std::string> unknown_columns;
  bool velocities_from_poses = false;  ///< velocities came from the kinematic map
};

/// A push log file: the trajectory and what the file says beyond the physics, kept so that
/// writing back a log read in gives the same text.
struct PushLogFile {
  Trajectory log;
  /// The `# patch` text as the file has it ("rectangle 0.090 0.09"): written while it still
  /// describes log.patch, else log.patch's own Spec(). Empty: Spec().
  std::string patch_spec;
  /// Further `# key = value` metadata, in order (noise description, scene name, ...).
  std::vector<std::pair<std::string, std::string>> extra_metadata;
};

/// Reads a log. Velocities: as given when present, else from poses by the backward-Euler
/// kinematic map (first row's velocity: 0, flagged by mode kStart). Applied moments: tx, ty,
/// tz plus r x f when px, py, pz are present. theta is unwrapped. log.measured names the
/// columns present. Throws LogError.
PushLogFile ReadPushLogFile(const std::string& path, const LogReadOptions& options = {},
                            LogReadReport* report = nullptr);
/// Same, from the text of a log in memory; `source` names it in messages (fuzzing, tests).
PushLogFile ParsePushLogFile(std::string_view text, const std::string& source,
                             const LogReadOptions& options = {}, LogReadReport* report = nullptr);
/// The trajectory alone of ReadPushLogFile and ParsePushLogFile, for those that only fit it.
Trajectory ReadPushLog(const std::string& path, const LogReadOptions& options = {},
                       LogReadReport* report = nullptr);
Trajectory ParsePushLog(std::string_view text, const std::string& source,
                        const LogReadOptions& options = {}, LogReadReport* report = nullptr);

/// The `# patch` text that WritePushLog writes for `file`; empty without a patch.
std::string PatchText(const PushLogFile& file);

/// Writes `file` with the metadata comments (slider, patch, truth, extra) and the column
/// groups of file.log.measured, plus those whose data would otherwise be lost (non-zero
/// forces, fz or moments) and the mode column whenever a row after the first starts a run.
/// Numbers at full precision (ExactNumber). Throws std::invalid_argument for metadata a file
/// cannot hold, std::runtime_error if the file cannot be written. Writes to a temporary file
/// and renames, so a failed write never leaves a complete-looking file.
void WritePushLog(const PushLogFile& file, const std::string& path);
void WritePushLog(const PushLogFile& file, std::ostream& out);
/// A trajectory alone: no metadata beyond the physics, the patch as its Spec().
void WritePushLog(const Trajectory& trajectory, const std::string& path);
void WritePushLog(const Trajectory& trajectory, std::ostream& out);

/// A push log as named columns: what WritePushLog writes, without the text (the Python
/// module's arrays). Numbers as written; theta unwrapped; moments are the residual ones when
/// push points are written (log-format.md).
struct PushLogColumns {
  std::vector<std::string> names;           ///< "t", "x", ... in file order, without "mode"
  std::vector<std::vector<double>> values;  ///< one per name, one value per row
  std::vector<std::string> mode;  ///< the mode column ("start", "slide", "stick"), or empty
};

/// The columns WritePushLog would write for `trajectory` (metadata aside).
PushLogColumns ColumnsOf(const Trajectory& trajectory);

/// Reads a log given as columns and `# key = value` metadata exactly as ReadPushLog reads
/// the file they make (same checks, same messages): `source` names it, the metadata are lines
/// 1 to N, the header line N + 1 and row i (from 0) line N + 2 + i. Throws LogError, also for
/// columns of unequal length and for names or text that the file could not hold.
PushLogFile ParsePushLogColumns(const PushLogColumns& columns,
                                const std::vector<std::pair<std::string, std::string>>& metadata,
                                const std::string& source, const LogReadOptions& options = {},
                                LogReadReport* report = nullptr);

}  // namespace slideid
