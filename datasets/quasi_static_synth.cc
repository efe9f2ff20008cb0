#include "datasets/quasi_static_synth.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace slideid {
namespace {

/// A force sample is due at the first step whose start u dt reaches its time k / rate; this
/// absorbs the rounding of u dt (~1e-16 s relative), far below a step.
constexpr double kSampleTimeSlack_s = 1e-12;
/// After the tip stops, the slider is followed until it rests, for at most this long [s]:
/// a stiff finger relaxes within milliseconds.
constexpr double kMaxSettle_s = 0.5;
/// Edges are touched in their middle 70%: corners make the contact point ambiguous.
constexpr double kEdgeMargin = 0.15;

Eigen::Matrix2d Rotation(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

/// State of the finger's point on the slider.
struct ContactKinematics {
  Eigen::Vector2d arm;       ///< from the CM, world [m]
  Eigen::Vector2d point;     ///< world [m]
  Eigen::Vector2d velocity;  ///< world [m/s]
};

ContactKinematics Contact(const PlanarState& q, const Eigen::Vector2d& contact_body) {
  ContactKinematics c;
  c.arm = Rotation(q.theta) * contact_body;
  c.point = Eigen::Vector2d(q.x, q.y) + c.arm;
  c.velocity = Eigen::Vector2d(q.vx - q.wz * c.arm.y(), q.vy + q.wz * c.arm.x());
  return c;
}

/// Running sums of the sliding steps for the pair.
struct SlideSums {
  Eigen::Vector2d force_body = Eigen::Vector2d::Zero();
  Eigen::Vector2d force_world = Eigen::Vector2d::Zero();
  double moment = 0, peak = 0;
  int steps = 0;
};

/// The pushes' pairs from the sliding steps' sums (SimulatedPush::row and world_row).
void FillRows(const SlideSums& sums, double dt, const Eigen::Vector2d& contact_body,
              SimulatedPush& out) {
  const PlanarState &start = out.start, &end = out.end;
  const double duration = sums.steps * dt;
  const Eigen::Vector2d moved(end.x - start.x, end.y - start.y);  // world
  const Eigen::Vector2d d = Rotation(-start.theta) * moved;
  const double dtheta = end.theta - start.theta;
  const Eigen::Vector3d twist = BodyTwistFromPoseChange(d, dtheta) / duration;
  const Eigen::Vector2d f_body = sums.force_body / sums.steps;
  const double moment = sums.moment / sums.steps;
  WrenchTwistRow& row = out.row;
  row.pair = {f_body.x(), f_body.y(), 0.0, moment, twist.x(), twist.y(), twist.z()};
  row.duration_s = duration;
  row.dx_m = d.x();
  row.dy_m = d.y();
  row.dtheta_rad = dtheta;
  row.contact_x_m = contact_body.x();
  row.contact_y_m = contact_body.y();
  row.peak_force_n = sums.peak;
  row.samples = sums.steps;
  const Eigen::Vector2d f_world = sums.force_world / sums.steps;
  const Eigen::Vector2d v_world = moved / duration;
  out.world_row.pair = {f_world.x(), f_world.y(),      0.0, moment, v_world.x(),
                        v_world.y(), dtheta / duration};
  out.world_row.duration_s = duration;
  out.world_row.peak_force_n = sums.peak;
  out.world_row.samples = sums.steps;
}

}  // namespace

bool SpringPushOptions::IsValid(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(std::isfinite(stiffness_npm) && stiffness_npm > 0.0)) return fail("stiffness must be > 0");
  if (!std::isfinite(damping_nspm)) return fail("damping must be finite");
  if (!(std::isfinite(dt_s) && dt_s > 0.0)) return fail("dt must be > 0");
  if (!(force_rate_hz > 0.0 && robot_rate_hz > 0.0)) return fail("sample rates must be > 0");
  return step.IsValid(why);
}

SimulatedPush SimulateSpringPush(const SliderProperties& slider_in, const ReducedFriction& friction,
                                 const PlanarState& start, const SpringPush& push,
                                 const SpringPushOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("SimulateSpringPush: " + why);
  if (!(push.speed_mps > 0.0 && push.rest_s >= 0.0 && push.push_s > 0.0) ||
      !(push.direction_body.norm() > 0.0)) {
    throw std::invalid_argument(
        "SimulateSpringPush: speed and push time must be > 0, rest >= 0, "
        "and the direction non-zero");
  }
  SliderProperties slider = slider_in;
  slider.com_height_m = 0.0;  // the ECP stays under the CM (no tilting moments)
  const double k = options.stiffness_npm;
  const double damping =
      options.damping_nspm >= 0.0 ? options.damping_nspm : 2.0 * std::sqrt(k * slider.mass_kg);
  const double dt = options.dt_s;
  const Eigen::Vector2d dir = Rotation(start.theta) * push.direction_body.normalized();  // world
  PlanarState q = start;
  q.vx = q.vy = q.wz = 0.0;
  const Eigen::Vector2d tip0 =
      Contact(q, push.contact_body_m).point - dir * push.speed_mps * push.rest_s;
  const double t_stop = push.rest_s + push.push_s;
  auto tip = [&](double t) { return tip0 + dir * push.speed_mps * std::min(t, t_stop); };

  SimulatedPush out;
  out.start = q;
  out.tool_yaw_rad = std::atan2(dir.y(), dir.x());
  for (int i = 0; i / options.robot_rate_hz <= t_stop; ++i) {
    out.tool_t_s.push_back(i / options.robot_rate_hz);
    out.tool_world_m.push_back(tip(out.tool_t_s.back()));
  }
  SlideSums sums;
  int next_force_sample = 0;
  const long long steps = std::llround((t_stop + kMaxSettle_s) / dt);
  for (long long u = 0; u < steps; ++u) {
    const double t = u * dt;
    const ContactKinematics c = Contact(q, push.contact_body_m);
    Eigen::Vector2d f = Eigen::Vector2d::Zero();
    if (t >= push.rest_s) {
      const Eigen::Vector2d tip_velocity =
          t < t_stop ? Eigen::Vector2d(dir * push.speed_mps) : Eigen::Vector2d::Zero();
      f = k * (tip(t) - c.point) + damping * (tip_velocity - c.velocity);
    }
    if (t <= t_stop && t + kSampleTimeSlack_s >= next_force_sample / options.force_rate_hz) {
      out.force_t_s.push_back(next_force_sample / options.force_rate_hz);
      out.force_world_n.push_back(f);
      ++next_force_sample;
    }
    if (t > t_stop && q.vx == 0.0 && q.vy == 0.0 && q.wz == 0.0) break;  // at rest: done
    const AppliedWrench applied{f.x(), f.y(), 0.0, 0.0, 0.0, c.arm.x() * f.y() - c.arm.y() * f.x()};
    const StepResult r = SolveStep(slider, friction, q, applied, dt, options.step);
    if (!r.ok()) {
      throw std::runtime_error("SimulateSpringPush: the step at t = " + std::to_string(t) +
                               " s failed: " + r.message);
    }
    q = r.state;
    out.max_speed_mps = std::max(out.max_speed_mps, std::hypot(q.vx, q.vy));
    if (r.mode == StepMode::kSlide) {
      const Eigen::Vector2d f_body = Rotation(-q.theta) * f;
      sums.force_body += f_body;
      sums.force_world += f;
      sums.moment += applied.tz;
      sums.peak = std::max(sums.peak, f.norm());
      ++sums.steps;
      ++out.slide_steps;
    } else {
      ++out.stick_steps;
    }
  }
  if (sums.steps == 0) {
    throw std::invalid_argument("SimulateSpringPush: the push never slid the slider");
  }
  out.end = q;
  out.end.vx = out.end.vy = out.end.wz = 0.0;
  FillRows(sums, dt, push.contact_body_m, out);
  return out;
}

bool QuasiStaticSynthSpec::IsValid(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(slider.mass_kg > 0.0 && slider.inertia_kgm2 > 0.0 && slider.gravity_mps2 > 0.0)) {
    return fail("mass, inertia and gravity must be > 0");
  }
  if (!(friction.a > 0.0 && friction.b > 0.0 && friction.c > 0.0)) {
    return fail("a, b and c must be > 0");
  }
  if (outline.size() < 3) return fail("the outline needs at least 3 vertices");
  if (pushes < 1) return fail("pushes must be >= 1");
  if (!(max_angle_rad >= 0.0 && max_angle_rad < 1.5)) {
    return fail("max_angle_rad must be in [0, 1.5)");
  }
  if (!(speed_mps > 0.0 && rest_s >= 0.0 && push_s > 0.0)) {
    return fail("speed and push time must be > 0, rest >= 0");
  }
  return options.IsValid(why);
}

std::vector<SimulatedPush> SimulateSpringPushes(const QuasiStaticSynthSpec& spec) {
  std::string why;
  if (!spec.IsValid(&why)) throw std::invalid_argument("SimulateSpringPushes: " + why);
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::size_t n = spec.outline.size();
  double perimeter = 0;
  for (std::size_t i = 0; i < n; ++i)
    perimeter += (spec.outline[(i + 1) % n] - spec.outline[i]).norm();

  std::vector<SimulatedPush> pushes;
  PlanarState state;
  for (int p = 0; p < spec.pushes; ++p) {
    // An edge with probability proportional to its length, a point in its middle.
    double at = unit(rng) * perimeter;
    std::size_t edge = 0;
    for (; edge + 1 < n; ++edge) {
      const double length = (spec.outline[(edge + 1) % n] - spec.outline[edge]).norm();
      if (at < length) break;
      at -= length;
    }
    const Eigen::Vector2d a = spec.outline[edge], b = spec.outline[(edge + 1) % n];
    const double s = kEdgeMargin + (1.0 - 2.0 * kEdgeMargin) * unit(rng);
    const double angle = spec.max_angle_rad * (2.0 * unit(rng) - 1.0);
    SpringPush push;
    push.contact_body_m = a + s * (b - a);
    const Eigen::Vector2d inward = Eigen::Vector2d(-(b - a).y(), (b - a).x()).normalized();
    push.direction_body = spec.aim_at_cm ? Eigen::Vector2d(-push.contact_body_m)
                                         : Eigen::Vector2d(Rotation(angle) * inward);
    push.speed_mps = spec.speed_mps;
    push.rest_s = spec.rest_s;
    push.push_s = spec.push_s;
    pushes.push_back(SimulateSpringPush(spec.slider, spec.friction, state, push, spec.options));
    state = pushes.back().end;
  }
  return pushes;
}

WrenchTwistData PairsFromPushes(const QuasiStaticSynthSpec& spec,
                                const std::vector<SimulatedPush>& pushes, PairFrame frame) {
  WrenchTwistData data;
  data.mass_kg = spec.slider.mass_kg;
  data.gravity_mps2 = spec.slider.gravity_mps2;
  data.inertia_kgm2 = spec.slider.inertia_kgm2;
  data.com_height_m = 0.0;
  data.source = "simulated spring pushes, seed " + std::to_string(spec.seed) +
                (frame == PairFrame::kBody ? ", body frame" : ", world frame");
  data.true_friction = spec.friction.ToFrictionParameters();
  for (std::size_t i = 0; i < pushes.size(); ++i) {
    WrenchTwistRow row = frame == PairFrame::kBody ? pushes[i].row : pushes[i].world_row;
    row.push = static_cast<int>(i + 1);
    data.rows.push_back(row);
  }
  return data;
}

WrenchTwistData ExactQuasiStaticPairs(const std::vector<Eigen::Vector3d>& twists,
                                      const SliderProperties& slider,
                                      const ReducedFriction& friction) {
  WrenchTwistData data;
  data.mass_kg = slider.mass_kg;
  data.gravity_mps2 = slider.gravity_mps2;
  data.inertia_kgm2 = slider.inertia_kgm2;
  data.source = "exact quasi-static pairs";
  data.true_friction = friction.ToFrictionParameters();
  for (std::size_t i = 0; i < twists.size(); ++i) {
    const Eigen::Vector3d w =
        QuasiStaticWrench(twists[i], friction, slider.mass_kg * slider.gravity_mps2);
    WrenchTwistRow row;
    row.push = static_cast<int>(i + 1);
    row.pair = {w.x(), w.y(), 0.0, w.z(), twists[i].x(), twists[i].y(), twists[i].z()};
    data.rows.push_back(row);
  }
  return data;
}

}  // namespace slideid
