#pragma once
// What noise a synthetic log carries, and the sensor defects of its push stream (a constant
// force offset, a delay against the poses): plain data, part of a LogSpec
// (datasets/log_spec.h). Applied by datasets/noise.h and datasets/sensor_model.h.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace slideid {

/// Standard deviations of zero-mean Gaussian noise added to the written signals, and
/// motion-capture outliers. All >= 0; outlier_fraction in [0, 1]. Also the deterministic
/// defects of the push stream, with the sign conventions of the trajectory fit's nuisances
/// (estimator/internal/segment_cost.h), so that a fit with --fit-force-bias / --fit-delay recovers
/// them: any finite value, 0 by default.
struct NoiseSpec {
  double pose_m = 0.0;          ///< on x, y [m]
  double angle_rad = 0.0;       ///< on theta [rad] (added to the unwrapped angle)
  double velocity_mps = 0.0;    ///< on vx, vy [m/s]
  double spin_radps = 0.0;      ///< on wz [rad/s]
  double force_relative = 0.0;  ///< on fx, fy, fz as a fraction of the value (moments too
                                ///< when the row has no push point)
  double force_n = 0.0;         ///< on fx, fy, fz [N]; moments follow as r x f at a push point
  /// On px, py [m]: where the pusher touches, as its tracker reports it (rows with a push
  /// point only); the moments follow as r x f from the reported point.
  double push_point_m = 0.0;
  double outlier_fraction = 0.0;  ///< fraction of rows whose pose jumps
  double outlier_m = 0.0;         ///< size of such a jump [m] (and outlier_m / 0.05 rad)
  std::uint64_t seed = 1;         ///< one seed, one noise stream
  /// Force offset [N]: what the force channel reads with no force on the object. Every row's
  /// logged (fx, fy) is the true one plus (x, y), rows without a push included; the offset
  /// acts at the row's push point (its moment about the CM follows), at the CM without one.
  double force_bias_x_n = 0.0;
  double force_bias_y_n = 0.0;  ///< see force_bias_x_n [N]
  /// Delay of the push stream against the poses [s]: the wrench logged at t (force, push
  /// point and moments about the CM) is the true one at t - delay; before the first
  /// simulated row the first row's, after the last the last row's. Negative: it leads.
  double force_delay_s = 0.0;

  /// True when no noise is added (the seed does not matter then). Defects are not noise.
  bool IsZero() const;
  /// True when a force offset or a delay is set.
  bool HasDefects() const;
  /// False (and why) when a value is negative or not finite, the fraction exceeds 1, or a
  /// defect is not finite.
  bool IsValid(std::string* why) const;
  /// `# noise_* = value` metadata entries describing this noise, then the defects that are
  /// set (`noise_force_bias_x_n`, `noise_force_bias_y_n`, `noise_force_delay_s`).
  std::vector<std::pair<std::string, std::string>> Metadata() const;
  /// One line without commas, "pose_m=0.0003 angle_rad=0.003 ... seed=7" (manifests), then
  /// " force_bias_x_n=... force_delay_s=..." for the defects that are set.
  std::string Describe() const;
};

}  // namespace slideid
