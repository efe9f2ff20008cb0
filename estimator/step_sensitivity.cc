#include "estimator/step_sensitivity.h"

#include <ceres/jet.h>

#include <Eigen/Dense>

#include "forward_model/step_equations.h"

namespace slideid {
namespace {

// Jet variables: z (4 unknowns of the step), then x = (v_x, v_y, w_z, log a, log b, log c).
constexpr int kZ = 4, kX = 6;
using Jet = ceres::Jet<double, kZ + kX>;

StepTerms<Jet> JetTerms(const StepTerms<double>& t, const PlanarState& state, double dt_s,
                        const AppliedWrench& applied) {
  StepTerms<Jet> s;
  s.m = Jet(t.m);
  s.I = Jet(t.I);
  s.qz = Jet(t.qz);
  s.pn = Jet(t.pn);
  s.a = Jet(std::log(t.a), kZ + 3);
  s.b = Jet(std::log(t.b), kZ + 4);
  s.c = Jet(std::log(t.c), kZ + 5);
  s.a = exp(s.a);
  s.b = exp(s.b);
  s.c = exp(s.c);
  s.ptx = Jet(t.ptx);
  s.pty = Jet(t.pty);
  const Jet vx(state.vx, kZ + 0), vy(state.vy, kZ + 1), wz(state.wz, kZ + 2);
  s.k << s.m * vx + dt_s * applied.fx, s.m * vy + dt_s * applied.fy,
      s.I * wz + dt_s * applied.tz;
  return s;
}

}  // namespace

bool SolveStepWithSensitivity(const SliderProperties& slider, const ReducedFriction& abc,
                              const PlanarState& state, const AppliedWrench& applied,
                              double dt_s, StepSensitivity* out) {
  out->step = SolveStep(slider, abc.ToFrictionParameters(), state, applied, dt_s);
  out->dnu_dnu.setZero();
  out->dnu_dlogabc.setZero();
  if (!out->step.ok()) return false;
  if (out->step.mode == StepMode::kStick) return true;

  const StepEquations eq(slider, abc, state, applied, dt_s);
  const StepResult& r = out->step;
  const double P = abc.a * r.pn;
  // Recover the scaled unknowns of the solution (e_t = 1, so sigma is the slip speed s).
  Eigen::Matrix<Jet, 4, 1> z;
  z << Jet(r.pt / P, 0), Jet(r.po / (P * abc.b), 1), Jet(r.pr / (P * abc.c), 2), Jet(r.sigma, 3);
  const StepTerms<Jet> terms = JetTerms(eq.terms(), state, dt_s, applied);
  const Eigen::Matrix<Jet, 4, 1> f = ScaledStepResidual(terms, z, eq.velocity_scale());
  const Eigen::Matrix<Jet, 3, 1> nu = StepEndVelocity(terms, StepImpulses(terms, z));

  Eigen::Matrix4d f_z;
  Eigen::Matrix<double, 4, kX> f_x;
  for (int i = 0; i < 4; ++i) {
    f_z.row(i) = f(i).v.head<kZ>().transpose();
    f_x.row(i) = f(i).v.tail<kX>().transpose();
  }
  const Eigen::PartialPivLU<Eigen::Matrix4d> lu(f_z);
  if (!(std::abs(lu.determinant()) > 0)) return false;
  const Eigen::Matrix<double, 4, kX> dz_dx = -lu.solve(f_x);
  Eigen::Matrix<double, 3, kX> dnu_dx;
  for (int i = 0; i < 3; ++i) {
    dnu_dx.row(i) = nu(i).v.tail<kX>().transpose() + nu(i).v.head<kZ>().transpose() * dz_dx;
  }
  if (!dnu_dx.allFinite()) return false;
  out->dnu_dnu = dnu_dx.leftCols<3>();
  out->dnu_dlogabc = dnu_dx.rightCols<3>();
  return true;
}

}  // namespace slideid
