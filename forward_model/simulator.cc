#include "forward_model/simulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "forward_model/number_format.h"

namespace slideid {
namespace {

StepRecord RecordOf(const StepResult& step) {
  return {step.pt, step.po, step.pr, step.sigma, step.ecp_world};
}

// Most steps one simulation keeps in memory.
constexpr double kMaxSimulationSteps = 2e7;

// Wrench of every push active at t, and the point of the push when exactly one is active
// (a log row has one push point; several simultaneous pushes go in as moments).
AppliedWrench PushWrench(const Scene& scene, double t, const PlanarState& pose,
                         std::optional<Eigen::Vector3d>* point) {
  AppliedWrench total;
  int active = 0;
  point->reset();
  for (const PushSpec& push : scene.pushes) {
    if (push.MagnitudeAt(t) <= 0.0) continue;
    Eigen::Vector3d where;
    const AppliedWrench w = push.WrenchAt(t, pose, scene.slider.com_height_m, &where);
    total.fx += w.fx;
    total.fy += w.fy;
    total.fz += w.fz;
    total.tx += w.tx;
    total.ty += w.ty;
    total.tz += w.tz;
    if (++active == 1) *point = where;
  }
  if (active > 1) point->reset();
  return total;
}

Trajectory EmptyTrajectory(const Scene& scene) {
  Trajectory traj;
  traj.slider = scene.slider;
  traj.patch = scene.patch;
  traj.true_friction = scene.friction.paper();
  const bool pushed = !scene.pushes.empty() || scene.pusher.has_value();
  traj.measured.push_point = pushed;
  traj.measured.force = pushed;
  if (scene.pusher) {
    traj.measured.tip = true;
    traj.tip_radius_m = scene.pusher->tip_radius_m;
  }
  return traj;
}

void Fail(SimulationSummary* summary, SimulationStatus status, double t,
          const std::string& message) {
  summary->status = status;
  summary->failure_time_s = t;
  summary->message = Printf("t = %.6g s: ", t) + message;
}

/// One step of a pusher-driven scene from `row`, whose applied wrench and push point
/// become the tip's (held over the step, as a log row's force is); sigma is the reduced
/// step's.
StepResult PusherStep(const Scene& scene, const SimulationOptions& options, TrajectorySample* row,
                      double t_next, TipMode* tip_mode) {
  const Pusher& pusher = *scene.pusher;
  PusherStepOptions pusher_options = options.pusher;
  pusher_options.step = options.step;
  const PusherStepResult r =
      SolvePusherStep(scene.slider, scene.friction.reduced(), scene.patch, pusher, row->state,
                      pusher.path.PositionAt(row->t_s), pusher.path.PositionAt(t_next),
                      AppliedWrench{}, scene.dt_s, pusher_options);
  row->applied = r.applied;
  row->push_point_world.reset();
  if (r.tip_mode != TipMode::kApart) {
    row->push_point_world = Eigen::Vector3d(r.contact.point_world.x(), r.contact.point_world.y(),
                                            pusher.height_m.value_or(scene.slider.com_height_m));
  }
  *tip_mode = r.tip_mode;
  StepResult step = r.step;
  step.residual = std::max(step.residual, r.residual);  // the summary's worst: either solve's
  return step;
}

}  // namespace

bool SimulationOptions::IsValid(std::string* why) const {
  if (!(hull_tolerance_m >= 0)) {
    if (why) *why = "hull_tolerance_m must be >= 0";
    return false;
  }
  PusherStepOptions p = pusher;
  p.step = step;
  return p.IsValid(why);
}

SimulationResult Simulate(const Scene& scene, const SimulationOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("Simulate: " + why);
  if (!(scene.dt_s > 0) || !(scene.duration_s > 0)) {
    throw std::invalid_argument("Simulate: dt and duration must be > 0");
  }
  if (!scene.friction.IsValid(&why)) throw std::invalid_argument("Simulate: " + why);
  if (scene.pusher) {
    if (!scene.pushes.empty()) {
      throw std::invalid_argument(
          "Simulate: a scene is driven by force pushes or by a pusher, "
          "not both");
    }
    if (!scene.pusher->IsValid(&why)) throw std::invalid_argument("Simulate: " + why);
  }
  // The trajectory is kept in memory (~200 bytes a step): beyond this it would not fit.
  const double requested = scene.duration_s / scene.dt_s;
  if (!(requested <= kMaxSimulationSteps)) {
    throw std::invalid_argument(
        Printf("Simulate: duration / dt = %.3g / %.3g = %.3g steps; at most %.0e (about 4 GB "
               "of trajectory): use a larger dt or a shorter duration",
               scene.duration_s, scene.dt_s, requested, kMaxSimulationSteps));
  }
  SimulationResult result;
  Trajectory& traj = result.trajectory;
  SimulationSummary& summary = result.summary;
  traj = EmptyTrajectory(scene);

  const long steps = std::lround(scene.duration_s / scene.dt_s);
  TrajectorySample sample;
  sample.t_s = 0.0;
  sample.state = scene.initial;
  sample.mode = SampleMode::kStart;
  sample.applied = PushWrench(scene, 0.0, sample.state, &sample.push_point_world);
  if (scene.pusher) sample.tip_world = scene.pusher->path.PositionAt(0.0);
  traj.samples.reserve(steps + 1);
  traj.steps.reserve(steps + 1);
  traj.samples.push_back(sample);
  traj.steps.emplace_back();

  for (long u = 0; u < steps; ++u) {
    TrajectorySample& prev = traj.samples.back();
    const double t_next = (u + 1) * scene.dt_s;
    TipMode tip_mode = TipMode::kApart;
    StepResult step = scene.pusher ? PusherStep(scene, options, &prev, t_next, &tip_mode)
                                   : SolveStep(scene.slider, scene.friction.reduced(), prev.state,
                                               prev.applied, scene.dt_s, options.step);
    step.sigma *= scene.friction.paper().e_t;  // the paper's: the reduced step's is sigma / e_t
    if (!step.ok()) {
      Fail(&summary,
           step.status == StepStatus::kLiftOff ? SimulationStatus::kLiftOff
                                               : SimulationStatus::kNoConvergence,
           prev.t_s, step.message);
      return result;
    }
    TrajectorySample next;
    next.t_s = t_next;
    next.state = step.state;
    next.mode = step.mode == StepMode::kStick ? SampleMode::kStick : SampleMode::kSlide;
    next.applied = PushWrench(scene, t_next, next.state, &next.push_point_world);
    if (scene.pusher) next.tip_world = scene.pusher->path.PositionAt(t_next);
    traj.samples.push_back(next);
    traj.steps.push_back(RecordOf(step));

    ++summary.steps;
    summary.tip_stick_steps += tip_mode == TipMode::kStick;
    summary.tip_slide_steps += tip_mode == TipMode::kSlide;
    (step.mode == StepMode::kStick ? summary.stick_steps : summary.slide_steps)++;
    if (step.mode == StepMode::kStick) {
      if (summary.rest_time_s < 0) summary.rest_time_s = t_next;
    } else {
      summary.rest_time_s = -1;
    }
    summary.max_step_residual = std::max(summary.max_step_residual, step.residual);
    summary.max_step_iterations = std::max(summary.max_step_iterations, step.iterations);
    const double distance = scene.patch.SignedDistanceToHull(step.EcpBody());
    summary.max_hull_signed_distance_m = std::max(summary.max_hull_signed_distance_m, distance);
    if (distance > options.hull_tolerance_m) {
      summary.failure_ecp_world = step.ecp_world;
      Fail(&summary, SimulationStatus::kToppling, t_next,
           Printf("ECP (%.6g, %.6g) m world, (%.6g, %.6g) m body, left the patch hull: the "
                  "slider would tip",
                  step.ecp_world.x(), step.ecp_world.y(), step.EcpBody().x(), step.EcpBody().y()));
      return result;
    }
  }
  return result;
}

PlanarState ReplayStart(const Trajectory& log) {
  PlanarState s = log.samples[0].state;
  if (log.measured.velocity) return s;
  const PlanarState& b = log.samples[1].state;
  const double dt = log.samples[1].t_s - log.samples[0].t_s;
  s.vx = (b.x - s.x) / dt;
  s.vy = (b.y - s.y) / dt;
  s.wz = (b.theta - s.theta) / dt;
  return s;
}

SimulationResult ReplayLog(const Trajectory& log, const SceneFriction& friction, int substeps,
                           const SimulationOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("ReplayLog: " + why);
  if (!friction.IsValid(&why)) throw std::invalid_argument("ReplayLog: " + why);
  if (log.samples.size() < 2) throw std::invalid_argument("ReplayLog: the log has < 2 rows");
  if (substeps < 1) throw std::invalid_argument("ReplayLog: substeps must be >= 1");
  SimulationResult result;
  Trajectory& traj = result.trajectory;
  traj.slider = log.slider;
  traj.patch = log.patch;
  traj.true_friction = friction.paper();
  traj.measured = log.measured;
  traj.measured.pose = traj.measured.velocity = traj.measured.step_info = true;
  TrajectorySample first = log.samples.front();
  first.state = ReplayStart(log);
  first.mode = SampleMode::kStart;
  traj.samples.push_back(first);
  traj.steps.push_back(StepAt(log, 0));
  for (size_t u = 0; u + 1 < log.samples.size(); ++u) {
    const double h = (log.samples[u + 1].t_s - log.samples[u].t_s) / substeps;
    TrajectorySample next = log.samples[u + 1];
    StepRecord record;  // the substeps' impulses summed, the last one's sigma and ECP
    PlanarState state = traj.samples.back().state;
    for (int k = 0; k < substeps; ++k) {
      const StepResult step =
          SolveStep(log.slider, friction.reduced(), state, log.samples[u].applied, h, options.step);
      if (!step.ok()) {
        Fail(&result.summary,
             step.status == StepStatus::kLiftOff ? SimulationStatus::kLiftOff
                                                 : SimulationStatus::kNoConvergence,
             log.samples[u].t_s + k * h, step.message);
        return result;
      }
      state = step.state;
      record.pt += step.pt;
      record.po += step.po;
      record.pr += step.pr;
      record.sigma = step.sigma * friction.paper().e_t;  // the paper's, as Simulate's
      record.ecp_world = step.ecp_world;
      next.mode = step.mode == StepMode::kStick ? SampleMode::kStick : SampleMode::kSlide;
      ++result.summary.steps;
      (step.mode == StepMode::kStick ? result.summary.stick_steps : result.summary.slide_steps)++;
    }
    next.state = state;
    traj.samples.push_back(next);
    traj.steps.push_back(record);
  }
  return result;
}

const char* ToString(SimulationStatus status) {
  switch (status) {
    case SimulationStatus::kOk:
      return "ok";
    case SimulationStatus::kToppling:
      return "toppling";
    case SimulationStatus::kNoConvergence:
      return "no convergence";
    case SimulationStatus::kLiftOff:
      return "lift-off";
  }
  return "?";
}

}  // namespace slideid
