#pragma once
// Synthetic MIT push-dataset recordings made by our simulator, with known friction and every
// known defect of the real files available on demand (docs/real-data.md): what the tests of
// the importer use instead of the third-party files. A square plate is pushed at a
// body-fixed point of one edge along a body-fixed direction; the streams sample the
// simulation on their own clocks:
//  - object_pose: the CM pose (the MIT object frame is centred), theta wrapped to (-pi, pi];
//  - tip_pose: the pusher centre, one tip radius outside the edge at the push point (the
//    contact point minus the radius along the inward normal); still before and after;
//  - ft_wrench: minus the applied force (the reaction on the sensor) or the force itself,
//    plus an offset that drifts linearly from its value before to its value after the push.
// The result is plain data (io/mit_push_recording.h); writing it goes through io/.

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

#include "forward_model/scene.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"
#include "io/mit_push_recording.h"

namespace slideid {

/// Defects of the real files, injected on demand (all off by default).
struct MitSynthDefects {
  int backward_steps = 0;  ///< object_pose rows swapped with their successor (unsorted)
  int duplicate_rows = 0;  ///< object_pose and tip_pose rows each written twice
  /// From each (time [s after the start], k), theta is reported turned by k pi/2 (a
  /// symmetric marker set re-assigned); the latest entry before a row applies.
  std::vector<std::pair<double, int>> quarter_turns;
  bool dead_force = false;  ///< every ft_wrench row repeats the first one
  double saturation_n = 0;  ///< > 0: fx and fy clipped to +-saturation_n
  /// object_pose rows in [first, second) [s after the start] dropped (motion-capture gaps).
  std::vector<std::pair<double, double>> pose_gaps;
  /// Every glitch_every-th object pose (0: none) is moved glitch_m away in x: a marker swap.
  int glitch_every = 0;
  double glitch_m = 5.0;
  /// Stored force turned by this angle [rad] (a wrong sensor frame).
  double force_frame_rad = 0;
  /// Tip moved this far further out along the edge normal [m] (a pusher that misses).
  double tip_clearance_m = 0;
};

struct MitSynthSpec {
  /// 90 mm x 90 mm x 13 mm steel plate (like the MIT rect1; mass from its geometry).
  SliderProperties slider{0.835, 0.835 * (0.09 * 0.09 + 0.09 * 0.09) / 12.0, 0.0065, 9.81};
  ReducedFriction friction{0.3, 1.2, 0.035};  ///< c [m]
  double side_m = 0.09;                       ///< the square's side [m]
  /// Where the pusher acts, on an edge (body frame) [m], and the direction it pushes.
  Eigen::Vector2d push_point_body{-0.045, -0.02};
  Eigen::Vector2d push_direction_body{1.0, 0.2};
  /// Push magnitude: mu m g (force_ratio + amplitude_ratio cos(2 pi t / period)), at least
  /// 0: slides and sticks in turn, turns about 0.3 rad, at 0.05-0.2 m/s like the real pushes.
  double force_ratio = 1.0, amplitude_ratio = 0.6, period_s = 0.3;
  double rest_before_s = 0.3;  ///< still, touching, before the push [s]
  double push_s = 0.9;         ///< push duration [s]
  double rest_after_s = 0.4;   ///< after the push; the tip stays where it stopped [s]
  /// Before and after the push the tip stands this much farther from the outline [m]
  /// (0: it rests against the object, as the MIT pushes start).
  double rest_clearance_m = 0.0;
  /// Before the push the tip presses the object with this force along the push direction
  /// [N] (a pre-load; below what friction holds, so the object stays still).
  double preload_n = 0.0;
  double sim_dt_s = 1e-3;
  Eigen::Vector3d initial_pose{0.35, -0.05, 3.0};  ///< x, y [m], theta [rad] (crosses pi)
  double object_rate_hz = 200, tip_rate_hz = 237, ft_rate_hz = 250;
  double clock_jitter = 0.1;  ///< each interval is (1 + U(-j, j)) / rate
  /// The tip and force streams start this much later and end this much earlier [s]: the
  /// streams do not cover the same span.
  double stream_inset_s = 0.02;
  double t_epoch_s = 1476728847.0;  ///< Unix time of the start
  double tip_radius_m = 0.00475;
  double pose_noise_m = 3e-4, angle_noise_rad = 3e-3;  ///< motion capture
  double tip_noise_m = 1e-5;                           ///< robot
  double force_noise_n = 0.05;                         ///< per force sample
  Eigen::Vector2d offset_before_n{-1.5, -0.5}, offset_after_n{-1.5, -0.5};
  bool store_reaction = true;  ///< ft_wrench holds minus the force on the object
  MitSynthDefects defects;
  std::uint64_t seed = 1;
};

/// A recording and the truth it was made from.
struct MitSynthResult {
  MitPushRecording recording;
  Scene scene;           ///< what was simulated (friction: the truth)
  Trajectory simulated;  ///< one row per simulated step, times from the start [s]
};

/// Simulates the push and samples the streams. Deterministic by spec.seed. Throws
/// std::invalid_argument when the spec is unusable (a push point off the edges, a
/// simulation that fails: the message says why).
MitSynthResult MakeMitPushRecording(const MitSynthSpec& spec);

}  // namespace slideid
