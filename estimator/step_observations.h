#pragma once
// Per-step quantities of a push log that the cheap estimators use: the measured friction
// impulses and ECP velocities of model.md, "Appendix A, corrected", the
// noise they carry, and which steps are sliding steps that can inform an estimate.

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/planar_state.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// One log interval u -> u+1, as measured.
struct StepObservation {
  int row = 0;             ///< index u of the starting sample in the log
  double h_s = 0;          ///< t_{u+1} - t_u [s]
  PlanarState start, end;  ///< measured states at u and u+1
  AppliedWrench applied;   ///< held over the step (the row u wrench)
  double pn = 0;           ///< h (m g - f_z) [N s]
  /// (p_t, p_o, p_r) = M (nu' - nu) - applied, with the coupling term (*) [N s, N s, N m s].
  Eigen::Vector3d friction_impulse = Eigen::Vector3d::Zero();
  /// (v_t, v_o, v_r) at the end of the step, at the ECP implied by friction_impulse.
  Eigen::Vector3d ecp_velocity = Eigen::Vector3d::Zero();
  /// The log says this step stuck (mode column), or, without a mode column, the end
  /// velocity is exactly zero.
  bool logged_stick = false;
  /// False for the first step of each run of a poses-only log: the kinematic map gives no
  /// velocity at a run's first row, so this step's start velocity is unknown.
  bool start_velocity_known = true;
  /// The step ends at a row marked `start`: it spans a gap in the record, and no model step
  /// joins its two rows.
  bool across_gap = false;
  /// Velocities differentiated from poses, and the applied force switches (by more than
  /// kForceSwitchFraction of the log's largest push) at the row before, at, or after this
  /// step: a differentiated velocity is the mean over the interval before its row, so the
  /// step's change of velocity spans half an interval of the other force.
  bool near_force_switch = false;
};

/// A change of the horizontal force between consecutive rows above this fraction of the
/// log's largest push is a switch (a push starting or stopping), not the variation of a
/// push within its course (a 30% oscillation over 0.15 s changes by at most 13% per 10 ms
/// row).
constexpr double kForceSwitchFraction = 0.25;

/// All steps of a log (rows 0..N-2 start a step). Without the velocity columns, velocities
/// come from the poses by the kinematic map (SetVelocitiesFromPoses). The slider must have mass,
/// inertia, com_height and gravity set.
std::vector<StepObservation> ExtractStepObservations(const Trajectory& log);

/// Calls `f` with each step of `log`, in order, that ExtractStepObservations would list,
/// one at a time: a 1e6-row log's steps take 224 MB at once. Same checks and throws.
void ForEachStepObservation(const Trajectory& log,
                            const std::function<void(const StepObservation&)>& f);

/// The noise on the velocities and their changes as the steps use them, read off the log
/// itself (estimator/log_diagnostics.h: MAD of high differences). Measured velocities with
/// noise s give v' - v with noise sqrt(2) s; velocities differentiated from poses with noise
/// s_q over an interval h carry sqrt(2) s_q / h, and their changes (q' - 2 q + q_) / h
/// sqrt(6) s_q / h. All 0 where the log shows no noise (exact logs, or too few rows).
struct StepNoise {
  bool differentiated = false;    ///< velocities come from the poses (no velocity columns)
  double velocity_mps = 0;        ///< on v_x and v_y [m/s]
  double spin_radps = 0;          ///< on w_z [rad/s]
  double delta_velocity_mps = 0;  ///< on each component of v' - v [m/s]
  double delta_spin_radps = 0;    ///< on w' - w [rad/s]
  /// Covariance of the noise on v' - v with that on v' (per component) [m^2/s^2]: s_v^2
  /// for measured velocities, 3 s_q^2 / h^2 for differentiated ones; the same for w.
  double delta_end_velocity_cov = 0;
  double delta_end_spin_cov = 0;
};

/// Reads the step noise of `log` (DiagnoseLog; the median log interval for differentiated
/// velocities).
StepNoise ReadStepNoise(const Trajectory& log);

/// A step counts as at rest when its CM speed |v|_w = sqrt(v_x^2 + v_y^2 + (L w_z)^2),
/// L = sqrt(I_z / m), is at most this many times its noise sqrt(2 s_v^2 + (L s_w)^2).
/// A noisy log has no mode column, and its rest and sticking rows read as slow motion in
/// random directions: their friction impulses are noise, and kept as sliding steps they
/// pull a towards 0 (a log with long rests gave a 6x too low). At 3 times the noise a
/// resting row passes for sliding with probability below 0.3% (one Gaussian channel), and
/// a sliding step is lost only while slower than that.
constexpr double kRestSpeedSigmas = 3.0;

/// Whether a step can inform a per-step estimate: the log says it slid over the whole
/// interval. When not, records why in `result`:
///  - "sticking": the mode column says so, or (without one) the end velocity is exactly 0;
///  - "start velocity unknown": the first step of a poses-only log;
///  - "at rest (speed within the noise)": its end speed is within kRestSpeedSigmas of the
///    noise (noisy rest and sticking rows, which no mode column flags);
///  - "start of a sliding phase": it starts from rest (speed within the noise, or exactly
///    0), so it may have stuck for part of the interval, which the log cannot show;
///  - "next to a force switch": near_force_switch (velocities differentiated from poses).
bool SlidingStep(const StepObservation& step, const StepNoise& noise, double radius_m,
                 EstimateResult* result);

/// Poses differentiated over windows of this much log time show whether a log whose steps
/// all pass for rest moves (RateTooHighForItsNoise).
constexpr double kMotionWindow_s = 0.05;

/// Why a poses-only log can have no sliding step although it moves: velocities differentiated
/// from one row to the next carry sqrt(2) s_q / h of noise, and at a high rate with noisy
/// poses (1 kHz, 0.8 mm: 1.1 m/s) every step's speed is within the noise SlidingStep allows
/// for. When the poses, differentiated over kMotionWindow_s windows (k rows: noise, and so
/// the rest threshold, k times smaller), move in at least a quarter of the windows, a
/// sentence saying so and what to do; "" otherwise (a log at rest, measured velocities, or
/// a window of one row).
std::string RateTooHighForItsNoise(const Trajectory& log, const StepNoise& noise, double radius_m);

}  // namespace slideid
