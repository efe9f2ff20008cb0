#pragma once
// Synthetic quasi-static pushes: a slider pushed slowly by a point finger, simulated step by
// step with the forward model (forward_model/step_solver.h), and the wrench-twist pairs
// formed from them as an importer forms them from a real log. The finger is a stiff
// spring-damper from a tip moving on a straight line at a few mm/s to a point fixed on the
// slider's edge (a finger that does not slip), engaged once the tip reaches that point.
// Pushes follow each other from where the previous one left the slider, as in the tripod
// experiments. Deterministic by seed (std::mt19937_64; another standard library may change
// the draws).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "forward_model/planar_state.h"
#include "forward_model/slider.h"
#include "forward_model/step_solver.h"
#include "forward_model/wrench_twist_pair.h"

namespace slideid {

/// One push by the finger.
struct SpringPush {
  Eigen::Vector2d contact_body_m = Eigen::Vector2d::Zero();  ///< finger point, body frame [m]
  /// Direction the tip moves, in the body frame at the push start (normalised on use).
  Eigen::Vector2d direction_body = Eigen::Vector2d::UnitX();
  double speed_mps = 0.003;  ///< tip speed [m/s]
  double rest_s = 1.0;       ///< the tip travels this long before it reaches the point [s]
  double push_s = 4.0;       ///< then pushes this long, and stops: the trace ends [s]
};

/// How pushes are simulated and sampled.
struct SpringPushOptions {
  /// Finger stiffness [N/m]: 2e4 deflects 0.2 mm at 4 N, so the tip stays on the edge as
  /// the tripod's finger does, and loads 4 N in 0.08 s at 2.5 mm/s (the tripod's force
  /// traces reach half their force 0.02 to 0.14 s after contact, median 0.05 s).
  double stiffness_npm = 2e4;
  /// Finger damping [N s/m]; a negative value means critical damping of the slider's mass,
  /// 2 sqrt(k m), which keeps the stick-slip ringing of an undamped spring out of the forces.
  double damping_nspm = -1.0;
  /// Simulation step [s]. The spring is explicit in the step: stable while
  /// dt sqrt(k / m_eff) << 2, with m_eff down to ~0.3 m at an edge far from the CM
  /// (sqrt(2e4 / 0.45) * 1e-3 = 0.21 for the tripod block).
  double dt_s = 1e-3;
  double force_rate_hz = 100.0;  ///< force samples per second (the tripod's F/T: ~100 Hz)
  double robot_rate_hz = 33.0;   ///< tool poses per second (the tripod's robot: ~33 Hz)
  StepOptions step;

  bool IsValid(std::string* why) const;
};

/// A simulated push: what a sensor records, and the pair formed from the simulation.
struct SimulatedPush {
  PlanarState start, end;                      ///< slider at rest before, and where it ends (world)
  std::vector<double> force_t_s;               ///< force sample times from the trace start [s]
  std::vector<Eigen::Vector2d> force_world_n;  ///< finger force on the slider, world [N]
  std::vector<double> tool_t_s;                ///< tool sample times [s]
  std::vector<Eigen::Vector2d> tool_world_m;   ///< tip position, world [m]
  double tool_yaw_rad = 0;                     ///< the tool points along the push direction
  /// The pair from the simulation itself: the body-frame wrench (moment about the CM)
  /// averaged over the steps in which the slider slides, and the constant body twist that
  /// carries `start` to `end` (the SE(2) logarithm) over those steps' span; the diagnostics
  /// (pose change, contact point, peak force, steps averaged) filled in.
  WrenchTwistRow row;
  /// The same in the world frame (the frame of the model's t, o axes: model.md): the
  /// world-frame wrench averaged over the sliding steps, the CM's mean world velocity and
  /// the mean spin over their span; contact point and pose change left unknown.
  WrenchTwistRow world_row;
  int slide_steps = 0, stick_steps = 0;
  double max_speed_mps = 0;  ///< largest CM speed: quasi-static means a few mm/s
};

/// Simulates one push from `start` (at rest). Throws std::invalid_argument for invalid
/// properties, options or a push that never slides the slider; a step that does not
/// converge is a std::runtime_error naming its time.
SimulatedPush SimulateSpringPush(const SliderProperties& slider, const ReducedFriction& friction,
                                 const PlanarState& start, const SpringPush& push,
                                 const SpringPushOptions& options = {});

/// What to draw for a series of pushes on a polygonal slider.
struct QuasiStaticSynthSpec {
  SliderProperties slider;  ///< com_height is taken as 0: the ECP stays under the CM
  ReducedFriction friction;
  /// The slider's outline in the body frame (from the CM), counter-clockwise [m]; the finger
  /// touches a random edge at a random point of its middle 70%.
  std::vector<Eigen::Vector2d> outline;
  int pushes = 20;
  std::uint64_t seed = 1;
  /// The tip moves within this angle of the edge's inward normal [rad] (the finger's
  /// friction cone; the tripod's finger pushes up to ~30 deg off the normal).
  double max_angle_rad = 0.5;
  /// Aim every push at the CM (no moment): pure translation when b = 1.
  bool aim_at_cm = false;
  double speed_mps = 0.003;  ///< tip speed [m/s]
  double rest_s = 1.0;       ///< [s]
  double push_s = 4.0;       ///< [s]
  SpringPushOptions options;

  bool IsValid(std::string* why) const;
};

/// Simulates `spec.pushes` pushes in sequence from the origin. Throws as SimulateSpringPush.
std::vector<SimulatedPush> SimulateSpringPushes(const QuasiStaticSynthSpec& spec);

/// The frame pairs are written in.
enum class PairFrame {
  kBody,   ///< the slider's frame at each push start (what the tripod importer writes)
  kWorld,  ///< the world frame: b is then the anisotropy along the world axes, as simulated
};

/// The pushes' rows (push numbered from 1) in `frame` with the slider's properties and the
/// truth.
WrenchTwistData PairsFromPushes(const QuasiStaticSynthSpec& spec,
                                const std::vector<SimulatedPush>& pushes,
                                PairFrame frame = PairFrame::kBody);

/// Exact pairs of the model (QuasiStaticWrench) for the given twists, normal force m g.
WrenchTwistData ExactQuasiStaticPairs(const std::vector<Eigen::Vector3d>& twists,
                                      const SliderProperties& slider,
                                      const ReducedFriction& friction);

}  // namespace slideid
