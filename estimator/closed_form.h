#pragma once
// Closed-form estimator: one estimate of a, b, c per sliding step from model.md,
// "Appendix A (identification), corrected", aggregated by the median.

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Default of ClosedFormOptions::divisor_fraction. A divisor of an Appendix A formula
/// counts as "near zero" below this fraction of its
/// step's own scale (|v|_w = sqrt(v_t^2 + v_o^2 + (L v_r)^2) for velocities, |p|_w =
/// sqrt(p_t^2 + p_o^2 + (p_r / L)^2) for impulses, L = sqrt(I_z / m)). Noise on a divisor
/// is amplified by scale / |divisor|, so 0.1 caps that at 10x the noise of a step along the
/// axis, while still using every step whose direction is within ~84 deg of the axis. Exact
/// data need no margin at all; this only matters under noise.
constexpr double kDivisorFraction = 0.1;

/// Fewest per-step estimates from which a median and its spread mean anything.
constexpr int kMinStepsPerParameter = 3;

/// Per step (sliding, start velocity known, divisors clear of zero), Appendix A gives
/// a^2, b^2, c^2; each parameter is the median of its steps' estimates, with standard
/// error 1.2533 * 1.4826 * MAD / sqrt(n) and 95% interval value +- kZ95 stderr (lower end
/// clamped above 0). A parameter with fewer than kMinStepsPerParameter steps is not
/// identifiable. Residuals: per step, each estimate's relative deviation from the median
/// (NaN where the step gave none); used = the step gave an estimate of a.
/// Throws std::invalid_argument for invalid options or slider properties. When fewer than
/// kMinStepsPerParameter steps give an estimate of a, the status is kTooLittleExcitation
/// ("too little sliding ...").
EstimateResult EstimateClosedForm(const Trajectory& log, const IdentifyOptions& options);

}  // namespace slideid
