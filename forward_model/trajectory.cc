#include "forward_model/trajectory.h"

namespace slideid {

void SetVelocitiesFromPoses(Trajectory* log) {
  auto& samples = log->samples;
  if (samples.empty()) return;
  samples.front().state.vx = samples.front().state.vy = samples.front().state.wz = 0.0;
  for (std::size_t u = 1; u < samples.size(); ++u) {
    const PlanarState& a = samples[u - 1].state;
    PlanarState& b = samples[u].state;
    const double dt = samples[u].t_s - samples[u - 1].t_s;
    b.vx = (b.x - a.x) / dt;
    b.vy = (b.y - a.y) / dt;
    b.wz = (b.theta - a.theta) / dt;
  }
}

}  // namespace slideid
