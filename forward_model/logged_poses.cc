#include "forward_model/logged_poses.h"

namespace slideid {

std::vector<PlanarState> LoggedOrIntegratedPoses(const Trajectory& log) {
  std::vector<PlanarState> out;
  for (const TrajectorySample& s : log.samples) out.push_back(s.state);
  if (log.measured.pose) return out;
  for (size_t u = 1; u < out.size(); ++u) {
    const double dt = log.samples[u].t_s - log.samples[u - 1].t_s;
    out[u].x = out[u - 1].x + dt * out[u].vx;
    out[u].y = out[u - 1].y + dt * out[u].vy;
    out[u].theta = out[u - 1].theta + dt * out[u].wz;
  }
  return out;
}

}  // namespace slideid
