#pragma once
// What the estimator tests share: scenes with names, poses-only logs through the CSV
// reader, and the check that an estimate recovers the truth.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "io/push_log.h"
#include "tests/synthetic_scenes.h"

namespace slideid::testing {

// Simulated logs carry exact velocities and impulses, so every estimator fits them exactly
// up to the step solver's convergence and rounding; 1e-6 relative leaves room for both.
constexpr double kExactRelTol = 1e-6;

/// A path in a directory made once per test process (ctest runs processes in parallel).
inline std::string TempPath(const std::string& name) {
  static const std::string dir = [] {
    std::string pattern = ::testing::TempDir() + "slideid_test_XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    return pattern;
  }();
  return dir + "/" + name;
}

/// The log with velocities dropped, written and read back: the reader derives them from
/// the poses, as it does for a motion-capture log.
inline Trajectory PosesOnly(const Trajectory& log, const std::string& name) {
  Trajectory poses = log;
  poses.columns.velocity = false;
  const std::string path = TempPath(name);
  WritePushLog(poses, path);
  LogReadReport report;
  Trajectory read = ReadPushLog(path, {}, &report);
  EXPECT_TRUE(report.velocities_from_poses);
  return read;
}

/// Every parameter identifiable, within kExactRelTol of the truth, inside a positive CI.
inline void ExpectRecovers(const EstimateResult& r, const ReducedFriction& truth,
                           const std::string& what) {
  EXPECT_TRUE(r.converged) << what << ": " << r.message;
  const double expected[3] = {truth.a, truth.b, truth.c};
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    ASSERT_TRUE(p.identifiable) << what << " " << ParameterName(i) << ": " << p.note;
    EXPECT_NEAR(p.value / expected[i], 1.0, kExactRelTol)
        << what << " " << ParameterName(i) << " = " << p.value << ", truth " << expected[i];
    EXPECT_GT(p.ci95_lo, 0.0);
    EXPECT_LE(p.ci95_lo, p.value);
    EXPECT_GE(p.ci95_hi, p.value);
  }
}

/// Every parameter identifiable, its standard error at most `max_rel_stderr` of the truth,
/// and the estimate within `n_sigmas` of its standard errors of the truth.
inline void ExpectWithinStandardErrors(const EstimateResult& r, const ReducedFriction& truth,
                                       double max_rel_stderr, double n_sigmas,
                                       const std::string& what) {
  const double expected[3] = {truth.a, truth.b, truth.c};
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    ASSERT_TRUE(p.identifiable) << what << " " << ParameterName(i);
    EXPECT_LE(p.stderr_value / expected[i], max_rel_stderr) << what << " " << ParameterName(i);
    EXPECT_LE(std::abs(p.value - expected[i]), n_sigmas * p.stderr_value)
        << what << " " << ParameterName(i) << " = " << p.value << " +- " << p.stderr_value
        << ", truth " << expected[i];
  }
}

struct NamedScene {
  const char* name;
  Scene scene;
};

/// The scenes: free slide with spin, pushed, tilting moments, anisotropic b != 1.
inline std::vector<NamedScene> FullyIdentifiableScenes() {
  return {{"FreeSlideWithSpin", FreeSlideWithSpin()},
          {"PushedSlider", PushedSlider()},
          {"TiltingPush", TiltingPush()},
          {"Anisotropic", Anisotropic()}};
}

}  // namespace slideid::testing
