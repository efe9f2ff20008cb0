#pragma once
// What a simulation needs: the slider, its friction and contact patch, the initial state, the
// pushes, the step and the duration. Scene files are read by io/scene_file.h.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "forward_model/contact_patch.h"
#include "forward_model/planar_state.h"
#include "forward_model/pusher.h"
#include "forward_model/slider.h"

namespace slideid {

/// A push at a body-fixed point along a body-fixed direction, magnitude
/// force + amplitude cos(2 pi t / period) [N], clamped at 0 (a pusher cannot pull),
/// applied during [start, stop).
struct PushSpec {
  Eigen::Vector2d point_body = Eigen::Vector2d::Zero();       ///< [m]
  double height_m = 0.0;                                      ///< z of the push point [m]
  Eigen::Vector2d direction_body = Eigen::Vector2d::UnitX();  ///< unit vector
  double force_n = 0.0;
  double amplitude_n = 0.0;
  double period_s = 0.0;  ///< 0: no periodic part
  double start_s = 0.0;
  double stop_s = 1e300;

  /// Magnitude at time t [N] (0 outside [start, stop)).
  double MagnitudeAt(double t_s) const;
  /// World-frame force and its moment about the CM for the slider at `pose`; writes the
  /// world push point when `point_world` is not null.
  AppliedWrench WrenchAt(double t_s, const PlanarState& pose, double com_height_m,
                         Eigen::Vector3d* point_world = nullptr) const;
};

/// A scene's friction as the simulator takes it: the three combinations the motion depends on
/// (every step's), and the paper's four parameters its logs record as their truth (whose e_t
/// scales the slip sigma they report). Made from the paper's four (a scene file's, a dataset's
/// draws) or from (a, b, c) alone (a fit's, a fixture's), whose four are the e_t = 1 form
/// (ReducedFriction::ToFrictionParameters); either way the other form is made once, here.
class SceneFriction {
 public:
  SceneFriction() : SceneFriction(FrictionParameters{}) {}
  SceneFriction(const FrictionParameters& paper)  // NOLINT(google-explicit-constructor)
      : paper_(paper), reduced_(ReducedFriction::From(paper)) {}
  SceneFriction(const ReducedFriction& reduced)  // NOLINT(google-explicit-constructor)
      : paper_(reduced.ToFrictionParameters()), reduced_(reduced) {}

  /// a, b, c: all a step needs.
  const ReducedFriction& reduced() const { return reduced_; }
  /// mu, e_t, e_o, e_r: the truth a log records.
  const FrictionParameters& paper() const { return paper_; }
  /// Whether mu, e_t, e_o and e_r are finite and > 0; `why` gives them and a, b, c.
  bool IsValid(std::string* why) const;

 private:
  FrictionParameters paper_;
  ReducedFriction reduced_;
};

/// Everything a simulation needs (physics only: how a log samples it is datasets' LogSpec).
struct Scene {
  std::string source;  ///< where it came from (a file, a generator), for messages
  SliderProperties slider;
  SceneFriction friction;
  ContactPatch patch = ContactPatch::Rectangle(0.05, 0.05);
  PlanarState initial;
  /// Empty: free sliding. A scene file gives them in [push], [push.1], ... or draws them
  /// from a [program] section (io/scene_file.h).
  std::vector<PushSpec> pushes;
  /// A position-controlled pusher instead of the force pushes (a scene has one or the
  /// other): its tip follows its path and the step solves its contact (pusher_step.h).
  std::optional<Pusher> pusher;
  double dt_s = 0.01;       ///< simulation step [s]
  double duration_s = 1.0;  ///< simulated time [s]
};

}  // namespace slideid
