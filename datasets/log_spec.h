#pragma once
// How a simulated trajectory becomes a log, as a sensor would record it: sampling, columns
// and noise. Plain data: a scene file's [sim] log_every, [log] and [noise] sections
// (LoggedScene, io/scene_file.h) and a dataset's logs (datasets/dataset.h); applied by
// datasets/sensor_model.h (MakeLog).

#include <optional>
#include <string>

#include "datasets/noise_spec.h"

namespace slideid {

/// Which motion columns a log carries.
enum class LogMotion {
  kPoses,       ///< x, y, theta only (motion capture); readers derive velocities
  kVelocities,  ///< vx, vy, wz only
  kBoth,
};

/// How the push enters the log.
enum class LogPush {
  kPoint,    ///< fx, fy and the push point px, py, pz (moments follow as r x f)
  kMoments,  ///< fx, fy and the total moments tx, ty, tz about the CM
};

struct LogSpec {
  /// Log every k-th simulated step (k >= 1): simulate at dt, log at dt * k. A row's force is
  /// the one applied at the row's time, held over the next log interval (log-format.md);
  /// when the push varies within the interval this is an approximation, as in real logs.
  int log_every = 1;
  /// Log each row's wrench as the mean over its log interval (the impulse, as a logger that
  /// averages a faster force sensor records it) instead of the wrench at the row's time;
  /// the push point is then the mean point of contact, and the moments those of the mean
  /// force at it. Only matters for log_every > 1.
  bool mean_wrench = false;
  LogMotion motion = LogMotion::kBoth;
  LogPush push = LogPush::kPoint;
  /// Keep the simulator's own columns (ECP, impulses, sigma, mode). Unset: kept when the
  /// noise is zero (the log is then the truth), dropped otherwise (a sensor does not see them).
  std::optional<bool> step_info;
  /// Write theta wrapped to (-pi, pi] (as many trackers report it); noise is added first.
  bool wrap_theta = false;
  NoiseSpec noise;

  /// False (and why) for log_every < 1 or invalid noise.
  bool IsValid(std::string* why) const;
  /// IsValid, and for a log with pushes also: push points need the poses.
  bool IsValidFor(bool has_pushes, std::string* why) const;
};

const char* ToString(LogMotion motion);  ///< "poses", "velocities", "both"
const char* ToString(LogPush push);      ///< "point", "moments"
/// Parse the names above; false for anything else.
bool ParseLogMotion(const std::string& text, LogMotion* motion);
bool ParseLogPush(const std::string& text, LogPush* push);

}  // namespace slideid
