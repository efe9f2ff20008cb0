// The default trajectory fit on data it was not tuned on (issue 17): a CI-sized part of the
// randomized scene suite (datasets/scene_suite.h, judged by fixtures/suite_check.h; the full
// suite is benchmarks/scene_suite.cc and docs/scene-suite.md), and the hold-out-like logs of
// the issue (datasets/scenes/holdout_*.ini).
//
// The suite's logs are fixed by their seed, so the counts below are deterministic. They
// guard what the estimator reaches today, measured when written; the goals (99.5%
// in the best basin, 99% within 3 standard errors) are not reached yet and are stated
// beside each threshold.

#include "datasets/scene_suite.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "datasets/sensor_model.h"
#include "estimator/robust_statistics.h"
#include "fixtures/suite_check.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"
#include "io/scene_file.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

constexpr int kLogs = 80;
constexpr int kMaxRows = 1500;

suite::Tally RunSuite() {
  suite::Tally c;
  SceneSuiteLimits limits;
  limits.max_rows = kMaxRows;
  for (int k = 0; k < kLogs; ++k) {
    const SuiteLog made = MakeSuiteLog(k, kSceneSuiteSeed, limits);
    const suite::Outcome o = suite::Judge(made);
    c.Add(o);
    if (!o.determined) continue;
    if (o.max_abs_z > 3 || !o.in_best_basin) {
      std::printf("  log %d (%s): max |z| %.2f, best basin from %s%s\n", k, made.Describe().c_str(),
                  o.max_abs_z, o.best_from.c_str(), o.in_best_basin ? "" : " (default not in it)");
    }
  }
  return c;
}

TEST(SceneSuite, DefaultFitOnWidelyDrawnLogs) {
  const suite::Tally c = RunSuite();
  ASSERT_GE(c.determined, kLogs * 9 / 10) << "too many logs identified nothing";
  const double basin = double(c.basin) / c.determined;
  const double within3 = double(c.within3) / c.determined;
  const double ok_within3 = double(c.ok_within3) / c.determined;
  std::printf(
      "%d logs identified: best basin %.1f%%, within 3 SE %.1f%% (ok ones %.1f%%), "
      "narrow ok %d/%d\n",
      c.determined, 100 * basin, 100 * within3, 100 * ok_within3, c.narrow_ok, c.narrow);
  // Goal 99.5%; measured when written: see the message above and docs/scene-suite.md.
  EXPECT_GE(basin, 0.97);  // 100% (75/75) when written (87.0% as judged before 2026-11-25)
  // Goal 99%.
  EXPECT_GE(within3, 0.97);  // 97.3% (73/75) when written; 100% (75/75) since 2026-11-27
  // Estimates left "ok" (not suspect) beyond 3 standard errors: fewer still.
  EXPECT_GE(ok_within3, within3);
  EXPECT_GE(ok_within3, 0.97);  // 98.7% (74/75) when written, 100% since; goal 99%
  // Goal met: a parameter whose interval is under +-1% is within 1.5%.
  EXPECT_EQ(c.narrow_ok, c.narrow);
  // Coverage: each parameter's at least 88%; over all three (about 210 intervals) at most
  // 99%. One parameter's 70 intervals all hold the truth in 3% of draws even when
  // calibrated at 95% (0.95^70), so an upper bound is asked of the pool, where calibrated
  // intervals exceed 99% with probability 0.15% (binomial, 210 at 95%).
  int intervals = 0, covered = 0;
  for (int i = 0; i < 3; ++i) {
    const double coverage = double(c.covered[i]) / c.intervals[i];
    EXPECT_GE(coverage, 0.88) << ParameterName(i);
    intervals += c.intervals[i];
    covered += c.covered[i];
  }
  EXPECT_LE(double(covered) / intervals, 0.99);
}

// The cross-check (TrajectoryOptions::cross_check): suite log 623, 156 rows of pushing a
// disk at 250 Hz, fits b = 1.314 [1.174, 1.470] for a truth of 1.135 over its default
// segments, an interval that misses the truth; a fit over segments 3 times as long gives
// 1.136, beyond both fits' errors, and the estimate is marked suspect instead of ok.
// (Until 2026-11-27 this was log 471, a free slide of a flat box whose a was 264% off and
// whose interval excluded the truth, and then log 461, whose b of 1.0207 [0.9994, 1.0424]
// for a truth of 1 the long segments' fit put at 0.9988; since the heads of the seed stage
// are in log time, that fit gives 1.0007, within both fits' errors, and 461's interval
// holds the truth.)
TEST(SceneSuite, CrossCheckMarksAnEstimateThatDependsOnTheSegmentation) {
  const SuiteLog made = MakeSuiteLog(623);
  ASSERT_EQ(made.log.samples.size(), 156u) << made.Describe();
  IdentifyOptions options;
  options.trajectory.cross_check = false;
  const EstimateResult unchecked = Identify(made.log, options);
  ASSERT_TRUE(unchecked.parameters[kB].identifiable);
  ASSERT_GT(std::abs(unchecked.parameters[kB].value / made.truth[kB] - 1), 0.015)
      << "the log no longer shows the problem";
  EXPECT_EQ(unchecked.parameters[kB].verdict, Verdict::kOk);
  const EstimateResult checked = Identify(made.log, IdentifyOptions{});
  EXPECT_EQ(checked.parameters[kB].value, unchecked.parameters[kB].value);
  EXPECT_EQ(checked.parameters[kB].verdict, Verdict::kSuspect);
  EXPECT_NE(checked.parameters[kB].reason.find("depends on how the log is cut"), std::string::npos)
      << checked.parameters[kB].reason;
  EXPECT_EQ(checked.status, TerminationStatus::kConvergedWithCaveats);
}

// Rule (iv) of identifiability.h: suite log 100, 0.2 s of pushing a tall box. The fit gives
// up a (standard error 0.87 in logs) and holds it where it stopped; b, computed with a held,
// came out 0.87 [0.74, 1.03] "ok" for a truth of 1.51. With a free over its plausible range
// b is not determined either: every parameter the fit still reports holds the truth.
TEST(SceneSuite, AParameterDeterminedOnlyByHoldingAnotherIsNotReportedAsKnown) {
  const SuiteLog made = MakeSuiteLog(100);
  ASSERT_EQ(made.log.samples.size(), 217u) << made.Describe();
  const EstimateResult r = Identify(made.log, IdentifyOptions{});
  ASSERT_FALSE(r.parameters[kA].identifiable) << "the log no longer shows the problem";
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    if (!p.identifiable) continue;
    EXPECT_TRUE(p.ci95_lo <= made.truth[i] && made.truth[i] <= p.ci95_hi)
        << ParameterName(i) << " " << p.value << " [" << p.ci95_lo << ", " << p.ci95_hi
        << "], truth " << made.truth[i] << "; " << p.note;
  }
}

// The same from the command line: identify marks the estimate, --no-cross-check does not.
// The seed stage's segment heads are 0.2 s of log time (trajectory_fit.cc, kSeedHead_s).
// Until 2026-11-27 they were 20 intervals at any rate: 20 ms at 1 kHz, where the poses'
// noise hides the friction's curvature, and the fit of these two free slides at 1 kHz went
// to another basin: log 9060 (0.8 mm noise) ended at a = 0.0006 and c = 4.6 m for a truth
// of 0.18 and 0.016 m, both suspect; log 7458 at b 98% low, 11.8 standard errors off.
// (7458's a, 46% high, has an interval spanning a factor 7 since the white-noise interval
// takes each channel's own noise (2026-11-28): not determined by its 0.18 s of slide.)
TEST(SceneSuite, HighRateFreeSlidesAreSeededOverHeadsOfLogTime) {
  for (const int index : {9060, 7458}) {
    const SuiteLog made = MakeSuiteLog(index);
    ASSERT_EQ(made.rate_hz, 1000) << made.Describe();
    ASSERT_EQ(made.motion, SuiteMotion::kFreeSlide) << made.Describe();
    const EstimateResult r = Identify(made.log, IdentifyOptions{});
    ASSERT_TRUE(r.parameters[kB].identifiable) << index << ": " << r.parameters[kB].reason;
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      if (!p.identifiable) continue;
      EXPECT_EQ(p.verdict, Verdict::kOk) << index << " " << ParameterName(i) << ": " << p.reason;
      EXPECT_LT(std::abs(p.value - made.truth[i]), 3 * p.stderr_value)
          << index << " " << ParameterName(i) << ": " << p.value << " against " << made.truth[i];
    }
  }
}

// Held-out log 12139 (a flat box pushed with rests, 574 rows at 200 Hz, 8 segments): c's
// information sits in one segment's push, so its cluster-robust variance rests on 1.1
// degrees of freedom, and there it came out at a fifth of the white-noise one, with c 12%
// (5.9 standard errors) off and marked ok. The white-noise floor now applies to such a
// parameter too (kWhiteFloorDegreesOfFreedom), as it did only below 8 segments.
TEST(SceneSuite, AVarianceOnFewDegreesOfFreedomTakesTheWhiteNoiseFloor) {
  const SuiteLog made = MakeSuiteLog(12139);
  const EstimateResult r = Identify(made.log, IdentifyOptions{});
  const ParameterEstimate& c = r.parameters[kC];
  ASSERT_TRUE(c.identifiable) << c.reason;
  EXPECT_NE(c.note.find("taken as its floor"), std::string::npos) << c.note;
  EXPECT_LE(c.ci95_lo, made.truth[kC]) << c.value << " against " << made.truth[kC];
  EXPECT_GE(c.ci95_hi, made.truth[kC]) << c.value << " against " << made.truth[kC];
  EXPECT_LT(std::abs(c.value - made.truth[kC]), 3 * c.stderr_value);
}

TEST(SceneSuite, IdentifyCrossChecksUnlessToldNot) {
  const std::string log = testing::TempPath("suite_623.csv");
  WritePushLog(MakeSuiteLog(623).log, log);
  const testing::ToolRun checked = testing::RunTool("identify", "--log " + log);
  EXPECT_NE(checked.all().find("depends on how the log is cut"), std::string::npos)
      << checked.all();
  const testing::ToolRun unchecked = testing::RunTool("identify", "--no-cross-check --log " + log);
  EXPECT_EQ(unchecked.code, 0) << unchecked.all();
  EXPECT_EQ(unchecked.all().find("depends on how the log is cut"), std::string::npos)
      << unchecked.all();
  const testing::ToolRun wrong =
      testing::RunTool("identify", "--method closed-form --no-cross-check --log " + log);
  EXPECT_NE(wrong.code, 0) << wrong.all();
}

Trajectory HoldOutLog(const std::string& scene_file, ReducedFriction* truth) {
  const LoggedScene scene =
      LoadScene(std::string(SLIDEID_SOURCE_DIR) + "/datasets/scenes/" + scene_file);
  *truth = scene.friction.reduced();
  const SimulationResult sim = Simulate(scene);
  EXPECT_TRUE(sim.summary.ok()) << sim.summary.message;
  return MakeLog(sim.trajectory, scene.log);
}

// The two hold-out-like logs of issue 17, made from settings chosen before any fit looked
// at them. Asked of both: every parameter identified, its 95% interval holding the truth;
// and the goal, every estimate within 1.5%. The pushed one: +0.75% / -0.39% /
// -1.43% since its segments are 0.35 s, not 35 rows, long (+3.5% / -3.4% / -4.1% before).
// The free slide of a disk: -0.56% / +0.23% / +0.32% in 3 segments of 35 intervals with the
// discretization allowance (-1.8% / -2.6% / +0.3% in 5 segments of 19 before; over noise
// seeds 6-12 of its scene, every estimate within 1.54%).
void ExpectHonestIntervals(const std::string& scene_file, double within = 0) {
  ReducedFriction truth;
  const Trajectory log = HoldOutLog(scene_file, &truth);
  const EstimateResult r = Identify(log, IdentifyOptions{});
  ASSERT_TRUE(r.converged) << r.message;
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    ASSERT_TRUE(p.identifiable) << ParameterName(i) << ": " << p.reason;
    EXPECT_TRUE(p.ci95_lo <= truth[i] && truth[i] <= p.ci95_hi)
        << ParameterName(i) << " " << p.value << " [" << p.ci95_lo << ", " << p.ci95_hi
        << "], truth " << truth[i];
    if (within > 0) EXPECT_NEAR(p.value / truth[i], 1.0, within) << ParameterName(i);
    std::printf("%s %s: %+.2f%%\n", scene_file.c_str(), ParameterName(i),
                100 * (p.value / truth[i] - 1));
  }
}

TEST(SceneSuite, HoldOutLikeFreeSlideComesOutWithinItsIntervalsAndOnePointFivePercent) {
  ExpectHonestIntervals("holdout_free_disk.ini", 0.015);
}

// The hold-out-like free slide of issue 17 (datasets/scenes/holdout_free_disk.ini),
// simulated once; its noise is drawn per log (scene.log.noise.seed).
struct HoldOutFreeDisk {
  LoggedScene scene =
      LoadScene(std::string(SLIDEID_SOURCE_DIR) + "/datasets/scenes/holdout_free_disk.ini");
  ReducedFriction truth = scene.friction.reduced();
  SimulationResult sim = Simulate(scene);
};

// The free disk over 30 noise seeds, against the segments it had before free slides were
// left long (5 of 19 intervals; TrajectorySegmentSteps): the estimate is reported "ok" with
// its interval widened for the time step (the fit with 2 substeps is the one reported), the
// median error is at most half the short segments', and the intervals hold the truth about
// as often as the scene suite's free slides' (86-99%). Measured when written: medians 0.39 /
// 0.53 / 0.42% against 1.44 / 1.22 / 1.86%; 1 of 90 estimates beyond 3 standard errors
// (b, 3.02), 85 of 90 intervals holding the truth (87, none beyond 3, since the white-noise
// interval takes each channel's own noise).
TEST(SceneSuite, AFreeSlideInLongSegmentsIsMorePreciseAndItsIntervalsStillHold) {
  HoldOutFreeDisk disk;
  ASSERT_TRUE(disk.sim.summary.ok()) << disk.sim.summary.message;
  IdentifyOptions short_segments;
  short_segments.trajectory.segment_steps = 19;
  std::array<std::vector<double>, 3> long_error, short_error;
  int estimates = 0, covered = 0, beyond3 = 0;
  for (int seed = 100; seed < 130; ++seed) {
    disk.scene.log.noise.seed = seed;
    const Trajectory log = MakeLog(disk.sim.trajectory, disk.scene.log);
    const EstimateResult r = Identify(log, IdentifyOptions{});
    const EstimateResult before = Identify(log, short_segments);
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      ASSERT_TRUE(p.identifiable) << ParameterName(i) << ": " << p.reason;
      EXPECT_EQ(p.verdict, Verdict::kOk) << ParameterName(i) << ": " << p.reason;
      EXPECT_NE(p.note.find("for the time step's own error"), std::string::npos) << p.note;
      ++estimates;
      covered += p.ci95_lo <= disk.truth[i] && disk.truth[i] <= p.ci95_hi;
      beyond3 += std::abs(p.value - disk.truth[i]) > 3 * p.stderr_value;
      long_error[i].push_back(std::abs(p.value / disk.truth[i] - 1));
      if (before.parameters[i].identifiable) {
        short_error[i].push_back(std::abs(before.parameters[i].value / disk.truth[i] - 1));
      }
    }
  }
  std::printf("%d of %d intervals hold the truth; %d estimates beyond 3 standard errors\n", covered,
              estimates, beyond3);
  EXPECT_GE(covered, estimates * 8 / 10);
  EXPECT_LE(beyond3, 2);
  for (int i = 0; i < 3; ++i) {
    const double ours = Median(long_error[i]), theirs = Median(short_error[i]);
    std::printf("%s: median error %.2f%% in long segments, %.2f%% in 19-interval ones\n",
                ParameterName(i), 100 * ours, 100 * theirs);
    EXPECT_LE(ours, theirs / 2) << ParameterName(i);
  }
}

// The white-noise interval of a log fitted in few segments weighs each residual channel by
// its own noise. The hold-out-like free slide's heading (3 mrad times L = 3.5 cm: 0.11 mm)
// is five times finer than its position (0.5 mm); one variance pooled over the three
// channels understated the position's, on which a and b rest, and overstated the heading's,
// on which c does. Two ways of the same spread: over 150 noise draws of one slide, the
// estimates' own spread (log units) over the intervals' standard error (RMS). Measured when
// written: a, b, c 0.98, 1.00, 0.75 with each channel's noise (c's interval also carries the
// time step's allowance); 1.16, 1.21, 0.48 with one variance; 427 of 450 intervals held the
// truth (416 before).
TEST(SceneSuite, TheWhiteNoiseIntervalTakesEachChannelsOwnNoise) {
  HoldOutFreeDisk disk;
  ASSERT_TRUE(disk.sim.summary.ok()) << disk.sim.summary.message;
  constexpr int kDraws = 150;
  std::array<std::vector<double>, 3> log_error, log_stderr;
  int estimates = 0, covered = 0;
  for (int seed = 1000; seed < 1000 + kDraws; ++seed) {
    disk.scene.log.noise.seed = seed;
    const EstimateResult r =
        Identify(MakeLog(disk.sim.trajectory, disk.scene.log), IdentifyOptions{});
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      ASSERT_TRUE(p.identifiable) << ParameterName(i) << ": " << p.reason;
      ASSERT_NE(p.note.find("treats the residuals as independent"), std::string::npos) << p.note;
      log_error[i].push_back(std::log(p.value / disk.truth[i]));
      log_stderr[i].push_back(std::log(p.ci95_hi / p.ci95_lo) / (2 * p.interval_quantile));
      ++estimates;
      covered += p.ci95_lo <= disk.truth[i] && disk.truth[i] <= p.ci95_hi;
    }
  }
  for (int i = 0; i < 3; ++i) {
    double mean = 0, spread = 0, rms_stderr = 0;
    for (double e : log_error[i]) mean += e / kDraws;
    for (double e : log_error[i]) spread += (e - mean) * (e - mean) / (kDraws - 1);
    for (double s : log_stderr[i]) rms_stderr += s * s / kDraws;
    const double ratio = std::sqrt(spread / rms_stderr);
    std::printf("%s: estimates spread %.3g (log), intervals' standard error %.3g: ratio %.2f\n",
                ParameterName(i), std::sqrt(spread), std::sqrt(rms_stderr), ratio);
    // The ratio's own sampling error over 150 draws is about 6%.
    EXPECT_GT(ratio, 0.65) << ParameterName(i);
    EXPECT_LT(ratio, 1.15) << ParameterName(i);
  }
  std::printf("%d of %d intervals hold the truth\n", covered, estimates);
  EXPECT_GE(covered, estimates * 91 / 100);
}

TEST(SceneSuite, HoldOutLikePushAt250HzComesOutWithinItsIntervalsAndOnePointFivePercent) {
  ExpectHonestIntervals("holdout_pushed_250hz.ini", 0.015);
}

}  // namespace
}  // namespace slideid
