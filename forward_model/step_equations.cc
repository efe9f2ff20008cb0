#include "forward_model/step_equations.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "forward_model/number_format.h"

namespace slideid {
namespace {
constexpr double kEps = std::numeric_limits<double>::epsilon();
// The scalar root stops at |g| below this; the 4x4 residual is then checked anyway.
constexpr double kScalarTolerance = 4 * kEps;
constexpr int kMaxScalarIterations = 200;
// First-guess slip speed, as a fraction of the free slip speed, when the decoupled problem
// would stick but the coupled one slides.
constexpr double kGuessSlipFraction = 1e-2;
// A first guess needs no more digits than Newton's first quadratic step doubles.
constexpr double kGuessTolerance = 1e-8;
// The decoupled guess takes the scalar root's Newton step from |g| <= 1e-4 without
// evaluating g after it: g is nearly linear in s, so the step squares |g| to about 1e-8
// (issue 19: that last evaluation, a square root and four divisions in series, was a
// quarter of the guess's time).
constexpr double kGuessAcceptAfterStep = 1e-4;
// ComponentwiseResidual measures each row against its own terms plus this fraction of
// the same terms with the impulses at the ellipsoid's size. Without it a row whose exact
// value is zero (no spin: tau_r = 0) is measured against its own rounding residue and
// never converges (ratio 1, issue 5); with the whole ellipsoid instead, the spin of a
// slider whose c |w| << |v| was only accurate to 1e-12 |v| / (c |w|) relative, and c was
// identified to 5e-5 only. 1e-6: the spin is then accurate to 1e-18 of the friction's
// capacity, still far above what Newton reaches (tau_r ~ 1e-30 in that case).
constexpr double kEllipsoidFloor = 1e-6;
}  // namespace

StepEquations::StepEquations(const SliderProperties& slider, const ReducedFriction& friction,
                             const PlanarState& state, const AppliedWrench& applied, double dt_s) {
  t_.m = slider.mass_kg;
  t_.I = slider.inertia_kgm2;
  t_.qz = slider.com_height_m;
  t_.pn = dt_s * (slider.mass_kg * slider.gravity_mps2 - applied.fz);
  t_.a = friction.a;
  t_.b = friction.b;
  t_.c = friction.c;
  t_.ptx = dt_s * applied.tx;
  t_.pty = dt_s * applied.ty;
  t_.k << t_.m * state.vx + dt_s * applied.fx, t_.m * state.vy + dt_s * applied.fy,
      t_.I * state.wz + dt_s * applied.tz;
  P_ = t_.a * t_.pn;
  const double u0 = t_.k(0) / t_.m, u1 = t_.b * t_.k(1) / t_.m, u2 = t_.c * t_.k(2) / t_.I;
  velocity_scale_ = std::sqrt(u0 * u0 + u1 * u1 + u2 * u2);
  // Squares overflow from ~1e154 m/s and underflow below ~1e-154 m/s (issue 5): the scaled
  // norm, slower, only then.
  if (!std::isfinite(velocity_scale_) || (velocity_scale_ < 1e-150 && velocity_scale_ > 0) ||
      (velocity_scale_ == 0 && (u0 != 0 || u1 != 0 || u2 != 0))) {
    velocity_scale_ = std::hypot(u0, u1, u2);
  }
  PrecomputeJacobianTerms();
}

void StepEquations::PrecomputeJacobianTerms() {
  pw_[0] = P_;
  pw_[1] = P_ * t_.b;
  pw_[2] = P_ * t_.c;
  // (ptx / pn) / I, not ptx / (pn I): the product underflows for tiny masses (issue 5:
  // m = 1e-300 kg gave 0 / 0 = NaN).
  dw_[0] = t_.ptx / t_.pn / t_.I;
  dw_[1] = t_.pty / t_.pn / t_.I;
  dw_[2] = 1.0 / t_.I;
  dr_ = -t_.qz / t_.pn;
  inv_m_ = 1.0 / t_.m;
  inv_pn_ = 1.0 / t_.pn;
  inv_I_ = 1.0 / t_.I;
  reciprocals_ = std::isnormal(t_.m) && std::isnormal(t_.pn) && std::isnormal(t_.I) &&
                 std::isnormal(inv_m_) && std::isnormal(inv_pn_) && std::isnormal(inv_I_);
}

const Eigen::Vector3d& StepEquations::RowTerms() const {
  if (row_terms_ready_) return row_terms_;
  row_terms_ready_ = true;
  // Magnitudes of the terms of u = (v_t, b v_o, c v_r) with every friction impulse at the
  // size of the ellipsoid (|p_t| <= P, |p_o| <= P b, |p_r| <= P c).
  if (reciprocals_) {
    // By the reciprocals of the constructor (issue 19: this is on the path of every step
    // that slides, and only kEllipsoidFloor of it enters the test).
    const double tx = std::abs(t_.ptx) * inv_pn_, ty = std::abs(t_.pty) * inv_pn_;
    const double w = (std::abs(t_.k(2)) + P_ * t_.c + P_ * (tx + t_.b * ty)) * inv_I_;
    const double rx = ty + t_.qz * t_.a, ry = tx + t_.qz * t_.a * t_.b;
    row_terms_ << (std::abs(t_.k(0)) + P_) * inv_m_ + w * ry,
        t_.b * ((std::abs(t_.k(1)) + P_ * t_.b) * inv_m_ + w * rx), t_.c * w;
    return row_terms_;
  }
  const double w = (std::abs(t_.k(2)) + P_ * t_.c +
                    P_ * ((std::abs(t_.ptx) + t_.b * std::abs(t_.pty)) / t_.pn)) /
                   t_.I;
  const double rx = std::abs(t_.pty) / t_.pn + t_.qz * t_.a;
  const double ry = std::abs(t_.ptx) / t_.pn + t_.qz * t_.a * t_.b;
  row_terms_ << (std::abs(t_.k(0)) + P_) / t_.m + w * ry,
      t_.b * ((std::abs(t_.k(1)) + P_ * t_.b) / t_.m + w * rx), t_.c * w;
  return row_terms_;
}

Eigen::Vector3d StepEquations::StoppingImpulse() const {
  Eigen::Vector3d p;
  p(0) = -t_.k(0);
  p(1) = -t_.k(1);
  p(2) = -t_.k(2) - (p(0) * t_.ptx + p(1) * t_.pty) / t_.pn;
  return p;
}

bool StepEquations::InsideEllipsoid(const Eigen::Vector3d& p, double beyond_ratio,
                                    bool* beyond) const {
  const double qo = p(1) / t_.b, qr = p(2) / t_.c;
  const double lhs = p(0) * p(0) + qo * qo + qr * qr, rhs = P_ * P_;
  if (beyond) *beyond = false;
  if (std::isnormal(lhs) && std::isnormal(rhs)) {
    // lhs / rhs and EllipsoidRatio^2 differ by a few ulps where EllipsoidRatio's divisors
    // P b and P c are normal: a relative margin of kSquaresMargin covers that.
    if (beyond) {
      const double limit =
          (1.0 + beyond_ratio) * (1.0 + beyond_ratio) * (1.0 + kSquaresMargin) * rhs;
      *beyond = lhs > limit && std::isfinite(limit) && std::isnormal(P_ * t_.b) &&
                std::isnormal(P_ * t_.c);
    }
    return lhs <= rhs;
  }
  // The squares under- or overflowed (masses or steps far from 1; issue 5: m = 1e-300 kg
  // "stuck" with 0 <= 0): in ratios to a p_n.
  if (p(0) == 0.0 && p(1) == 0.0 && p(2) == 0.0) return true;  // at rest, even if P_ = 0
  const double rt = p(0) / P_, ro = qo / P_, rr = qr / P_;
  return rt * rt + ro * ro + rr * rr <= 1.0;
}

Eigen::Vector3d StepEquations::EndVelocity(const Eigen::Vector3d& p) const {
  return StepEndVelocity(t_, p);
}

Eigen::Vector2d StepEquations::EcpOffset(const Eigen::Vector3d& p) const {
  return StepEcpOffset(t_, p);
}

Eigen::Vector3d StepEquations::EcpVelocity(const Eigen::Vector3d& p, Eigen::Matrix3d* dv_dp) const {
  const Eigen::Vector3d nu = EndVelocity(p);
  const Eigen::Vector2d r = EcpOffset(p);
  const double w = nu(2);
  if (dv_dp) {
    // (ptx / pn) / I, not ptx / (pn I): the product underflows for tiny masses (issue 5:
    // m = 1e-300 kg gave 0 / 0 = NaN).
    const Eigen::RowVector3d dw(t_.ptx / t_.pn / t_.I, t_.pty / t_.pn / t_.I, 1.0 / t_.I);
    const double dr = -t_.qz / t_.pn;  // d r_x / d p_t = d r_y / d p_o
    dv_dp->row(0) = -r(1) * dw;
    (*dv_dp)(0, 0) += 1.0 / t_.m;
    (*dv_dp)(0, 1) -= w * dr;
    dv_dp->row(1) = r(0) * dw;
    (*dv_dp)(1, 1) += 1.0 / t_.m;
    (*dv_dp)(1, 0) += w * dr;
    dv_dp->row(2) = dw;
  }
  return {nu(0) - w * r(1), nu(1) + w * r(0), w};
}

Eigen::Vector3d StepEquations::Impulses(const Eigen::Vector4d& z) const {
  return StepImpulses(t_, z);
}

void StepEquations::Evaluate(const Eigen::Vector4d& z, Eigen::Vector4d* f,
                             Eigen::Matrix4d* jac) const {
  Residual(z, f);
  if (jac) {
    Eigen::Matrix3d block;
    JacobianBlock(z, &block);
    jac->topLeftCorner<3, 3>() = block;
    jac->topRightCorner<3, 1>() = z.head<3>();
    jac->bottomLeftCorner<1, 3>() = velocity_scale_ * z.head<3>().transpose();
    (*jac)(3, 3) = 0.0;
  }
}

double StepEquations::ComponentwiseResidual(const Eigen::Vector4d& z,
                                            const Eigen::Vector4d& f) const {
  // |terms| of nu' = M^-1 (k + p + coupling), of the ECP offsets and of u + s tau at z,
  // plus kEllipsoidFloor of the same with the impulses at the ellipsoid's size.
  const Eigen::Vector3d p = Impulses(z).cwiseAbs();
  const double s = std::abs(z(3));
  Eigen::Vector3d terms;
  if (reciprocals_) {
    // The same magnitudes by the reciprocals of the constructor (issue 19: this test runs in
    // the last one or two Newton iterations of every step).
    const double tx = std::abs(t_.ptx) * inv_pn_, ty = std::abs(t_.pty) * inv_pn_;
    const double w = (std::abs(t_.k(2)) + p(2) + p(0) * tx + p(1) * ty) * inv_I_;
    const double rx = ty + t_.qz * (p(0) * inv_pn_);
    const double ry = tx + t_.qz * (p(1) * inv_pn_);
    terms << (std::abs(t_.k(0)) + p(0)) * inv_m_ + w * ry + s * std::abs(z(0)),
        t_.b * ((std::abs(t_.k(1)) + p(1)) * inv_m_ + w * rx) + s * std::abs(z(1)),
        t_.c * w + s * std::abs(z(2));
  } else {
    const double w = (std::abs(t_.k(2)) + p(2) + p(0) * (std::abs(t_.ptx) / t_.pn) +
                      p(1) * (std::abs(t_.pty) / t_.pn)) /
                     t_.I;
    const double rx = std::abs(t_.pty) / t_.pn + t_.qz * (p(0) / t_.pn);
    const double ry = std::abs(t_.ptx) / t_.pn + t_.qz * (p(1) / t_.pn);
    terms << (std::abs(t_.k(0)) + p(0)) / t_.m + w * ry + s * std::abs(z(0)),
        t_.b * ((std::abs(t_.k(1)) + p(1)) / t_.m + w * rx) + s * std::abs(z(1)),
        t_.c * w + s * std::abs(z(2));
  }
  double worst = 0;
  for (int i = 0; i < 3; ++i) {
    const double scale = terms(i) + kEllipsoidFloor * RowTerms()(i);
    if (scale > 0) worst = std::max(worst, std::abs(f(i)) / scale);
  }
  return worst;
}

double StepEquations::ConvergenceResidual(const Eigen::Vector4d& z, const Eigen::Vector4d& f,
                                          double tolerance) const {
  const double normwise = RelativeResidual(z, f);
  if (!(normwise <= tolerance)) return normwise;
  return std::max(normwise, ComponentwiseResidual(z, f));
}

bool StepEquations::ScalesRepresentableOneByOne(std::string* why, bool with_equation_terms) const {
  auto fail = [&](const char* what, double value) {
    if (why) *why = Printf("%s = %g is outside the normal range of double", what, value);
    return false;
  };
  // Subnormal a p_n (< 2.2e-308 N s) has lost digits already: the solve then stalls.
  if (!(P_ >= std::numeric_limits<double>::min()) || !std::isfinite(P_)) {
    return fail("a p_n (the ellipsoid's size) [N s]", P_);
  }
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(t_.k(i))) return fail("M nu + applied impulse [N s, N m s]", t_.k(i));
  }
  if (!std::isfinite(t_.ptx) || !std::isfinite(t_.pty)) {
    return fail("tilting impulse [N m s]", std::isfinite(t_.ptx) ? t_.pty : t_.ptx);
  }
  if (!std::isfinite(velocity_scale_)) return fail("free slip speed V [m/s]", velocity_scale_);
  if (with_equation_terms) {
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(RowTerms()(i))) {
        return fail("magnitude of a scaled equation's terms (e.g. c^2 a p_n / I) [m/s]",
                    RowTerms()(i));
      }
    }
  }
  return true;
}

double StepEquations::CouplingSpeed() const {
  const double offset =
      (std::abs(t_.ptx) + std::abs(t_.pty)) / t_.pn + t_.qz * t_.a * std::max(1.0, t_.b);
  return std::abs(t_.k(2)) / t_.I * offset;
}

bool StepEquations::UniqueSlidingRoot() const {
  // u(tau) = u_0 + A_1 tau + b d (g . tau) (tau_o, -tau_t, 0), with p = P W tau, W = diag(1,
  // b, c), d = q_z P / p_n, w' = w_0 + g . tau, g = P (t_x / p_n, b t_y / p_n, c) / I and
  // A_1 = diag(P / m, P b^2 / m, 0) + (antisymmetric: the spin w_0 about the ECP's shift)
  // + h g^T, h = (t_x / p_n, b t_y / p_n, c). The quadratic part's Jacobian is
  // b d (e g^T + (g . tau) R), e = (tau_o, -tau_t, 0), R antisymmetric, so with S the
  // symmetric part of A_1 (positive semidefinite: g = P h / I),
  //   x^T (du/dtau) x = x^T S x + b d (e . x) (g . x)   for every x,
  // and on the unit ball |e . x| <= |x_12| (x_12 = (x_t, x_o): |e| <= 1 and e has no third
  // entry). With 2 |x_12| |g . x| <= alpha |x_12|^2 + (g . x)^2 / alpha for any alpha > 0,
  // du/dtau has a positive definite symmetric part everywhere on the ball if
  //   M(alpha) = alpha S - (b d / 2) (alpha^2 diag(1, 1, 0) + g g^T)
  // is positive definite (the inequality times alpha: no division). Then u is strictly
  // monotone on the ball, and a sliding root (u + s tau = 0, |tau| = 1, s > 0: tau solves
  // the variational inequality of u on the ball) is the only one. alpha = |g| first, then
  // 2 |g| and |g| / 2 (issue 19: the round-2 test, S - b d (|g_12| + |g|) / 2 I > 0,
  // bounded the quadratic part in every direction at once and passed on 764 of
  // step_benchmark's 1024 general steps; this one passes on 991, those 764 included).
  if (!reciprocals_) return false;  // (issue 5's domain probes: the usual guesses)
  const double P = P_, b = t_.b, c = t_.c;
  const double h0 = t_.ptx * inv_pn_, h1 = b * t_.pty * inv_pn_, h2 = c;
  const double g0 = pw_[0] * dw_[0], g1 = pw_[1] * dw_[1], g2 = pw_[2] * dw_[2];
  const double d = t_.qz * P * inv_pn_;
  const double d0 = P * inv_m_, d1 = pw_[1] * b * inv_m_;
  const double g_sq = g0 * g0 + g1 * g1 + g2 * g2, g_norm = std::sqrt(g_sq);
  const double h_norm = std::abs(h0) + std::abs(h1) + std::abs(h2);  // >= |h|
  // The margins: 0.1% of the quadratic part's bound, and 1e-9 of S's size off its diagonal
  // (the minors below round at a few ulps of their terms).
  const double k = 1.001 * 0.5 * b * d;
  const double floor = 1e-9 * (d0 + d1 + h_norm * g_norm);
  // S - floor I, and k g g^T.
  const double s00 = d0 + h0 * g0 - floor, s11 = d1 + h1 * g1 - floor, s22 = h2 * g2 - floor;
  const double s01 = 0.5 * (h0 * g1 + h1 * g0), s02 = 0.5 * (h0 * g2 + h2 * g0),
               s12 = 0.5 * (h1 * g2 + h2 * g1);
  const double q00 = k * g0 * g0, q11 = k * g1 * g1, q22 = k * g2 * g2, q01 = k * g0 * g1,
               q02 = k * g0 * g2, q12 = k * g1 * g2;
  for (const double ratio : {1.0, 2.0, 0.5}) {
    const double alpha = ratio * g_norm, ka2 = k * alpha * alpha;
    const double m00 = alpha * s00 - ka2 - q00, m11 = alpha * s11 - ka2 - q11,
                 m22 = alpha * s22 - q22;
    const double m01 = alpha * s01 - q01, m02 = alpha * s02 - q02, m12 = alpha * s12 - q12;
    // Sylvester's criterion: the leading principal minors positive (false for NaN).
    const double minor2 = m00 * m11 - m01 * m01;
    const double minor3 = m00 * (m11 * m22 - m12 * m12) - m01 * (m01 * m22 - m12 * m02) +
                          m02 * (m01 * m12 - m11 * m02);
    if (m00 > 0 && minor2 > 0 && minor3 > 0) return true;
  }
  return false;
}

double StepEquations::EllipsoidRatio(const Eigen::Vector3d& p) const {
  const double qt = p(0) / P_, qo = p(1) / (P_ * t_.b), qr = p(2) / (P_ * t_.c);
  return std::sqrt(qt * qt + qo * qo + qr * qr);
}

Eigen::Vector4d StepEquations::LinearisedStopGuess() const {
  const Eigen::Vector3d p = StoppingImpulse();
  Eigen::Vector4d z;
  z << p(0) / P_, p(1) / (P_ * t_.b), p(2) / (P_ * t_.c), 0.0;
  Eigen::Vector4d f;
  Eigen::Matrix4d jac;
  Evaluate(z, &f, &jac);  // at s = 0 the 3x3 block is A = du/dtau
  const Eigen::Matrix3d A = jac.topLeftCorner<3, 3>();
  const Eigen::Vector3d rhs = A * z.head<3>();
  auto tau_at = [&](double s, Eigen::Vector3d* dtau) {
    const Eigen::PartialPivLU<Eigen::Matrix3d> lu(A + s * Eigen::Matrix3d::Identity());
    const Eigen::Vector3d tau = lu.solve(rhs);
    if (dtau) *dtau = -lu.solve(tau);
    return tau;
  };
  // g(s) = 1 / |tau(s)| - 1: negative at s = 0 (outside the ellipsoid), positive for s
  // large against |A|; Newton inside a bracket, bisection (geometric: s spans decades)
  // where Newton leaves it.
  double lo = 0.0, hi = 2.0 * z.head<3>().norm() * A.norm();
  for (int i = 0; i < 60 && !(tau_at(hi, nullptr).norm() < 1.0); ++i) hi *= 4.0;
  if (!(hi > 0) || !std::isfinite(hi)) return StoppingGuess();
  double s = hi * kGuessTolerance;
  Eigen::Vector3d tau, dtau;
  for (int it = 0; it < kMaxScalarIterations; ++it) {
    tau = tau_at(s, &dtau);
    const double n = tau.norm();
    const double g = 1.0 / n - 1.0;
    if (std::abs(g) <= kGuessTolerance || !std::isfinite(g)) break;
    if (g < 0)
      lo = s;
    else
      hi = s;
    const double dg = -tau.dot(dtau) / (n * n * n);
    double next = s - g / dg;
    if (!(next > lo && next < hi)) next = lo > 0 ? std::sqrt(lo * hi) : 0.5 * hi;
    s = next;
    if (hi - lo <= 4 * kEps * hi) break;
  }
  if (!tau.allFinite() || !(tau.norm() > 0) || !(s > 0)) return StoppingGuess();
  z.head<3>() = tau.normalized();
  z(3) = s;
  return z;
}

Eigen::Vector4d StepEquations::EcpVelocityGuess(Eigen::Vector4d z, int sweeps) const {
  for (int i = 0; i < sweeps; ++i) {
    const Eigen::Vector3d v = EcpVelocity(Impulses(z), nullptr);
    const Eigen::Vector3d u(v(0), t_.b * v(1), t_.c * v(2));
    const double speed = u.norm();
    if (!(speed > 0) || !std::isfinite(speed)) break;
    z << -u / speed, speed;
  }
  return z;
}

Eigen::Vector4d StepEquations::DecoupledAt(double s) const {
  // p_i = -P D_i k_i / (M_i s + P D_i), D = (1, b^2, c^2): tau = p / (P weight).
  return {-t_.k(0) / (t_.m * s + P_), -t_.b * t_.k(1) / (t_.m * s + P_ * t_.b * t_.b),
          -t_.c * t_.k(2) / (t_.I * s + P_ * t_.c * t_.c), s};
}

double StepEquations::DecoupledSlipLowerBound() const {
  if (reciprocals_) {
    // By the reciprocals (issue 19's fifth round: the first link of the first guess's chain).
    return std::max(std::max(std::max(0.0, (std::abs(t_.k(0)) - P_) * inv_m_),
                             (t_.b * std::abs(t_.k(1)) - P_ * (t_.b * t_.b)) * inv_m_),
                    (t_.c * std::abs(t_.k(2)) - P_ * (t_.c * t_.c)) * inv_I_);
  }
  const double mass[3] = {t_.m, t_.m, t_.I};
  const double weight[3] = {1.0, t_.b, t_.c};
  double lo = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double d = weight[i] * weight[i];
    lo = std::max(lo, (weight[i] * std::abs(t_.k(i)) - P_ * d) / mass[i]);
  }
  return lo;
}

bool StepEquations::SolveDecoupled(Eigen::Vector4d* z, int* iterations, double tolerance,
                                   double accept_after_step) const {
  tolerance = std::max(tolerance, kScalarTolerance);
  const Eigen::Vector3d mass(t_.m, t_.m, t_.I);
  const Eigen::Vector3d weight(1.0, t_.b, t_.c);
  // Bracket: each term of |tau|^2 alone reaching 1 gives a lower bound; the free slip speed
  // (no friction at all) an upper bound.
  double lo = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double d = weight(i) * weight(i);
    lo = std::max(lo, (weight(i) * std::abs(t_.k(i)) - P_ * d) / mass(i));
  }
  double hi = std::max(velocity_scale_, lo);
  double s = lo;
  for (int it = 1; it <= kMaxScalarIterations; ++it) {
    // g(s) = |tau(s)|^{-1} - 1, increasing in s; exactly linear with one non-zero term.
    // With q = sqrt(phi) = |tau|: g = (1 - q) / q, g' = -phi' / (2 phi q), and the Newton
    // step g / g' = 2 phi (q - 1) / phi': one square root and one division in series per
    // iteration (issue 19; the three divisions of the terms are independent).
    double phi = 0, dphi = 0;
    for (int i = 0; i < 3; ++i) {
      const double d = weight(i) * weight(i);
      const double den = mass(i) * s + P_ * d;
      if (t_.k(i) == 0.0) continue;
      const double ratio = t_.k(i) / den;  // squared as a ratio: no under/overflow
      const double term = d * ratio * ratio;
      phi += term;
      dphi -= 2.0 * term * mass(i) / den;
    }
    const double q = std::sqrt(phi);
    *iterations = it;
    if (std::abs(1.0 - q) <= tolerance * q) break;  // |g| <= tolerance
    if (q > 1.0)                                    // g < 0
      lo = s;
    else
      hi = s;
    if (hi - lo <= 2 * kEps * hi) break;
    double next = s - 2.0 * phi * (q - 1.0) / dphi;
    if (!(next > lo && next < hi)) {
      next = 0.5 * (lo + hi);
    } else if (std::abs(1.0 - q) <= accept_after_step * q) {
      s = next;  // |g| squared (about) is below the tolerance after this step
      break;
    }
    s = next;
  }
  if (!(s > 0)) return false;
  *z = DecoupledAt(s);
  return true;
}

Eigen::Vector4d StepEquations::DecoupledGuess() const {
  return DecoupledGuess(kGuessTolerance, kGuessAcceptAfterStep);
}

Eigen::Vector4d StepEquations::DecoupledGuess(double tolerance, double accept_after_step) const {
  Eigen::Vector4d z;
  int its = 0;
  const Eigen::Vector3d weight(1.0, t_.b, t_.c);
  double phi0 = 0;  // |tau(0)|^2: the decoupled stick test
  for (int i = 0; i < 3; ++i) phi0 += std::pow(t_.k(i) / (P_ * weight(i)), 2);
  if (phi0 > 1.0 && SolveDecoupled(&z, &its, tolerance, accept_after_step)) return z;
  z = DecoupledAt(kGuessSlipFraction * velocity_scale_);
  z.head<3>().normalize();
  return z;
}

Eigen::Vector4d StepEquations::StoppingGuess() const {
  const Eigen::Vector3d p = StoppingImpulse();
  Eigen::Vector4d z;
  z.head<3>() << p(0) / P_, p(1) / (P_ * t_.b), p(2) / (P_ * t_.c);
  const double excess = z.head<3>().norm();  // > 1 whenever the step slides
  // Per axis, |tau_i(s)| = 1 at s = P (|tau_i(0)| - 1) / M_i with M = (m, m/b^2, I/c^2).
  const Eigen::Vector3d mass(t_.m, t_.m / (t_.b * t_.b), t_.I / (t_.c * t_.c));
  const Eigen::Vector3d share = z.head<3>().cwiseAbs2() / (excess * excess);
  z(3) = P_ * std::max(excess - 1.0, kGuessSlipFraction) / share.dot(mass);
  z.head<3>() /= excess;
  return z;
}

Eigen::Vector4d StepEquations::PureTranslationClosedForm() const {
  const double k = std::hypot(t_.k(0), t_.k(1));
  return {-t_.k(0) / k, -t_.k(1) / k, 0.0, (k - P_) / t_.m};
}

StepEquations StepEquations::WithCouplingScaled(double scale) const {
  StepEquations scaled = *this;
  scaled.t_.qz *= scale;
  scaled.t_.ptx *= scale;
  scaled.t_.pty *= scale;
  scaled.row_terms_ready_ = false;
  scaled.PrecomputeJacobianTerms();
  return scaled;
}

}  // namespace slideid
