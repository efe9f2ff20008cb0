#pragma once
// Closed-form estimator: one estimate of a, b, c per sliding step from model.md,
// "Appendix A (identification), corrected", aggregated by a robust mean over the steps of
// one log or of several logs of one slider on one surface.

#include <vector>

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

/// A divisor must also be at least this many times its own noise (StepNoise: s_v for v_t,
/// v_o, s_w for v_r, m sqrt(2 or 6) ... for p_t): a ratio whose divisor is within 3 sigma
/// of zero has a heavy tail and a sign that noise can flip.
constexpr double kDivisorSigmas = 3.0;

/// Fewest per-step estimates from which a robust mean and its spread mean anything: enough
/// that a few wild steps cannot make the estimate. With 3, motion-capture glitches did: 5
/// steps whose velocities a 5 mm jump made, in a noisy log where every honest step fell
/// below the divisor and noise checks, gave a = 40 and c = 2 times the truth, c marked ok
/// (benchmarks/coverage.cc, condition outliers, 1 log of 200).
constexpr int kMinStepsPerParameter = 10;

/// Friction impulse over its noise below which a log's per-step estimates are biased, not
/// just noisy (errors in variables): each step's estimate is a ratio of noisy impulses and
/// velocities, whose bias grows as 1 / SNR^2 and whose sign noise can flip once the SNR is
/// near 1. Signal: the median over the log's sliding steps of |(p_t, p_o)| (a, b) or |p_r|
/// (c); noise: m or I_z times the noise of v' - v (StepNoise). Velocities differentiated
/// from 0.3 mm motion capture at 100 Hz give about 0.5-1.3 (the bundled log: 1.3);
/// velocities measured to 2 mm/s about 10. Both cheap methods use it.
constexpr double kMinImpulseSnr = 3.0;

/// Per step (sliding over the whole interval, SlidingStep; divisors clear of zero by
/// kDivisorFraction of the step's scale and kDivisorSigmas of their noise), Appendix A gives
/// a^2, b^2, c^2; each parameter is Huber's robust mean (clip 1.345 scales, about the median)
/// of its steps' log-estimates over every log. Logs whose sliding steps' impulses are below
/// kMinImpulseSnr times their noise are left out of it; when none is left the parameter is
/// not identifiable, with the reason.
///
/// The interval is formed in log space, exp(centre +- q stderr), so it never reaches 0. Its
/// standard error is the M-estimator's sandwich, scale sqrt(S) / sum(psi'), S the
/// block-level long-run variance of the steps' psi (estimator/step_covariance.h:
/// neighbouring steps share a velocity sample), q Student's t with (blocks - 1) degrees of
/// freedom. Over several logs it is also computed with the logs as clusters (G / (G - 1), t
/// with G - 1 degrees of freedom), and the wider is reported, with a note when the logs'
/// spread widened it.
///
/// Errors in variables: a step's log-estimate is half a sum of logs of noisy factors, and
/// E[log(x + e)] = log x - var(e) / (2 x^2), so its bias is bounded by its variance, which
/// the steps' spread (scale^2) measures. When that bound exceeds kMaxNoiseBiasStderrs
/// standard errors the parameter is not identifiable, with the reason and held_at the
/// estimate: the robust mean is then precise enough that its bias may matter (typically at
/// 2 mm/s of velocity noise on a few hundred steps), and the equation error, which corrects
/// it, does better. Verdicts: JudgeEstimates (estimator/plausibility.h); an interval
/// spanning more than a factor kMaxIntervalFactor is not identifiable.
///
/// Residuals: per step, each estimate's relative deviation from the centre (NaN where the
/// step gave none); used = the step gave an estimate of a. With several logs,
/// result.logs holds each log on its own and result.heterogeneity whether they agree.
/// Throws std::invalid_argument for invalid options, slider properties or an empty list.
/// When fewer than kMinStepsPerParameter steps give an estimate of a, the status is
/// kTooLittleExcitation ("too little sliding ...").
EstimateResult EstimateClosedForm(const Trajectory& log, const IdentifyOptions& options);
EstimateResult EstimateClosedForm(const std::vector<Trajectory>& logs,
                                  const IdentifyOptions& options);

}  // namespace slideid
