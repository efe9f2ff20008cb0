#include "prediction/predict.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <tuple>

#include "estimator/pusher_friction.h"
#include "estimator/robust_statistics.h"
#include "forward_model/contact_patch.h"

namespace slideid {
namespace {

// Travel below this [m] is no travel: the per-100-mm errors and the fraction of the
// displacement are left at 0 rather than divided by it.
constexpr double kNoTravelM = 1e-9;
// Rows push when their force exceeds this fraction of the log's typical push
// (estimator/pusher_friction.h): the tip registration reads the contact gap there.
constexpr double kPushingFraction = 0.1;

std::string Named(const Trajectory& log) { return log.source.empty() ? "the log" : log.source; }

/// The pusher the log describes: its tip's path, radius and mu_p.
Pusher LoggedPusher(const Trajectory& log, double mu_pusher) {
  const bool every_row =
      std::all_of(log.samples.begin(), log.samples.end(),
                  [](const TrajectorySample& s) { return s.tip_world.has_value(); });
  if (!log.measured.tip || !every_row) {
    throw std::invalid_argument(Named(log) +
                                ": the pusher drive needs the tip's path (columns "
                                "tip_x, tip_y); use the force drive, or add them");
  }
  if (!log.tip_radius_m) {
    throw std::invalid_argument(Named(log) +
                                ": the pusher drive needs the tip's radius "
                                "(metadata '# tip_radius = ...' [m])");
  }
  if (!log.patch) {
    throw std::invalid_argument(Named(log) +
                                ": the pusher drive needs the outline the tip "
                                "touches (metadata '# patch = ...')");
  }
  std::vector<double> times;
  std::vector<Eigen::Vector2d> points;
  for (const TrajectorySample& s : log.samples) {
    times.push_back(s.t_s);
    points.push_back(*s.tip_world);
  }
  Pusher pusher;
  pusher.path = PusherPath(times, points);
  pusher.tip_radius_m = *log.tip_radius_m;
  pusher.mu = mu_pusher;
  return pusher;
}

/// The tip radius at which the tip touches the outline, on the median, where the log
/// pushes (force above kPushingFraction of its 90th percentile); the logged one when no
/// row pushes.
double RegisteredRadius(const Trajectory& log, const ContactPatch& patch) {
  const double pushing = kPushingFraction * TypicalPush({&log});
  std::vector<double> gaps;
  for (const TrajectorySample& s : log.samples) {
    if (std::hypot(s.applied.fx, s.applied.fy) <= pushing) continue;
    gaps.push_back(ContactWithTip(patch, s.state, *s.tip_world, *log.tip_radius_m).gap_m);
  }
  if (gaps.empty()) return *log.tip_radius_m;  // no force: nothing to register to
  return std::max(0.0, *log.tip_radius_m + Median(gaps));
}

/// Steps over log interval u: `substeps` per median interval in it, so that a long one (a
/// gap in the record) is stepped at the log's usual rate; the tip's path goes on across it,
/// and one step of its length would not follow the contact.
int StepsOver(const Trajectory& log, size_t u, double median, int substeps) {
  const double span = log.samples[u + 1].t_s - log.samples[u].t_s;
  return substeps * std::max(1, static_cast<int>(std::ceil(span / median - 1e-9)));
}

/// A predicted trajectory of `log`, its first row at `start`: the log's slider, outline
/// and tip, with the pose, the velocity and the tip's path (each replay adds its own).
Trajectory PredictionShell(const Trajectory& log, const PlanarState& start) {
  Trajectory out;
  out.source = log.source;
  out.slider = log.slider;
  out.patch = log.patch;
  out.tip_radius_m = log.tip_radius_m;
  out.measured = Measurements{};
  out.measured.force = out.measured.step_info = false;
  out.measured.tip = true;
  TrajectorySample row;
  row.t_s = log.samples[0].t_s;
  row.state = start;
  row.mode = SampleMode::kStart;
  row.tip_world = log.samples[0].tip_world;
  out.samples.push_back(row);
  return out;
}

void Count(const PusherStepResult& r, SimulationSummary* summary) {
  ++summary->steps;
  (r.step.mode == StepMode::kStick ? summary->stick_steps : summary->slide_steps)++;
  summary->tip_stick_steps += r.tip_mode == TipMode::kStick;
  summary->tip_slide_steps += r.tip_mode == TipMode::kSlide;
  summary->max_step_residual = std::max(summary->max_step_residual, r.residual);
  summary->max_step_iterations = std::max(summary->max_step_iterations, r.iterations);
}

/// The log replayed by its pusher: each interval in `substeps` steps, rows at its times.
SimulationResult ReplayPusher(const Trajectory& log, const ReducedFriction& friction,
                              const Pusher& pusher, const PredictionOptions& options) {
  const ContactPatch& patch = *log.patch;
  SimulationResult result;
  Trajectory& out = result.trajectory;
  out = PredictionShell(log, ReplayStart(log));
  out.true_friction = friction.ToFrictionParameters();
  out.measured.force = out.measured.push_point = true;
  const double median = MedianInterval(log);
  for (size_t u = 0; u + 1 < log.samples.size(); ++u) {
    const double t0 = log.samples[u].t_s;
    const int steps = StepsOver(log, u, median, options.substeps);
    const double h = (log.samples[u + 1].t_s - t0) / steps;
    PlanarState state = out.samples.back().state;
    Eigen::Vector2d impulse = Eigen::Vector2d::Zero();
    PusherStepResult r;
    for (int k = 0; k < steps; ++k) {
      const double t = t0 + k * h;
      r = SolvePusherStep(log.slider, friction, patch, pusher, state, pusher.path.PositionAt(t),
                          pusher.path.PositionAt(t + h), AppliedWrench{}, h, options.step);
      if (!r.ok()) {
        result.summary.status = SimulationStatus::kNoConvergence;
        result.summary.failure_time_s = t;
        result.summary.message = "t = " + std::to_string(t) + " s: " + r.message;
        return result;
      }
      Count(r, &result.summary);
      impulse += r.impulse_world;
      state = r.step.state;
      if (k == 0 && r.tip_mode != TipMode::kApart) {
        out.samples.back().push_point_world = Eigen::Vector3d(
            r.contact.point_world.x(), r.contact.point_world.y(), log.slider.com_height_m);
      }
    }
    // The row's force: the interval's mean, at the first step's contact (as a log holds it).
    TrajectorySample& held = out.samples.back();
    const Eigen::Vector2d force = impulse / (log.samples[u + 1].t_s - t0);
    if (held.push_point_world) {
      const Eigen::Vector3d arm =
          *held.push_point_world -
          Eigen::Vector3d(held.state.x, held.state.y, log.slider.com_height_m);
      held.applied = WrenchFromForceAt(force.x(), force.y(), 0.0, arm.x(), arm.y(), arm.z());
    }
    TrajectorySample next;
    next.t_s = log.samples[u + 1].t_s;
    next.state = state;
    next.mode = r.step.mode == StepMode::kStick ? SampleMode::kStick : SampleMode::kSlide;
    next.tip_world = log.samples[u + 1].tip_world;
    out.samples.push_back(next);
  }
  return result;
}

/// One quasi-static step: the slider's twist (world frame, about the CM) when the tip moves
/// at `tip_velocity` to its end position, where it meets the slider at `contact` (at the
/// slider's pose now): the overlap there is what the slider must move out of.
/// The twist lies along the limit surface's normal at the tip's wrench, A J^T f with
/// A = diag(1, 1/b^2, 1/c^2) (the ellipsoid of model.md, world axes, a scaled out); the
/// contact point moves with the tip (sticking) when that needs a force inside the friction
/// cone, else along the cone's edge with the tip's normal speed. A tip that does not reach
/// the slider leaves it still: without inertia nothing else moves it.
Eigen::Vector3d QuasiStaticTwist(const ReducedFriction& f, const TipContact& contact,
                                 const PlanarState& pose, const Eigen::Vector2d& tip_velocity,
                                 double mu_pusher, double h) {
  const Eigen::Vector2d n_in = -contact.normal_world, t(-n_in.y(), n_in.x());
  // The contact is taken with the tip at the step's end: the slider's contact point must
  // move out of the overlap over the step, and the tip's own motion is already in it.
  if (!(contact.gap_m < 0)) return Eigen::Vector3d::Zero();
  const double normal_speed = -contact.gap_m / h;
  const Eigen::Vector2d r = contact.point_world - Eigen::Vector2d(pose.x, pose.y);
  Eigen::Matrix<double, 2, 3> J;
  J << 1, 0, -r.y(), 0, 1, r.x();
  const Eigen::Vector3d A(1.0, 1.0 / (f.b * f.b), 1.0 / (f.c * f.c));
  const Eigen::Matrix2d M = J * A.asDiagonal() * J.transpose();  // positive definite
  const Eigen::Vector2d stick = normal_speed * n_in + tip_velocity.dot(t) * t;
  const Eigen::Vector2d force = M.ldlt().solve(stick);
  if (std::abs(force.dot(t)) <= mu_pusher * force.dot(n_in)) {
    return A.asDiagonal() * (J.transpose() * force);
  }
  const double side = force.dot(t) > 0 ? 1.0 : -1.0;
  const Eigen::Vector2d edge = n_in + side * mu_pusher * t;
  const Eigen::Vector3d twist = A.asDiagonal() * (J.transpose() * edge);
  const double rate = n_in.dot(J * twist);  // > 0: M is positive definite, edge . n_in = 1
  return twist * (normal_speed / rate);
}

/// The log replayed by its pusher through the quasi-static model, stepped as ReplayPusher.
SimulationResult ReplayQuasiStatic(const Trajectory& log, const ReducedFriction& friction,
                                   const Pusher& pusher, const PredictionOptions& options) {
  const ContactPatch& patch = *log.patch;
  SimulationResult result;
  Trajectory& out = result.trajectory;
  PlanarState start = log.samples[0].state;
  start.vx = start.vy = start.wz = 0;  // without inertia, no motion but the tip's
  out = PredictionShell(log, start);
  const double median = MedianInterval(log);
  for (size_t u = 0; u + 1 < log.samples.size(); ++u) {
    const double t0 = log.samples[u].t_s;
    const int steps = StepsOver(log, u, median, options.substeps);
    const double h = (log.samples[u + 1].t_s - t0) / steps;
    PlanarState q = out.samples.back().state;
    for (int k = 0; k < steps; ++k) {
      const double t = t0 + k * h;
      const Eigen::Vector2d from = pusher.path.PositionAt(t), to = pusher.path.PositionAt(t + h);
      const TipContact contact = ContactWithTip(patch, q, to, pusher.tip_radius_m);
      const Eigen::Vector3d v =
          QuasiStaticTwist(friction, contact, q, (to - from) / h, pusher.mu, h);
      q.x += h * v.x();
      q.y += h * v.y();
      q.theta += h * v.z();
      q.vx = v.x();
      q.vy = v.y();
      q.wz = v.z();
      ++result.summary.steps;
    }
    TrajectorySample next;
    next.t_s = log.samples[u + 1].t_s;
    next.state = q;
    next.mode = SampleMode::kSlide;
    next.tip_world = log.samples[u + 1].tip_world;
    out.samples.push_back(next);
  }
  return result;
}

bool AnyForce(const Trajectory& log) {
  return std::any_of(log.samples.begin(), log.samples.end(), [](const TrajectorySample& s) {
    return s.applied.fx != 0 || s.applied.fy != 0 || s.applied.tz != 0;
  });
}

/// The travel of the pusher over the first `rows` rows, and what it is the travel of.
std::pair<double, std::string> Travel(const Trajectory& log, size_t rows) {
  auto path_length = [&](auto point) {
    double length = 0;
    for (size_t u = 1; u < rows; ++u) {
      const auto a = point(log.samples[u - 1]), b = point(log.samples[u]);
      if (a && b) length += (*b - *a).norm();
    }
    return length;
  };
  if (log.measured.tip) {
    return {path_length([](const TrajectorySample& s) { return s.tip_world; }), "tip"};
  }
  if (log.measured.push_point) {
    return {path_length([](const TrajectorySample& s) -> std::optional<Eigen::Vector2d> {
              if (!s.push_point_world) return std::nullopt;
              return s.push_point_world->head<2>().eval();
            }),
            "push point"};
  }
  return {path_length([](const TrajectorySample& s) -> std::optional<Eigen::Vector2d> {
            return Eigen::Vector2d(s.state.x, s.state.y);
          }),
          "object"};
}

}  // namespace

double RegisteredTipRadius(const Trajectory& log) {
  LoggedPusher(log, 0.0);  // throws, naming what is missing
  return RegisteredRadius(log, *log.patch);
}

bool PredictionOptions::IsValid(std::string* why) const {
  auto fail = [why](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (substeps < 1 || substeps > kMaxSubstepsPerInterval) {
    return fail("substeps must be 1 to " + std::to_string(kMaxSubstepsPerInterval));
  }
  if (!(part_position_m > 0) || !(part_rotation_rad > 0)) {
    return fail("the parting thresholds must be > 0");
  }
  return step.IsValid(why);
}

PredictionErrors CompareWithLog(const Trajectory& log, const Trajectory& predicted,
                                const PredictionOptions& options) {
  PredictionErrors e;
  const size_t rows = std::min(log.samples.size(), predicted.samples.size());
  if (rows == 0) return e;
  for (size_t u = 0; u < rows; ++u) {
    const PlanarState &p = predicted.samples[u].state, &q = log.samples[u].state;
    const double position = std::hypot(p.x - q.x, p.y - q.y);
    const double rotation = std::abs(p.theta - q.theta);
    e.mean_position_m += position / rows;
    e.mean_rotation_rad += rotation / rows;
    if (!e.parting_time_s &&
        (position > options.part_position_m || rotation > options.part_rotation_rad)) {
      e.parting_time_s = log.samples[u].t_s - log.samples[0].t_s;
    }
    e.final_position_m = position;
    e.final_rotation_rad = rotation;
  }
  std::tie(e.travel_m, e.travel_of) = Travel(log, rows);
  if (e.travel_m > kNoTravelM) {
    e.final_position_per_100mm_m = e.final_position_m * 0.1 / e.travel_m;
    e.final_rotation_per_100mm_rad = e.final_rotation_rad * 0.1 / e.travel_m;
  }
  const PlanarState &first = log.samples.front().state, &last = log.samples[rows - 1].state;
  e.logged_displacement_m = std::hypot(last.x - first.x, last.y - first.y);
  if (e.logged_displacement_m > kNoTravelM) {
    e.final_position_fraction = e.final_position_m / e.logged_displacement_m;
  }
  return e;
}

Prediction PredictPush(const Trajectory& log, const ReducedFriction& friction,
                       std::optional<double> mu_pusher, const PredictionOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("prediction options: " + why);
  if (log.samples.size() < 2) {
    throw std::invalid_argument(Named(log) + ": a prediction needs at least 2 rows");
  }
  Prediction p;
  p.drive = options.drive;
  if (options.drive != PredictionDrive::kForce) {
    if (!mu_pusher) {
      throw std::invalid_argument(
          "the pusher drive needs the tip-edge friction mu_p (a fit's "
          "mu_pusher, or --mu-pusher)");
    }
    p.mu_pusher = *mu_pusher;
    Pusher pusher = LoggedPusher(log, *mu_pusher);
    if (options.register_tip) {
      pusher.tip_radius_m = RegisteredRadius(log, *log.patch);
    }
    p.tip_radius_m = pusher.tip_radius_m;
    const SimulationResult r = options.drive == PredictionDrive::kPusher
                                   ? ReplayPusher(log, friction, pusher, options)
                                   : ReplayQuasiStatic(log, friction, pusher, options);
    p.predicted = r.trajectory;
    p.summary = r.summary;
  } else {
    if (!AnyForce(log)) {
      throw std::invalid_argument(Named(log) +
                                  ": the force drive needs logged forces (fx, fy); "
                                  "this log has none");
    }
    SimulationOptions sim;
    sim.step = options.step.step;
    const SimulationResult r = ReplayLog(log, friction, options.substeps, sim);
    p.predicted = r.trajectory;
    p.summary = r.summary;
  }
  p.predicted.source = log.source;
  p.errors = CompareWithLog(log, p.predicted, options);
  return p;
}

const char* ToString(PredictionDrive drive) {
  switch (drive) {
    case PredictionDrive::kPusher:
      return "pusher";
    case PredictionDrive::kForce:
      return "force";
    case PredictionDrive::kQuasiStatic:
      return "quasi-static";
  }
  return "?";
}

bool ParsePredictionDrive(const std::string& text, PredictionDrive* drive) {
  if (text == "pusher")
    *drive = PredictionDrive::kPusher;
  else if (text == "force")
    *drive = PredictionDrive::kForce;
  else if (text == "quasi-static")
    *drive = PredictionDrive::kQuasiStatic;
  else
    return false;
  return true;
}

}  // namespace slideid
