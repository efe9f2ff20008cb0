#pragma once
// The MIT push-dataset JSON file: one object with the arrays `object_pose`, `tip_pose` and
// `ft_wrench`, each a list of [t, a, b, c] rows (io/mit_push_recording.h; format and known
// problems of the real files: docs/real-data.md). Read and written with nlohmann-json.
// Bad files throw MitPushError naming the file and the JSON path (or, for a JSON syntax
// error, the line and column).

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "io/mit_push_recording.h"

namespace slideid {

/// Bad MIT push file. The message is "file: $.path: what" for content errors and
/// "file:line:column: what" for JSON syntax errors.
class MitPushError : public std::runtime_error {
 public:
  /// `json_path` empty and `line` > 0 for a syntax error; both empty for a file error.
  MitPushError(const std::string& file, const std::string& json_path, int line, int column,
               const std::string& what);
  const std::string& file() const { return file_; }
  const std::string& json_path() const { return json_path_; }  ///< e.g. "$.tip_pose[3][1]"
  int line() const { return line_; }      ///< 1-based; 0 when not a syntax error
  int column() const { return column_; }  ///< 1-based byte column; 0 when not a syntax error

 private:
  std::string file_, json_path_;
  int line_, column_;
};

/// Parses the text of one file. Every stream must be present and hold at least one row;
/// every row must be an array of exactly 4 finite numbers. Other keys are ignored. Rows
/// are kept in file order. `source` names the text in messages. Throws MitPushError.
MitPushRecording ParseMitPushJson(std::string_view text, const std::string& source);
/// Same, from a file. Throws MitPushError (also when the file cannot be read or is empty).
MitPushRecording ReadMitPushJson(const std::string& path);

/// The text of `recording` in the same format, one row per line, numbers at full precision
/// (round trips exactly through ParseMitPushJson).
std::string FormatMitPushJson(const MitPushRecording& recording);
/// Writes FormatMitPushJson to `path` via a temporary file and a rename, so a failed write
/// never leaves a complete-looking file. Throws std::runtime_error naming the path.
void WriteMitPushJson(const MitPushRecording& recording, const std::string& path);

/// What a dataset file name says about its push:
/// `motion_surface=<surface>_shape=<shape>_a=<acc>_v=<mm/s>_i=<side>_s=<0..1>_t=<rad>.json`
/// (the reading of mcubelab/pdproc's preprocess.py). Fields absent from the name stay empty.
struct MitPushFileName {
  std::string surface;                  ///< "plywood", "abs", "delrin", "pu"
  std::string shape;                    ///< object name: "rect1", "hex", ...
  std::optional<double> velocity_mm_s;  ///< push speed [mm/s]
  std::optional<double> acceleration;   ///< `a=` as written (0: constant speed)
  std::optional<double> side;           ///< `i=`: side index of the object
  std::optional<double> position;       ///< `s=`: position along the side, 0..1
  std::optional<double> angle_rad;      ///< `t=`: push angle [rad]
};
/// Reads the fields of a file name (directories and extension ignored). Never throws.
MitPushFileName ParseMitPushFileName(const std::string& path);

/// What SortAndDeduplicate did to one stream.
struct StreamCleanup {
  int rows_in = 0;             ///< rows as stored
  int backward_steps = 0;      ///< times a row's t is below the previous row's, in file order
  int duplicates_dropped = 0;  ///< rows dropped because an earlier row has the same t
  /// Of those, rows whose values differed from the kept row (not just repeated).
  int conflicting_duplicates = 0;
};

/// Sorts `rows` by time (stable) and keeps the first row of each time, in file order.
StreamCleanup SortAndDeduplicate(std::vector<MitStreamRow>* rows);

}  // namespace slideid
