#include "forward_model/pusher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace slideid {
namespace {

// Below this distance [m] the tip centre sits on the outline and the direction to it is
// rounding: the edge's own outward normal is used instead.
constexpr double kOnOutlineM = 1e-12;
// TravelToTouch stops within this of the outline [m], after at most this many steps (each
// step covers the gap: a line grazing the outline converges slowest).
constexpr double kTouchTolerance_m = 1e-14;
constexpr int kMaxTouchSteps = 10000;

Eigen::Vector2d Rotate(double theta, const Eigen::Vector2d& v) {
  const double c = std::cos(theta), s = std::sin(theta);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

/// Whether p lies inside the closed polyline `ring` (even-odd rule).
bool Inside(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0; i + 1 < ring.size(); ++i) {
    const Eigen::Vector2d &a = ring[i], &b = ring[i + 1];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
      inside = !inside;
    }
  }
  return inside;
}

/// Body-frame contact against a polygon's edges (closed, counter-clockwise).
TipContact PolygonContact(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::infinity();
  TipContact c;
  Eigen::Vector2d edge_normal = Eigen::Vector2d::UnitX();
  for (size_t i = 0; i + 1 < ring.size(); ++i) {
    const Eigen::Vector2d a = ring[i], e = ring[i + 1] - ring[i];
    const double length2 = e.squaredNorm();
    if (length2 == 0.0) continue;  // a repeated vertex (a closing point) is no edge
    const double s = std::clamp((p - a).dot(e) / length2, 0.0, 1.0);
    const Eigen::Vector2d q = a + s * e;
    const double d = (p - q).norm();
    if (d < best) {
      best = d;
      c.point_world = q;
      edge_normal = Eigen::Vector2d(e.y(), -e.x()) / std::sqrt(length2);
    }
  }
  const bool inside = Inside(ring, p);
  c.gap_m = inside ? -best : best;
  c.normal_world = best > kOnOutlineM
                       ? Eigen::Vector2d((p - c.point_world) / best * (inside ? -1 : 1))
                       : edge_normal;
  return c;
}

}  // namespace

PusherPath::PusherPath(std::vector<double> times_s, std::vector<Eigen::Vector2d> points_m)
    : times_s_(std::move(times_s)), points_m_(std::move(points_m)) {
  if (times_s_.empty() || times_s_.size() != points_m_.size()) {
    throw std::invalid_argument("pusher path: needs at least one point and one time per point");
  }
  for (size_t i = 0; i < times_s_.size(); ++i) {
    std::ostringstream where;
    where << "pusher path point " << i + 1 << ": ";
    if (!std::isfinite(times_s_[i]) || !points_m_[i].allFinite()) {
      throw std::invalid_argument(where.str() + "time and position must be finite");
    }
    if (i > 0 && !(times_s_[i] > times_s_[i - 1])) {
      where << "t = " << times_s_[i] << " s is not after the previous " << times_s_[i - 1];
      throw std::invalid_argument(where.str());
    }
  }
}

PusherPath PusherPath::Polyline(double start_s, const Eigen::Vector2d& start,
                                const std::vector<Eigen::Vector2d>& points,
                                const std::vector<double>& speeds_mps) {
  if (points.size() != speeds_mps.size()) {
    throw std::invalid_argument("pusher polyline: one speed per segment");
  }
  std::vector<double> times = {start_s};
  std::vector<Eigen::Vector2d> at = {start};
  for (size_t i = 0; i < points.size(); ++i) {
    const double length = (points[i] - at.back()).norm();
    if (!(speeds_mps[i] > 0) || !std::isfinite(speeds_mps[i])) {
      throw std::invalid_argument("pusher polyline: segment " + std::to_string(i + 1) +
                                  ": speed must be > 0 and finite");
    }
    if (!(length > 0)) {
      throw std::invalid_argument("pusher polyline: segment " + std::to_string(i + 1) +
                                  " has zero length");
    }
    times.push_back(times.back() + length / speeds_mps[i]);
    at.push_back(points[i]);
  }
  return PusherPath(times, at);
}

Eigen::Vector2d PusherPath::PositionAt(double t_s) const {
  if (t_s <= times_s_.front()) return points_m_.front();
  if (t_s >= times_s_.back()) return points_m_.back();
  const size_t j = std::upper_bound(times_s_.begin(), times_s_.end(), t_s) - times_s_.begin();
  const double w = (t_s - times_s_[j - 1]) / (times_s_[j] - times_s_[j - 1]);
  return (1 - w) * points_m_[j - 1] + w * points_m_[j];
}

double PusherPath::Length() const {
  double length = 0;
  for (size_t i = 1; i < points_m_.size(); ++i) length += (points_m_[i] - points_m_[i - 1]).norm();
  return length;
}

bool Pusher::IsValid(std::string* why) const {
  auto fail = [why](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (!(std::isfinite(tip_radius_m) && tip_radius_m >= 0)) return fail("tip radius must be >= 0");
  if (!(std::isfinite(mu) && mu >= 0)) return fail("pusher friction mu_p must be >= 0");
  if (height_m && !(std::isfinite(*height_m) && *height_m >= 0)) {
    return fail("pusher contact height must be >= 0");
  }
  return true;
}

TipContact ContactWithTip(const ContactPatch& patch, const PlanarState& pose,
                          const Eigen::Vector2d& tip_centre_world, double tip_radius_m) {
  const Eigen::Vector2d cm(pose.x, pose.y);
  const Eigen::Vector2d p = Rotate(-pose.theta, tip_centre_world - cm);  // body frame
  TipContact body;
  const double radius = patch.OuterRadius();
  if (radius > 0) {
    const double r = p.norm();
    body.normal_world = r > kOnOutlineM ? Eigen::Vector2d(p / r) : Eigen::Vector2d::UnitX();
    body.point_world = radius * body.normal_world;
    body.gap_m = r - radius;
  } else {
    body = PolygonContact(patch.Outline(), p);
  }
  TipContact world;
  world.point_world = cm + Rotate(pose.theta, body.point_world);
  world.normal_world = Rotate(pose.theta, body.normal_world);
  world.gap_m = body.gap_m - tip_radius_m;
  return world;
}

double TravelToTouch(const ContactPatch& patch, const PlanarState& pose,
                     const Eigen::Vector2d& from, const Eigen::Vector2d& direction,
                     double tip_radius_m, double max_m) {
  double travel = 0;
  for (int k = 0; k < kMaxTouchSteps && travel < max_m; ++k) {
    const double gap = ContactWithTip(patch, pose, from + travel * direction, tip_radius_m).gap_m;
    if (gap <= kTouchTolerance_m) return travel;
    travel += gap;
  }
  return std::min(travel, max_m);
}

}  // namespace slideid
