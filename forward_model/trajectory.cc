#include "forward_model/trajectory.h"

#include <algorithm>

namespace slideid {

const StepRecord& StepAt(const Trajectory& log, std::size_t row) {
  static const StepRecord kNone;
  return log.steps.empty() ? kNone : log.steps[row];
}

void KeepFirstRows(Trajectory* log, std::size_t rows) {
  if (log->samples.size() > rows) log->samples.resize(rows);
  if (log->steps.size() > rows) log->steps.resize(rows);
}

bool StartsRun(const Trajectory& log, std::size_t row) {
  return row == 0 || log.samples[row].mode == SampleMode::kStart;
}

bool HasGaps(const Trajectory& log) {
  for (std::size_t u = 1; u < log.samples.size(); ++u) {
    if (StartsRun(log, u)) return true;
  }
  return false;
}

std::vector<std::pair<int, int>> Runs(const Trajectory& log) {
  std::vector<std::pair<int, int>> runs;
  const int n = static_cast<int>(log.samples.size());
  for (int u = 0; u < n; ++u) {
    if (StartsRun(log, u)) runs.emplace_back(u, u);
    runs.back().second = u;
  }
  return runs;
}

double MedianInterval(const Trajectory& log) {
  std::vector<double> h;
  for (std::size_t u = 1; u < log.samples.size(); ++u) {
    if (!StartsRun(log, u)) h.push_back(log.samples[u].t_s - log.samples[u - 1].t_s);
  }
  if (h.empty()) return 0.0;
  const std::size_t n = h.size();
  std::nth_element(h.begin(), h.begin() + n / 2, h.end());
  const double upper = h[n / 2];
  if (n % 2 == 1) return upper;
  return 0.5 * (*std::max_element(h.begin(), h.begin() + n / 2) + upper);
}

PlanarState StateWithPoseVelocity(const Trajectory& log, std::size_t row) {
  PlanarState b = log.samples[row].state;
  if (StartsRun(log, row)) {
    b.vx = b.vy = b.wz = 0.0;
    return b;
  }
  const PlanarState& a = log.samples[row - 1].state;
  const double dt = log.samples[row].t_s - log.samples[row - 1].t_s;
  b.vx = (b.x - a.x) / dt;
  b.vy = (b.y - a.y) / dt;
  b.wz = (b.theta - a.theta) / dt;
  return b;
}

void SetVelocitiesFromPoses(Trajectory* log) {
  // Row u's velocity reads the poses of rows u - 1 and u only, which this leaves alone.
  for (std::size_t u = 0; u < log->samples.size(); ++u) {
    log->samples[u].state = StateWithPoseVelocity(*log, u);
  }
}

}  // namespace slideid
