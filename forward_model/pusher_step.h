#pragma once
// One backward-Euler step of a slider driven by a position-controlled round pusher
// (forward_model/pusher.h), inside the same step as the support's ECP friction
// (forward_model/step_solver.h).
//
// At the tip, over the step (impulses, the contact geometry taken at the step's start pose
// and the tip's end position, as time-stepping contact methods do):
//  - the normal impulse lambda_n >= 0 is complementary to the gap at the end of the step,
//    g0 - h u_n >= 0 (u_n: the slider's contact point's velocity towards the tip), so the
//    tip can leave the edge and come back;
//  - the tangential impulse obeys Coulomb's law with mu_p and maximum dissipation: sticking
//    (the contact point moves with the tip, |lambda_t| <= mu_p lambda_n) or sliding along
//    the edge (|lambda_t| = mu_p lambda_n, opposing the slip).
// For a given tip impulse the slider's step is SolveStep's with the impulse's wrench added
// to the applied one, so the support friction keeps all its guarantees. The tip impulse is
// found by an outer solve: apart (no impulse) if the free step leaves a gap; else sticking,
// by Broyden's method on the two velocity conditions started from the rigid-body (frictionless
// support) response; else sliding, a bracketed scalar root of the gap for each slip
// direction. Every answer is checked: its residuals are in the result, and a step that
// does not meet them is a status, not a silently wrong state.

#include <Eigen/Core>
#include <string>

#include "forward_model/contact_patch.h"
#include "forward_model/planar_state.h"
#include "forward_model/pusher.h"
#include "forward_model/slider.h"
#include "forward_model/step_solver.h"

namespace slideid {

struct PusherStepOptions {
  StepOptions step;  ///< for the support's step inside
  /// The tip's two velocity conditions (the gap over h, and the slip when sticking) are met
  /// to this fraction of the step's velocity scale (the tip speed, the slider's speed, the
  /// gap over h and a g h, the largest of them).
  double relative_tolerance = 1e-10;
  int max_iterations = 100;  ///< outer iterations of each solve (Broyden or scalar root)

  bool IsValid(std::string* why) const;
};

enum class TipMode { kApart, kStick, kSlide };

struct PusherStepResult {
  StepResult step;  ///< the slider's step under the tip's impulse (its status is the step's)
  TipMode tip_mode = TipMode::kApart;
  TipContact contact;  ///< at the step's start pose and the tip's end position
  /// The tip's impulse on the slider over the step, world axes [N s], and its normal
  /// (into the slider, >= 0) and tangential (along the normal turned +90 deg) parts.
  Eigen::Vector2d impulse_world = Eigen::Vector2d::Zero();
  double lambda_n = 0, lambda_t = 0;
  /// The applied wrench the step held: the one given plus the tip's impulse over h.
  AppliedWrench applied;
  double gap_end_m = 0;  ///< g0 - h u_n at the solution (>= 0 up to the tolerance)
  double slip_mps = 0;   ///< the contact point's velocity along the edge relative to the tip
  double residual = 0;   ///< the tip's conditions, relative to the velocity scale
  int iterations = 0;    ///< outer iterations, all solves together
  std::string message;   ///< why it failed, empty on success

  bool ok() const { return step.ok(); }
};

/// Advances `state` by dt_s with the tip's centre moving from `tip_start` to `tip_end`
/// (world [m]) against `patch`'s outline, `applied` (any other wrench) held over the step.
/// Throws std::invalid_argument for invalid inputs (as SolveStep, and the pusher's);
/// non-convergence is a status.
PusherStepResult SolvePusherStep(const SliderProperties& slider, const ReducedFriction& friction,
                                 const ContactPatch& patch, const Pusher& pusher,
                                 const PlanarState& state, const Eigen::Vector2d& tip_start,
                                 const Eigen::Vector2d& tip_end, const AppliedWrench& applied,
                                 double dt_s, const PusherStepOptions& options = {});

const char* ToString(TipMode mode);

}  // namespace slideid
