#pragma once
// What the closed form and the equation error share beyond the steps themselves
// (estimator/step_observations.h): the impulse signal-to-noise check, the context of the
// plausibility verdicts, and per-log results of a pooled estimate.

#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "estimator/plausibility.h"
#include "estimator/step_observations.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// One log's steps as the cheap methods see them.
struct LogSteps {
  const Trajectory* log = nullptr;
  std::vector<StepObservation> steps;
  StepNoise noise;
  double radius_m = 0;    ///< L = sqrt(I_z / m)
  int lag = 0;            ///< steps over which scores are correlated (step_covariance.h)
  double max_push_n = 0;  ///< largest applied horizontal force (LogDiagnostics)
};

/// Extracts the steps (unless `with_steps` is false: a caller that streams them with
/// ForEachStepObservation) and reads the noise of `log`.
LogSteps ReadLogSteps(const Trajectory& log, bool with_steps = true);

/// Why logs that move gave no sliding step (RateTooHighForItsNoise of the first log it
/// applies to, "log k: " before it when there are several), as "; " and a clause to end a
/// "too little sliding" message with; "" when no log is such.
std::string RateTooHighNote(const std::vector<LogSteps>& logs);

/// Friction impulse over its noise on the used steps `used` (indices into s.steps): the
/// median of |(p_t, p_o)| / (m s_dv) (translation) or |p_r| / (I_z s_dw) (rotation),
/// s_dv, s_dw the noise of v' - v, w' - w (StepNoise). Infinite on a log without noise,
/// NaN without steps.
double ImpulseSnr(const LogSteps& s, const std::vector<int>& used, bool rotation);
/// The same from the used steps' impulse magnitudes: |(p_t, p_o)| (translation) or |p_r|
/// (rotation), in the steps' order.
double ImpulseSnrOf(const LogSteps& s, const std::vector<double>& magnitudes, bool rotation);
/// The magnitude ImpulseSnr takes of a step's friction impulse.
inline double ImpulseMagnitude(const StepObservation& o, bool rotation) {
  const Eigen::Vector3d& p = o.friction_impulse;
  return rotation ? std::abs(p(2)) : std::hypot(p(0), p(1));
}

/// The change of a step's friction impulse (p_t, p_o, p_r) if its force were the mean of
/// its row's and the next row's (varying within the interval) instead of its row's held
/// over it: -h df / 2. Zero at a force switch (kForceSwitchFraction), where holding is
/// right.
Eigen::Vector3d ForceHoldImpulseShift(const LogSteps& s, const StepObservation& o);

/// The step with its ECP velocity taken at the middle of the interval (the mean of its
/// start and end CM velocities and spins, same ECP offset) instead of its end: what a motion
/// that changes within the interval, rather than the model's backward-Euler step, gives.
StepObservation MidInterval(const StepObservation& o);

/// The reason a parameter is not identifiable when every log's impulses are swamped by
/// noise (snr below kMinImpulseSnr).
std::string LowSnrReason(double snr, bool differentiated, bool rotation);

/// The plausibility context of the logs: their weights and largest pushes.
PlausibilityContext CheapContext(const std::vector<LogSteps>& logs);

/// An estimate of log(parameter) with its interval exp(log_value +- quantile stderr_log).
struct LogEstimate {
  double log_value = std::numeric_limits<double>::quiet_NaN();
  double stderr_log = std::numeric_limits<double>::quiet_NaN();
  double quantile = kZ95;
  /// How far the log's noise may have moved the estimate (errors in variables) [in
  /// log(parameter)]; 0 when not assessed.
  double noise_bias_bound_log = 0;
  /// How far the estimate moves if the forces vary within the log's rows rather than being
  /// held over them (the log cannot tell) [in log(parameter)]; the interval holds the
  /// truth for either reading (BiasAwareHalfWidth).
  double force_hold_shift_log = 0;
  std::string note;
};

/// A noise-bias bound above this many standard errors makes a parameter not identifiable
/// by a cheap method: an interval of +-1.96 standard errors around an estimate that may be
/// off by more than half a standard error covers the truth too rarely (below 92%).
constexpr double kMaxNoiseBiasStderrs = 0.5;

/// The half-width h of a 95% interval around an estimate that is Gaussian with standard
/// deviation `sd` about a value up to `bias` from the truth: P(|N(bias, sd^2)| <= h) = 0.95
/// (1.96 sd without bias, bias + 1.645 sd when the bias dominates). Between the linear sum
/// 1.96 sd + bias, which over-covered (99% where the forces are held), and the quadrature
/// sum, which under-covered (77% on 3000-row logs whose forces vary within rows).
double BiasAwareHalfWidth(double sd, double bias);
/// Bisections of BiasAwareHalfWidth over [1.96 sd, 1.96 sd + bias]: 40 halve it to 1e-12.
constexpr int kHalfWidthBisections = 40;

/// The parameter of `e`: value exp(log_value), stderr value stderr_log, interval
/// exp(log_value +- BiasAwareHalfWidth(quantile stderr_log / 1.96, force_hold_shift_log)),
/// e's note (saying how far the force-hold shift widened it); not identifiable, held at its value
/// and with the reason, when its noise-bias bound exceeds kMaxNoiseBiasStderrs standard errors.
ParameterEstimate FromLogEstimate(const LogEstimate& e);

/// Fewest logs for the cluster-robust (between-log) interval of a pooled estimate.
constexpr int kMinLogClusters = 2;

}  // namespace slideid
