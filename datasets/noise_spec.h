#pragma once
// What noise a synthetic log carries: plain data, part of a LogSpec (datasets/log_spec.h).
// Applied by datasets/noise.h and datasets/sensor_model.h.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace slideid {

/// Standard deviations of zero-mean Gaussian noise added to the written signals, and
/// motion-capture outliers. All >= 0; outlier_fraction in [0, 1].
struct NoiseSpec {
  double pose_m = 0.0;          ///< on x, y [m]
  double angle_rad = 0.0;       ///< on theta [rad] (added to the unwrapped angle)
  double velocity_mps = 0.0;    ///< on vx, vy [m/s]
  double spin_radps = 0.0;      ///< on wz [rad/s]
  double force_relative = 0.0;  ///< on fx, fy, fz as a fraction of the value (moments too
                                ///< when the row has no push point)
  double force_N = 0.0;         ///< on fx, fy, fz [N]; moments follow as r x f at a push point
  /// On px, py [m]: where the pusher touches, as its tracker reports it (rows with a push
  /// point only); the moments follow as r x f from the reported point.
  double push_point_m = 0.0;
  double outlier_fraction = 0.0;  ///< fraction of rows whose pose jumps
  double outlier_m = 0.0;         ///< size of such a jump [m] (and outlier_m / 0.05 rad)
  std::uint64_t seed = 1;         ///< one seed, one noise stream

  /// True when no noise is added (the seed does not matter then).
  bool IsZero() const;
  /// False (and why) when a value is negative, not finite, or the fraction exceeds 1.
  bool IsValid(std::string* why) const;
  /// `# noise_* = value` metadata entries describing this noise.
  std::vector<std::pair<std::string, std::string>> Metadata() const;
  /// One line without commas, "pose_m=0.0003 angle_rad=0.003 ... seed=7" (manifests).
  std::string Describe() const;
};

}  // namespace slideid
