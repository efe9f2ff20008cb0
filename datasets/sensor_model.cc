#include "datasets/sensor_model.h"

#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "datasets/noise.h"
#include "forward_model/constants.h"

namespace slideid {
namespace {

// A delayed time t - d that lies within this fraction of a simulated step after a row's
// time counts as that row's: t - d computed in floating point lands a few ulps short of the
// row when d is a whole number of steps, and would otherwise pick the row before.
constexpr double kRowTimeSlack = 1e-9;

/// The mean of the wrenches of rows [first, first + k): what a sensor that integrates over
/// the log interval reports, so that the logged impulse is the applied one.
AppliedWrench IntervalMean(const std::vector<TrajectorySample>& rows, size_t first, int k) {
  AppliedWrench mean;
  for (size_t i = first; i < first + k; ++i) {
    const AppliedWrench& w = rows[i].applied;
    mean.fx += w.fx / k;
    mean.fy += w.fy / k;
    mean.fz += w.fz / k;
    mean.tx += w.tx / k;
    mean.ty += w.ty / k;
    mean.tz += w.tz / k;
  }
  return mean;
}

/// Every k-th row of `log`; a kept row's mode and step (when the log has steps) summarise
/// the simulated steps of its log interval.
void Decimate(Trajectory* log, int k) {
  const std::vector<TrajectorySample>& rows = log->samples;
  const std::vector<StepRecord>& steps = log->steps;
  std::vector<TrajectorySample> out;
  std::vector<StepRecord> out_steps;
  if (!rows.empty()) {
    out.reserve(rows.size() / k + 1);
    out.push_back(rows.front());
    if (!steps.empty()) {
      out_steps.reserve(rows.size() / k + 1);
      out_steps.push_back(steps.front());
    }
  }
  for (size_t end = k; end < rows.size(); end += k) {
    TrajectorySample kept = rows[end];
    bool all_stick = true;
    for (size_t i = end - k + 1; i <= end; ++i) {
      all_stick = all_stick && rows[i].mode == SampleMode::kStick;
    }
    kept.mode = all_stick ? SampleMode::kStick : SampleMode::kSlide;
    out.push_back(kept);
    if (steps.empty()) continue;
    StepRecord step = steps[end];  // the last step's sigma and ECP, the impulses summed
    step.pt = step.po = step.pr = 0.0;
    for (size_t i = end - k + 1; i <= end; ++i) {
      step.pt += steps[i].pt;
      step.po += steps[i].po;
      step.pr += steps[i].pr;
    }
    out_steps.push_back(step);
  }
  log->samples = std::move(out);
  log->steps = std::move(out_steps);
}

/// Gives log row r (simulated row r k) the mean wrench of its interval, and no push point
/// (a mean of forces at moving points has none). An interval is complete when the row that
/// ends it was simulated; the last row (no interval after it) keeps its own wrench.
void SetIntervalMeanWrench(const std::vector<TrajectorySample>& simulated, int k,
                           std::vector<TrajectorySample>* log_rows) {
  for (size_t r = 0; r < log_rows->size(); ++r) {
    const size_t first = r * k;
    if (first + k < simulated.size()) (*log_rows)[r].applied = IntervalMean(simulated, first, k);
    (*log_rows)[r].push_point_world.reset();
  }
}

double Wrap(double theta) {
  const double wrapped = theta - 2.0 * kPi * std::ceil((theta - kPi) / (2.0 * kPi));
  return wrapped <= -kPi ? wrapped + 2.0 * kPi : wrapped;
}

/// The push stream delayed by `delay_s` (NoiseSpec::force_delay_s): each row's wrench and
/// push point are those of the row in force at t - delay (the simulated wrench is held
/// over each step), clamped to the first and the last row.
void DelayPushStream(Trajectory* log, double delay_s) {
  std::vector<TrajectorySample>& rows = log->samples;
  const int n = static_cast<int>(rows.size());
  if (n < 2) return;
  const double slack = kRowTimeSlack * (rows[1].t_s - rows[0].t_s);
  std::vector<AppliedWrench> applied(n);
  std::vector<std::optional<Eigen::Vector3d>> point(n);
  int j = 0;
  for (int i = 0; i < n; ++i) {
    const double t = rows[i].t_s - delay_s + slack;
    while (j > 0 && rows[j].t_s > t) --j;
    while (j + 1 < n && rows[j + 1].t_s <= t) ++j;
    applied[i] = rows[j].applied;
    point[i] = rows[j].push_point_world;
  }
  for (int i = 0; i < n; ++i) {
    rows[i].applied = applied[i];
    rows[i].push_point_world = point[i];
  }
}

/// Adds the force offset (NoiseSpec::force_bias_*) to every row: at the row's push point,
/// whose lever is taken from the logged (noisy) pose as a reader takes it, else at the CM.
void AddForceBias(Trajectory* log, double bias_x_n, double bias_y_n) {
  for (TrajectorySample& s : log->samples) {
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    if (s.push_point_world) {
      r = *s.push_point_world - Eigen::Vector3d(s.state.x, s.state.y, log->slider.com_height_m);
    }
    const AppliedWrench o = WrenchFromForceAt(bias_x_n, bias_y_n, 0.0, r.x(), r.y(), r.z());
    s.applied.fx += o.fx;
    s.applied.fy += o.fy;
    s.applied.tx += o.tx;
    s.applied.ty += o.ty;
    s.applied.tz += o.tz;
  }
}

bool AnyForce(const Trajectory& t) {
  for (const TrajectorySample& s : t.samples) {
    if (!s.applied.IsZero() || s.push_point_world) return true;
  }
  return false;
}

}  // namespace

Trajectory MakeLog(const Trajectory& simulated, const LogSpec& spec) {
  std::string why;
  if (!spec.IsValidFor(AnyForce(simulated), &why)) {
    throw std::invalid_argument("MakeLog: " + why);
  }
  Trajectory log = simulated;
  if (spec.noise.force_delay_s != 0.0) DelayPushStream(&log, spec.noise.force_delay_s);
  if (spec.log_every > 1) {
    Decimate(&log, spec.log_every);
  }
  if (spec.wrench == LogWrench::kIntervalMean) {
    SetIntervalMeanWrench(simulated.samples, spec.log_every, &log.samples);
  }
  Measurements& c = log.measured;
  c.pose = spec.motion != LogMotion::kVelocities;
  c.velocity = spec.motion != LogMotion::kPoses;
  const bool pushed = AnyForce(log);
  c.force = c.force || pushed;
  c.push_point = pushed && spec.push == LogPush::kPoint;
  c.moments = pushed && spec.push == LogPush::kMoments;
  c.step_info = spec.step_info.value_or(spec.noise.IsZero() && !spec.noise.HasDefects());
  if (!spec.noise.IsZero()) ApplyNoise(&log, spec.noise);
  if (spec.noise.force_bias_x_n != 0.0 || spec.noise.force_bias_y_n != 0.0) {
    AddForceBias(&log, spec.noise.force_bias_x_n, spec.noise.force_bias_y_n);
    c.force = true;
  }
  if (!c.step_info) log.steps = {};
  if (!c.velocity) SetVelocitiesFromPoses(&log);
  if (spec.wrap_theta) {
    for (TrajectorySample& s : log.samples) s.state.theta = Wrap(s.state.theta);
  }
  return log;
}

}  // namespace slideid
