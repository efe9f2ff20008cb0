#include "forward_model/step_equations.h"

#include <algorithm>
#include <cmath>
#include <limits>

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
}  // namespace

StepEquations::StepEquations(const SliderProperties& slider, const ReducedFriction& friction,
                             const PlanarState& state, const AppliedWrench& applied,
                             double dt_s) {
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
  velocity_scale_ = std::sqrt(std::pow(t_.k(0) / t_.m, 2) + std::pow(t_.b * t_.k(1) / t_.m, 2) +
                              std::pow(t_.c * t_.k(2) / t_.I, 2));
}

Eigen::Vector3d StepEquations::StoppingImpulse() const {
  Eigen::Vector3d p;
  p(0) = -t_.k(0);
  p(1) = -t_.k(1);
  p(2) = -t_.k(2) - (p(0) * t_.ptx + p(1) * t_.pty) / t_.pn;
  return p;
}

bool StepEquations::InsideEllipsoid(const Eigen::Vector3d& p) const {
  const double qo = p(1) / t_.b, qr = p(2) / t_.c;
  return p(0) * p(0) + qo * qo + qr * qr <= P_ * P_;
}

Eigen::Vector3d StepEquations::EndVelocity(const Eigen::Vector3d& p) const {
  return StepEndVelocity(t_, p);
}

Eigen::Vector2d StepEquations::EcpOffset(const Eigen::Vector3d& p) const {
  return StepEcpOffset(t_, p);
}

Eigen::Vector3d StepEquations::EcpVelocity(const Eigen::Vector3d& p,
                                           Eigen::Matrix3d* dv_dp) const {
  const Eigen::Vector3d nu = EndVelocity(p);
  const Eigen::Vector2d r = EcpOffset(p);
  const double w = nu(2);
  if (dv_dp) {
    const Eigen::RowVector3d dw(t_.ptx / (t_.pn * t_.I), t_.pty / (t_.pn * t_.I), 1.0 / t_.I);
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
  *f = ScaledStepResidual(t_, z, velocity_scale_);
  if (jac) {
    // Analytic: dp/dtau = P diag(weight), du/dv = diag(weight), dv/dp from EcpVelocity.
    const Eigen::Vector3d weight(1.0, t_.b, t_.c);
    const Eigen::Vector3d tau = z.head<3>();
    Eigen::Matrix3d dv_dp;
    EcpVelocity(Impulses(z), &dv_dp);
    jac->topLeftCorner<3, 3>() = P_ * weight.asDiagonal() * dv_dp * weight.asDiagonal();
    jac->topLeftCorner<3, 3>().diagonal().array() += z(3);
    jac->topRightCorner<3, 1>() = tau;
    jac->bottomLeftCorner<1, 3>() = velocity_scale_ * tau.transpose();
    (*jac)(3, 3) = 0.0;
  }
}

double StepEquations::RelativeResidual(const Eigen::Vector4d& z,
                                       const Eigen::Vector4d& f) const {
  const double scale = velocity_scale_ + std::abs(z(3));
  const double motion = scale > 0 ? f.head<3>().cwiseAbs().maxCoeff() / scale : 0.0;
  const double sphere = velocity_scale_ > 0 ? 2.0 * std::abs(f(3)) / velocity_scale_ : 0.0;
  return std::max(motion, sphere);
}

Eigen::Vector4d StepEquations::DecoupledAt(double s) const {
  // p_i = -P D_i k_i / (M_i s + P D_i), D = (1, b^2, c^2): tau = p / (P weight).
  return {-t_.k(0) / (t_.m * s + P_), -t_.b * t_.k(1) / (t_.m * s + P_ * t_.b * t_.b),
          -t_.c * t_.k(2) / (t_.I * s + P_ * t_.c * t_.c), s};
}

bool StepEquations::SolveDecoupled(Eigen::Vector4d* z, int* iterations,
                                   double tolerance) const {
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
    double phi = 0, dphi = 0;
    for (int i = 0; i < 3; ++i) {
      const double d = weight(i) * weight(i);
      const double den = mass(i) * s + P_ * d;
      if (t_.k(i) == 0.0) continue;
      const double term = d * t_.k(i) * t_.k(i) / (den * den);
      phi += term;
      dphi -= 2.0 * term * mass(i) / den;
    }
    const double g = 1.0 / std::sqrt(phi) - 1.0;
    *iterations = it;
    if (std::abs(g) <= tolerance) break;
    if (g < 0) lo = s; else hi = s;
    if (hi - lo <= 2 * kEps * hi) break;
    const double dg = -0.5 * dphi / (phi * std::sqrt(phi));
    double next = s - g / dg;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    s = next;
  }
  if (!(s > 0)) return false;
  *z = DecoupledAt(s);
  return true;
}

Eigen::Vector4d StepEquations::DecoupledGuess() const {
  Eigen::Vector4d z;
  int its = 0;
  const Eigen::Vector3d weight(1.0, t_.b, t_.c);
  double phi0 = 0;  // |tau(0)|^2: the decoupled stick test
  for (int i = 0; i < 3; ++i) phi0 += std::pow(t_.k(i) / (P_ * weight(i)), 2);
  if (phi0 > 1.0 && SolveDecoupled(&z, &its, kGuessTolerance)) return z;
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
  return scaled;
}

}  // namespace slideid
