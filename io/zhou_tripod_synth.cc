#include "io/zhou_tripod_synth.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include "io/zhou_tripod_import.h"

namespace slideid {
namespace {

Eigen::Matrix2d Rotation(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

}  // namespace

TripodLog TripodLogFromPushes(const std::vector<SimulatedPush>& pushes,
                              const TripodSynthOptions& options) {
  if (!(options.force_noise_n >= 0.0 && options.pose_noise_mm >= 0.0) ||
      !options.sensor_bias_n.allFinite()) {
    throw std::invalid_argument("TripodLogFromPushes: noise must be >= 0, the bias finite");
  }
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto vicon = [&](const PlanarState& q) {
    TripodPose p = TripodViconPose(Eigen::Vector3d(q.x, q.y, q.theta), options.object_z_mm);
    p.x_mm += options.pose_noise_mm * gauss(rng);
    p.y_mm += options.pose_noise_mm * gauss(rng);
    return p;
  };
  TripodLog log;
  double clock = options.start_time_s;
  for (const SimulatedPush& sim : pushes) {
    TripodPush push;
    push.pre = vicon(sim.start);
    push.post = vicon(sim.end);
    const Eigen::Matrix2d to_tool = Rotation(-sim.tool_yaw_rad);
    for (std::size_t i = 0; i < sim.force_t_s.size(); ++i) {
      const Eigen::Vector2d sensor =
          TripodSensorForce(to_tool * sim.force_world_n[i]) + options.sensor_bias_n +
          options.force_noise_n * Eigen::Vector2d(gauss(rng), gauss(rng));
      push.forces.push_back({clock + sim.force_t_s[i], sensor.x(), sensor.y(), 0});
    }
    const double half = sim.tool_yaw_rad / 2;
    for (std::size_t i = 0; i < sim.tool_t_s.size(); ++i) {
      const Eigen::Vector2d p = 1000.0 * sim.tool_world_m[i];
      push.robot.push_back(
          {clock + sim.tool_t_s[i],
           {p.x(), p.y(), options.tool_z_mm, std::cos(half), 0.0, 0.0, std::sin(half)},
           0});
    }
    log.pushes.push_back(push);
    clock += sim.force_t_s.empty() ? 10.0 : sim.force_t_s.back() + 10.0;
  }
  return log;
}

QuasiStaticSynthSpec TripodSynthSpec(const ReducedFriction& friction, int pushes,
                                     std::uint64_t seed) {
  QuasiStaticSynthSpec spec;
  spec.slider.mass_kg = kTripodMass_kg;
  spec.slider.inertia_kgm2 = kTripodInertiaEstimate_kgm2;
  spec.friction = friction;
  const auto v = TripodBlockVertices();
  spec.outline.assign(v.begin(), v.end());
  spec.pushes = pushes;
  spec.seed = seed;
  spec.speed_mps = 0.0025;
  spec.rest_s = 1.5;
  spec.push_s = 4.5;
  return spec;
}

}  // namespace slideid
