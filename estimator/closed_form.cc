#include "estimator/closed_form.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "estimator/cheap_methods.h"
#include "estimator/identifiability.h"
#include "estimator/internal/method_cores.h"
#include "estimator/plausibility.h"
#include "estimator/pooling.h"
#include "estimator/robust_statistics.h"
#include "estimator/simex.h"  // LogEstimate
#include "estimator/step_covariance.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Huber's clip in units of the scale: 95% of the mean's efficiency on Gaussian steps,
/// while a step far off (a ratio whose divisor noise nearly cancelled) counts no more than
/// 1.345 scales.
constexpr double kHuberLocationK = 1.345;
/// The location iteration stops when a step moves it by less than this many scales; it
/// converges linearly from the median in a few iterations.
constexpr double kLocationTolerance = 1e-10;
constexpr int kMaxLocationIterations = 100;
/// Steps whose spread is below this fraction of their spread under another reading of the
/// log rule that reading out (noisy logs: about 1; exact logs: 1e-10 and less).
constexpr double kMinReadingScale = 0.5;

// By index, not ReducedFriction: a, b, c share each check, sample and interval, and may be NaN.
const char* const kSymbol[3] = {"a", "b", "c"};

/// |x| is nonzero, at least `fraction` of `scale` and kDivisorSigmas of `noise`.
bool ClearOfZero(double x, double scale, double fraction, double noise) {
  return std::abs(x) > 0 && std::abs(x) >= fraction * scale &&
         std::abs(x) >= kDivisorSigmas * noise;
}

std::string ExclusionSummary(const EstimateResult& r) {
  std::string s;
  for (const auto& [reason, count] : r.steps_excluded) {
    s += (s.empty() ? "" : ", ") + reason + " " + std::to_string(count);
  }
  return s.empty() ? "none" : s;
}

/// a^2, b^2, c^2 of one step by model.md, Appendix A, corrected (no checks).
std::array<double, 3> SquaredEstimates(const StepObservation& o) {
  const double vt = o.ecp_velocity(0), vo = o.ecp_velocity(1), vr = o.ecp_velocity(2);
  const double pt = o.friction_impulse(0), po = o.friction_impulse(1), pr = o.friction_impulse(2);
  const double pn = o.pn;
  return {{(pt / pn) * (pt / pn) + pt * po * vo / (pn * pn * vt) + pt * pr * vr / (pn * pn * vt),
           po * vt / (pt * vo), pr * vt / (pt * vr)}};
}

/// One sliding step's estimates of a, b, c; NaN where a divisor is near zero or the
/// estimate is not positive, with the reason recorded.
std::array<double, 3> StepEstimates(const StepObservation& o, const LogSteps& s, double fraction,
                                    EstimateResult* result) {
  const double radius = s.radius_m;
  const double vt = o.ecp_velocity(0), vo = o.ecp_velocity(1), vr = o.ecp_velocity(2);
  const double pt = o.friction_impulse(0), po = o.friction_impulse(1), pr = o.friction_impulse(2);
  const double v_scale = std::sqrt(vt * vt + vo * vo + radius * radius * vr * vr);
  const double p_scale = std::sqrt(pt * pt + po * po + pr * pr / (radius * radius));
  const double sv = s.noise.velocity_mps, sw = s.noise.spin_radps;
  const double sp = s.log->slider.mass_kg * s.noise.delta_velocity_mps;

  // Each check names the first divisor that fails.
  std::array<std::string, 3> reason;
  if (!ClearOfZero(vt, v_scale, fraction, sv)) reason[kA] = "v_t near zero";
  if (!ClearOfZero(pt, p_scale, fraction, sp)) {
    reason[kB] = reason[kC] = "p_t near zero";
  } else {
    if (!ClearOfZero(vo, v_scale, fraction, sv)) reason[kB] = "v_o near zero";
    if (!ClearOfZero(radius * vr, v_scale, fraction, radius * sw)) reason[kC] = "v_r near zero";
  }
  const std::array<double, 3> squared = SquaredEstimates(o);
  std::array<double, 3> estimate{{kNaN, kNaN, kNaN}};
  for (int i = 0; i < 3; ++i) {
    if (reason[i].empty() && !(squared[i] > 0 && std::isfinite(squared[i]))) {
      reason[i] = "non-positive estimate";
    }
    if (!reason[i].empty()) {
      result->Exclude(std::string(kSymbol[i]) + ": " + reason[i]);
    } else {
      estimate[i] = std::sqrt(squared[i]);
    }
  }
  return estimate;
}

/// Per-step log-estimates of one parameter over every log, with where each came from.
struct Samples {
  std::vector<double> x;
  std::vector<int> log, row;
  /// The same steps' log-estimates under the other readings of the log (FromLogEstimate):
  /// forces varying within rows, and the direction of sliding at mid-interval.
  std::vector<double> x_force_varying, x_mid_interval;
};

/// 1/2 log of the squared estimate `i` of `o`, or `fallback` where it is not positive.
double HalfLogOr(const StepObservation& o, int i, double fallback) {
  const double squared = SquaredEstimates(o)[i];
  return squared > 0 && std::isfinite(squared) ? 0.5 * std::log(squared) : fallback;
}

/// What the steps of all logs gave.
struct Collected {
  std::array<Samples, 3> samples;
  std::array<std::string, 3> snr_reason;  ///< set when a log was left out for its noise
  int steps_with_a = 0;                   ///< before the noise check
  std::vector<StepResidual> residuals;    ///< value: the estimates themselves, for now
};

/// One pass over the log's steps, streamed (ForEachStepObservation: a 1e6-row log's steps
/// took 224 MB at once): each sliding step's estimates go into c's samples as they come,
/// with the impulse magnitudes of the noise check, and a parameter the check leaves out is
/// taken back out of the samples after the pass. `keep_residuals`: the per-step residuals
/// (--residuals) too.
void CollectLog(const LogSteps& s, int k, double fraction, bool keep_residuals, Collected* c,
                EstimateResult* result) {
  const size_t rows = s.log->samples.size();
  const size_t steps = rows >= 2 ? rows - 1 : 0;
  std::vector<std::array<double, 3>> estimates;  // per step, only for the residuals
  std::vector<int> step_rows;
  if (keep_residuals) {
    estimates.reserve(steps);
    step_rows.reserve(steps);
  }
  std::array<size_t, 3> before{}, used{};
  for (int i = 0; i < 3; ++i) {
    Samples& x = c->samples[i];
    before[i] = x.x.size();
    // Untouched capacity costs address space only; the samples no longer grow by copies.
    for (auto* v : {&x.x, &x.x_force_varying, &x.x_mid_interval}) v->reserve(before[i] + steps);
    for (auto* v : {&x.log, &x.row}) v->reserve(before[i] + steps);
  }
  std::vector<double> translation_impulse, rotation_impulse;  // of the sliding steps
  ForEachStepObservation(*s.log, [&](const StepObservation& o) {
    std::array<double, 3> estimate{{kNaN, kNaN, kNaN}};
    if (SlidingStep(o, s.noise, s.radius_m, result)) {
      translation_impulse.push_back(ImpulseMagnitude(o, false));
      rotation_impulse.push_back(ImpulseMagnitude(o, true));
      estimate = StepEstimates(o, s, fraction, result);
      for (int i = 0; i < 3; ++i) {
        if (std::isnan(estimate[i])) continue;
        ++used[i];
        const double x = std::log(estimate[i]);
        StepObservation varying = o;
        varying.friction_impulse += ForceHoldImpulseShift(s, o);
        c->samples[i].x.push_back(x);
        c->samples[i].x_force_varying.push_back(HalfLogOr(varying, i, x));
        c->samples[i].x_mid_interval.push_back(HalfLogOr(MidInterval(o), i, x));
        c->samples[i].log.push_back(k);
        c->samples[i].row.push_back(o.row);
      }
    }
    if (keep_residuals) {
      estimates.push_back(estimate);
      step_rows.push_back(o.row);
    }
  });
  c->steps_with_a += static_cast<int>(used[kA]);
  // Every estimate divides translational impulses; c's also rotational ones. A log whose
  // sliding steps' impulses do not stand out of their noise gives biased estimates.
  const double translation = ImpulseSnrOf(s, translation_impulse, false);
  const double rotation = ImpulseSnrOf(s, rotation_impulse, true);
  std::array<bool, 3> kept{};
  for (int i = 0; i < 3; ++i) {
    const bool low_translation = translation < kMinImpulseSnr;
    kept[i] = !low_translation && !(i == kC && rotation < kMinImpulseSnr);
    if (!kept[i]) {
      result->Exclude(std::string(kSymbol[i]) + ": impulse noise swamps the friction",
                      static_cast<int>(used[i]));
      c->snr_reason[i] = low_translation ? LowSnrReason(translation, s.noise.differentiated, false)
                                         : LowSnrReason(rotation, s.noise.differentiated, true);
      Samples& x = c->samples[i];
      for (auto* v : {&x.x, &x.x_force_varying, &x.x_mid_interval}) v->resize(before[i]);
      for (auto* v : {&x.log, &x.row}) v->resize(before[i]);
    }
  }
  if (!keep_residuals) return;
  c->residuals.reserve(c->residuals.size() + estimates.size());
  for (size_t j = 0; j < estimates.size(); ++j) {
    StepResidual r;
    r.log = k;
    r.row = step_rows[j];
    r.t_s = s.log->samples[step_rows[j]].t_s;
    for (int i = 0; i < 3; ++i) r.value[i] = kept[i] ? estimates[j][i] : kNaN;
    r.used = !std::isnan(r.value[kA]);
    c->residuals.push_back(r);
  }
}

/// Huber's M-estimate of location of per-step log-estimates (closed_form.h): the centre m
/// with sum psi((x - m) / s) = 0, s = 1.4826 MAD, psi clipped at kHuberLocationK; started
/// from the median.
struct Location {
  double centre = kNaN;
  double scale = 0;
  std::vector<double> psi;  ///< psi((x - centre) / scale) per step
  double slope = 0;         ///< sum psi' (steps within the clip)
};

Location HuberLocation(const std::vector<double>& x) {
  Location l;
  l.centre = Median(x);
  std::vector<double> deviation(x.size());
  for (size_t j = 0; j < x.size(); ++j) deviation[j] = std::abs(x[j] - l.centre);
  l.scale = kMadToSigma * Median(deviation);
  l.psi.assign(x.size(), 0.0);
  if (!(l.scale > 0)) return l;  // exact data: every step agrees with the median
  for (int iteration = 0; iteration < kMaxLocationIterations; ++iteration) {
    double sum = 0, slope = 0;
    for (size_t j = 0; j < x.size(); ++j) {
      const double u = (x[j] - l.centre) / l.scale;
      l.psi[j] = std::clamp(u, -kHuberLocationK, kHuberLocationK);
      sum += l.psi[j];
      slope += std::abs(u) <= kHuberLocationK ? 1.0 : 0.0;
    }
    l.slope = slope;
    if (!(slope > 0)) break;
    const double step = l.scale * sum / slope;
    l.centre += step;
    if (std::abs(step) <= kLocationTolerance * l.scale) break;
  }
  return l;
}

/// The robust mean of per-step log-estimates and its interval (closed_form.h).
LogEstimate RobustMeanEstimate(const Samples& s, const std::vector<int>& lag_of_log, bool spin) {
  const int n = static_cast<int>(s.x.size());
  const Location l = HuberLocation(s.x);
  std::string note = Printf("robust mean of %d per-step estimates", n);
  if (!(l.scale > 0) || !(l.slope > 0)) return {l.centre, 0.0, kZ95, 0.0, 0.0, note};
  // Sandwich: the centre moves by scale sum(psi) / sum(psi'). Neighbouring steps share a
  // velocity sample and their psi are correlated: the variance of sum(psi) is the
  // block-level long-run variance (step_covariance.h), and over several logs also the
  // cluster-robust one over the logs, where wider.
  Eigen::MatrixXd psi = Eigen::Map<const Eigen::VectorXd>(l.psi.data(), n);
  const double scale = l.scale / l.slope;
  const StepBlocks blocks = BlocksOfSteps(s.log, s.row, lag_of_log);
  const double block_var = BlockScoreCovariance(psi, blocks)(0, 0);
  double stderr_log, quantile;
  if (blocks.count >= kMinBlocks && block_var > 0) {
    stderr_log = scale * std::sqrt(block_var);
    quantile = StudentT95(blocks.count - 1);
    note += Printf(" in %d blocks", blocks.count);
  } else {
    stderr_log = scale * std::sqrt(psi.squaredNorm());
    quantile = kZ95;
    note += Printf("; only %d blocks of %d steps: interval from independent steps", blocks.count,
                   kBlockSteps);
  }
  int logs = 0;
  const double log_var = ClusterScoreCovariance(psi, s.log, &logs)(0, 0);
  if (logs >= kMinLogClusters) {
    note += Printf(" of %d logs", logs);
    const double stderr_between = scale * std::sqrt(log_var);
    const double t = StudentT95(logs - 1);
    if (t * stderr_between > quantile * stderr_log) {
      note += Printf(
          "; interval widened %.2fx: the logs differ by more than their noise "
          "(cluster-robust over %d logs, t quantile %.2f)",
          t * stderr_between / (quantile * stderr_log), logs, t);
      stderr_log = stderr_between;
      quantile = t;
    }
  }
  // Errors in variables: each step's estimate is half a sum of logs of noisy factors
  // (closed_form.h), and E[log(x + e)] = log x - var(e) / (2 x^2): its bias is at most its
  // own variance, which the steps' spread (scale^2) bounds.
  // The other readings of the log (as the equation error's; the mid-interval one for c),
  // unless the steps rule a reading out: when they agree far better as read than under it
  // (an exact log), the reading is not the log's.
  double shift = 0;
  for (const std::vector<double>* other : {&s.x_force_varying, &s.x_mid_interval}) {
    if (other == &s.x_mid_interval && !spin) continue;
    const Location alternative = HuberLocation(*other);
    if (l.scale >= kMinReadingScale * alternative.scale) {
      shift += std::abs(alternative.centre - l.centre);
    }
  }
  return {l.centre, stderr_log, quantile, l.scale * l.scale, shift, note};
}

/// Every log's per-step estimates (exclusions counted in `result`).
Collected CollectAll(const std::vector<const Trajectory*>& logs, double fraction,
                     bool keep_residuals, std::vector<LogSteps>* log_steps,
                     EstimateResult* result) {
  Collected c;
  for (size_t k = 0; k < logs.size(); ++k) {
    log_steps->push_back(ReadLogSteps(*logs[k], /*with_steps=*/false));
    const size_t rows = logs[k]->samples.size();
    result->steps_total += static_cast<int>(rows >= 2 ? rows - 1 : 0);
    CollectLog(log_steps->back(), static_cast<int>(k), fraction, keep_residuals, &c, result);
  }
  return c;
}

std::vector<int> Lags(const std::vector<LogSteps>& log_steps) {
  std::vector<int> lags;
  for (const LogSteps& s : log_steps) lags.push_back(s.lag);
  return lags;
}

}  // namespace

EstimateResult ClosedFormCore(const std::vector<const Trajectory*>& logs,
                              const IdentifyOptions& options, bool keep_residuals) {
  const auto start_time = std::chrono::steady_clock::now();
  EstimateResult result;
  result.method = EstimatorMethod::kClosedForm;
  result.residual_names = {{"a_step_rel", "b_step_rel", "c_step_rel"}};
  const double fraction = options.closed_form.divisor_fraction;
  std::vector<LogSteps> log_steps;
  Collected c =
      CollectAll(logs, fraction, keep_residuals && options.keep_residuals, &log_steps, &result);
  const std::vector<int> lag_of_log = Lags(log_steps);
  result.steps_used = static_cast<int>(c.samples[kA].x.size());
  if (c.steps_with_a < kMinStepsPerParameter) {
    result.status = TerminationStatus::kTooLittleExcitation;
    result.converged = false;
    result.message = "too little sliding to identify anything: " + std::to_string(c.steps_with_a) +
                     " of " + std::to_string(result.steps_total) +
                     " steps give an estimate of a = e_t mu (need " +
                     std::to_string(kMinStepsPerParameter) +
                     "); excluded: " + ExclusionSummary(result) + RateTooHighNote(log_steps);
    return result;
  }

  std::array<LogEstimate, 3> estimate;
  std::array<double, 3> log_centre{{kNaN, kNaN, kNaN}};
  for (int i = 0; i < 3; ++i) {
    const int n = static_cast<int>(c.samples[i].x.size());
    if (n < kMinStepsPerParameter) {
      result.parameters[i] = NotIdentifiable(
          kNaN, !c.snr_reason[i].empty()
                    ? c.snr_reason[i]
                    : "only " + std::to_string(n) + " steps give an estimate (need " +
                          std::to_string(kMinStepsPerParameter) + ")");
      continue;
    }
    estimate[i] = RobustMeanEstimate(c.samples[i], lag_of_log, i == kC);
    log_centre[i] = estimate[i].log_value;
  }
  std::array<double, 3> centre{{kNaN, kNaN, kNaN}};
  for (int i = 0; i < 3; ++i) {
    if (std::isnan(log_centre[i])) continue;
    centre[i] = std::exp(log_centre[i]);
    result.parameters[i] = FromLogEstimate(estimate[i]);
  }
  JudgeEstimates(CheapContext(log_steps), &result.parameters);

  for (StepResidual& r : c.residuals) {
    for (int i = 0; i < 3; ++i) r.value[i] = r.value[i] / centre[i] - 1.0;
  }
  result.residuals = std::move(c.residuals);
  result.message = "closed form: robust means of per-step estimates (a " +
                   std::to_string(c.samples[kA].x.size()) + ", b " +
                   std::to_string(c.samples[kB].x.size()) + ", c " +
                   std::to_string(c.samples[kC].x.size()) + " steps)";
  result.Conclude(true);
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

EstimateResult EstimateClosedForm(const Trajectory& log, const IdentifyOptions& options) {
  return EstimateAs(EstimatorMethod::kClosedForm, {&log}, options);
}

EstimateResult EstimateClosedForm(const std::vector<Trajectory>& logs,
                                  const IdentifyOptions& options) {
  return EstimateAs(EstimatorMethod::kClosedForm, Pointers(logs), options);
}

}  // namespace slideid
