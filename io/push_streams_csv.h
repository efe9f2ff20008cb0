#pragma once
// A push recorded as one CSV file per stream (`import-log --format streams`): the object's
// pose, the pusher tip's pose and the force, each file on its own clock and with its own
// column names, which a mapping names:
//
//   --pose pose.csv:t=stamp,x=px,y=py,theta=yaw,unit=ms
//   --tip tip.csv:t=time,x=x,y=y
//   --force ft.csv:t,fx,fy,frame=sensor,yaw=0.3
//
// Read (lines by fast-cpp-csv-parser's LineReader, io/text_lines.h) into an MIT push
// recording (io/mit_push_recording.h) for the one import pipeline; written by the tests'
// writer. Orientation is a yaw column (`theta`) or a quaternion (`qx, qy, qz, qw`, yaw as in
// io/ros_push_log.h). Times are in s, ms, us or ns (`unit=`), read exactly: "1476728847123"
// ms is the same double as "1476728847.123" s. The force is in world axes, or in a sensor
// frame turned by a fixed yaw (`frame=sensor,yaw=RAD`) or by the tip's logged yaw
// (`yaw=tip`), and is turned into world axes as it is read. Format: docs/real-data.md.

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/mit_push_recording.h"

namespace slideid {

/// Which stream a file holds.
enum class PushStream { kPose, kTip, kForce };
/// "pose", "tip" or "force".
const char* ToString(PushStream stream);

/// One stream's file and how to read it.
struct StreamCsvMapping {
  PushStream stream = PushStream::kPose;
  std::string option;  ///< where it came from, in messages ("--pose")
  std::string path;
  /// Key -> column name: t; x, y; theta or qx, qy, qz, qw (poses; the tip's orientation is
  /// optional); fx, fy and optionally tz (force).
  std::map<std::string, std::string> columns;
  int time_digits = 0;  ///< the time unit as a power of ten below seconds: 0 s, 3 ms, 6 us, 9 ns
  bool sensor_frame = false;             ///< force: in the sensor's frame, not the world's
  std::optional<double> sensor_yaw_rad;  ///< sensor frame: its fixed yaw; none: the tip's
  bool Quaternion() const { return columns.count("qw") > 0; }
};

/// Parses an option's text, "FILE" or "FILE:key=column,key,...,unit=ms,frame=sensor,yaw=0.3"
/// (a key alone names the column of the same name; the mapping follows the last ':';
/// unmapped keys default to columns named like them: t, x, y, theta; fx, fy). Throws
/// std::invalid_argument naming `option` ("--pose: unknown key 'thta' ...").
StreamCsvMapping ParseStreamMapping(PushStream stream, const std::string& option,
                                    const std::string& text);

/// The three streams' files.
struct PushStreamsCsv {
  StreamCsvMapping pose, tip, force;
};

/// The streams as read, and facts for the import report's notes (the files, their units and
/// the force frame).
struct PushStreamsRead {
  MitPushRecording recording;
  std::vector<std::string> notes;
};

/// Reads the three files. A file is a header line (the first line that is neither empty nor
/// a `#` comment; names may be quoted) and rows of cells; columns that are not mapped are
/// ignored. Throws LogError (io/push_log.h) naming the file, the line and the column: a
/// missing file, no header, a mapped column not in the header, a short row, a cell that is
/// not a finite number, a zero quaternion, a stream without rows.
PushStreamsRead ReadPushStreamsCsv(const PushStreamsCsv& files);
/// Same, from the files' texts in memory (fuzzing, tests); each mapping's path names it.
PushStreamsRead ParsePushStreamsCsv(const PushStreamsCsv& files, std::string_view pose_text,
                                    std::string_view tip_text, std::string_view force_text);

/// Why the streams cannot make a push when their time spans never overlap (one file stamped
/// by another clock, or in another unit than its mapping says), naming the files and their
/// spans; empty when each pair overlaps.
std::string StreamFilesOverlapProblem(const MitPushRecording& recording,
                                      const PushStreamsCsv& files);

/// The text of one stream of `recording` as `mapping` reads it back: a "seq" column first
/// (ignored by the reader), then the mapped columns in key order; times at full precision in
/// the mapping's unit, orientation as the mapping names it, the force turned into the
/// mapping's frame (for yaw=tip, by the tip's yaw in `recording`). The tests' writer.
std::string FormatPushStreamCsv(const MitPushRecording& recording, const StreamCsvMapping& mapping);
/// Writes the three files of `files` (atomically, io/atomic_file.h).
void WritePushStreamsCsv(const MitPushRecording& recording, const PushStreamsCsv& files);

}  // namespace slideid
