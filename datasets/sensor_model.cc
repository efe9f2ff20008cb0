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

/// Sets `kept`'s wrench (and push point) to the mean over rows[first, first + k) (clipped
/// to the rows): the impulse over the log interval starting at `kept`. With push points,
/// the push point is the row's CM plus the mean lever arm (contact point less CM: both move
/// over the interval), and the moments are those of the mean force there, as a reader of
/// the log's columns computes them (r from the row's CM at `com_height_m`).
void HoldMeanWrench(const std::vector<TrajectorySample>& rows, size_t first, int k,
                    double com_height_m, TrajectorySample* kept) {
  const size_t last = std::min(rows.size(), first + k);
  AppliedWrench mean;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int points = 0;
  const double n = static_cast<double>(last - first);
  for (size_t i = first; i < last; ++i) {
    const AppliedWrench& w = rows[i].applied;
    mean.fx += w.fx / n, mean.fy += w.fy / n, mean.fz += w.fz / n;
    mean.tx += w.tx / n, mean.ty += w.ty / n, mean.tz += w.tz / n;
    if (rows[i].push_point_world) {
      point += *rows[i].push_point_world - Eigen::Vector3d(rows[i].state.x, rows[i].state.y, 0);
      ++points;
    }
  }
  if (points > 0 && kept->push_point_world) {
    const Eigen::Vector3d p = point / points + Eigen::Vector3d(kept->state.x, kept->state.y, 0);
    kept->push_point_world = p;
    mean = WrenchFromForceAt(mean.fx, mean.fy, mean.fz, p.x() - kept->state.x,
                             p.y() - kept->state.y, p.z() - com_height_m);
  }
  kept->applied = mean;
}

/// Every k-th row; step columns summarise the simulated steps of each log interval.
std::vector<TrajectorySample> Decimate(const std::vector<TrajectorySample>& rows, int k,
                                       bool mean_wrench, double com_height_m) {
  std::vector<TrajectorySample> out;
  if (rows.empty()) return out;
  out.reserve(rows.size() / k + 1);
  auto hold = [&](size_t first, TrajectorySample* kept) {
    if (mean_wrench) HoldMeanWrench(rows, first, k, com_height_m, kept);
  };
  out.push_back(rows.front());
  hold(0, &out.back());
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
    hold(end, &kept);
    out.push_back(kept);
  }
  return out;
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
    log.samples = Decimate(simulated.samples, spec.log_every, spec.mean_wrench,
                           simulated.slider.com_height_m);
    log.extra_metadata.emplace_back("log_every", std::to_string(spec.log_every));
    if (spec.mean_wrench) log.extra_metadata.emplace_back("log_wrench", "mean");
    if (log.samples.size() >= 2) {
      log.extra_metadata.emplace_back("log_dt",
                                      Format(log.samples[1].t_s - log.samples[0].t_s));
    }
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
