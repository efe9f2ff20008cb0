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
}  // namespace

StepEquations::StepEquations(const SliderProperties& slider, const ReducedFriction& friction,
                             const PlanarState& state, const AppliedWrench& applied,
                             double dt_s)
    : m_(slider.mass_kg),
      I_(slider.inertia_kgm2),
      qz_(slider.com_height_m),
      pn_(dt_s * (slider.mass_kg * slider.gravity_mps2 - applied.fz)),
      a_(friction.a),
      b_(friction.b),
      c_(friction.c),
      ptx_(dt_s * applied.tx),
      pty_(dt_s * applied.ty) {
  k_ << m_ * state.vx + dt_s * applied.fx, m_ * state.vy + dt_s * applied.fy,
      I_ * state.wz + dt_s * applied.tz;
  P_ = a_ * pn_;
  velocity_scale_ = std::sqrt(std::pow(k_(0) / m_, 2) + std::pow(b_ * k_(1) / m_, 2) +
                              std::pow(c_ * k_(2) / I_, 2));
}

Eigen::Vector3d StepEquations::StoppingImpulse() const {
  Eigen::Vector3d p;
  p(0) = -k_(0);
  p(1) = -k_(1);
  p(2) = -k_(2) - (p(0) * ptx_ + p(1) * pty_) / pn_;
  return p;
}

bool StepEquations::InsideEllipsoid(const Eigen::Vector3d& p) const {
  const double qo = p(1) / b_, qr = p(2) / c_;
  return p(0) * p(0) + qo * qo + qr * qr <= P_ * P_;
}

Eigen::Vector3d StepEquations::EndVelocity(const Eigen::Vector3d& p) const {
  return {(k_(0) + p(0)) / m_, (k_(1) + p(1)) / m_,
          (k_(2) + p(2) + (p(0) * ptx_ + p(1) * pty_) / pn_) / I_};
}

Eigen::Vector2d StepEquations::EcpOffset(const Eigen::Vector3d& p) const {
  return {(pty_ - qz_ * p(0)) / pn_, (-ptx_ - qz_ * p(1)) / pn_};
}

Eigen::Vector3d StepEquations::EcpVelocity(const Eigen::Vector3d& p,
                                           Eigen::Matrix3d* dv_dp) const {
  const Eigen::Vector3d nu = EndVelocity(p);
  const Eigen::Vector2d r = EcpOffset(p);
  const double w = nu(2);
  if (dv_dp) {
    const Eigen::RowVector3d dw(ptx_ / (pn_ * I_), pty_ / (pn_ * I_), 1.0 / I_);
    const double dr = -qz_ / pn_;  // d r_x / d p_t = d r_y / d p_o
    dv_dp->row(0) = -r(1) * dw;
    (*dv_dp)(0, 0) += 1.0 / m_;
    (*dv_dp)(0, 1) -= w * dr;
    dv_dp->row(1) = r(0) * dw;
    (*dv_dp)(1, 1) += 1.0 / m_;
    (*dv_dp)(1, 0) += w * dr;
    dv_dp->row(2) = dw;
  }
  return {nu(0) - w * r(1), nu(1) + w * r(0), w};
}

Eigen::Vector3d StepEquations::Impulses(const Eigen::Vector4d& z) const {
  return {P_ * z(0), P_ * b_ * z(1), P_ * c_ * z(2)};
}

void StepEquations::Evaluate(const Eigen::Vector4d& z, Eigen::Vector4d* f,
                             Eigen::Matrix4d* jac) const {
  const Eigen::Vector3d weight(1.0, b_, c_);
  const Eigen::Vector3d tau = z.head<3>();
  const double s = z(3);
  Eigen::Matrix3d dv_dp;
  const Eigen::Vector3d v = EcpVelocity(Impulses(z), jac ? &dv_dp : nullptr);
  f->head<3>() = weight.cwiseProduct(v) + s * tau;
  (*f)(3) = 0.5 * velocity_scale_ * (tau.squaredNorm() - 1.0);
  if (jac) {
    // dp/dtau = P diag(weight), du/dv = diag(weight).
    jac->topLeftCorner<3, 3>() =
        P_ * weight.asDiagonal() * dv_dp * weight.asDiagonal();
    jac->topLeftCorner<3, 3>().diagonal().array() += s;
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
  return {-k_(0) / (m_ * s + P_), -b_ * k_(1) / (m_ * s + P_ * b_ * b_),
          -c_ * k_(2) / (I_ * s + P_ * c_ * c_), s};
}

bool StepEquations::SolveDecoupled(Eigen::Vector4d* z, int* iterations) const {
  const Eigen::Vector3d mass(m_, m_, I_);
  const Eigen::Vector3d weight(1.0, b_, c_);
  // Bracket: each term of |tau|^2 alone reaching 1 gives a lower bound; the free slip speed
  // (no friction at all) an upper bound.
  double lo = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double d = weight(i) * weight(i);
    lo = std::max(lo, (weight(i) * std::abs(k_(i)) - P_ * d) / mass(i));
  }
  double hi = std::max(velocity_scale_, lo);
  double s = lo;
  for (int it = 1; it <= kMaxScalarIterations; ++it) {
    // g(s) = |tau(s)|^{-1} - 1, increasing in s; exactly linear with one non-zero term.
    double phi = 0, dphi = 0;
    for (int i = 0; i < 3; ++i) {
      const double d = weight(i) * weight(i);
      const double den = mass(i) * s + P_ * d;
      if (k_(i) == 0.0) continue;
      const double term = d * k_(i) * k_(i) / (den * den);
      phi += term;
      dphi -= 2.0 * term * mass(i) / den;
    }
    const double g = 1.0 / std::sqrt(phi) - 1.0;
    *iterations = it;
    if (std::abs(g) <= kScalarTolerance) break;
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
  const Eigen::Vector3d weight(1.0, b_, c_);
  double phi0 = 0;  // |tau(0)|^2: the decoupled stick test
  for (int i = 0; i < 3; ++i) phi0 += std::pow(k_(i) / (P_ * weight(i)), 2);
  if (phi0 > 1.0 && SolveDecoupled(&z, &its)) return z;
  z = DecoupledAt(kGuessSlipFraction * velocity_scale_);
  z.head<3>().normalize();
  return z;
}

Eigen::Vector4d StepEquations::StoppingGuess() const {
  const Eigen::Vector3d p = StoppingImpulse();
  Eigen::Vector4d z;
  z.head<3>() << p(0) / P_, p(1) / (P_ * b_), p(2) / (P_ * c_);
  const double excess = z.head<3>().norm();  // > 1 whenever the step slides
  // Per axis, |tau_i(s)| = 1 at s = P (|tau_i(0)| - 1) / M_i with M = (m, m/b^2, I/c^2).
  const Eigen::Vector3d mass(m_, m_ / (b_ * b_), I_ / (c_ * c_));
  const Eigen::Vector3d share = z.head<3>().cwiseAbs2() / (excess * excess);
  z(3) = P_ * std::max(excess - 1.0, kGuessSlipFraction) / share.dot(mass);
  z.head<3>() /= excess;
  return z;
}

Eigen::Vector4d StepEquations::PureTranslationClosedForm() const {
  const double k = std::hypot(k_(0), k_(1));
  return {-k_(0) / k, -k_(1) / k, 0.0, (k - P_) / m_};
}

StepEquations StepEquations::WithCouplingScaled(double scale) const {
  StepEquations scaled = *this;
  scaled.qz_ *= scale;
  scaled.ptx_ *= scale;
  scaled.pty_ *= scale;
  return scaled;
}

}  // namespace slideid
