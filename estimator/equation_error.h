#pragma once
// Equation-error estimator: a Ceres fit of theta = (log a, log b, log c) to the measured
// friction impulses, with the model of model.md, "Only three parameters matter", evaluated
// at the measured ECP velocities.

#include <cmath>
#include <limits>
#include <vector>

#include "estimator/estimate.h"
#include "estimator/step_observations.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Robust-loss scale floor (dimensionless, residuals are impulses over p_n): when the
/// residuals at the seed are at rounding level (exact logs), a loss scale of that size
/// would make Huber/Cauchy act on rounding noise. 1e-9 is far below any measurement noise
/// (a of order 0.1..1) and far above rounding (~1e-16).
constexpr double kMinLossSigma = 1e-9;

/// Fits (log a, log b, log c) by Ceres (DENSE_QR, within kFrictionLowerBound..UpperBound,
/// options.loss at options.loss_scale_sigmas times the residuals' robust scale at the seed)
/// to the sliding steps of the log (SlidingStep: rest phases, sticking, the first step of
/// each sliding phase and, for differentiated velocities, steps next to a force switch
/// excluded), seeded by EstimateClosedForm (a = 0.3, b = 1, c = L where it gives none). A
/// log whose friction impulses are below kMinImpulseSnr times their noise (velocities
/// differentiated from noisy poses) is left out, with the reason; c is not identifiable when
/// the rotational impulses are. Parameters that AssessIdentifiability rejects (with the
/// residuals' robust scale, 1.4826 MAD) are held at their seed and the rest refitted.
///
/// Errors in variables are corrected by SIMEX (estimator/simex.h) when the residuals show
/// the noise the log's velocities carry; a correction beyond kMaxSimexBiasLog makes the
/// parameter not identifiable.
///
/// Intervals: exp(theta +- q stderr), stderr from the robust sandwich B^-1 S B^-1,
/// B = sum rho' J^T J, S the block-level long-run covariance of the scores rho' J^T r
/// (estimator/step_covariance.h: neighbouring steps share a velocity sample, which makes
/// their noise cancel in the fit; the white-noise covariance overstated the error 4x), q
/// Student's t with (blocks - 1) degrees of freedom; with fewer than kMinBlocks blocks, the
/// white-noise sandwich (wider). The robust weights rho' keep outliers (rows no noisy log can
/// flag) from inflating it. The interval also holds the estimate the fit would give if the
/// forces varied linearly within the rows instead of being held over them (the log cannot
/// tell; BiasAwareHalfWidth), with a note. Over several logs the cluster-robust sandwich
/// with the logs as clusters (G / (G - 1), t with G - 1 degrees of freedom) is used where
/// wider, with a note. Verdicts: JudgeEstimates (estimator/plausibility.h), with the
/// residuals' scale against the one the log's velocity noise implies (model mismatch).
/// Residuals: per step, names "t", "o", "r", NaN for unused steps.
/// Seeded by the closed form of the same log. Throws std::invalid_argument for invalid
/// options; too little sliding is the status kTooLittleExcitation.
EstimateResult EstimateEquationError(const Trajectory& log, const IdentifyOptions& options);

/// The same over several logs of one slider on one surface: one fit over the steps of all
/// of them, each log with its own slider properties; result.logs has each log fitted on its
/// own and result.heterogeneity whether they agree. Throws std::invalid_argument for an
/// empty list.
EstimateResult EstimateEquationError(const std::vector<Trajectory>& logs,
                                     const IdentifyOptions& options);

}  // namespace slideid
