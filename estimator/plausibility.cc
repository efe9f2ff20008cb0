#include "estimator/plausibility.h"

#include <cmath>
#include <string>

#include "forward_model/number_format.h"

namespace slideid {
namespace {

// A number for a reason's text: %.3g, or "over 1e308" where it overflowed (an interval
// of [6e-260, 1e258], the friction of a 1e308 kg slider), which printed as "inf".
std::string Magnitude(double v) {
  return std::isfinite(v) ? Printf("%.3g", v) : std::string("over 1e308");
}

}  // namespace

void MarkSuspect(ParameterEstimate* p, const std::string& reason) {
  p->verdict = Verdict::kSuspect;
  p->reason += (p->reason.empty() ? "" : "; ") + reason;
}

void JudgeEstimates(const PlausibilityContext& c, std::array<ParameterEstimate, 3>* parameters) {
  const double floor = std::isfinite(c.model_floor) ? c.model_floor : 0.0;
  const double mismatch = c.residual_rms / std::hypot(c.log_noise, floor);
  for (int i = 0; i < 3; ++i) {
    ParameterEstimate& p = (*parameters)[i];
    if (!p.identifiable) {
      p.verdict = Verdict::kNotIdentifiable;
      continue;
    }
    const double factor = p.ci95_hi / p.ci95_lo;
    if (!(p.ci95_lo > 0) || !(factor <= kMaxIntervalFactor)) {
      ParameterEstimate held;
      held.held_at = p.value;
      held.reason =
          p.ci95_lo > 0
              ? Printf(
                    "its 95%% interval [%.3g, %.3g] spans a factor %s: the log does not "
                    "determine it",
                    p.ci95_lo, p.ci95_hi, Magnitude(factor).c_str())
              : Printf(
                    "its 95%% interval [%.3g, %.3g] reaches down to zero: the log does not "
                    "determine it",
                    p.ci95_lo, p.ci95_hi);
      if (mismatch > kMismatchRatio) {
        held.reason += Printf(
            " (its residuals are %.3g times the log's own noise and the "
            "model's discretisation: the model does not fit it, which widens "
            "the interval)",
            mismatch);
      }
      p = held;
      continue;
    }
    p.verdict = Verdict::kOk;
    p.reason.clear();
    if (mismatch > kMismatchRatio) {
      MarkSuspect(&p, floor > 0 ? Printf("residuals %.3g times the log's own noise and the "
                                         "model's discretisation together (model mismatch: "
                                         "%.3g against %.3g)",
                                         mismatch, c.residual_rms, std::hypot(c.log_noise, floor))
                                : Printf("residuals %.3g times the log's own noise (model "
                                         "mismatch: %.3g against %.3g)",
                                         mismatch, c.residual_rms, c.log_noise));
    }
    if (i == kA) {
      for (const PushCapacity& log : c.logs) {
        const double friction = p.value * log.weight_n;
        if (log.max_push_n > 0 && friction > kFrictionOverPush * log.max_push_n) {
          MarkSuspect(&p, Printf("implies %s N of friction against a largest push of %.3g N: "
                                 "the slider could not have slid",
                                 Magnitude(friction).c_str(), log.max_push_n));
          break;
        }
      }
    }
    const double v = std::log(p.value);
    if (std::abs(v - std::log(c.lower[i])) < kAtBoundLog ||
        std::abs(v - std::log(c.upper[i])) < kAtBoundLog) {
      MarkSuspect(&p,
                  Printf("at a bound of the search range [%.3g, %.3g]", c.lower[i], c.upper[i]));
    }
    if (c.seed[i] > 0 && std::abs(v - std::log(c.seed[i])) > std::log(kSeedFactor)) {
      MarkSuspect(&p, Printf("%.3g times the seed %.3g the fit started from", p.value / c.seed[i],
                             c.seed[i]));
    }
  }
}

}  // namespace slideid
