#pragma once
// The quasi-static estimator's Ceres residuals (estimator/quasi_static_fit.h). Internal: not
// installed, so that the public headers do not expose Ceres.

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>

#include "forward_model/wrench_twist_pair.h"

namespace slideid {

/// Magnitude residual of one pair (1, dimensionless), blocks log a, log b, log c:
/// w (log sqrt(f_x^2 + f_y^2 / b^2 + m_z^2 / c^2) - log a - log N).
/// `weight` is read at each evaluation (the fit re-weights). Returns false, never throws.
struct LimitSurfaceMagnitudeResidual {
  LimitSurfaceMagnitudeResidual(const WrenchTwistPair& p, double normal_force_n,
                                const double* weight)
      : w(weight) {
    // The wrench over its largest component, so that squares neither overflow nor
    // underflow at any magnitude; the scale goes into log N.
    const double scale = std::max({std::abs(p.fx), std::abs(p.fy), std::abs(p.mz)});
    const double s = scale > 0.0 ? scale : 1.0;
    fx = p.fx / s;
    fy = p.fy / s;
    mz = p.mz / s;
    log_n = std::log(normal_force_n) - std::log(s);
  }

  template <typename T>
  bool operator()(const T* log_a, const T* log_b, const T* log_c, T* residual) const {
    using std::exp;
    using std::log;
    const T q =
        T(fx * fx) + T(fy * fy) * exp(T(-2) * log_b[0]) + T(mz * mz) * exp(T(-2) * log_c[0]);
    if (!(q > T(0))) return false;
    residual[0] = T(*w) * (T(0.5) * log(q) - log_a[0] - T(log_n));
    return true;
  }

  static ceres::CostFunction* Create(const WrenchTwistPair& p, double normal_force_n,
                                     const double* weight) {
    return new ceres::AutoDiffCostFunction<LimitSurfaceMagnitudeResidual, 1, 1, 1, 1>(
        new LimitSurfaceMagnitudeResidual(p, normal_force_n, weight));
  }

  double fx, fy, mz;  ///< applied wrench over its largest component [1, 1, m]
  double log_n;       ///< log of the normal force over that component
  const double* w;    ///< weight, 1 / the magnitude residuals' scale
};

/// Direction residual of one pair (3, dimensionless), blocks log a, log b, log c:
/// w (xi_hat - n_hat), the chord between the unit measured twist
/// xi_hat = (v_x, v_y, L w_z) / |.| and the unit predicted normal
/// n_hat = (f_x, f_y / b^2, L m_z / c^2) / |.|; its length is 2 sin(angle / 2), monotone in
/// the angle up to pi. Returns false, never throws.
struct TwistDirectionResidual {
  TwistDirectionResidual(const WrenchTwistPair& p, double length_scale_m, const double* weight)
      : w(weight) {
    // Both vectors over their largest component first: no overflow or underflow in squares.
    const double f_scale = std::max({std::abs(p.fx), std::abs(p.fy), std::abs(p.mz)});
    const double fs = f_scale > 0.0 ? f_scale : 1.0;
    fx = p.fx / fs;
    fy = p.fy / fs;
    lmz = length_scale_m * (p.mz / fs);
    double xi[3] = {p.vx, p.vy, length_scale_m * p.wz};
    const double v_scale = std::max({std::abs(xi[0]), std::abs(xi[1]), std::abs(xi[2])});
    for (double& x : xi) x /= v_scale > 0.0 ? v_scale : 1.0;
    const double norm = std::sqrt(xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
    // EstimateQuasiStatic refuses zero twists and L is > 0; 0 keeps a misuse finite.
    for (int k = 0; k < 3; ++k) xi_hat[k] = norm > 0.0 ? xi[k] / norm : 0.0;
  }

  template <typename T>
  bool operator()(const T* /*log_a*/, const T* log_b, const T* log_c, T* residual) const {
    using std::exp;
    using std::sqrt;
    const T n[3] = {T(fx), T(fy) * exp(T(-2) * log_b[0]), T(lmz) * exp(T(-2) * log_c[0])};
    const T norm2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (!(norm2 > T(0))) return false;
    const T inv = T(1) / sqrt(norm2);
    for (int k = 0; k < 3; ++k) residual[k] = T(*w) * (T(xi_hat[k]) - n[k] * inv);
    return true;
  }

  static ceres::CostFunction* Create(const WrenchTwistPair& p, double length_scale_m,
                                     const double* weight) {
    return new ceres::AutoDiffCostFunction<TwistDirectionResidual, 3, 1, 1, 1>(
        new TwistDirectionResidual(p, length_scale_m, weight));
  }

  double fx, fy, lmz;  ///< applied force and L m_z, over the wrench's largest component
  double xi_hat[3];    ///< unit measured twist in L-scaled coordinates
  const double* w;     ///< weight, 1 / the direction residuals' scale
};

}  // namespace slideid
