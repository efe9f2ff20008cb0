#pragma once
// Quasi-static estimator: a, b, c from wrench-twist pairs, one per slow push
// (forward_model/wrench_twist_pair.h; model.md, "Only three parameters matter", with inertia
// neglected and the ECP under the CM). The friction wrench lies on the ellipsoidal limit
// surface, so the pair's applied wrench has the ellipsoid norm a N, and the twist is along
// the surface's normal:
//
//     sqrt(f_x^2 + (f_y / b)^2 + (m_z / c)^2) = a N        (magnitude: mostly a)
//     (v_x, v_y, w_z) parallel to (f_x, f_y / b^2, m_z / c^2)   (direction: b and c)
//
// Both are fitted at once by Ceres in theta = (log a, log b, log c), with a robust loss,
// and judged by the same identifiability rule and intervals as the other estimators
// (estimator/identifiability.h). b is the anisotropy along the axes of the frame the pairs
// are written in (object axes for the tripod importer's pairs).

#include <algorithm>
#include <cmath>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/wrench_twist_pair.h"

namespace slideid {

/// Options of EstimateQuasiStatic: the method's own (estimate.h) and the slider's.
struct QuasiStaticFitOptions {
  /// Robust loss, its scale and iterations.
  QuasiStaticOptions method;
  int threads = 1;        ///< Ceres threads
  double weight_n = 0.0;  ///< m g [N], > 0: a pair's normal force is weight_n - fz
  /// L [m] (>= 0): spin enters twist directions as L w_z and the predicted normal as
  /// L m_z / c^2, so that lengths and angles mix in one direction. 0: the seed's c.
  /// QuasiStaticOptionsFor sets the radius of gyration sqrt(I / m) when I is known.
  double length_scale_m = 0.0;

  bool IsValid(std::string* why) const;
};

/// Fewest pairs a fit takes: three parameters, three residual degrees of freedom per pair.
constexpr int kMinQuasiStaticPairs = 3;

/// Floor of the residual scales (dimensionless: a log ratio and a chord of unit vectors):
/// exact synthetic pairs leave residuals at rounding level, and a scale of that size would
/// make the weights and the robust loss act on rounding. 1e-9 is far below any measurement
/// noise and far above rounding (~1e-16).
constexpr double kMinQuasiStaticSigma = 1e-9;

/// Fits (log a, log b, log c) to `pairs`.
///
/// Seed: b = 1; c from the pairs' spin, c^2 = m_z |v| / (|f| w_z) (the isotropic relation),
/// median over the pairs where m_z w_z > 0 (else L, else the median moment arm |m_z| / |f|);
/// a the median of the ellipsoid norm over N.
/// Weights: each residual kind is divided by its own robust scale (magnitude: 1.4826 MAD of
/// the log ratios; direction: the median angle / 1.1774, the per-axis sigma of a 2-D
/// Gaussian), estimated at the seed and again after a first robust fit, so each kind counts
/// by its precision and neither's units decide. Then options.method.loss at
/// loss_scale_sigmas (units of those scales), DENSE_QR; parameters that AssessIdentifiability
/// rejects (Fisher information of theta from J^T J of the weighted residuals; residual
/// variance s^2 = sum r^2 / (3 n - n_free), a pair having 1 magnitude and 2 direction
/// degrees of freedom) are held at their seed and the rest refitted; standard errors from
/// ceres::Covariance of the un-robustified problem times s^2.
/// Residuals per pair (row = index): "log_wrench_ratio", "twist_angle_rad" (between the
/// measured twist and the predicted normal, L-scaled) and "spin_share_misfit" (predicted
/// minus measured spin component of the unit directions); t is NaN.
/// Throws std::invalid_argument for invalid options, fewer than kMinQuasiStaticPairs pairs,
/// or a pair that is not finite, has a zero wrench or twist, or a normal force <= 0 (the
/// message names the pair, 1-based).
EstimateResult EstimateQuasiStatic(const std::vector<WrenchTwistPair>& pairs,
                                   const QuasiStaticFitOptions& options);

/// Options for `data`: weight m g, L = sqrt(I / m) when the inertia is known (else 0).
QuasiStaticFitOptions QuasiStaticOptionsFor(const WrenchTwistData& data,
                                            const IdentifyOptions& options);

/// Tolerance within which two sets' weights m g are one slider's [relative].
constexpr double kSameWeightRelative = 1e-9;

/// Pairs from several files (sets) of one slider on one surface: one set is fitted on its
/// own (EstimateQuasiStatic of its pairs); several are each fitted on their own and all
/// their pairs together (FitOneOrMany, estimator/pooling.h: per-set entries named by
/// their source, heterogeneity). Throws std::invalid_argument for no sets, sets of
/// different weights (naming both), or a set that cannot be fitted (its source first).
EstimateResult EstimateQuasiStatic(const std::vector<WrenchTwistData>& sets,
                                   const IdentifyOptions& options);

}  // namespace slideid
