#include "estimator/cheap_methods.h"

#include <cmath>
#include <limits>

#include "estimator/closed_form.h"
#include "estimator/identifiability.h"
#include "estimator/log_diagnostics.h"
#include "estimator/robust_statistics.h"
#include "estimator/step_covariance.h"
#include "forward_model/number_format.h"

namespace slideid {

LogSteps ReadLogSteps(const Trajectory& log, bool with_steps) {
  LogSteps s;
  s.log = &log;
  if (with_steps) s.steps = ExtractStepObservations(log);
  s.noise = ReadStepNoise(log);
  s.max_push_n = DiagnoseLog(log).max_push_n;
  s.radius_m = std::sqrt(log.slider.inertia_kgm2 / log.slider.mass_kg);
  s.lag = s.noise.differentiated ? kDifferentiatedVelocityLag : kMeasuredVelocityLag;
  return s;
}

std::string RateTooHighNote(const std::vector<LogSteps>& logs) {
  for (size_t k = 0; k < logs.size(); ++k) {
    const std::string why = RateTooHighForItsNoise(*logs[k].log, logs[k].noise, logs[k].radius_m);
    if (why.empty()) continue;
    return "; " + (logs.size() > 1 ? "log " + std::to_string(k + 1) + ": " : std::string()) + why;
  }
  return "";
}

double ImpulseSnr(const LogSteps& s, const std::vector<int>& used, bool rotation) {
  std::vector<double> magnitudes;
  magnitudes.reserve(used.size());
  for (int k : used) magnitudes.push_back(ImpulseMagnitude(s.steps[k], rotation));
  return ImpulseSnrOf(s, magnitudes, rotation);
}

double ImpulseSnrOf(const LogSteps& s, const std::vector<double>& magnitudes, bool rotation) {
  if (magnitudes.empty()) return std::numeric_limits<double>::quiet_NaN();
  const SliderProperties& slider = s.log->slider;
  const double noise = rotation ? slider.inertia_kgm2 * s.noise.delta_spin_radps
                                : slider.mass_kg * s.noise.delta_velocity_mps;
  if (!(noise > 0)) return std::numeric_limits<double>::infinity();
  std::vector<double> ratio;
  ratio.reserve(magnitudes.size());
  for (const double m : magnitudes) ratio.push_back(m / noise);
  return Median(ratio);
}

Eigen::Vector3d ForceHoldImpulseShift(const LogSteps& s, const StepObservation& o) {
  const AppliedWrench& now = s.log->samples[o.row].applied;
  const AppliedWrench& next = s.log->samples[o.row + 1].applied;
  const double dfx = next.fx - now.fx, dfy = next.fy - now.fy, dtz = next.tz - now.tz;
  if (std::hypot(dfx, dfy) > kForceSwitchFraction * s.max_push_n) return Eigen::Vector3d::Zero();
  // p = M (nu' - nu) - h f: a mean force larger by df / 2 takes h df / 2 off the impulse.
  const double half_h = 0.5 * o.h_s;
  return Eigen::Vector3d(-half_h * dfx, -half_h * dfy, -half_h * dtz);
}

StepObservation MidInterval(const StepObservation& o) {
  StepObservation mid = o;
  const double w_end = o.end.wz, w_mid = 0.5 * (o.start.wz + o.end.wz);
  // ecp_velocity = (v_x - w r_y, v_y + w r_x, w): the offset from the end values.
  const double minus_ry = w_end != 0 ? (o.ecp_velocity(0) - o.end.vx) / w_end : 0.0;
  const double rx = w_end != 0 ? (o.ecp_velocity(1) - o.end.vy) / w_end : 0.0;
  mid.ecp_velocity << 0.5 * (o.start.vx + o.end.vx) + w_mid * minus_ry,
      0.5 * (o.start.vy + o.end.vy) + w_mid * rx, w_mid;
  return mid;
}

std::string LowSnrReason(double snr, bool differentiated, bool rotation) {
  return Printf(
      "the %s of a step is only %.2g times its noise (need %.3g): the per-step estimates are "
      "biased, not just noisy%s",
      rotation ? "rotational friction impulse" : "friction impulse", snr, kMinImpulseSnr,
      differentiated ? " (velocities differentiated from noisy poses; use the trajectory method)"
                     : "");
}

PlausibilityContext CheapContext(const std::vector<LogSteps>& logs) {
  PlausibilityContext c;
  for (const LogSteps& s : logs) {
    const SliderProperties& slider = s.log->slider;
    c.logs.push_back({slider.mass_kg * slider.gravity_mps2, s.max_push_n});
  }
  return c;
}

double BiasAwareHalfWidth(double sd, double bias) {
  // Coverage of +-h around an estimate N(b, sd^2) at the truth; increasing in h.
  auto coverage = [&](double h) {
    return 0.5 * (std::erfc(-(h - bias) / (sd * std::sqrt(2.0))) -
                  std::erfc(-(-h - bias) / (sd * std::sqrt(2.0))));
  };
  double lo = kZ95 * sd, hi = kZ95 * sd + bias;
  for (int k = 0; k < kHalfWidthBisections; ++k) {
    const double mid = 0.5 * (lo + hi);
    (coverage(mid) < 0.95 ? lo : hi) = mid;
  }
  return hi;
}

ParameterEstimate FromLogEstimate(const LogEstimate& e) {
  if (e.noise_bias_bound_log > kMaxNoiseBiasStderrs * e.stderr_log) {
    return NotIdentifiable(
        std::exp(e.log_value),
        Printf("the log's noise may bias it by up to %.2g%%, %.2g times its standard error "
               "%.2g%% (errors in variables: ratios and directions of noisy velocities); the "
               "equation-error fit (measured velocities) or the trajectory method do better",
               100 * e.noise_bias_bound_log, e.noise_bias_bound_log / e.stderr_log,
               100 * e.stderr_log));
  }
  ParameterEstimate p = EstimateFromLog(e.log_value, e.stderr_log, e.quantile);
  p.note = e.note;
  const double shift = e.force_hold_shift_log;
  if (shift > 0 && e.stderr_log > 0) {
    const double half = BiasAwareHalfWidth(e.quantile * e.stderr_log / kZ95, shift);
    p.ci95_lo = std::exp(e.log_value - half);
    p.ci95_hi = std::exp(e.log_value + half);
    p.note += (p.note.empty() ? "" : "; ") +
              Printf(
                  "interval widened %.2fx: another reading of the log (forces varying within "
                  "its rows rather than held; for c also the direction of sliding at "
                  "mid-interval) would move the estimate by %.2g%%",
                  half / (e.quantile * e.stderr_log), 100 * shift);
  }
  return p;
}

}  // namespace slideid
