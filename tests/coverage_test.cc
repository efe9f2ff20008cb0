// Calibration of the trajectory fit's 95% intervals (issue 11), on a CI-sized part of the
// coverage suite (benchmarks/coverage.cc, datasets/coverage_conditions.h): 200 short logs per
// condition (about 2.5 s each), each with its own slider, friction, push program and noise,
// fixed seeds. The
// intervals must hold the truth in 90-98% of the logs for every parameter: fewer claims
// more than the fit knows, more claims less.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "datasets/coverage_conditions.h"
#include "estimator/identify.h"

namespace slideid {
namespace {

constexpr int kLogs = 200;
// The band of issue 11. A calibrated 95% interval lands in it with probability 0.98 on 200
// logs (binomial: 95% +- 1.5%), 0.95 on 100; the seeds are fixed, so the test is
// deterministic. Measured when written: 95 / 94 / 97.5%, 93 / 96 / 96.5% and 91.5 / 93.5 /
// 96.5% for a / b / c in the three conditions below.
constexpr double kLow = 0.90, kHigh = 0.98;

struct Coverage {
  std::array<int, 3> intervals{}, covered{};
  int failed = 0;
};

Coverage Measure(const CoverageCondition& condition) {
  Coverage c;
  IdentifyOptions options;
  options.method = EstimatorMethod::kTrajectory;
  for (int k = 0; k < kLogs; ++k) {
    const CoverageLog made = MakeCoverageLog(condition, k);
    const EstimateResult r = Identify(made.log, options);
    if (r.status == TerminationStatus::kTooLittleExcitation) {
      ++c.failed;
      continue;
    }
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      if (!p.identifiable || !std::isfinite(p.ci95_lo) || !std::isfinite(p.ci95_hi)) continue;
      ++c.intervals[i];
      c.covered[i] += p.ci95_lo <= made.truth[i] && made.truth[i] <= p.ci95_hi;
    }
  }
  return c;
}

void ExpectCalibrated(const CoverageCondition& condition) {
  const Coverage c = Measure(condition);
  EXPECT_EQ(c.failed, 0) << condition.name;
  for (int i = 0; i < 3; ++i) {
    // Every log of the suite slides, turns and changes direction: each parameter is
    // identified in (nearly) all of them, so the coverage is not bought by abstaining.
    ASSERT_GE(c.intervals[i], kLogs - 2) << condition.name << " " << ParameterName(i);
    const double coverage = double(c.covered[i]) / c.intervals[i];
    EXPECT_GE(coverage, kLow) << condition.name << " " << ParameterName(i);
    EXPECT_LE(coverage, kHigh) << condition.name << " " << ParameterName(i);
  }
}

TEST(Coverage, TrajectoryIntervalsHoldTheTruthOnShortLogsSimulatedAtTheLogRate) {
  CoverageCondition c = FindCoverageCondition("exact-rate");
  c.rows = 300;
  ExpectCalibrated(c);
}

TEST(Coverage, TrajectoryIntervalsHoldTheTruthOnShortLogsSimulatedFinerThanLogged) {
  ExpectCalibrated(FindCoverageCondition("short-300"));
}

TEST(Coverage, TrajectoryIntervalsHoldTheTruthOnShortLogsWithNoisyForcesAndPushPoints) {
  ExpectCalibrated(FindCoverageCondition("users"));
}

}  // namespace
}  // namespace slideid
