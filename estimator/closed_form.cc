#include "estimator/closed_form.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "estimator/identifiability.h"
#include "estimator/robust_statistics.h"
#include "estimator/step_observations.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// sqrt(pi / 2): asymptotic standard error of the median over that of the mean (Gaussian).
constexpr double kMedianOverMeanStdErr = 1.2533;

const char* const kSymbol[3] = {"a", "b", "c"};


/// |x| is nonzero and at least `fraction` of `scale`.
bool ClearOfZero(double x, double scale, double fraction) {
  return std::abs(x) > 0 && std::abs(x) >= fraction * scale;
}

std::string ExclusionSummary(const EstimateResult& r) {
  std::string s;
  for (const auto& [reason, count] : r.steps_excluded) {
    s += (s.empty() ? "" : ", ") + reason + " " + std::to_string(count);
  }
  return s.empty() ? "none" : s;
}

}  // namespace

EstimateResult EstimateClosedForm(const Trajectory& log, const IdentifyOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  std::string why;
  if (!options.closed_form.IsValid(&why)) {
    throw std::invalid_argument("EstimateClosedForm: " + why);
  }
  const double fraction = options.closed_form.divisor_fraction;
  const std::vector<StepObservation> steps = ExtractStepObservations(log);
  const double radius = std::sqrt(log.slider.inertia_kgm2 / log.slider.mass_kg);  // L [m]

  EstimateResult result;
  result.method = EstimatorMethod::kClosedForm;
  result.steps_total = static_cast<int>(steps.size());
  result.residual_names = {{"a_step_rel", "b_step_rel", "c_step_rel"}};

  // Per-step estimates of a, b, c (NaN where the step gives none).
  std::vector<std::array<double, 3>> per_step(steps.size(), {{kNaN, kNaN, kNaN}});
  std::array<std::vector<double>, 3> usable;
  for (size_t k = 0; k < steps.size(); ++k) {
    const StepObservation& o = steps[k];
    if (!InformativeStep(o, &result)) continue;
    const double vt = o.ecp_velocity(0), vo = o.ecp_velocity(1), vr = o.ecp_velocity(2);
    const double pt = o.friction_impulse(0), po = o.friction_impulse(1),
                 pr = o.friction_impulse(2);
    const double pn = o.pn;
    const double v_scale = std::sqrt(vt * vt + vo * vo + radius * radius * vr * vr);
    const double p_scale = std::sqrt(pt * pt + po * po + pr * pr / (radius * radius));

    // Appendix A, corrected (model.md). Each check names the first divisor that fails.
    std::array<double, 3> squared{{kNaN, kNaN, kNaN}};
    std::array<std::string, 3> reason;
    if (!ClearOfZero(vt, v_scale, fraction)) {
      reason[kA] = "v_t near zero";
    } else {
      squared[kA] = (pt / pn) * (pt / pn) + pt * po * vo / (pn * pn * vt) +
                    pt * pr * vr / (pn * pn * vt);
    }
    if (!ClearOfZero(pt, p_scale, fraction)) {
      reason[kB] = reason[kC] = "p_t near zero";
    } else {
      if (!ClearOfZero(vo, v_scale, fraction)) {
        reason[kB] = "v_o near zero";
      } else {
        squared[kB] = po * vt / (pt * vo);
      }
      if (!ClearOfZero(radius * vr, v_scale, fraction)) {
        reason[kC] = "v_r near zero";
      } else {
        squared[kC] = pr * vt / (pt * vr);
      }
    }
    for (int i = 0; i < 3; ++i) {
      if (reason[i].empty() && !(squared[i] > 0 && std::isfinite(squared[i]))) {
        reason[i] = "non-positive estimate";
      }
      if (!reason[i].empty()) {
        result.Exclude(std::string(kSymbol[i]) + ": " + reason[i]);
        continue;
      }
      per_step[k][i] = std::sqrt(squared[i]);
      usable[i].push_back(per_step[k][i]);
    }
  }

  result.steps_used = static_cast<int>(usable[kA].size());
  if (result.steps_used < kMinStepsPerParameter) {
    result.status = TerminationStatus::kTooLittleExcitation;
    result.converged = false;
    result.message =
        "too little sliding to identify anything: " + std::to_string(result.steps_used) +
        " of " + std::to_string(steps.size()) + " steps give an estimate of a = e_t mu (need " +
        std::to_string(kMinStepsPerParameter) + "); excluded: " + ExclusionSummary(result);
    return result;
  }

  std::array<double, 3> median{{kNaN, kNaN, kNaN}};
  for (int i = 0; i < 3; ++i) {
    const int n = static_cast<int>(usable[i].size());
    if (n < kMinStepsPerParameter) {
      result.parameters[i] = NotIdentifiable(
          kNaN, "only " + std::to_string(n) + " steps give an estimate (need " +
                    std::to_string(kMinStepsPerParameter) + ")");
      continue;
    }
    median[i] = Median(usable[i]);
    std::vector<double> deviation(usable[i].size());
    for (int j = 0; j < n; ++j) deviation[j] = std::abs(usable[i][j] - median[i]);
    const double mad = Median(deviation);
    ParameterEstimate& p = result.parameters[i];
    p.identifiable = true;
    p.value = median[i];
    p.stderr_value = kMedianOverMeanStdErr * kMadToSigma * mad / std::sqrt(double(n));
    p.ci95_lo = std::max(p.value - kZ95 * p.stderr_value, std::numeric_limits<double>::min());
    p.ci95_hi = p.value + kZ95 * p.stderr_value;
    p.note = "median of " + std::to_string(n) +
             " per-step estimates; interval value +- 1.96 standard errors of the median";
  }

  result.residuals.reserve(steps.size());
  for (size_t k = 0; k < steps.size(); ++k) {
    StepResidual r;
    r.row = steps[k].row;
    r.t_s = log.samples[steps[k].row].t_s;
    for (int i = 0; i < 3; ++i) r.value[i] = per_step[k][i] / median[i] - 1.0;
    r.used = !std::isnan(per_step[k][kA]);
    result.residuals.push_back(r);
  }
  result.message = "closed form: medians of per-step estimates (a " +
                   std::to_string(usable[kA].size()) + ", b " +
                   std::to_string(usable[kB].size()) + ", c " +
                   std::to_string(usable[kC].size()) + " steps)";
  for (ParameterEstimate& p : result.parameters) p.verdict = p.identifiable ? Verdict::kOk : Verdict::kNotIdentifiable;
  result.Conclude(true);
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace slideid
