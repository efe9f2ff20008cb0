#pragma once
// Reading and writing push logs in the CSV format of docs/log-format.md (shared docs).
// The reader uses fast-cpp-csv-parser; columns are found by name in any order.

#include <iosfwd>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
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
};

/// Notes the reader made that are not errors (unknown columns, unwrapped theta, ...).
struct LogReadReport {
  std::vector<std::string> notes;
  std::vector<std::string> unknown_columns;
  bool velocities_from_poses = false;  ///< velocities came from the kinematic map
};

/// Reads a log. Velocities: as given when present, else from poses by the backward-Euler
/// kinematic map (first row's velocity: 0, flagged by mode kStart). Applied moments: tx, ty,
/// tz plus r x f when px, py, pz are present. theta is unwrapped. Throws LogError.
Trajectory ReadPushLog(const std::string& path, const LogReadOptions& options = {},
                       LogReadReport* report = nullptr);

/// Writes `trajectory` with the metadata comments (slider, patch, truth, extra) and the
/// column groups in trajectory.columns. Numbers at full precision (%.17g). Throws
/// std::runtime_error if the file cannot be written. Writes to a temporary file and renames,
/// so a failed write never leaves a complete-looking file.
void WritePushLog(const Trajectory& trajectory, const std::string& path);
void WritePushLog(const Trajectory& trajectory, std::ostream& out);

}  // namespace slideid
