#pragma once
// Sensor-like noise on a simulated log: Gaussian pose, velocity and force noise and
// motion-capture outliers, reproducible by seed.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "forward_model/trajectory.h"

namespace slideid {

/// Standard deviations of zero-mean Gaussian noise added to the written signals.
struct NoiseSpec {
  double pose_m = 0.0;          ///< on x, y [m]
  double angle_rad = 0.0;       ///< on theta [rad]
  double velocity_mps = 0.0;    ///< on vx, vy [m/s]
  double spin_radps = 0.0;      ///< on wz [rad/s]
  double force_relative = 0.0;  ///< on fx, fy, fz and moments, as a fraction of the value
  double force_N = 0.0;         ///< on fx, fy, fz [N] (moments get force_N * |r| if known)
  double outlier_fraction = 0.0;  ///< fraction of rows whose pose jumps
  double outlier_m = 0.0;         ///< size of such a jump [m] (and outlier_m / 0.05 rad)
  std::uint64_t seed = 1;

  bool IsZero() const;
  /// `# noise_* = value` metadata entries describing this noise.
  std::vector<std::pair<std::string, std::string>> Metadata() const;
};

/// A copy of `log` with noise added to what its columns carry; step_info columns
/// (ECP, impulses, mode) are dropped, since a sensor does not measure them. The noise
/// description is appended to extra_metadata.
Trajectory AddNoise(const Trajectory& log, const NoiseSpec& noise);

}  // namespace slideid
