#pragma once
// The verdict on each estimate (estimate.h, Verdict): whether a value the data determine
// is also believable. Shared by every method, so that "suspect" means the same everywhere.
//
// An identifiable parameter becomes kSuspect, with the reason, when
//  - the fit's residuals sit far above the noise the log itself shows (model mismatch:
//    the estimate explains a different motion from the one logged);
//  - the friction it implies, a m g, is more than kFrictionOverPush times the largest push
//    of a pushed log (the slider could then never have been made to slide);
//  - it sits at a bound of the search range;
//  - it is orders of magnitude from the seed the fit started from.
// It becomes kNotIdentifiable when its 95% interval spans more than a factor
// kMaxIntervalFactor (a value known to within a factor 7 says nothing: identifiability.h).

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/slider.h"

namespace slideid {

/// Residual RMS above this many times the log's own noise is model mismatch. A fit that
/// describes the log leaves residuals at its noise (ratio ~1; a little more where
/// unlogged force noise makes the motion wander). 3 is far outside that.
constexpr double kMismatchRatio = 3.0;
/// Friction force a m g above this many times the largest push.
constexpr double kFrictionOverPush = 1.5;
/// A log-parameter within this of a bound of the search range is at the bound.
constexpr double kAtBoundLog = 1e-3;
/// Estimate and seed further apart than this factor.
constexpr double kSeedFactor = 10.0;
/// exp(2 * 1.96 * 0.5): the interval of a log-parameter with standard error 0.5.
constexpr double kMaxIntervalFactor = 7.1;

/// One log's capacity to make a slider slide.
struct PushCapacity {
  double weight_n = 0;    ///< m g
  double max_push_n = 0;  ///< largest applied horizontal force (0: not a pushed log)
};

/// What the checks look at; NaN or empty entries skip their check.
struct PlausibilityContext {
  double residual_rms = std::numeric_limits<double>::quiet_NaN();
  double log_noise = std::numeric_limits<double>::quiet_NaN();  ///< same channels
  /// The residuals the method's own model error leaves on an exact log, in the same
  /// channels (0: not known). The mismatch check compares the residuals with the log's
  /// noise and this together: a noise-free simulated log leaves residuals of the fit's
  /// discretisation, tens of times its rounding-level noise, and that is no reason to
  /// distrust it.
  double model_floor = 0;
  std::vector<PushCapacity> logs;
  ReducedFriction seed{std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::quiet_NaN()};
  ReducedFriction lower{0, 0, 0};  ///< search range; 0 / inf: none
  ReducedFriction upper{std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity()};
};

/// Makes `p` suspect, adding `reason` to any it has (the checks below, and identify
/// --follow's rows after a warning of the log reader).
void MarkSuspect(ParameterEstimate* p, const std::string& reason);

/// Sets the verdict (and reason) of every parameter: kNotIdentifiable ones stay so; an
/// identifiable one whose interval spans more than kMaxIntervalFactor becomes not
/// identifiable (held at its value); the others are kOk or kSuspect by the checks above.
void JudgeEstimates(const PlausibilityContext& context,
                    std::array<ParameterEstimate, 3>* parameters);

}  // namespace slideid
