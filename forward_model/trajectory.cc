#include "forward_model/trajectory.h"

namespace slideid {

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

void SetVelocitiesFromPoses(Trajectory* log) {
  auto& samples = log->samples;
  for (std::size_t u = 0; u < samples.size(); ++u) {
    PlanarState& b = samples[u].state;
    if (StartsRun(*log, u)) {
      b.vx = b.vy = b.wz = 0.0;
      continue;
    }
    const PlanarState& a = samples[u - 1].state;
    const double dt = samples[u].t_s - samples[u - 1].t_s;
    b.vx = (b.x - a.x) / dt;
    b.vy = (b.y - a.y) / dt;
    b.wz = (b.theta - a.theta) / dt;
  }
}

}  // namespace slideid
