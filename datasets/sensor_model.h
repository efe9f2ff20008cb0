#pragma once
// From a simulated trajectory to the log a sensor would have recorded: decimation (log every
// k-th simulated step), the columns written, and noise (datasets/noise.h).

#include "datasets/log_spec.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Applies `spec` to `simulated` (a Simulate() trajectory, one row per simulated step):
/// - delays the push stream by spec.noise.force_delay_s, on the simulated rows: each row's
///   wrench and push point become those in force at its time minus the delay;
/// - keeps rows 0, k, 2k, ... (k = log_every). The step columns of a kept row describe the
///   log interval ending there: impulses summed over its simulated steps, ECP and sigma of
///   its last step, `stick` only if all stuck;
/// - gives each row the wrench the log format holds over the next log interval
///   (spec.wrench): the one at the row's time (at-row-time: exact for a push constant over
///   the interval, an approximation when it varies within it, as in real logs), or the mean
///   over that interval (interval-mean: the logged impulse is the applied one; the rows then
///   carry no push point, and the last row keeps its own wrench);
/// - sets what the log measures: poses / velocities / both; push point or total moments;
///   step info (spec.step_info, by default only for a noiseless log);
/// - adds the noise (ApplyNoise), then the force offset spec.noise.force_bias_* to every
///   row (at its push point, lever from the noisy pose, as a reader computes it);
/// - for a poses-only log, sets the velocities from the poses as a reader would, so that the
///   returned trajectory equals the written-and-read-back one;
/// - wraps theta to (-pi, pi] when asked (after the noise).
/// What it did, as its file's metadata: io/simulated_log.h. Throws std::invalid_argument for
/// an invalid spec.
Trajectory MakeLog(const Trajectory& simulated, const LogSpec& spec);

}  // namespace slideid
