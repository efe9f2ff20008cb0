#include "datasets/sensor_model.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "datasets/noise.h"

namespace slideid {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string Format(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

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

/// Every k-th row; step columns summarise the simulated steps of each log interval.
std::vector<TrajectorySample> Decimate(const std::vector<TrajectorySample>& rows, int k) {
  std::vector<TrajectorySample> out;
  if (rows.empty()) return out;
  out.reserve(rows.size() / k + 1);
  out.push_back(rows.front());
  for (size_t end = k; end < rows.size(); end += k) {
    TrajectorySample kept = rows[end];
    bool all_stick = true;
    kept.pt = kept.po = kept.pr = 0.0;
    for (size_t i = end - k + 1; i <= end; ++i) {
      kept.pt += rows[i].pt;
      kept.po += rows[i].po;
      kept.pr += rows[i].pr;
      all_stick = all_stick && rows[i].mode == SampleMode::kStick;
    }
    kept.mode = all_stick ? SampleMode::kStick : SampleMode::kSlide;
    out.push_back(kept);
  }
  return out;
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
  if (spec.log_every > 1) {
    log.samples = Decimate(simulated.samples, spec.log_every);
    log.extra_metadata.emplace_back("log_every", std::to_string(spec.log_every));
    if (log.samples.size() >= 2) {
      log.extra_metadata.emplace_back("log_dt",
                                      Format(log.samples[1].t_s - log.samples[0].t_s));
    }
  }
  if (spec.wrench == LogWrench::kIntervalMean) {
    SetIntervalMeanWrench(simulated.samples, spec.log_every, &log.samples);
    log.extra_metadata.emplace_back("log_wrench", ToString(spec.wrench));
  }
  LogColumns& c = log.columns;
  c.pose = spec.motion != LogMotion::kVelocities;
  c.velocity = spec.motion != LogMotion::kPoses;
  const bool pushed = AnyForce(log);
  c.force = c.force || pushed;
  c.push_point = pushed && spec.push == LogPush::kPoint;
  c.moments = pushed && spec.push == LogPush::kMoments;
  c.step_info = spec.step_info.value_or(spec.noise.IsZero());
  if (!spec.noise.IsZero()) {
    ApplyNoise(&log, spec.noise);
    for (const auto& entry : spec.noise.Metadata()) log.extra_metadata.push_back(entry);
  }
  if (!c.step_info) {
    for (TrajectorySample& s : log.samples) {
      s.pt = s.po = s.pr = s.sigma = 0.0;
      s.ecp_world.setZero();
    }
  }
  if (!c.velocity) SetVelocitiesFromPoses(&log);
  if (spec.wrap_theta) {
    for (TrajectorySample& s : log.samples) s.state.theta = Wrap(s.state.theta);
  }
  return log;
}

}  // namespace slideid
