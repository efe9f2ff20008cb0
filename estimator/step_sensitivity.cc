#include "estimator/step_sensitivity.h"

#include <ceres/jet.h>

#include <Eigen/Dense>

#include "forward_model/step_equations.h"

namespace slideid {
namespace {

// Jet variables x = (v_x, v_y, w_z, log a, log b, log c) and, with the wrench, (f_x, f_y,
// t_z, t_x, t_y); the derivatives with respect to the step's unknowns z come from the
// solver's analytic Jacobian.
constexpr int kStateAndParameters = 6;
constexpr int kWithWrench = 11;

template <int N>
StepTerms<ceres::Jet<double, N>> JetTerms(const StepTerms<double>& t, const PlanarState& state,
                                          double dt_s, const AppliedWrench& applied) {
  using Jet = ceres::Jet<double, N>;
  StepTerms<Jet> s;
  s.m = Jet(t.m);
  s.I = Jet(t.I);
  s.qz = Jet(t.qz);
  s.pn = Jet(t.pn);
  s.a = exp(Jet(std::log(t.a), 3));
  s.b = exp(Jet(std::log(t.b), 4));
  s.c = exp(Jet(std::log(t.c), 5));
  const Jet vx(state.vx, 0), vy(state.vy, 1), wz(state.wz, 2);
  if constexpr (N == kWithWrench) {
    const Jet fx(applied.fx, 6), fy(applied.fy, 7), tz(applied.tz, 8);
    s.ptx = dt_s * Jet(applied.tx, 9);
    s.pty = dt_s * Jet(applied.ty, 10);
    s.k << s.m * vx + dt_s * fx, s.m * vy + dt_s * fy, s.I * wz + dt_s * tz;
  } else {
    s.ptx = Jet(t.ptx);
    s.pty = Jet(t.pty);
    s.k << s.m * vx + dt_s * applied.fx, s.m * vy + dt_s * applied.fy,
        s.I * wz + dt_s * applied.tz;
  }
  return s;
}

// d nu' / dx for the step `eq` solved at scaled unknowns `z_value`.
template <int N>
bool Sensitivities(const StepEquations& eq, const ReducedFriction& abc,
                   const PlanarState& state, const AppliedWrench& applied, double dt_s,
                   const Eigen::Vector4d& z_value, double pn,
                   Eigen::Matrix<double, 3, N>* dnu_dx) {
  using Jet = ceres::Jet<double, N>;
  const Eigen::Matrix<Jet, 4, 1> z = z_value.cast<Jet>();
  const StepTerms<Jet> terms = JetTerms<N>(eq.terms(), state, dt_s, applied);
  const Eigen::Matrix<Jet, 4, 1> f = ScaledStepResidual(terms, z, eq.velocity_scale());
  const Eigen::Matrix<Jet, 3, 1> nu = StepEndVelocity(terms, StepImpulses(terms, z));

  Eigen::Vector4d f_value;
  Eigen::Matrix4d f_z;
  eq.Evaluate(z_value, &f_value, &f_z);
  Eigen::Matrix<double, 4, N> f_x;
  for (int i = 0; i < 4; ++i) f_x.row(i) = f(i).v.transpose();
  const Eigen::PartialPivLU<Eigen::Matrix4d> lu(f_z);
  if (!(std::abs(lu.determinant()) > 0)) return false;
  const Eigen::Matrix<double, 4, N> dz_dx = -lu.solve(f_x);
  // nu' = M^-1 (k + p + coupling), p = P diag(1, b, c) tau: d nu' / d z in closed form.
  const StepTerms<double>& t = eq.terms();
  const double P = abc.a * pn;
  Eigen::Matrix3d dnu_dp = Eigen::Matrix3d::Zero();
  dnu_dp(0, 0) = 1.0 / t.m;
  dnu_dp(1, 1) = 1.0 / t.m;
  // (ptx / pn) / I: the product pn I underflows for tiny masses (issue 5, as in
  // StepEquations::EcpVelocity).
  dnu_dp.row(2) << t.ptx / t.pn / t.I, t.pty / t.pn / t.I, 1.0 / t.I;
  Eigen::Matrix<double, 3, 4> dnu_dz = Eigen::Matrix<double, 3, 4>::Zero();
  dnu_dz.leftCols<3>() = dnu_dp * (P * Eigen::Vector3d(1.0, abc.b, abc.c)).asDiagonal();
  for (int i = 0; i < 3; ++i) dnu_dx->row(i) = nu(i).v.transpose();
  *dnu_dx += dnu_dz * dz_dx;
  return dnu_dx->allFinite();
}

}  // namespace

bool SolveStepWithSensitivity(const SliderProperties& slider, const ReducedFriction& abc,
                              const PlanarState& state, const AppliedWrench& applied,
                              double dt_s, StepSensitivity* out,
                              const StepOptions& options, bool with_wrench) {
  out->step = SolveStep(slider, abc, state, applied, dt_s, options);
  out->dnu_dnu.setZero();
  out->dnu_dlogabc.setZero();
  out->dnu_dwrench.setZero();
  if (!out->step.ok()) return false;
  if (out->step.mode == StepMode::kStick) return true;

  const StepEquations eq(slider, abc, state, applied, dt_s);
  // The reduced step's unknowns are its scaled solution (sigma is the slip speed s).
  const Eigen::Vector4d z = out->step.scaled_solution;
  if (with_wrench) {
    Eigen::Matrix<double, 3, kWithWrench> d;
    if (!Sensitivities<kWithWrench>(eq, abc, state, applied, dt_s, z, out->step.pn, &d)) {
      return false;
    }
    out->dnu_dnu = d.leftCols<3>();
    out->dnu_dlogabc = d.middleCols<3>(3);
    out->dnu_dwrench = d.rightCols<5>();
    return true;
  }
  Eigen::Matrix<double, 3, kStateAndParameters> d;
  if (!Sensitivities<kStateAndParameters>(eq, abc, state, applied, dt_s, z, out->step.pn, &d)) {
    return false;
  }
  out->dnu_dnu = d.leftCols<3>();
  out->dnu_dlogabc = d.rightCols<3>();
  return true;
}

}  // namespace slideid
