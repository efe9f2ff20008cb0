#include "estimator/step_sensitivity.h"

#include <ceres/jet.h>

#include <Eigen/Dense>

#include "forward_model/step_equations.h"

namespace slideid {
namespace {

// Jet variables x = (v_x, v_y, w_z, log a, log b, log c); the derivatives with respect to
// the step's unknowns z come from the solver's analytic Jacobian.
constexpr int kX = 6;
using Jet = ceres::Jet<double, kX>;

StepTerms<Jet> JetTerms(const StepTerms<double>& t, const PlanarState& state, double dt_s,
                        const AppliedWrench& applied) {
  StepTerms<Jet> s;
  s.m = Jet(t.m);
  s.I = Jet(t.I);
  s.qz = Jet(t.qz);
  s.pn = Jet(t.pn);
  s.a = Jet(std::log(t.a), 3);
  s.b = Jet(std::log(t.b), 4);
  s.c = Jet(std::log(t.c), 5);
  s.a = exp(s.a);
  s.b = exp(s.b);
  s.c = exp(s.c);
  s.ptx = Jet(t.ptx);
  s.pty = Jet(t.pty);
  const Jet vx(state.vx, 0), vy(state.vy, 1), wz(state.wz, 2);
  s.k << s.m * vx + dt_s * applied.fx, s.m * vy + dt_s * applied.fy,
      s.I * wz + dt_s * applied.tz;
  return s;
}

}  // namespace

bool SolveStepWithSensitivity(const SliderProperties& slider, const ReducedFriction& abc,
                              const PlanarState& state, const AppliedWrench& applied,
                              double dt_s, StepSensitivity* out,
                              const StepOptions& options) {
  out->step = SolveStep(slider, abc, state, applied, dt_s, options);
  out->dnu_dnu.setZero();
  out->dnu_dlogabc.setZero();
  if (!out->step.ok()) return false;
  if (out->step.mode == StepMode::kStick) return true;

  const StepEquations eq(slider, abc, state, applied, dt_s);
  const StepResult& r = out->step;
  const double P = abc.a * r.pn;
  // Recover the scaled unknowns of the solution (e_t = 1, so sigma is the slip speed s).
  const Eigen::Vector4d z_value(r.pt / P, r.po / (P * abc.b), r.pr / (P * abc.c), r.sigma);
  const Eigen::Matrix<Jet, 4, 1> z = z_value.cast<Jet>();
  const StepTerms<Jet> terms = JetTerms(eq.terms(), state, dt_s, applied);
  const Eigen::Matrix<Jet, 4, 1> f = ScaledStepResidual(terms, z, eq.velocity_scale());
  const Eigen::Matrix<Jet, 3, 1> nu = StepEndVelocity(terms, StepImpulses(terms, z));

  Eigen::Vector4d f_value;
  Eigen::Matrix4d f_z;
  eq.Evaluate(z_value, &f_value, &f_z);
  Eigen::Matrix<double, 4, kX> f_x;
  for (int i = 0; i < 4; ++i) f_x.row(i) = f(i).v.transpose();
  const Eigen::PartialPivLU<Eigen::Matrix4d> lu(f_z);
  if (!(std::abs(lu.determinant()) > 0)) return false;
  const Eigen::Matrix<double, 4, kX> dz_dx = -lu.solve(f_x);
  // nu' = M^-1 (k + p + coupling), p = P diag(1, b, c) tau: d nu' / d z in closed form.
  const StepTerms<double>& t = eq.terms();
  Eigen::Matrix3d dnu_dp = Eigen::Matrix3d::Zero();
  dnu_dp(0, 0) = 1.0 / t.m;
  dnu_dp(1, 1) = 1.0 / t.m;
  // (ptx / pn) / I: the product pn I underflows for tiny masses (issue 5, as in
  // StepEquations::EcpVelocity).
  dnu_dp.row(2) << t.ptx / t.pn / t.I, t.pty / t.pn / t.I, 1.0 / t.I;
  Eigen::Matrix<double, 3, 4> dnu_dz = Eigen::Matrix<double, 3, 4>::Zero();
  dnu_dz.leftCols<3>() = dnu_dp * (P * Eigen::Vector3d(1.0, abc.b, abc.c)).asDiagonal();
  Eigen::Matrix<double, 3, kX> dnu_dx;
  for (int i = 0; i < 3; ++i) dnu_dx.row(i) = nu(i).v.transpose();
  dnu_dx += dnu_dz * dz_dx;
  if (!dnu_dx.allFinite()) return false;
  out->dnu_dnu = dnu_dx.leftCols<3>();
  out->dnu_dlogabc = dnu_dx.rightCols<3>();
  return true;
}

}  // namespace slideid
