#pragma once
// Exact derivatives of one step's end velocity with respect to its start velocity, the
// log-parameters (log a, log b, log c) and, on request, the applied wrench, by the implicit
// function theorem on the step's scaled equations (forward_model/step_equations.h):
// dz/dx = -F_z^-1 F_x.

#include <Eigen/Core>

#include "forward_model/step_solver.h"

namespace slideid {

/// A solved step and its sensitivities. While sticking, nu' = 0 locally: all are zero.
struct StepSensitivity {
  StepResult step;
  Eigen::Matrix3d dnu_dnu = Eigen::Matrix3d::Zero();      ///< d nu' / d nu
  Eigen::Matrix3d dnu_dlogabc = Eigen::Matrix3d::Zero();  ///< d nu' / d(log a, log b, log c)
  /// d nu' / d(f_x, f_y, t_z, t_x, t_y) [per N and N m], filled when asked for.
  Eigen::Matrix<double, 3, 5> dnu_dwrench = Eigen::Matrix<double, 3, 5>::Zero();
};

/// Solves the step with (a, b, c) and fills the derivatives (those with respect to the
/// applied wrench too when `with_wrench`). Returns false when the step failed
/// (non-convergence, lift-off) or the Jacobian of the equations is singular.
/// The derivatives of the scaled equations with respect to x are written out by hand
/// (ScaledStepResidual's partials: a few dozen flops a column).
bool SolveStepWithSensitivity(const SliderProperties& slider, const ReducedFriction& abc,
                              const PlanarState& state, const AppliedWrench& applied, double dt_s,
                              StepSensitivity* out, const StepOptions& options = {},
                              bool with_wrench = false);

/// The same derivatives of an already solved sliding step by automatic differentiation of
/// ScaledStepResidual (ceres::Jet): an independent computation, for tests, about five
/// times slower. `out->step` must hold the solved step.
bool StepSensitivityByAutodiff(const SliderProperties& slider, const ReducedFriction& abc,
                               const PlanarState& state, const AppliedWrench& applied, double dt_s,
                               StepSensitivity* out, bool with_wrench);

}  // namespace slideid
