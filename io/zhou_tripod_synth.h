#pragma once
// Synthetic tripod logs (io/zhou_tripod_log.h) from simulated spring pushes
// (datasets/quasi_static_synth.h): what the ICRA 2016 rig would have recorded of the same
// pushes, through the inverse of the importer's conventions (io/zhou_tripod_import.h),
// with sensor noise and a sensor bias. For tests of the importer against the truth.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "datasets/quasi_static_synth.h"
#include "io/zhou_tripod_log.h"

namespace slideid {

/// How the synthetic rig records.
struct TripodSynthOptions {
  std::uint64_t seed = 1;
  double force_noise_n = 0.005;  ///< Gaussian, per sensor axis [N] (the logs: 0.002-0.02)
  /// Sensor bias [N], sensor frame, in every sample (the importer removes the first sample).
  Eigen::Vector2d sensor_bias_n = Eigen::Vector2d(0.03, -0.03);
  double pose_noise_mm = 0.0;      ///< Gaussian on the Vicon positions [mm]
  double object_z_mm = 10.0;       ///< Vicon height of the block frame [mm]
  double tool_z_mm = 20.0;         ///< tool height [mm]
  double start_time_s = 1.4398e9;  ///< clock of the first sample (Unix time, as the logs)
};

/// One push of the log per simulated push, the pushes' object outline being the tripod
/// block's. Throws std::invalid_argument for invalid options.
TripodLog TripodLogFromPushes(const std::vector<SimulatedPush>& pushes,
                              const TripodSynthOptions& options = {});

/// The spec that draws pushes on the tripod block (outline, mass, the README's inertia
/// estimate) with the given friction: speed 2.5 mm/s, 1.5 s before contact, 4.5 s of push,
/// as in the logs.
QuasiStaticSynthSpec TripodSynthSpec(const ReducedFriction& friction, int pushes,
                                     std::uint64_t seed);

}  // namespace slideid
