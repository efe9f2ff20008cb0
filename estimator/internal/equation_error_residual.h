#pragma once
// The equation-error estimator's Ceres residual (estimator/equation_error.h). Internal: not
// installed, so that the public headers do not expose Ceres.

#include <ceres/ceres.h>

#include <cmath>
#include <limits>

#include "estimator/step_observations.h"

namespace slideid {

/// Residuals of one step (3, dimensionless) for parameter blocks log a, log b, log c:
/// ((p_t - m_t) / p_n, (p_o - m_o) / p_n, (p_r - m_r) / (p_n L)) with
/// m = -a p_n (v_t, b^2 v_o, c^2 v_r) / sqrt(v_t^2 + b^2 v_o^2 + c^2 v_r^2).
/// Returns false (never throws) where the model's speed is not positive or not finite.
struct EquationErrorResidual {
  EquationErrorResidual(const StepObservation& o, double radius_m)
      : vt(o.ecp_velocity(0)),
        vo(o.ecp_velocity(1)),
        vr(o.ecp_velocity(2)),
        qt(o.friction_impulse(0) / o.pn),
        qo(o.friction_impulse(1) / o.pn),
        qr(o.friction_impulse(2) / (o.pn * radius_m)),
        radius(radius_m) {}

  template <typename T>
  bool operator()(const T* log_a, const T* log_b, const T* log_c, T* residual) const {
    using std::exp;
    using std::sqrt;
    const T a = exp(log_a[0]);
    const T b2 = exp(T(2) * log_b[0]);
    const T c2 = exp(T(2) * log_c[0]);
    const T speed2 = vt * vt + b2 * vo * vo + c2 * vr * vr;
    // Not positive, or overflowed at a trial point far out: no residual there.
    if (!(speed2 > T(0)) || !(speed2 < T(std::numeric_limits<double>::max()))) return false;
    const T k = a / sqrt(speed2);  // a / |v|_D
    residual[0] = qt + k * vt;
    residual[1] = qo + k * b2 * vo;
    residual[2] = qr + k * c2 * vr / radius;
    return true;
  }

  static ceres::CostFunction* Create(const StepObservation& o, double radius_m) {
    return new ceres::AutoDiffCostFunction<EquationErrorResidual, 3, 1, 1, 1>(
        new EquationErrorResidual(o, radius_m));
  }

  double vt, vo, vr;  ///< measured ECP velocity [m/s, m/s, rad/s]
  double qt, qo, qr;  ///< measured friction impulses over p_n (p_r also over L)
  double radius;      ///< L = sqrt(I_z / m) [m]
};

}  // namespace slideid
