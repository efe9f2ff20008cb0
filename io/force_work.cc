#include "io/force_work.h"

#include <algorithm>
#include <cmath>

#include "estimator/log_diagnostics.h"

namespace slideid {

namespace {

ForceWork ForceWorkOf(const Trajectory& log, const LogDiagnostics& d) {
  ForceWork w;
  const double noise = std::isfinite(d.pose_noise_m) ? d.pose_noise_m : 0.0;
  for (std::size_t u = 0; u + 1 < log.samples.size(); ++u) {
    if (StartsRun(log, u + 1)) continue;
    const TrajectorySample& a = log.samples[u];
    const TrajectorySample& b = log.samples[u + 1];
    const double fx = a.applied.fx, fy = a.applied.fy;
    if (!(std::hypot(fx, fy) >= kForceWorkPushFraction * d.max_push_n)) continue;
    // The contact point's travel over the interval, as a point fixed on the object: the
    // CM's plus the turn of its arm from the CM.
    const bool at_point = a.push_point_world.has_value();
    const double rx = at_point ? a.push_point_world->x() - a.state.x : 0.0;
    const double ry = at_point ? a.push_point_world->y() - a.state.y : 0.0;
    const double turn = b.state.theta - a.state.theta;
    const double c = std::cos(turn), s = std::sin(turn);
    const double dx = b.state.x - a.state.x + (c * rx - s * ry - rx);
    const double dy = b.state.y - a.state.y + (s * rx + c * ry - ry);
    if (!(std::hypot(dx, dy) > kForceWorkMovingOverNoise * noise)) continue;
    ++w.rows;
    w.positive += fx * dx + fy * dy > 0;
    const double ch = std::cos(a.state.theta), sh = std::sin(a.state.theta);
    w.positive_in_object_frame += (ch * fx - sh * fy) * dx + (sh * fx + ch * fy) * dy > 0;
  }
  return w;
}

SpinWork SpinWorkOf(const Trajectory& log, const LogDiagnostics& d) {
  SpinWork w;
  const double noise = std::isfinite(d.angle_noise_rad) ? d.angle_noise_rad : 0.0;
  auto pushes = [&](const TrajectorySample& a) {
    return std::hypot(a.applied.fx, a.applied.fy) >= kForceWorkPushFraction * d.max_push_n;
  };
  double largest_moment = 0;
  for (const TrajectorySample& a : log.samples)
    if (pushes(a)) largest_moment = std::max(largest_moment, std::abs(a.applied.tz));
  if (!(largest_moment > 0)) return w;
  for (std::size_t u = 0; u + 1 < log.samples.size(); ++u) {
    if (StartsRun(log, u + 1)) continue;
    const TrajectorySample& a = log.samples[u];
    if (!pushes(a) || !(std::abs(a.applied.tz) >= kForceWorkPushFraction * largest_moment))
      continue;
    // The turn over the interval against the noise of a difference of two headings.
    const double turn = log.samples[u + 1].state.theta - a.state.theta;
    if (!(std::abs(turn) > kSpinOverNoise * std::sqrt(2.0) * noise)) continue;
    ++w.rows;
    w.positive += a.applied.tz * turn > 0;
  }
  return w;
}

}  // namespace

PushWork MeasurePushWork(const Trajectory& log) {
  PushWork w;
  if (!log.measured.pose || !log.measured.force) return w;
  const LogDiagnostics d = DiagnoseLog(log);
  if (!(d.max_push_n > 0)) return w;
  w.force = ForceWorkOf(log, d);
  w.spin = SpinWorkOf(log, d);
  return w;
}

ForceWork MeasureForceWork(const Trajectory& log) { return MeasurePushWork(log).force; }

SpinWork MeasureSpinWork(const Trajectory& log) { return MeasurePushWork(log).spin; }

}  // namespace slideid
