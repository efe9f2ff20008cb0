#pragma once
// The conditions of the interval-coverage suite (issue 11; benchmarks/coverage.cc and
// tests/coverage_test.cc): ways of making synthetic logs that users' data meet, each one
// change from a base of 100 Hz motion-capture poses of a 1 kHz simulation. Every log is
// drawn by DrawDatasetLog (datasets/dataset.h) from the dataset defaults, so a condition's
// logs hold varied sliders, friction and push programs, deterministically by seed.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "datasets/log_spec.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// How one condition's logs are made.
struct CoverageCondition {
  std::string name;
  std::string what;    ///< one line for tables
  int rows = 1000;     ///< rows of every log (the simulated log is cut to this)
  int log_every = 10;  ///< simulated steps per 10 ms log interval (1: the fit's model is exact)
  bool mean_wrench =
      false;  ///< log each interval's mean wrench (LogWrench::kIntervalMean, push = moments)
  LogMotion motion = LogMotion::kPoses;
  NoiseSpec noise;  ///< its seed is drawn per log
};

/// Log interval of every condition: 100 Hz, a common motion-capture rate [s].
constexpr double kCoverageLogDt_s = 0.01;
/// The dataset seed of the suite: conditions of one length share sliders, friction and
/// push programs (and noise streams).
constexpr std::uint64_t kCoverageSeed = 20261;

/// The base (`base`: 1000 rows of poses with 0.3 mm and 3 mrad noise, simulated at 1 ms,
/// forces exact), the control simulated at the log rate (`exact-rate`), and one condition
/// per factor of issue 11: `finer-0.1ms`, `force-1%`, `force-3%`, `push-point` (0.4 mm),
/// `short-300`, `long-3000`, `poses+velocities`, `outliers`, and `users` (300 rows, 2% force
/// and 0.4 mm push-point noise together).
std::vector<CoverageCondition> CoverageConditions();

/// The condition of that name; throws std::invalid_argument naming it when there is none.
CoverageCondition FindCoverageCondition(const std::string& name);

/// One log of a condition and the truth (a, b, c [m]) it was made with.
struct CoverageLog {
  Trajectory log;
  std::array<double, 3> truth{};
};

/// Log `index` of `condition`, drawn from `seed`. Throws std::runtime_error when the draw
/// fails (DrawDatasetLog) or the simulation is shorter than the condition's rows.
CoverageLog MakeCoverageLog(const CoverageCondition& condition, int index,
                            std::uint64_t seed = kCoverageSeed);

}  // namespace slideid
