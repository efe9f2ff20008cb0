#include "forward_model/scene.h"

#include <algorithm>
#include <cmath>

#include "forward_model/constants.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {}  // namespace

bool SceneFriction::IsValid(std::string* why) const {
  for (const double x : {paper_.mu, paper_.e_t, paper_.e_o, paper_.e_r}) {
    if (!(std::isfinite(x) && x > 0)) {
      if (why) {
        *why = Printf(
            "the friction must be finite and > 0: mu = %g, e_t = %g, e_o = %g, e_r = %g (a = %g, "
            "b = %g, c = %g)",
            paper_.mu, paper_.e_t, paper_.e_o, paper_.e_r, reduced_.a, reduced_.b, reduced_.c);
      }
      return false;
    }
  }
  return true;
}

double PushSpec::MagnitudeAt(double t_s) const {
  if (t_s < start_s || t_s >= stop_s) return 0.0;
  double magnitude = force_n;
  if (period_s > 0.0) magnitude += amplitude_n * std::cos(2.0 * kPi * t_s / period_s);
  return std::max(0.0, magnitude);  // a pusher cannot pull
}

AppliedWrench PushSpec::WrenchAt(double t_s, const PlanarState& pose, double com_height_m,
                                 Eigen::Vector3d* point_world) const {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const Eigen::Vector2d r_xy(c * point_body.x() - s * point_body.y(),
                             s * point_body.x() + c * point_body.y());
  const Eigen::Vector2d f =
      MagnitudeAt(t_s) * Eigen::Vector2d(c * direction_body.x() - s * direction_body.y(),
                                         s * direction_body.x() + c * direction_body.y());
  if (point_world != nullptr) *point_world = {pose.x + r_xy.x(), pose.y + r_xy.y(), height_m};
  return WrenchFromForceAt(f.x(), f.y(), 0.0, r_xy.x(), r_xy.y(), height_m - com_height_m);
}

}  // namespace slideid
