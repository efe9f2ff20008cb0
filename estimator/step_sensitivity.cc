#include "estimator/step_sensitivity.h"

#include <ceres/jet.h>

#include <Eigen/Dense>
#include <type_traits>

#include "forward_model/adjugate3.h"
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
    s.k << s.m * vx + dt_s * applied.fx, s.m * vy + dt_s * applied.fy, s.I * wz + dt_s * applied.tz;
  }
  return s;
}

// d nu' / dx for the step `eq` solved at scaled unknowns `z_value`.
template <int N>
bool Sensitivities(const StepEquations& eq, const ReducedFriction& abc, const PlanarState& state,
                   const AppliedWrench& applied, double dt_s, const Eigen::Vector4d& z_value,
                   double pn, Eigen::Matrix<double, 3, N>* dnu_dx) {
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

// d nu' / dz in closed form: nu' = M^-1 (k + p + coupling), p = P diag(1, b, c) tau.
Eigen::Matrix<double, 3, 4> EndVelocityByUnknowns(const StepTerms<double>& t, double P) {
  Eigen::Matrix3d dnu_dp = Eigen::Matrix3d::Zero();
  dnu_dp(0, 0) = 1.0 / t.m;
  dnu_dp(1, 1) = 1.0 / t.m;
  // (ptx / pn) / I: the product pn I underflows for tiny masses (issue 5, as in
  // StepEquations::EcpVelocity).
  dnu_dp.row(2) << t.ptx / t.pn / t.I, t.pty / t.pn / t.I, 1.0 / t.I;
  Eigen::Matrix<double, 3, 4> dnu_dz = Eigen::Matrix<double, 3, 4>::Zero();
  dnu_dz.leftCols<3>() = dnu_dp * (P * Eigen::Vector3d(1.0, t.b, t.c)).asDiagonal();
  return dnu_dz;
}

// Relative size below which the 3x3 block of F_z (or its border) counts as singular, as in
// the step solver's Newton system (forward_model/step_solver.cc).
constexpr double kSingularBlock = 1e-12;

// dz/dx = -F_z^-1 F_x through the bordered structure of F_z = [[A, tau], [V tau^T, 0]], by
// the adjugate of A (issue 19: the pivoted 4x4 LU and its two triangular solves of N
// columns were 45% of SolveStepWithSensitivity). False where A is near singular or the
// border degenerate; the caller then solves by the LU.
template <int N>
bool SolveBordered(const StepEquations& eq, const Eigen::Vector4d& z,
                   const Eigen::Matrix<double, 4, N>& f_x, Eigen::Matrix<double, 4, N>* dz_dx) {
  Eigen::Matrix3d A;
  eq.JacobianBlock(z, &A);
  const Eigen::Matrix3d adj = Adjugate3(A);  // A^-1 = adj / det
  const double det = Determinant3(A, adj);
  if (!(std::abs(det) > kSingularBlock * A.cwiseAbs().maxCoeff())) return false;
  const Eigen::Vector3d g = eq.velocity_scale() * z.head<3>();  // F_4's row, V tau^T
  const Eigen::Vector3d w = adj * z.head<3>();                  // det A^-1 tau
  const double border = g.dot(w);
  if (!(std::abs(border) > kSingularBlock * g.norm() * w.norm())) return false;
  // Column by column: x_s = (g u - r_s det) / (g w), x_h = (u - w x_s) / det, u = adj r_h.
  const Eigen::Matrix<double, 3, N> u = adj * f_x.template topRows<3>();
  const Eigen::Matrix<double, 1, N> x_s =
      (g.transpose() * u - det * f_x.template bottomRows<1>()) / border;
  dz_dx->template topRows<3>() = -(u - w * x_s) / det;
  dz_dx->template bottomRows<1>() = -x_s;
  return dz_dx->allFinite();
}

// Implicit function theorem: d nu'/dx = nu_x + nu_z dz/dx, dz/dx = -F_z^-1 F_x.
template <int N>
bool Combine(const StepEquations& eq, const Eigen::Vector4d& z, double pn,
             const Eigen::Matrix<double, 4, N>& f_x, const Eigen::Matrix<double, 3, N>& nu_x,
             Eigen::Matrix<double, 3, N>* dnu_dx) {
  Eigen::Matrix<double, 4, N> dz_dx;
  if (!SolveBordered<N>(eq, z, f_x, &dz_dx)) {
    Eigen::Vector4d f_value;
    Eigen::Matrix4d f_z;
    eq.Evaluate(z, &f_value, &f_z);
    const Eigen::PartialPivLU<Eigen::Matrix4d> lu(f_z);
    if (!(std::abs(lu.determinant()) > 0)) return false;
    dz_dx = -lu.solve(f_x);
  }
  *dnu_dx = nu_x + EndVelocityByUnknowns(eq.terms(), eq.terms().a * pn) * dz_dx;
  return dnu_dx->allFinite();
}

// The partials of ScaledStepResidual (F) and StepEndVelocity (nu) with respect to x, at the
// solution z, written out: each column of x changes k, log a, log b, log c, h t_x or h t_y
// by a known amount (a Direction); F_3 = V (|tau|^2 - 1) / 2 has V held, as in the solver.
template <int N>
void ExplicitPartials(const StepTerms<double>& t, const Eigen::Vector4d& z, double dt_s,
                      Eigen::Matrix<double, 4, N>* f_x, Eigen::Matrix<double, 3, N>* nu_x) {
  const double P = t.a * t.pn;
  const Eigen::Vector3d p(P * z(0), P * t.b * z(1), P * t.c * z(2));
  const double nu1 = (t.k(1) + p(1)) / t.m;  // nu_0 does not enter F's partials
  const double nu2 = (t.k(2) + p(2) + (p(0) * t.ptx + p(1) * t.pty) / t.pn) / t.I;
  const double r0 = (t.pty - t.qz * p(0)) / t.pn, r1 = (-t.ptx - t.qz * p(1)) / t.pn;
  struct Direction {
    Eigen::Vector3d dk = Eigen::Vector3d::Zero();
    double dloga = 0, dlogb = 0, dlogc = 0, dptx = 0, dpty = 0;
  };
  auto column = [&](const Direction& d, int col) {
    const double dp0 = p(0) * d.dloga, dp1 = p(1) * (d.dloga + d.dlogb),
                 dp2 = p(2) * (d.dloga + d.dlogc);
    const double dnu0 = (d.dk(0) + dp0) / t.m, dnu1 = (d.dk(1) + dp1) / t.m;
    const double dnu2 =
        (d.dk(2) + dp2 + (dp0 * t.ptx + p(0) * d.dptx + dp1 * t.pty + p(1) * d.dpty) / t.pn) / t.I;
    const double dr0 = (d.dpty - t.qz * dp0) / t.pn, dr1 = (-d.dptx - t.qz * dp1) / t.pn;
    (*f_x)(0, col) = dnu0 - dnu2 * r1 - nu2 * dr1;
    (*f_x)(1, col) = t.b * d.dlogb * (nu1 + nu2 * r0) + t.b * (dnu1 + dnu2 * r0 + nu2 * dr0);
    (*f_x)(2, col) = t.c * d.dlogc * nu2 + t.c * dnu2;
    (*f_x)(3, col) = 0.0;
    nu_x->col(col) << dnu0, dnu1, dnu2;
  };
  const double inertia[3] = {t.m, t.m, t.I};
  for (int i = 0; i < 3; ++i) {  // v_x, v_y, w_z: k = M nu + ...
    Direction d;
    d.dk(i) = inertia[i];
    column(d, i);
  }
  Direction da, db, dc;
  da.dloga = 1;
  db.dlogb = 1;
  dc.dlogc = 1;
  column(da, 3);
  column(db, 4);
  column(dc, 5);
  if constexpr (N == kWithWrench) {  // f_x, f_y, t_z enter k; t_x, t_y the tilting impulses
    for (int i = 0; i < 3; ++i) {
      Direction d;
      d.dk(i) = dt_s;
      column(d, 6 + i);
    }
    Direction dtx, dty;
    dtx.dptx = dt_s;
    dty.dpty = dt_s;
    column(dtx, 9);
    column(dty, 10);
  }
}

template <int N>
bool ExplicitSensitivities(const StepEquations& eq, const Eigen::Vector4d& z, double pn,
                           double dt_s, Eigen::Matrix<double, 3, N>* dnu_dx) {
  Eigen::Matrix<double, 4, N> f_x;
  Eigen::Matrix<double, 3, N> nu_x;
  ExplicitPartials<N>(eq.terms(), z, dt_s, &f_x, &nu_x);
  return Combine<N>(eq, z, pn, f_x, nu_x, dnu_dx);
}

template <int N>
void Store(const Eigen::Matrix<double, 3, N>& d, StepSensitivity* out) {
  out->dnu_dnu = d.template leftCols<3>();
  out->dnu_dlogabc = d.template middleCols<3>(3);
  if constexpr (N == kWithWrench) out->dnu_dwrench = d.template rightCols<5>();
}

// Solves nothing: fills out's derivatives for its sliding step with `sensitivities`.
template <typename Sensitivities>
bool FillSensitivities(const SliderProperties& slider, const ReducedFriction& abc,
                       const PlanarState& state, const AppliedWrench& applied, double dt_s,
                       bool with_wrench, StepSensitivity* out, Sensitivities sensitivities) {
  out->dnu_dnu.setZero();
  out->dnu_dlogabc.setZero();
  out->dnu_dwrench.setZero();
  if (!out->step.ok()) return false;
  if (out->step.mode == StepMode::kStick) return true;
  const StepEquations eq(slider, abc, state, applied, dt_s);
  // The reduced step's unknowns are its scaled solution (sigma is the slip speed s).
  const Eigen::Vector4d& z = out->step.scaled_solution;
  if (with_wrench) {
    Eigen::Matrix<double, 3, kWithWrench> d;
    if (!sensitivities(eq, z, std::integral_constant<int, kWithWrench>(), &d)) return false;
    Store<kWithWrench>(d, out);
  } else {
    Eigen::Matrix<double, 3, kStateAndParameters> d;
    if (!sensitivities(eq, z, std::integral_constant<int, kStateAndParameters>(), &d)) return false;
    Store<kStateAndParameters>(d, out);
  }
  return true;
}

}  // namespace

bool SolveStepWithSensitivity(const SliderProperties& slider, const ReducedFriction& abc,
                              const PlanarState& state, const AppliedWrench& applied, double dt_s,
                              StepSensitivity* out, const StepOptions& options, bool with_wrench) {
  out->step = SolveStep(slider, abc, state, applied, dt_s, options);
  const double pn = out->step.pn;
  return FillSensitivities(slider, abc, state, applied, dt_s, with_wrench, out,
                           [&](const StepEquations& eq, const Eigen::Vector4d& z, auto n, auto* d) {
                             return ExplicitSensitivities<decltype(n)::value>(eq, z, pn, dt_s, d);
                           });
}

bool StepSensitivityByAutodiff(const SliderProperties& slider, const ReducedFriction& abc,
                               const PlanarState& state, const AppliedWrench& applied, double dt_s,
                               StepSensitivity* out, bool with_wrench) {
  const double pn = out->step.pn;
  return FillSensitivities(slider, abc, state, applied, dt_s, with_wrench, out,
                           [&](const StepEquations& eq, const Eigen::Vector4d& z, auto n, auto* d) {
                             return Sensitivities<decltype(n)::value>(eq, abc, state, applied, dt_s,
                                                                      z, pn, d);
                           });
}

}  // namespace slideid
