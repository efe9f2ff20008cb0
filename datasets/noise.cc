#include "datasets/noise.h"

#include <cstdio>
#include <random>

namespace slideid {

bool NoiseSpec::IsZero() const {
  return pose_m == 0 && angle_rad == 0 && velocity_mps == 0 && spin_radps == 0 &&
         force_relative == 0 && force_N == 0 && outlier_fraction == 0;
}

std::vector<std::pair<std::string, std::string>> NoiseSpec::Metadata() const {
  std::vector<std::pair<std::string, std::string>> out;
  auto add = [&](const char* key, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    out.emplace_back(key, buf);
  };
  add("noise_pose_m", pose_m);
  add("noise_angle_rad", angle_rad);
  add("noise_velocity_mps", velocity_mps);
  add("noise_spin_radps", spin_radps);
  add("noise_force_relative", force_relative);
  add("noise_force_N", force_N);
  add("noise_outlier_fraction", outlier_fraction);
  add("noise_outlier_m", outlier_m);
  add("noise_seed", static_cast<double>(seed));
  return out;
}

Trajectory AddNoise(const Trajectory& log, const NoiseSpec& noise) {
  Trajectory out = log;
  out.columns.step_info = false;
  for (const auto& entry : noise.Metadata()) out.extra_metadata.push_back(entry);
  std::mt19937_64 rng(noise.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  // Draw every variate in a fixed order whatever the spec, so one seed gives one stream.
  for (TrajectorySample& s : out.samples) {
    const double n[11] = {normal(rng), normal(rng), normal(rng), normal(rng), normal(rng),
                          normal(rng), normal(rng), normal(rng), normal(rng), normal(rng),
                          normal(rng)};
    const double jump = uniform(rng), jump_angle = uniform(rng) * 6.283185307179586;
    s.state.x += noise.pose_m * n[0];
    s.state.y += noise.pose_m * n[1];
    s.state.theta += noise.angle_rad * n[2];
    s.state.vx += noise.velocity_mps * n[3];
    s.state.vy += noise.velocity_mps * n[4];
    s.state.wz += noise.spin_radps * n[5];
    if (jump < noise.outlier_fraction) {
      s.state.x += noise.outlier_m * std::cos(jump_angle);
      s.state.y += noise.outlier_m * std::sin(jump_angle);
      s.state.theta += noise.outlier_m / 0.05 * (n[10] > 0 ? 1 : -1);
    }
    AppliedWrench& w = s.applied;
    if (w.fx != 0 || w.fy != 0 || w.fz != 0) {
      w.fx += noise.force_relative * w.fx * n[6] + noise.force_N * n[7];
      w.fy += noise.force_relative * w.fy * n[8] + noise.force_N * n[9];
    }
    s.pt = s.po = s.pr = s.sigma = 0;
    s.ecp_world.setZero();
  }
  return out;
}

}  // namespace slideid
