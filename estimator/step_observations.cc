#include "estimator/step_observations.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "estimator/log_diagnostics.h"
#include "estimator/robust_statistics.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {

double ZeroIfNaN(double x) { return std::isfinite(x) ? x : 0.0; }

/// |v|_w = sqrt(v_x^2 + v_y^2 + (L w_z)^2) [m/s].
double Speed(const PlanarState& s, double radius_m) {
  return std::sqrt(s.vx * s.vx + s.vy * s.vy + radius_m * radius_m * s.wz * s.wz);
}

}  // namespace

std::vector<StepObservation> ExtractStepObservations(const Trajectory& log) {
  std::vector<StepObservation> steps;
  if (log.samples.size() >= 2) steps.reserve(log.samples.size() - 1);
  ForEachStepObservation(log, [&](const StepObservation& o) { steps.push_back(o); });
  return steps;
}

void ForEachStepObservation(const Trajectory& log,
                            const std::function<void(const StepObservation&)>& f) {
  // A poses-only log means kinematic-map velocities, whatever the samples carry: computed
  // row by row (StateWithPoseVelocity), not in a copy of the log.
  const bool from_poses = !log.measured.velocity;
  const auto state = [&](size_t u) {
    return from_poses ? StateWithPoseVelocity(log, u) : log.samples[u].state;
  };
  const SliderProperties& s = log.slider;
  if (!(s.mass_kg > 0 && s.inertia_kgm2 > 0 && s.com_height_m >= 0 && s.gravity_mps2 > 0)) {
    throw std::invalid_argument("ExtractStepObservations: slider properties not set");
  }
  if (log.samples.size() < 2) return;
  double max_push = 0;
  for (const TrajectorySample& sample : log.samples) {
    max_push = std::max(max_push, std::hypot(sample.applied.fx, sample.applied.fy));
  }
  auto switches = [&](size_t from, size_t to) {
    if (to >= log.samples.size()) return false;
    const AppliedWrench& a = log.samples[from].applied;
    const AppliedWrench& b = log.samples[to].applied;
    return std::hypot(b.fx - a.fx, b.fy - a.fy) > kForceSwitchFraction * max_push;
  };
  const bool has_mode = log.measured.step_info || log.measured.mode;
  PlanarState next_state = state(0);
  for (size_t u = 0; u + 1 < log.samples.size(); ++u) {
    const TrajectorySample& a = log.samples[u];
    const TrajectorySample& b = log.samples[u + 1];
    StepObservation o;
    o.row = static_cast<int>(u);
    o.h_s = b.t_s - a.t_s;
    o.start = next_state;
    o.end = next_state = state(u + 1);
    o.applied = a.applied;
    o.start_velocity_known = log.measured.velocity || !StartsRun(log, u);
    o.across_gap = StartsRun(log, u + 1);
    o.near_force_switch =
        !log.measured.velocity && ((u > 0 && switches(u - 1, u)) || switches(u, u + 1));
    const double h = o.h_s;
    o.pn = h * (s.mass_kg * s.gravity_mps2 - a.applied.fz);
    // Appendix A, corrected: friction impulses from Newton-Euler with the coupling term (*).
    const double pt = s.mass_kg * (o.end.vx - o.start.vx) - h * a.applied.fx;
    const double po = s.mass_kg * (o.end.vy - o.start.vy) - h * a.applied.fy;
    const double pr = s.inertia_kgm2 * (o.end.wz - o.start.wz) - h * a.applied.tz -
                      (pt * h * a.applied.tx + po * h * a.applied.ty) / o.pn;
    o.friction_impulse << pt, po, pr;
    const double rx = (h * a.applied.ty - s.com_height_m * pt) / o.pn;
    const double ry = (-h * a.applied.tx - s.com_height_m * po) / o.pn;
    const double w = o.end.wz;
    o.ecp_velocity << o.end.vx - w * ry, o.end.vy + w * rx, w;
    o.logged_stick =
        has_mode ? b.mode == SampleMode::kStick : (o.end.vx == 0 && o.end.vy == 0 && o.end.wz == 0);
    f(o);
  }
}

StepNoise ReadStepNoise(const Trajectory& log) {
  const LogDiagnostics d = DiagnoseLog(log);
  StepNoise n;
  n.differentiated = !log.measured.velocity;
  if (!n.differentiated) {
    n.velocity_mps = ZeroIfNaN(d.velocity_noise_mps);
    n.spin_radps = ZeroIfNaN(d.spin_noise_radps);
    n.delta_velocity_mps = std::sqrt(2.0) * n.velocity_mps;
    n.delta_spin_radps = std::sqrt(2.0) * n.spin_radps;
    n.delta_end_velocity_cov = n.velocity_mps * n.velocity_mps;
    n.delta_end_spin_cov = n.spin_radps * n.spin_radps;
    return n;
  }
  const double h = MedianInterval(log);
  if (!(h > 0)) return n;
  const double pose = ZeroIfNaN(d.pose_noise_m), angle = ZeroIfNaN(d.angle_noise_rad);
  n.velocity_mps = std::sqrt(2.0) * pose / h;
  n.spin_radps = std::sqrt(2.0) * angle / h;
  n.delta_velocity_mps = std::sqrt(6.0) * pose / h;
  n.delta_spin_radps = std::sqrt(6.0) * angle / h;
  n.delta_end_velocity_cov = 3.0 * pose * pose / (h * h);
  n.delta_end_spin_cov = 3.0 * angle * angle / (h * h);
  return n;
}

namespace {

/// The rest threshold of SlidingStep [m/s].
double RestSpeed(const StepNoise& noise, double radius_m) {
  return kRestSpeedSigmas * std::sqrt(2 * noise.velocity_mps * noise.velocity_mps +
                                      radius_m * radius_m * noise.spin_radps * noise.spin_radps);
}

}  // namespace

std::string RateTooHighForItsNoise(const Trajectory& log, const StepNoise& noise, double radius_m) {
  const double h = MedianInterval(log);
  const double rest = RestSpeed(noise, radius_m);
  if (!noise.differentiated || !(h > 0) || !(rest > 0)) return "";
  const int k = static_cast<int>(std::lround(kMotionWindow_s / h));
  if (k < 2) return "";
  // Differentiated over k rows, the velocities' noise is k times smaller: so is rest.
  const double window_rest = rest / k;
  int windows = 0;
  std::vector<double> moving;
  for (size_t j = 0; j + k < log.samples.size(); j += k) {
    bool gap = false;
    for (size_t u = j + 1; u <= j + k; ++u) gap |= StartsRun(log, u);
    const TrajectorySample& first = log.samples[j];
    const TrajectorySample& last = log.samples[j + k];
    const double span = last.t_s - first.t_s;
    if (gap || !(span > 0)) continue;
    const double vx = (last.state.x - first.state.x) / span;
    const double vy = (last.state.y - first.state.y) / span;
    const double w = (last.state.theta - first.state.theta) / span;
    const double speed = std::sqrt(vx * vx + vy * vy + radius_m * radius_m * w * w);
    ++windows;
    if (speed > window_rest) moving.push_back(speed);
  }
  if (windows == 0 || 4 * static_cast<int>(moving.size()) < windows) return "";
  return Printf(
      "the log is not at rest: over %.0f ms windows its poses move at a median %.3g m/s (above "
      "their noise in %zu of %d windows), but velocities differentiated between rows %.3g ms "
      "apart carry so much of the poses' noise that a step passes for sliding only above "
      "%.3g m/s (a high rate for noisy poses); the trajectory method fits the poses themselves",
      1000 * kMotionWindow_s, Median(moving), moving.size(), windows, 1000 * h, rest);
}

bool SlidingStep(const StepObservation& step, const StepNoise& noise, double radius_m,
                 EstimateResult* result) {
  if (step.logged_stick) {
    result->Exclude("sticking");
    return false;
  }
  if (step.across_gap) {
    result->Exclude("across a gap in the log");
    return false;
  }
  if (!step.start_velocity_known) {
    result->Exclude("start velocity unknown");
    return false;
  }
  if (step.near_force_switch) {
    result->Exclude("next to a force switch");
    return false;
  }
  const double rest = RestSpeed(noise, radius_m);
  // Exact logs (no noise): only an exact 0 is rest.
  if (!(Speed(step.end, radius_m) > rest)) {
    result->Exclude("at rest (speed within the noise)");
    return false;
  }
  if (!(Speed(step.start, radius_m) > rest)) {
    result->Exclude("start of a sliding phase");
    return false;
  }
  return true;
}

}  // namespace slideid
