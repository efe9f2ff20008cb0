#include "io/row_times.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "estimator/log_diagnostics.h"
#include "estimator/robust_statistics.h"

namespace slideid {
namespace {

// A row moves well clear of the poses' noise where its neighbours' median step is this many
// times that noise (estimator/log_diagnostics.h: index-based, so jittered times do not
// enter), so that the noise moves its relative step by a tenth at most.
constexpr double kMovingOverNoise = 10.0;
// The neighbours a row's step is compared with: this many on each side, within its run.
constexpr int kStepNeighbours = 2;

// Slope of y on x by least squares (NaN where x does not vary).
double Slope(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= static_cast<double>(x.size());
  my /= static_cast<double>(y.size());
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  return sxx > 0 ? sxy / sxx : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

RowTimesSpread MeasureRowTimes(const Trajectory& log) {
  RowTimesSpread s;
  s.median_interval_s = MedianInterval(log);
  const double h = s.median_interval_s;
  if (!(h > 0)) return s;
  const std::size_t n = log.samples.size();
  std::vector<double> deviation;
  for (std::size_t u = 1; u < n; ++u) {
    if (!StartsRun(log, u))
      deviation.push_back(std::abs(log.samples[u].t_s - log.samples[u - 1].t_s - h));
  }
  s.spread = kMadToSigma * Median(deviation) / h;
  if (!(s.spread >= kRowTimesSpreadToCheck) || !log.measured.pose) return s;
  // step[u]: the translation over the interval ending at row u (NaN at a run's start).
  std::vector<double> step(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t u = 1; u < n; ++u) {
    if (StartsRun(log, u)) continue;
    const PlanarState& a = log.samples[u - 1].state;
    const PlanarState& b = log.samples[u].state;
    step[u] = std::hypot(b.x - a.x, b.y - a.y);
  }
  const double noise = DiagnoseLog(log).pose_noise_m;  // NaN: no row counts as moving
  std::vector<double> local(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t u = 1; u < n; ++u) {
    std::vector<double> around;
    for (int k = -kStepNeighbours; k <= kStepNeighbours; ++k) {
      const std::ptrdiff_t v = static_cast<std::ptrdiff_t>(u) + k;
      if (v >= 1 && v < static_cast<std::ptrdiff_t>(n) && std::isfinite(step[v])) {
        around.push_back(step[v]);
      }
    }
    if (around.size() < 3 || !std::isfinite(step[u])) continue;
    local[u] = Median(around);
  }
  std::vector<double> interval, relative_step;
  for (std::size_t u = 1; u < n; ++u) {
    if (!(local[u] > kMovingOverNoise * noise) || !(local[u] > 0)) continue;
    interval.push_back((log.samples[u].t_s - log.samples[u - 1].t_s) / h);
    relative_step.push_back(step[u] / local[u]);
  }
  s.moving_rows = static_cast<int>(interval.size());
  if (s.moving_rows >= kMinRowTimesMovingRows) s.step_slope = Slope(interval, relative_step);
  return s;
}

bool TimesLookStampedOnArrival(const RowTimesSpread& s) {
  return s.spread >= kRowTimesSpreadToCheck && s.step_slope < kStampedSlope;
}

void PutRowsOnRegularTimes(Trajectory* log) {
  for (const auto& [first, last] : Runs(*log)) {
    if (last <= first) continue;
    const double t0 = log->samples[first].t_s, t1 = log->samples[last].t_s;
    const double h = (t1 - t0) / (last - first);
    for (int u = first + 1; u < last; ++u) log->samples[u].t_s = t0 + (u - first) * h;
  }
}

}  // namespace slideid
