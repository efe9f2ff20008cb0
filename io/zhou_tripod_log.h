#pragma once
// The text logs of Zhou, Paolini, Bagnell and Mason, ICRA 2016 ("A convex polynomial
// force-motion model for planar sliding"): a triangular block on three point supports,
// pushed 50 times per file by a robot finger with a 2-axis force sensor
// (../shared/data/real-pushes/README.md, section 2; their ParseLog.m reads the same).
//
// Whitespace-separated numbers, one record per line:
//
//     N                                      number of pushes
//     N times:
//       x y z qw qx qy qz                    object pose before the push (mm; Vicon body)
//       x y z qw qx qy qz                    object pose after the push
//       K                                    number of force samples
//       K lines: t fx fy                     s (Unix time), N; sensor frame
//       M                                    number of robot poses
//       M lines: t x y z qw qx qy qz         s, mm, tool pose quaternion
//
// The reader checks the syntax: every line has the fields of its record, every number is
// finite, every count matches the lines that follow it, and the file is neither cut short
// nor longer than its counts say. Errors are LogError naming the file, the line and the
// field. What the numbers mean (frames, offsets, contact) is io/zhou_tripod_import.h.

#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace slideid {

/// A pose as the logs write it: position [mm] and unit quaternion (w, x, y, z).
struct TripodPose {
  double x_mm = 0.0, y_mm = 0.0, z_mm = 0.0;
  double qw = 1.0, qx = 0.0, qy = 0.0, qz = 0.0;
};

/// One force sample: time [s] and the 2-axis sensor reading [N], sensor frame.
struct TripodForceSample {
  double t_s = 0.0;
  double fx_n = 0.0, fy_n = 0.0;
  int line = 0;  ///< line in the file (0 when not read from one)
};

/// One robot tool pose at time t [s].
struct TripodRobotSample {
  double t_s = 0.0;
  TripodPose pose;
  int line = 0;  ///< line in the file (0 when not read from one)
};

/// One push: the object's poses before and after, the force trace and the tool trajectory.
struct TripodPush {
  TripodPose pre, post;
  std::vector<TripodForceSample> forces;
  std::vector<TripodRobotSample> robot;
  int line = 0;              ///< line of the pre-push pose
  int force_count_line = 0;  ///< line of K
  int robot_count_line = 0;  ///< line of M
};

/// A whole log.
struct TripodLog {
  std::vector<TripodPush> pushes;
};

/// Most pushes, and most samples per stream, a file may announce: far above any experiment
/// (the logs hold 50 pushes of ~670 and ~220 samples), low enough that a corrupt count
/// cannot make the reader reserve gigabytes.
constexpr long long kMaxTripodPushes = 100000;
constexpr long long kMaxTripodSamples = 10000000;

/// Reads a tripod log. Throws LogError (file, line, field) for bad syntax, a count that
/// does not match its lines, a truncated or empty file, or a file it cannot read.
TripodLog ReadZhouTripodLog(const std::string& path);
/// Same, from text in memory; `source` names it in messages (fuzzing, tests).
TripodLog ParseZhouTripodLog(std::string_view text, const std::string& source);

/// Writes a log in the same format, numbers as the shortest text that reads back exactly.
/// Throws std::runtime_error if the file cannot be written (temporary file, then rename).
void WriteZhouTripodLog(const TripodLog& log, const std::string& path);
void WriteZhouTripodLog(const TripodLog& log, std::ostream& out);

}  // namespace slideid
