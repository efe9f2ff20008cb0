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

/// Which wrench a decimated log row carries (log_every > 1; with log_every = 1 both agree).
enum class LogWrench {
  kAtRowTime,     ///< the one applied at the row's time (a force sensor sampled at the row)
  kIntervalMean,  ///< the mean over the log interval the row starts (a sensor that
                  ///< integrates over the interval): the logged impulse is the applied one
};

struct LogSpec {
  /// Log every k-th simulated step (k >= 1): simulate at dt, log at dt * k. A row's force is
  /// held over the next log interval (log-format.md); which force, `wrench` says.
  int log_every = 1;
  LogMotion motion = LogMotion::kBoth;
  LogPush push = LogPush::kPoint;
  /// At the row's time (default): when the push varies within the interval, an
  /// approximation, as in real logs. The interval mean has no single push point, so it
  /// needs push = moments when the log has pushes.
  LogWrench wrench = LogWrench::kAtRowTime;
  /// Keep the simulator's own columns (ECP, impulses, sigma, mode). Unset: kept when the
  /// noise is zero and the push stream has no defect (the log is then the truth), dropped
  /// otherwise (a sensor does not see them).
  std::optional<bool> step_info;
  /// Write theta wrapped to (-pi, pi] (as many trackers report it); noise is added first.
  bool wrap_theta = false;
  NoiseSpec noise;

  /// False (and why) for log_every < 1 or invalid noise.
  bool IsValid(std::string* why) const;
  /// IsValid, and for a log with pushes also: push points need the poses, and the
  /// interval-mean wrench needs push = moments.
  bool IsValidFor(bool has_pushes, std::string* why) const;
};

const char* ToString(LogMotion motion);  ///< "poses", "velocities", "both"
const char* ToString(LogPush push);      ///< "point", "moments"
const char* ToString(LogWrench wrench);  ///< "at-row-time", "interval-mean"
/// Parse the names above; false for anything else.
bool ParseLogMotion(const std::string& text, LogMotion* motion);
bool ParseLogPush(const std::string& text, LogPush* push);
bool ParseLogWrench(const std::string& text, LogWrench* wrench);

}  // namespace slideid
