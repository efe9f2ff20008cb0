#pragma once
// Runs a scene through the step solver and records the trajectory in the log data type,
// checking every step's ECP against the patch's convex hull (model.md, "No-toppling check").

#include <Eigen/Core>
#include <string>

#include "forward_model/pusher_step.h"
#include "forward_model/scene.h"
#include "forward_model/step_solver.h"
#include "forward_model/trajectory.h"

namespace slideid {

struct SimulationOptions {
  StepOptions step;
  /// The pusher's contact solve of a pusher-driven scene (its `step` is replaced by the
  /// one above).
  PusherStepOptions pusher;
  /// How far the ECP may sit outside the hull before it counts as toppling [m]. Covers the
  /// rounding of the ECP (~1e-16 m relative); any real excursion is much larger.
  double hull_tolerance_m = 1e-9;

  bool IsValid(std::string* why) const;
};

enum class SimulationStatus {
  kOk,
  kToppling,       ///< the ECP left the hull: the slider would tip
  kNoConvergence,  ///< a step did not converge
  kLiftOff,        ///< the applied vertical force lifted the slider
};

struct SimulationSummary {
  SimulationStatus status = SimulationStatus::kOk;
  std::string message;  ///< names the time and the ECP on failure
  double failure_time_s = 0;
  Eigen::Vector2d failure_ecp_world = Eigen::Vector2d::Zero();
  int steps = 0, slide_steps = 0, stick_steps = 0;
  /// A pusher-driven scene: steps with the tip sticking to the edge, sliding along it.
  int tip_stick_steps = 0, tip_slide_steps = 0;
  /// Largest signed distance of the ECP to the hull boundary over all steps [m]
  /// (negative: always inside, by at least its magnitude).
  double max_hull_signed_distance_m = -1e300;
  double max_step_residual = 0;
  int max_step_iterations = 0;
  /// Time from which the slider stayed at rest to the end, or < 0 if it never did [s].
  double rest_time_s = -1;

  bool ok() const { return status == SimulationStatus::kOk; }
};

struct SimulationResult {
  Trajectory trajectory;  ///< up to and including the failing step, if any
  SimulationSummary summary;
};

/// Simulates `scene` for its duration at its dt. Throws std::invalid_argument for invalid
/// scenes; numerical and physical failures are reported in the summary.
SimulationResult Simulate(const Scene& scene, const SimulationOptions& options = {});

/// The most forward-model steps per log interval the tools and options accept (identify's,
/// predict's and plot-log's --substeps, PredictionOptions): steps far below any time scale of
/// the motion make a run only slower, and a billion substeps a row of a 600-row log would
/// run for days.
constexpr int kMaxSubstepsPerInterval = 1000;

/// Replays a log's pushes with given friction: from the first row's state, steps the forward
/// model over each log interval (`substeps` equal steps) with that row's applied wrench held,
/// the wrench as logged (world frame, so it does not turn with the replayed slider). Rows at
/// the log's times, step columns filled. Initial velocity: the first row's, or, for a log
/// without velocity columns, the second row's backward-Euler velocity (the first row's is
/// unknown). No hull check (the fit, not the slider, is on trial). Throws
/// std::invalid_argument for a log with fewer than 2 rows, substeps < 1 or an invalid
/// friction; a failing step ends the replay with its status in the summary. The friction is
/// a fit's (a, b, c) or the paper's four (a log's truth), as a scene's (SceneFriction): the
/// steps take its (a, b, c), the replay's true_friction and sigma are its paper's (the e_t =
/// 1 form for a fit's).
SimulationResult ReplayLog(const Trajectory& log, const SceneFriction& friction, int substeps = 1,
                           const SimulationOptions& options = {});

/// Where ReplayLog starts (and predictions with it): the first row's state, its velocity for
/// a log without velocity columns the second row's backward difference (the first row's is
/// unknown). The log must have at least 2 rows.
PlanarState ReplayStart(const Trajectory& log);

const char* ToString(SimulationStatus status);

}  // namespace slideid
