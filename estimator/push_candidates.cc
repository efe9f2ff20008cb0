#include "estimator/push_candidates.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "forward_model/constants.h"
#include "forward_model/number_format.h"
#include "forward_model/pusher.h"

namespace slideid {
namespace {

/// A point at `fraction` of the closed polyline's length and the outward normal of its
/// edge (the outline runs counter-clockwise, so outward is the edge turned -90 deg).
void PointOnOutline(const std::vector<Eigen::Vector2d>& closed, double fraction,
                    Eigen::Vector2d* point, Eigen::Vector2d* normal) {
  double total = 0;
  for (size_t i = 0; i + 1 < closed.size(); ++i) total += (closed[i + 1] - closed[i]).norm();
  double left = fraction * total;
  for (size_t i = 0; i + 1 < closed.size(); ++i) {
    const Eigen::Vector2d edge = closed[i + 1] - closed[i];
    const double length = edge.norm();
    if (length <= 0) continue;
    if (left <= length || i + 2 == closed.size()) {
      const Eigen::Vector2d e = edge / length;
      *point = closed[i] + std::min(left, length) * e;
      *normal = Eigen::Vector2d(e.y(), -e.x());
      return;
    }
    left -= length;
  }
  *point = closed.front();
  *normal = Eigen::Vector2d::UnitX();
}

}  // namespace

bool PushCandidateOptions::IsValid(std::string* why) const {
  const auto fail = [&](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (contact_points < 1) return fail("contact_points must be >= 1");
  if (cone_fractions.empty()) return fail("cone_fractions must not be empty");
  for (double f : cone_fractions) {
    if (!(f >= -1 && f <= 1)) return fail("cone fractions must lie in [-1, 1]: " + ShortNumber(f));
  }
  if (lengths_m.empty()) return fail("lengths_m must not be empty");
  for (double l : lengths_m) {
    if (!(l > 0 && std::isfinite(l))) return fail("push lengths must be > 0 m: " + ShortNumber(l));
  }
  if (!(mu_pusher >= 0 && std::isfinite(mu_pusher))) {
    return fail("mu_pusher must be >= 0: " + ShortNumber(mu_pusher));
  }
  if (!(tip_speed_mps > 0 && std::isfinite(tip_speed_mps))) {
    return fail("tip_speed_mps must be > 0: " + ShortNumber(tip_speed_mps));
  }
  if (!(tip_radius_m >= 0 && std::isfinite(tip_radius_m))) {
    return fail("tip_radius_m must be >= 0: " + ShortNumber(tip_radius_m));
  }
  if (!(clearance_m > 0 && std::isfinite(clearance_m))) {
    return fail("clearance_m must be > 0: " + ShortNumber(clearance_m));
  }
  if (!(run_out_s >= 0 && std::isfinite(run_out_s))) {
    return fail("run_out_s must be >= 0: " + ShortNumber(run_out_s));
  }
  return true;
}

std::vector<PushCandidate> CandidatePushes(const ContactPatch& patch,
                                           const PushCandidateOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("push candidates: " + why);
  const std::vector<Eigen::Vector2d> outline = patch.Outline();
  const double half_cone = std::atan(options.mu_pusher);
  std::vector<PushCandidate> out;
  for (int k = 0; k < options.contact_points; ++k) {
    // Half a spacing in: a rectangle's or polygon's first vertex is not a point to push at
    // (its normal is undefined there).
    const double fraction = (k + 0.5) / options.contact_points;
    Eigen::Vector2d point, normal;
    PointOnOutline(outline, fraction, &point, &normal);
    for (double cone : options.cone_fractions) {
      const double angle = cone * half_cone;
      const Eigen::Vector2d inward = -normal;
      const Eigen::Vector2d direction(std::cos(angle) * inward.x() - std::sin(angle) * inward.y(),
                                      std::sin(angle) * inward.x() + std::cos(angle) * inward.y());
      for (double length : options.lengths_m) {
        PushCandidate c;
        c.outline_fraction = fraction;
        c.contact_body = point;
        c.direction_body = direction;
        c.angle_from_normal_rad = angle;
        c.length_m = length;
        out.push_back(c);
      }
    }
  }
  return out;
}

Scene PushScene(const SliderProperties& slider, const ReducedFriction& friction,
                const ContactPatch& patch, const PushCandidate& push,
                const PushCandidateOptions& options, double dt_s) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("push scene: " + why);
  if (!(dt_s > 0)) throw std::invalid_argument("push scene: dt must be > 0 s");
  Scene scene;
  scene.source = "advise-push candidate " + Describe(push);
  scene.slider = slider;
  scene.friction = friction;
  scene.patch = patch;
  scene.dt_s = dt_s;
  Pusher pusher;
  pusher.tip_radius_m = options.tip_radius_m;
  pusher.mu = options.mu_pusher;
  const Eigen::Vector2d d = push.direction_body.normalized();
  // Where the tip's centre touches when it arrives at the contact point along d, backed off
  // by the clearance along its path; then how far it really travels to touch (another part
  // of the outline may come first on a path at an angle).
  Eigen::Vector2d outward = Eigen::Vector2d::Zero();
  {
    std::vector<Eigen::Vector2d> outline = patch.Outline();
    Eigen::Vector2d p;
    PointOnOutline(outline, push.outline_fraction, &p, &outward);
  }
  const Eigen::Vector2d touching = push.contact_body + options.tip_radius_m * outward;
  // Backed off along -d until the tip is clear of the outline by the clearance.
  Eigen::Vector2d start = touching - options.clearance_m * d;
  for (int i = 0; i < 60; ++i) {
    const TipContact c = ContactWithTip(patch, PlanarState{}, start, options.tip_radius_m);
    if (c.gap_m >= options.clearance_m) break;
    start -= options.clearance_m * d;
  }
  const double reach = 4 * (touching - start).norm() + 1.0;
  const double meets = TravelToTouch(patch, PlanarState{}, start, d, options.tip_radius_m, reach);
  pusher.path = PusherPath::Polyline(0.0, start, {start + (meets + push.length_m) * d},
                                     {options.tip_speed_mps});
  scene.duration_s = pusher.path.end_s() + options.run_out_s;
  scene.pusher = pusher;
  return scene;
}

std::string Describe(const PushCandidate& push) {
  return Printf("outline %.3f (%.4g, %.4g) m, %+.0f deg from the normal, %.0f mm",
                push.outline_fraction, push.contact_body.x(), push.contact_body.y(),
                push.angle_from_normal_rad * kRadToDeg, push.length_m * 1e3);
}

}  // namespace slideid
