#pragma once
// A position-controlled round pusher: its tip's centre follows a path in time, and it
// touches the slider's outline (the contact patch's outer boundary: a flat object pushed at
// its edge). What a planner commands, where the force-driven scene logs what a sensor read.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "forward_model/contact_patch.h"
#include "forward_model/planar_state.h"

namespace slideid {

/// The tip centre's path: positions at strictly increasing times, linear in between, held
/// at the first before it and at the last after it. World frame [s, m].
class PusherPath {
 public:
  /// Throws std::invalid_argument naming the first bad entry: fewer than 1 point, times not
  /// strictly increasing, or a value not finite.
  PusherPath(std::vector<double> times_s, std::vector<Eigen::Vector2d> points_m);
  /// From `start` at time `start_s`, along each segment to points[i] at speeds_mps[i]
  /// (> 0). Throws std::invalid_argument for a bad speed, a zero-length segment or a count
  /// mismatch.
  static PusherPath Polyline(double start_s, const Eigen::Vector2d& start,
                             const std::vector<Eigen::Vector2d>& points,
                             const std::vector<double>& speeds_mps);

  Eigen::Vector2d PositionAt(double t_s) const;
  const std::vector<double>& times_s() const { return times_s_; }
  const std::vector<Eigen::Vector2d>& points_m() const { return points_m_; }
  double end_s() const { return times_s_.back(); }
  /// Length of the path [m].
  double Length() const;

 private:
  std::vector<double> times_s_;
  std::vector<Eigen::Vector2d> points_m_;
};

/// The pusher: its path, tip radius and the Coulomb friction between tip and slider edge.
struct Pusher {
  PusherPath path{{0.0}, {Eigen::Vector2d::Zero()}};
  double tip_radius_m = 0.00475;  ///< the MIT pusher's steel tip (Yu et al. 2016)
  /// Tip-edge friction coefficient mu_p (0: a frictionless tip; the MIT paper gives
  /// about 0.25 for its steel tip on steel objects).
  double mu = 0.25;
  /// Height of the contact above the support plane [m]; absent: at the CM's height, so
  /// the push has no tilting moment.
  std::optional<double> height_m;

  bool IsValid(std::string* why) const;
};

/// Where a round tip is relative to the slider's outline (world frame).
struct TipContact {
  Eigen::Vector2d point_world = Eigen::Vector2d::Zero();    ///< nearest outline point [m]
  Eigen::Vector2d normal_world = Eigen::Vector2d::UnitX();  ///< outward there (slider to tip)
  /// Signed distance from the tip centre to the outline less the tip radius [m]: the gap,
  /// negative when the tip overlaps the slider.
  double gap_m = 0;
};

/// The tip, centred at `tip_centre_world` with radius `tip_radius_m`, against `patch`'s
/// outer boundary with the slider at `pose`. Rectangles and polygons use their edges (a
/// vertex's normal points from the vertex to the tip centre), disks and rings the outer
/// circle exactly.
TipContact ContactWithTip(const ContactPatch& patch, const PlanarState& pose,
                          const Eigen::Vector2d& tip_centre_world, double tip_radius_m);

/// How far the tip's centre travels from `from` along the unit `direction` before the tip
/// touches `patch`'s outline, the slider at `pose` [m]; `max_m` when it does not within
/// that. Steps by the gap itself, which, being a distance, never steps past the outline
/// (sphere tracing), until the gap is below 1e-14 m. `from` must leave the tip apart.
double TravelToTouch(const ContactPatch& patch, const PlanarState& pose,
                     const Eigen::Vector2d& from, const Eigen::Vector2d& direction,
                     double tip_radius_m, double max_m);

}  // namespace slideid
