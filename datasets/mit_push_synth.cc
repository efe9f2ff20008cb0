#include "datasets/mit_push_synth.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "forward_model/constants.h"
#include "forward_model/simulator.h"

namespace slideid {
namespace {

double Wrap(double theta) { return std::remainder(theta, 2.0 * kPi); }

/// Outward normal of the square's edge that holds `point` (body frame).
Eigen::Vector2d EdgeNormal(const Eigen::Vector2d& point, double half) {
  constexpr double kOnEdge = 1e-9;  // m: the point must lie on an edge, not near one
  if (std::abs(std::abs(point.x()) - half) < kOnEdge && std::abs(point.y()) <= half) {
    return {point.x() > 0 ? 1.0 : -1.0, 0.0};
  }
  if (std::abs(std::abs(point.y()) - half) < kOnEdge && std::abs(point.x()) <= half) {
    return {0.0, point.y() > 0 ? 1.0 : -1.0};
  }
  throw std::invalid_argument(
      "MakeMitPushRecording: the push point is not on an edge of the square");
}

Scene MakeScene(const MitSynthSpec& spec) {
  Scene scene;
  scene.source = "mit_push_synth";
  scene.slider = spec.slider;
  scene.friction = spec.friction;
  scene.patch = ContactPatch::Rectangle(spec.side_m, spec.side_m);
  scene.initial = {spec.initial_pose.x(), spec.initial_pose.y(), spec.initial_pose.z(), 0, 0, 0};
  PushSpec push;
  push.point_body = spec.push_point_body;
  push.direction_body = spec.push_direction_body.normalized();
  push.height_m = spec.slider.com_height_m;
  const double friction_n = spec.friction.a * spec.slider.mass_kg * spec.slider.gravity_mps2;
  push.force_n = spec.force_ratio * friction_n;
  push.amplitude_n = spec.amplitude_ratio * friction_n;
  push.period_s = spec.period_s;
  push.start_s = spec.rest_before_s;
  push.stop_s = spec.rest_before_s + spec.push_s;
  scene.pushes.push_back(push);
  if (spec.preload_n > 0) {
    PushSpec preload = push;
    preload.force_n = spec.preload_n;
    preload.amplitude_n = 0;
    preload.start_s = 0;
    preload.stop_s = spec.rest_before_s;
    scene.pushes.push_back(preload);
  }
  scene.dt_s = spec.sim_dt_s;
  scene.duration_s = spec.rest_before_s + spec.push_s + spec.rest_after_s;
  return scene;
}

/// Stream times from `begin` to `end` [s after the start] at `rate` with jitter.
std::vector<double> Clock(double begin, double end, double rate, double jitter,
                          std::mt19937_64* rng) {
  std::uniform_real_distribution<double> phase(0.0, 1.0), wobble(-jitter, jitter);
  std::vector<double> times;
  for (double t = begin + phase(*rng) / rate; t <= end; t += (1.0 + wobble(*rng)) / rate) {
    times.push_back(t);
  }
  return times;
}

/// The simulated trajectory at any time: pose linear between steps, force held.
class Truth {
 public:
  Truth(const Trajectory& simulated, double dt) : s_(simulated.samples), dt_(dt) {}
  Eigen::Vector3d Pose(double t) const {
    const auto [k, w] = Step(t);
    const PlanarState &a = s_[k].state, &b = s_[std::min(k + 1, s_.size() - 1)].state;
    return {a.x + w * (b.x - a.x), a.y + w * (b.y - a.y), a.theta + w * (b.theta - a.theta)};
  }
  Eigen::Vector2d Force(double t) const {
    const AppliedWrench& f = s_[Step(t).first].applied;
    return {f.fx, f.fy};
  }

 private:
  std::pair<std::size_t, double> Step(double t) const {
    const double position = std::clamp(t / dt_, 0.0, static_cast<double>(s_.size() - 1));
    const std::size_t k = std::min(static_cast<std::size_t>(position), s_.size() - 1);
    return {k, position - static_cast<double>(k)};
  }
  const std::vector<TrajectorySample>& s_;
  double dt_;
};

int QuarterTurns(const MitSynthDefects& d, double t) {
  int k = 0;
  double latest = -1e300;
  for (const auto& [from, turns] : d.quarter_turns) {
    if (from <= t && from >= latest) {
      latest = from;
      k = turns;
    }
  }
  return k;
}

/// Swaps and repeats rows at evenly spaced places (never overlapping, so each swap is one
/// backward step and each repeat one dropped row).
void InjectStampDefects(const MitSynthDefects& d, MitPushRecording* r) {
  const std::size_t n = r->object_pose.size();
  for (int i = 0; i < d.backward_steps; ++i) {
    const std::size_t k = (i + 1) * n / (d.backward_steps + 1);
    if (k + 1 < n) std::swap(r->object_pose[k], r->object_pose[k + 1]);
  }
  for (auto* stream : {&r->object_pose, &r->tip_pose}) {
    const std::size_t m = stream->size();
    for (int i = d.duplicate_rows - 1; i >= 0; --i) {  // from the back: indices stay valid
      const std::size_t k = (2 * i + 1) * m / (2 * d.duplicate_rows);
      stream->insert(stream->begin() + k + 1, (*stream)[k]);
    }
  }
}

}  // namespace

MitSynthResult MakeMitPushRecording(const MitSynthSpec& spec) {
  const double half = spec.side_m / 2.0;
  const Eigen::Vector2d normal_out = EdgeNormal(spec.push_point_body, half);
  MitSynthResult result;
  result.scene = MakeScene(spec);
  const SimulationResult sim = Simulate(result.scene);
  if (!sim.summary.ok()) {
    throw std::invalid_argument("MakeMitPushRecording: the simulation failed: " +
                                sim.summary.message);
  }
  result.simulated = sim.trajectory;
  const Truth truth(result.simulated, spec.sim_dt_s);
  const MitSynthDefects& d = spec.defects;
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double end = result.scene.duration_s;
  const double push_start = spec.rest_before_s, push_stop = spec.rest_before_s + spec.push_s;
  MitPushRecording& r = result.recording;

  int pose_index = 0;
  for (double t : Clock(0.0, end, spec.object_rate_hz, spec.clock_jitter, &rng)) {
    const bool glitch = d.glitch_every > 0 && ++pose_index % d.glitch_every == 0;
    const bool dropped = std::any_of(d.pose_gaps.begin(), d.pose_gaps.end(),
                                     [&](const auto& g) { return t >= g.first && t < g.second; });
    const Eigen::Vector3d q = truth.Pose(t);
    const double theta = q.z() + spec.angle_noise_rad * gauss(rng) + QuarterTurns(d, t) * kPi / 2;
    const double x = q.x() + spec.pose_noise_m * gauss(rng),
                 y = q.y() + spec.pose_noise_m * gauss(rng);
    if (!dropped)
      r.object_pose.push_back(
          {spec.t_epoch_s + t, x + (glitch ? d.glitch_m : 0.0), y, Wrap(theta)});
  }
  // The tip follows the contact point during the push and stays still outside it.
  auto tip_at = [&](double t) {
    const Eigen::Vector3d q = truth.Pose(std::clamp(t, push_start, push_stop));
    const Eigen::Rotation2Dd rotation(q.z());
    const double rest = t < push_start || t > push_stop ? spec.rest_clearance_m : 0.0;
    return Eigen::Vector2d(
        q.head<2>() + rotation * (spec.push_point_body +
                                  (spec.tip_radius_m + d.tip_clearance_m + rest) * normal_out));
  };
  const double inset = spec.stream_inset_s;
  for (double t : Clock(inset, end - inset, spec.tip_rate_hz, spec.clock_jitter, &rng)) {
    const Eigen::Vector2d c = tip_at(t);
    r.tip_pose.push_back({spec.t_epoch_s + t, c.x() + spec.tip_noise_m * gauss(rng),
                          c.y() + spec.tip_noise_m * gauss(rng), 1e-5 * gauss(rng)});
  }
  const Eigen::Rotation2Dd frame(d.force_frame_rad);
  for (double t : Clock(inset, end - inset, spec.ft_rate_hz, spec.clock_jitter, &rng)) {
    const double w = std::clamp((t - push_start) / (push_stop - push_start), 0.0, 1.0);
    const Eigen::Vector2d offset =
        spec.offset_before_n + w * (spec.offset_after_n - spec.offset_before_n);
    Eigen::Vector2d f = frame * ((spec.store_reaction ? -1.0 : 1.0) * truth.Force(t)) + offset;
    f += spec.force_noise_n * Eigen::Vector2d(gauss(rng), gauss(rng));
    if (d.saturation_n > 0) {
      f = f.cwiseMax(-d.saturation_n).cwiseMin(d.saturation_n);
    }
    r.ft_wrench.push_back({spec.t_epoch_s + t, f.x(), f.y(), 1e-3 * gauss(rng)});
  }
  if (d.dead_force) {
    for (MitStreamRow& row : r.ft_wrench) {
      row = {row[0], r.ft_wrench.front()[1], r.ft_wrench.front()[2], r.ft_wrench.front()[3]};
    }
  }
  InjectStampDefects(d, &r);
  return result;
}

}  // namespace slideid
