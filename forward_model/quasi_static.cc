#include "forward_model/quasi_static.h"

#include <stdexcept>

namespace slideid {

Eigen::Vector3d QuasiStaticTwist(const Eigen::Vector2d& r, const Eigen::Vector2d& vc, double c_m) {
  if (!(c_m > 0)) throw std::invalid_argument("QuasiStaticTwist: c must be > 0");
  const double c2 = c_m * c_m;
  // The denominator is >= c^2 > 0.
  const double den = c2 + r.squaredNorm();
  const double vx = ((c2 + r.x() * r.x()) * vc.x() + r.x() * r.y() * vc.y()) / den;
  const double vy = ((c2 + r.y() * r.y()) * vc.y() + r.x() * r.y() * vc.x()) / den;
  const double wz = (r.x() * vy - r.y() * vx) / c2;
  return {vx, vy, wz};
}

}  // namespace slideid
