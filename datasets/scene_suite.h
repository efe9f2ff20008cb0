#pragma once
// The randomized scene suite (issue 17): logs drawn far wider than the coverage conditions
// (datasets/coverage_conditions.h), to ask what another lab's logs would look like. Each
// log draws, from its own seed:
//   - a slider: a box, a disk, a ring, a tall box (CM high over a small footprint, so the
//     patch's pressure tilts) or a flat box with its CM in the table plane (q_z = 0);
//   - isotropic or anisotropic friction;
//   - a motion: a free slide thrown with spin (no push), pushes with rests between them
//     (sticking) or pushes back to back (no rest);
//   - a length of 100 to 10,000 rows (log-uniform; a free slide at most as long as it
//     slides, plus a little rest) at 100 to 1000 Hz, simulated 1 to 10 times finer;
//   - poses only, or poses with velocities;
//   - motion-capture noise, 0-3% force noise, push-point noise, and in some logs outliers.
// Deterministic by (seed, index). benchmarks/scene_suite.cc runs the full suite and
// tests/scene_suite_test.cc a CI-sized part of it.

#include <array>
#include <cstdint>
#include <string>

#include "datasets/logged_scene.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// The seed of the suite's logs (the full suite and its CI-sized part draw the same logs).
constexpr std::uint64_t kSceneSuiteSeed = 20261125;

/// Limits of what a suite log is drawn from.
struct SceneSuiteLimits {
  int min_rows = 100;
  int max_rows = 10000;
  /// Multiplies every noise level after it is drawn (the draws stay the same): 0 gives the
  /// same log without noise, to tell a bias of the noise from one of the model.
  double noise_scale = 1.0;
};

/// How a suite log moves.
enum class SuiteMotion { kFreeSlide, kPushesWithRests, kPushesBackToBack };
const char* ToString(SuiteMotion motion);  ///< "free slide", "pushes+rests", "pushes"

/// One suite log and what it was made from.
struct SuiteLog {
  Trajectory log;
  LoggedScene scene;  ///< what `log` was made from (its file's metadata: io/simulated_log.h)
  std::array<double, 3> truth{};  ///< (a, b, c [m])
  SuiteMotion motion = SuiteMotion::kPushesWithRests;
  std::string slider;     ///< "box", "disk", "ring", "tall box", "flat box"
  double rate_hz = 100;   ///< log rate
  bool outliers = false;  ///< the log carries motion-capture outliers
  /// One line without commas: the slider, motion, rows, rate and noise.
  std::string Describe() const;
};

/// Log `index` of the suite. A draw that tips, lifts or fails to simulate is redrawn (with
/// the same index and a further attempt number); throws std::runtime_error after 50.
SuiteLog MakeSuiteLog(int index, std::uint64_t seed = kSceneSuiteSeed,
                      const SceneSuiteLimits& limits = {});

}  // namespace slideid
