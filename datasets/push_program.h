#pragma once
// Push programs: a sequence of pushes with rest periods between them, so that a log holds
// stick-slip transitions, rotation and varied directions. A random program draws each push
// from ranges, reproducibly by seed ([program] section of a scene; make-dataset).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "forward_model/contact_patch.h"
#include "forward_model/scene.h"
#include "forward_model/slider.h"

namespace slideid {

/// A closed interval [lo, hi] (lo <= hi) that a value is drawn from uniformly.
struct ValueRange {
  double lo = 0.0;
  double hi = 0.0;
};

/// How a random program draws its pushes. Each push: a point uniformly on the patch boundary
/// (body frame); a direction from it towards the CM, turned by a random angle within
/// `spread_rad` but at most so far that the line of action passes within
/// `max_lever_fraction` times the patch radius of the CM (pushes are body-fixed: a long
/// lever would spin the slider up like a thruster); a height; a constant force plus a
/// cosine of amplitude `amplitude_fraction` times it; a duration; then a rest with no push.
/// Pushes from all round the boundary give varied directions (b), the lever gives rotation
/// (c), the rests stick-slip transitions. Unset ranges take defaults scaled to the slider.
struct RandomProgramSpec {
  int count = 6;  ///< number of pushes (1 to kMaxCount)
  static constexpr int kMaxCount = 10000;
  std::uint64_t seed = 1;
  /// Constant part of the push [N]. Default: 1.1 to 1.6 times the sliding limit a m g.
  std::optional<ValueRange> force_n;
  ValueRange amplitude_fraction{0.0, 0.3};  ///< cosine amplitude / constant force
  ValueRange period_s{0.15, 0.5};           ///< cosine period [s]
  ValueRange duration_s{0.2, 0.6};          ///< how long each push lasts [s]
  ValueRange rest_s{0.2, 0.5};              ///< rest after each push [s]
  /// Height of the push point [m]. Default: 0.25 to 0.75 times com_height (low pushes
  /// keep the ECP inside the patch).
  std::optional<ValueRange> height_m;
  double spread_rad = 0.5;  ///< half-width of the direction's spread about the CM [rad]
  /// Largest distance of the line of action from the CM, as a fraction of the patch radius
  /// (the largest distance of its outline from the CM).
  double max_lever_fraction = 0.08;
  /// Aim every push at the CM at CM height: no moment about any axis, so no rotation (a
  /// log in which c is not identifiable).
  bool through_cm = false;
  double start_s = 0.0;  ///< when the first push starts [s]
  /// When > 0, pushes start and stop on multiples of this period [s], less `grid_lead_s`:
  /// a robot commands its pusher at its control rate, and a log at that rate then holds
  /// each row's force over exactly the interval in which it acts.
  double time_grid_s = 0.0;
  /// How far before each grid time the push switches [s] (half a simulation step, so
  /// that rounding of the simulated times cannot move the switch by a whole step).
  double grid_lead_s = 0.0;

  /// False (and why) for count < 1, lo > hi, negative durations, spread outside [0, pi/2],
  /// max_lever_fraction outside [0, 1].
  bool IsValid(std::string* why) const;
};

/// A drawn program and the time at which it ends (last push's stop plus its rest) [s].
struct PushProgram {
  std::vector<PushSpec> pushes;
  double end_s = 0.0;
};

/// Draws a random program for a slider with this patch, properties and friction (a and
/// com_height only set the default force and height ranges). Deterministic: one spec
/// (including its seed) gives one program. Throws std::invalid_argument for an invalid spec.
PushProgram RandomPushProgram(const RandomProgramSpec& spec, const ContactPatch& patch,
                              const SliderProperties& slider, const ReducedFriction& friction);

}  // namespace slideid
