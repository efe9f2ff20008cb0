#include "forward_model/wrench_twist_pair.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>

namespace slideid {
namespace {

/// Below this |angle| [rad] the SE(2) maps use their Taylor series (the closed forms divide
/// by the angle); the first omitted term is then below 1e-17 relative.
constexpr double kSmallAngle_rad = 1e-4;

/// V(w) of SE(2): a constant body twist (v, w) displaces by V(w) v over unit time.
Eigen::Matrix2d Se2V(double w) {
  double s, c;  // sin(w) / w and (1 - cos(w)) / w
  if (std::abs(w) < kSmallAngle_rad) {
    s = 1.0 - w * w / 6.0;
    c = w / 2.0 - w * w * w / 24.0;
  } else {
    s = std::sin(w) / w;
    c = (1.0 - std::cos(w)) / w;
  }
  Eigen::Matrix2d v;
  v << s, -c, c, s;
  return v;
}

}  // namespace

Eigen::Vector3d BodyTwistFromPoseChange(const Eigen::Vector2d& d, double dtheta) {
  // det V = s^2 + c^2 = 2 (1 - cos w) / w^2 > 0 for |w| < 2 pi: one full turn is the limit.
  const Eigen::Vector2d v = Se2V(dtheta).inverse() * d;
  return {v.x(), v.y(), dtheta};
}

Eigen::Vector3d PoseChangeFromBodyTwist(const Eigen::Vector3d& twist, double s) {
  const Eigen::Vector2d d = Se2V(s * twist.z()) * (s * twist.head<2>());
  return {d.x(), d.y(), s * twist.z()};
}

WrenchTwistPair InRotatedFrame(const WrenchTwistPair& pair, double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  WrenchTwistPair out = pair;
  out.fx = c * pair.fx + s * pair.fy;
  out.fy = -s * pair.fx + c * pair.fy;
  out.vx = c * pair.vx + s * pair.vy;
  out.vy = -s * pair.vx + c * pair.vy;
  return out;
}

WrenchTwistPair AboutPoint(const WrenchTwistPair& pair, const Eigen::Vector2d& point) {
  WrenchTwistPair out = pair;
  out.mz = pair.mz - (point.x() * pair.fy - point.y() * pair.fx);
  out.vx = pair.vx - pair.wz * point.y();
  out.vy = pair.vy + pair.wz * point.x();
  return out;
}

Eigen::Vector3d QuasiStaticWrench(const Eigen::Vector3d& twist, const ReducedFriction& friction,
                                  double normal_force_n) {
  if (!twist.allFinite() || twist.isZero(0.0)) {
    throw std::invalid_argument("QuasiStaticWrench: the twist must be finite and non-zero");
  }
  if (!(normal_force_n > 0.0) || !(friction.a > 0.0) || !(friction.b > 0.0) ||
      !(friction.c > 0.0)) {
    throw std::invalid_argument("QuasiStaticWrench: N, a, b and c must be > 0");
  }
  const Eigen::Vector3d d(1.0, friction.b * friction.b, friction.c * friction.c);
  const Eigen::Vector3d dv = d.cwiseProduct(twist);
  return friction.a * normal_force_n * dv / std::sqrt(twist.dot(dv));
}

Eigen::Vector3d LimitSurfaceNormal(const Eigen::Vector3d& wrench, const ReducedFriction& friction) {
  return {wrench.x(), wrench.y() / (friction.b * friction.b),
          wrench.z() / (friction.c * friction.c)};
}

std::vector<WrenchTwistPair> WrenchTwistData::Pairs() const {
  std::vector<WrenchTwistPair> pairs;
  pairs.reserve(rows.size());
  for (const WrenchTwistRow& row : rows) pairs.push_back(row.pair);
  return pairs;
}

}  // namespace slideid
