#pragma once
// The pushes advise-push chooses from (estimator/push_advice.h): a round tip, position
// controlled, coming in from just outside the slider (at rest at the origin, heading 0, so
// body and world axes agree) and pushing along a straight line. Each candidate is a contact
// point on the outline, a direction within the tip's friction cone there, and a length:
// the pushes a robot with a point pusher can make, and the shape of make-dataset's random
// pusher pushes (datasets/dataset.h, PusherDraw) so that the two compare like for like.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "forward_model/contact_patch.h"
#include "forward_model/scene.h"
#include "forward_model/slider.h"

namespace slideid {

/// One straight push by a round tip.
struct PushCandidate {
  /// Where on the outline the tip is aimed: the fraction of the outline's length from its
  /// first vertex, counter-clockwise, in [0, 1).
  double outline_fraction = 0;
  Eigen::Vector2d contact_body = Eigen::Vector2d::Zero();  ///< that point [m]
  /// The tip's direction of travel, a unit vector (body = world at the start).
  Eigen::Vector2d direction_body = Eigen::Vector2d::UnitX();
  /// The direction's angle from the inward normal there, counter-clockwise [rad]; within
  /// the friction cone, |angle| < atan(mu_p), the tip does not slip when it first touches.
  double angle_from_normal_rad = 0;
  double length_m = 0.05;  ///< tip travel after it touches [m]
};

/// How the candidates are laid out, and how each is pushed.
struct PushCandidateOptions {
  /// Contact points, equally spaced along the outline's length (>= 1).
  int contact_points = 16;
  /// Directions at each point, as fractions of the friction cone's half-angle atan(mu_p):
  /// 0 along the inward normal; each in [-1, 1]. 0.8 rather than 1: at the cone's edge the
  /// first touch is on the verge of slipping, which a small error in mu_p tips over.
  std::vector<double> cone_fractions{-0.8, -0.4, 0.0, 0.4, 0.8};
  /// Tip travel after touching [m] (each > 0): make-dataset's pusher range is 0.03-0.08.
  std::vector<double> lengths_m{0.03, 0.055, 0.08};
  /// Tip-edge friction mu_p that bounds the cone (>= 0): the result's estimate when it has
  /// one; else 0.25, the MIT steel tip on its objects (Yu et al. 2016; Pusher's default).
  double mu_pusher = 0.25;
  double tip_speed_mps = 0.05;    ///< > 0; the middle of make-dataset's 0.02-0.1 m/s
  double tip_radius_m = 0.00475;  ///< >= 0; the MIT pusher's
  /// The tip starts this far (along its path) before it would touch [m] (> 0), as
  /// make-dataset's pusher starts 5 mm clear of the slider.
  double clearance_m = 0.005;
  /// Simulated after the tip stops, for the slider to come to rest [s] (>= 0; 0.2, as
  /// make-dataset's pusher logs).
  double run_out_s = 0.2;

  bool IsValid(std::string* why) const;
};

/// Every candidate of `options` on `patch`'s outline: contact points x cone fractions x
/// lengths, in that nesting order. Throws std::invalid_argument for invalid options.
std::vector<PushCandidate> CandidatePushes(const ContactPatch& patch,
                                           const PushCandidateOptions& options);

/// The scene of `push` (the slider at rest at the origin, heading 0, `friction`), simulated
/// at `dt_s` until `run_out_s` after the tip stops. Throws std::invalid_argument for invalid
/// options or a dt_s <= 0.
Scene PushScene(const SliderProperties& slider, const ReducedFriction& friction,
                const ContactPatch& patch, const PushCandidate& push,
                const PushCandidateOptions& options, double dt_s);

/// A one-line description: "outline 0.375 (0.045, 0.012) m, 10 deg from the normal, 55 mm".
std::string Describe(const PushCandidate& push);

}  // namespace slideid
