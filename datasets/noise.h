#pragma once
// Sensor-like noise on a simulated log: Gaussian pose, velocity and force noise and
// motion-capture outliers, reproducible by seed. NoiseSpec (plain data) is in
// datasets/noise_spec.h.

#include "datasets/noise_spec.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// A copy of `log` with noise added to what it carries (log.measured); the step info (ECP,
/// impulses, mode) is dropped, since a sensor does not measure it. (A file says which noise
/// by noise.Metadata().) Throws std::invalid_argument for invalid noise.
Trajectory AddNoise(const Trajectory& log, const NoiseSpec& noise);

/// Adds the noise to `log` in place, nothing else (measurements and step info kept).
///
/// Per row, in this order from one seed: pose (x, y += pose_m N(0,1); theta += angle_rad
/// N(0,1), on the unwrapped angle), velocity (vx, vy, wz), force (fx, fy += force_relative
/// |f| N + force_n N; fz likewise when non-zero), outlier (with probability
/// outlier_fraction the pose jumps by outlier_m in a uniform direction and theta by
/// outlier_m / 0.05 rad). A pusher out of contact reads 0: rows without force get no
/// force noise. Moments: when the row has a push point, the total moment is recomputed as
/// r x f_measured plus the row's residual moment (the part not due to f), with r from the
/// push point to the measured CM when the log carries poses, so that a push-point log stays
/// consistent with its own columns; without a push point, moments get relative noise.
/// Push point (px, py += push_point_m N(0,1), rows with a push point only; the moments then
/// follow from the reported point).
/// The pose, velocity, fx, fy and outlier variates come from std::mt19937_64(seed) as in
/// the first AddNoise (same stream); fz and moment variates from a second engine, and the
/// push-point variates from a third, each seeded from the same seed.
void ApplyNoise(Trajectory* log, const NoiseSpec& noise);

}  // namespace slideid
