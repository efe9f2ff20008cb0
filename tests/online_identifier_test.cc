// The online identifier (estimator/online_identifier.h, issue 21): on synthetic logs of the
// coverage suite (datasets/coverage_conditions.h) its estimate at the end of a log lies in
// the batch trajectory fit's 95% interval, its intervals hold the truth along the log, and
// a change of the surface halfway through a log is found, located and re-converged on.
// The full measurement is benchmarks/online_coverage.cc (docs/online.md).

#include "estimator/online_identifier.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "datasets/coverage_conditions.h"
#include "datasets/dataset.h"
#include "datasets/noise.h"
#include "datasets/scene_suite.h"
#include "datasets/sensor_model.h"
#include "estimator/identify.h"
#include "forward_model/simulator.h"

namespace slideid {
namespace {

TEST(OnlineOptions, RejectsInvalidValuesNamingThem) {
  std::string why;
  EXPECT_TRUE(OnlineOptions{}.IsValid(&why)) << why;
  OnlineOptions o;
  o.substeps = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("substeps"), std::string::npos);
  o = OnlineOptions{};
  o.pose_noise_m = -1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("pose_noise_m"), std::string::npos);
  o = OnlineOptions{};
  o.change_window_rows = 4;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("change_window_rows"), std::string::npos);
  EXPECT_THROW(OnlineIdentifier(Trajectory{}, o), std::invalid_argument);
  Trajectory velocities_only;
  velocities_only.measured.pose = false;
  try {
    OnlineIdentifier id(velocities_only);
    FAIL() << "a log without poses was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no poses"), std::string::npos) << e.what();
  }
}

TEST(OnlineIdentifier, RejectsRowsThatGoBackInTimeOrAreNotFinite) {
  const CoverageLog made = MakeCoverageLog(FindCoverageCondition("short-300"), 0);
  OnlineIdentifier id(made.log);
  id.Update(made.log.samples[0]);
  id.Update(made.log.samples[1]);
  try {
    id.Update(made.log.samples[0]);
    FAIL() << "a row back in time was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("row 2"), std::string::npos) << e.what();
  }
  TrajectorySample bad = made.log.samples[2];
  bad.state.x = std::nan("");
  EXPECT_THROW(id.Update(bad), std::invalid_argument);
}

// Logs of the CI sample: two conditions of the coverage suite (the 1 ms simulation against
// the filter's 10 ms model, and the control where it is exact), kLogs each.
constexpr int kLogs = 20;
const char* const kConditions[] = {"short-300", "exact-rate"};

TEST(OnlineIdentifier, EndsInsideTheBatchFitsIntervalAndItsIntervalsHoldTheTruth) {
  // 2 x 20 logs x 3 parameters x 4 points along the log. The band for a calibrated 95%
  // interval over 40 logs is 95% +- 7% (two binomial standard errors); measured when
  // written: 92.5-100% at every point (a 39, 39, 37, 38 of 40; b 39, 40, 39, 39; c 37, 39,
  // 39, 40); with per-parameter variance factors that only widen, read from the windows
  // under way too, and the force noise read off the log (2026-11-27): a 39, 39, 39, 39;
  // b 40, 40, 40, 39; c 37, 39, 38, 40 (docs/online.md has the full suite). The agreement with the
  // batch fit: the two use the same rows with the same model, but not in the same way (a filter
  // with process noise against shooting segments), and the batch fit is the more accurate, so the
  // online estimate strays from its narrow interval: measured, a in 33, b in 37, c in 40 of 40;
  // with the force noise read off the log (2026-11-27), a in 37, b in 38, c in 40.
  constexpr double kCoverageLow = 0.88, kCoverageHigh = 1.0;
  constexpr double kWithinBatch = 0.8;
  constexpr double kFractions[4] = {0.25, 0.5, 0.75, 1.0};
  std::array<std::array<int, 3>, 4> covered{}, counted{};
  std::array<int, 3> within{}, compared{};
  for (const char* name : kConditions) {
    const CoverageCondition condition = FindCoverageCondition(name);
    for (int k = 0; k < kLogs; ++k) {
      const CoverageLog made = MakeCoverageLog(condition, k);
      const int rows = static_cast<int>(made.log.samples.size());
      std::vector<int> keep;
      for (double f : kFractions) keep.push_back(static_cast<int>(f * rows) - 1);
      const std::vector<OnlineResult> online = RunOnline(made.log, OnlineOptions{}, keep);
      ASSERT_EQ(online.size(), 4u);
      for (int f = 0; f < 4; ++f) {
        for (int i = 0; i < 3; ++i) {
          const ParameterEstimate& p = online[f].parameters[i];
          if (!p.identifiable) continue;
          ++counted[f][i];
          covered[f][i] += p.ci95_lo <= made.truth[i] && made.truth[i] <= p.ci95_hi;
        }
      }
      const EstimateResult batch = Identify(made.log, IdentifyOptions{});
      for (int i = 0; i < 3; ++i) {
        const ParameterEstimate& b = batch.parameters[i];
        const ParameterEstimate& p = online[3].parameters[i];
        ASSERT_TRUE(p.identifiable) << name << " log " << k << " " << ParameterName(i);
        if (!b.identifiable) continue;
        ++compared[i];
        within[i] += b.ci95_lo <= p.value && p.value <= b.ci95_hi;
      }
    }
  }
  for (int i = 0; i < 3; ++i) {
    std::printf("%s: coverage %d/%d %d/%d %d/%d %d/%d, inside the batch interval %d/%d\n",
                ParameterName(i), covered[0][i], counted[0][i], covered[1][i], counted[1][i],
                covered[2][i], counted[2][i], covered[3][i], counted[3][i], within[i], compared[i]);
  }
  for (int i = 0; i < 3; ++i) {
    // From a quarter of the rows on, every parameter is identified in nearly every log: the
    // coverage is not bought by abstaining.
    for (int f = 0; f < 4; ++f) {
      ASSERT_GE(counted[f][i], 2 * kLogs - 2) << ParameterName(i) << " at " << kFractions[f];
      const double share = double(covered[f][i]) / counted[f][i];
      EXPECT_GE(share, kCoverageLow) << ParameterName(i) << " at " << kFractions[f];
      EXPECT_LE(share, kCoverageHigh) << ParameterName(i) << " at " << kFractions[f];
    }
    EXPECT_GE(double(within[i]) / compared[i], kWithinBatch) << ParameterName(i);
  }
}

// Logs of the scene suite (datasets/scene_suite.h) at 1 kHz, beyond the coverage suite's
// 100 Hz: the process noise's acceleration is a white noise, the same allowance per second
// at any rate. Before 2026-11-28 each row took the acceleration times its own length,
// a tenth of the allowance per second at 1 kHz.
TEST(OnlineIdentifier, ItsIntervalsHoldTheTruthAtOneKilohertzToo) {
  // The first kHighRateLogs logs at 1 kHz of the suite drawn with at most kMaxRows rows (0.1
  // to 1.5 s), with the batch check; all three parameters pooled. Measured when written:
  // 121 of 135 intervals (89.6%) hold the truth at the end, against 115 of 139 (82.7%) with
  // the allowance per row; 126 of 134 with the early rows filtered again (94.0%,
  // FiltersTheEarlyRowsAgainFromWhereItHasGot). Not the 95% of a calibrated interval: on held-out 1
  // kHz logs of the suite (7000-7699 and 12000-12299, up to 10,000 rows) the end's intervals hold
  // it in 95-96% (a), 93-94% (b) and 88-89% (c) of logs, and short logs are the harder part
  // (docs/online.md). The bar is what those 597 held-out intervals give, 92.8%, less two
  // binomial standard errors of 135 (2 x 2.2%): the allowance per row fails it.
  constexpr int kHighRateLogs = 50, kMaxRows = 1500;
  constexpr double kCoverageLow = 0.883;
  int covered = 0, counted = 0, drawn = 0, missed_ok = 0, covered_suspect = 0;
  for (int index = 0; drawn < kHighRateLogs; ++index) {
    SceneSuiteLimits limits;
    limits.max_rows = kMaxRows;
    const SuiteLog made = MakeSuiteLog(index, kSceneSuiteSeed, limits);
    if (made.rate_hz != 1000) continue;
    ++drawn;
    const std::vector<OnlineResult> online =
        RunOnline(made.log, OnlineOptions{}, {static_cast<int>(made.log.samples.size()) - 1});
    ASSERT_EQ(online.size(), 1u);
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = online[0].parameters[i];
      if (!p.identifiable) continue;
      ++counted;
      const bool in = p.ci95_lo <= made.truth[i] && made.truth[i] <= p.ci95_hi;
      covered += in;
      const bool ok = p.verdict == Verdict::kOk;
      missed_ok += !in && ok;
      covered_suspect += in && !ok;
      if (!in)
        std::printf("suite log %d %s: %g [%g, %g] against %g, %s\n", index, ParameterName(i),
                    p.value, p.ci95_lo, p.ci95_hi, made.truth[i], ToString(p.verdict));
    }
  }
  std::printf(
      "1 kHz logs: %d of %d intervals hold the truth; %d misses marked ok, %d holding it "
      "marked suspect\n",
      covered, counted, missed_ok, covered_suspect);
  // Not bought by abstaining: at least five of every six identified (c is not, in a few
  // logs of 0.1-0.2 s).
  ASSERT_GE(6 * counted, 5 * 3 * kHighRateLogs);
  EXPECT_GE(double(covered) / counted, kCoverageLow);
}

// Scene suite log 12112 without noise: a flat box thrown spinning at 17 rad/s, 133 rows at
// 200 Hz. Started from the prior (a = 0.15), the filter's first rows are linearised far from
// the truth (0.573) and leave it 4% high 32 rows in and 1.2% high 120 rows in (started at the
// truth, it stays there to every printed digit). Filtered again from where it has got, at
// 1.5, 2, 3 and 4 times the warm-up (rows 24, 32, 48, 64), it is within 0.1% from row 24 on.
TEST(OnlineIdentifier, FiltersTheEarlyRowsAgainFromWhereItHasGot) {
  SceneSuiteLimits noiseless;
  noiseless.noise_scale = 0;
  const SuiteLog made = MakeSuiteLog(12112, kSceneSuiteSeed, noiseless);
  ASSERT_EQ(made.motion, SuiteMotion::kFreeSlide) << made.Describe();
  const OnlineOptions options;
  const std::vector<OnlineResult> online = RunOnline(made.log, options);
  const std::size_t first = 3 * options.warmup_rows / 2 - 1;  // the update of row 24
  EXPECT_EQ(online[first - 1].relinearisations, 0);
  EXPECT_EQ(online[first].relinearisations, 1);
  EXPECT_EQ(online.back().relinearisations, 4);
  for (std::size_t row = first; row < online.size(); ++row) {
    const ParameterEstimate& a = online[row].parameters[kA];
    ASSERT_TRUE(a.identifiable) << "row " << row;
    EXPECT_NEAR(a.value / made.truth[kA], 1, 1e-3) << "row " << row;
  }
}

// A log of one slider whose surface changes halfway: `first` (logged exactly, ending at
// rest), then the scene `second` simulated from where the first ended (its pushes are fixed
// to the body, so they act as drawn) and appended; poses then noisy as motion capture's.
// The friction ellipsoid has world axes (model.md), so the second half is simulated from
// there rather than moved there.
Trajectory Spliced(const Trajectory& first, LoggedScene second, std::uint64_t seed) {
  second.initial = first.samples.back().state;
  second.initial.vx = second.initial.vy = second.initial.wz = 0;
  const SimulationResult sim = Simulate(second);
  EXPECT_TRUE(sim.summary.ok()) << sim.summary.message;
  const Trajectory logged = MakeLog(sim.trajectory, second.log);
  Trajectory out = first;
  const double shift = first.samples.back().t_s + (first.samples[1].t_s - first.samples[0].t_s);
  for (size_t u = 1; u < logged.samples.size(); ++u) {  // row 0 is where the first ended
    TrajectorySample row = logged.samples[u];
    row.t_s += shift - logged.samples[1].t_s + logged.samples[0].t_s;
    if (row.mode == SampleMode::kStart) row.mode = SampleMode::kSlide;
    out.samples.push_back(row);
  }
  NoiseSpec noise;
  noise.pose_m = 3e-4;
  noise.angle_rad = 3e-3;
  noise.seed = seed;
  return AddNoise(out, noise);  // as a sensor logs it: no step columns (mode) either
}

DatasetSpec ExactSpec(double a) {
  DatasetSpec spec;
  spec.seed = 2111;
  spec.mu = {a, a};
  spec.e_t = {1, 1};
  spec.program.count = 8;
  spec.dt_s = 1e-3;
  spec.log.noise = NoiseSpec{};
  return spec;
}

TEST(OnlineIdentifier, FindsASwitchOfSurfaceAndReconvergesOnTheNewFriction) {
  // a goes from 0.3 to 0.4 (b and c unchanged) at the splice. Detection within
  // kMaxDelayRows rows of the first push on the new surface: measured when written, 3-25
  // rows over these logs; with the force noise read off the log (2026-11-27), 7-11 rows,
  // the size (refined 60 rows after the alarm) a x 1.295-1.344 (docs/online.md). The re-converged
  // estimate must lie in the batch fit's interval of the second half, and no alarm may come before
  // the switch.
  constexpr int kSwitchLogs = 5;
  constexpr int kMaxDelayRows = 60;
  // The second half's batch interval is narrow (0.15-0.5% wide on these exact-force logs);
  // the re-converged estimate, from a filter restarted at the change, lands in it in all 5
  // logs when written (log 0 by 1e-5).
  constexpr int kMinInside = kSwitchLogs;
  int inside = 0;
  for (int k = 0; k < kSwitchLogs; ++k) {
    Trajectory first, unused;
    DrawDatasetLog(ExactSpec(0.3), k, &first);
    const DatasetEntry second = DrawDatasetLog(ExactSpec(0.4), k, &unused);
    const int switch_row = static_cast<int>(first.samples.size());
    const Trajectory log = Spliced(first, second.scene, 77 + k);
    const std::vector<OnlineResult> online =
        RunOnline(log, OnlineOptions{}, {static_cast<int>(log.samples.size()) - 1});
    const OnlineResult& end = online.back();
    ASSERT_GE(end.changes.size(), 1u) << "log " << k;
    const FrictionChange& change = end.changes.front();
    EXPECT_GE(change.detected_row, switch_row) << "log " << k << ": an alarm before the switch";
    // The first push on the new surface.
    int first_push = switch_row;
    while (first_push < static_cast<int>(log.samples.size()) &&
           std::hypot(log.samples[first_push].applied.fx, log.samples[first_push].applied.fy) == 0)
      ++first_push;
    EXPECT_LE(change.detected_row - first_push, kMaxDelayRows) << "log " << k;
    EXPECT_NEAR(change.row, switch_row, kMaxDelayRows) << "log " << k;
    EXPECT_GT(change.ratio[0], 1.1) << "log " << k;  // a grew (by a third)
    EXPECT_LT(change.ratio[0], 1.6) << "log " << k;
    // The second half alone, fitted in batch.
    Trajectory second_half = log;
    second_half.samples.erase(second_half.samples.begin(),
                              second_half.samples.begin() + switch_row);
    second_half.steps.clear();  // the simulated steps would no longer match the rows
    second_half.samples.front().mode = SampleMode::kStart;
    const EstimateResult batch = Identify(second_half, IdentifyOptions{});
    const ParameterEstimate& b = batch.parameters[0];
    ASSERT_TRUE(b.identifiable);
    EXPECT_NEAR(end.parameters[0].value, 0.4, 0.01) << "log " << k;
    inside += b.ci95_lo <= end.parameters[0].value && end.parameters[0].value <= b.ci95_hi;
    std::printf(
        "switch log %d: rows %zu, switch at row %d, first push %d, change at row %d, "
        "alarm at row %d, a x %.3f; a %.5f, second half's batch %.5f [%.5f, %.5f]\n",
        k, log.samples.size(), switch_row, first_push, change.row, change.detected_row,
        change.ratio[0], end.parameters[0].value, b.value, b.ci95_lo, b.ci95_hi);
  }
  EXPECT_GE(inside, kMinInside);
}

TEST(OnlineIdentifier, RaisesNoAlarmOnUnchangedLogs) {
  // 100 logs each of the coverage suite's base and force-3% conditions cut to 600 rows. The
  // test arms once the filter has settled and four windows have given its variance factor
  // (about 200 rows in), so these logs test it over some 80,000 rows. The stated rate: at
  // most 0.15 false alarms per million tested rows of a consistent filter
  // (OnlineOptions::change_threshold); at that rate none come with probability 0.99. The
  // seeds are fixed: measured when written, none (with the 1e-6 tail as the threshold, one,
  // at row 321 of base log 10). Before the logged moment's lever carried the force's and the
  // point's noise into the spin's process noise (2026-11-28), force-3% raised alarms in 17
  // of its first 100 logs at 1000 rows, and in 7 of these.
  constexpr int kUnchangedLogs = 100;
  constexpr int kMinArmedRows = 50000;
  int alarms = 0, armed_rows = 0;
  for (const char* name : {"base", "force-3%"}) {
    CoverageCondition condition = FindCoverageCondition(name);
    condition.rows = 600;
    for (int k = 0; k < kUnchangedLogs; ++k) {
      const CoverageLog made = MakeCoverageLog(condition, k);
      OnlineIdentifier id(made.log);
      for (const TrajectorySample& row : made.log.samples)
        armed_rows += id.Update(row).change_test_armed;
      alarms += static_cast<int>(id.result().changes.size());
      EXPECT_EQ(id.result().changes.size(), 0u) << name << " log " << k;
    }
  }
  std::printf("unchanged logs: %d alarms over %d tested rows\n", alarms, armed_rows);
  EXPECT_GE(armed_rows, kMinArmedRows);
  EXPECT_EQ(alarms, 0);
}

TEST(OnlineIdentifier, FindsATenPercentChangeUnderForceNoise) {
  // The change test's power, that no quieter test may cost: a goes from 0.3 to 0.33 halfway
  // through 8 logs with 3% force noise. Measured when written (2026-11-28): found in all 8,
  // 6-28 rows after the switch (before the lever's noise, 5-34).
  constexpr int kLogs = 8;
  constexpr int kMaxDelayRows = 60;
  for (int k = 0; k < kLogs; ++k) {
    Trajectory first, unused;
    DrawDatasetLog(ExactSpec(0.3), k, &first);
    const DatasetEntry second = DrawDatasetLog(ExactSpec(0.33), k, &unused);
    const int switch_row = static_cast<int>(first.samples.size());
    NoiseSpec force_noise;
    force_noise.force_relative = 0.03;
    force_noise.seed = 991 + k;
    const Trajectory log = AddNoise(Spliced(first, second.scene, 77 + k), force_noise);
    const OnlineResult end =
        RunOnline(log, OnlineOptions{}, {static_cast<int>(log.samples.size()) - 1}).back();
    ASSERT_GE(end.changes.size(), 1u) << "log " << k;
    const FrictionChange& change = end.changes.front();
    EXPECT_GE(change.detected_row, switch_row) << "log " << k << ": an alarm before the switch";
    EXPECT_LE(change.detected_row - switch_row, kMaxDelayRows) << "log " << k;
  }
}

TEST(OnlineIdentifier, AnAlarmTheRowsAfterItDoNotBearOutIsWithdrawn) {
  // Scene suite log 15068: a box pushed and resting, 1335 rows at 250 Hz with motion-capture
  // outliers, whose friction does not change. The change test raises an alarm (measured
  // when written: one, statistic 36.1); the next change_window_rows rows are explained better by
  // the filter that went on without the change, so it is withdrawn and that filter goes on: at the
  // end, as the filter that never tested for changes, to the last bit. Without the confirmation the
  // alarm stands, and the filter ends with what it relearned since.
  const SuiteLog made = MakeSuiteLog(15068);
  const int last = static_cast<int>(made.log.samples.size()) - 1;
  const OnlineResult confirmed = RunOnline(made.log, OnlineOptions{}, {last}).back();
  OnlineOptions no_tests, unconfirmed;
  no_tests.detect_changes = false;
  unconfirmed.confirm_changes = false;
  const OnlineResult plain = RunOnline(made.log, no_tests, {last}).back();
  const OnlineResult alarmed = RunOnline(made.log, unconfirmed, {last}).back();
  EXPECT_EQ(confirmed.changes.size(), 0u);
  EXPECT_GE(confirmed.withdrawn_changes, 1);
  ASSERT_GE(alarmed.changes.size(), 1u);
  EXPECT_FALSE(alarmed.changes.front().confirmed);
  EXPECT_EQ(alarmed.withdrawn_changes, 0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(confirmed.parameters[i].value, plain.parameters[i].value) << i;
    EXPECT_EQ(confirmed.parameters[i].ci95_hi, plain.parameters[i].ci95_hi) << i;
  }
}

TEST(OnlineIdentifier, ASwitchOfSurfaceIsConfirmed) {
  // The switch of FindsASwitchOfSurfaceAndReconvergesOnTheNewFriction (a 0.3 -> 0.4), log 0:
  // the rows after the alarm bear the change out.
  Trajectory first, unused;
  DrawDatasetLog(ExactSpec(0.3), 0, &first);
  const DatasetEntry second = DrawDatasetLog(ExactSpec(0.4), 0, &unused);
  const Trajectory log = Spliced(first, second.scene, 77);
  const OnlineResult end =
      RunOnline(log, OnlineOptions{}, {static_cast<int>(log.samples.size()) - 1}).back();
  ASSERT_EQ(end.changes.size(), 1u);
  EXPECT_TRUE(end.changes.front().confirmed);
  EXPECT_EQ(end.withdrawn_changes, 0);
}

// A filter that linearised far from the truth early can settle on a narrow interval orders
// of magnitude off (the coverage suite's `outliers` condition: 1% of poses jump 5 mm). Such
// an answer is labelled: an estimate whose interval misses the truth by a factor 10 or more
// is marked suspect, saying how far it is from where the filter started (plausibility.h),
// never ok.
// A log of the coverage suite's `outliers` condition on which the filter alone runs off: c
// ends a factor 50 below the truth, on a narrow interval (the one of 1800 `outliers`,
// `force-3%` and `users` logs since each row's step is limited, kMaxLogStepPerRow; logs 71
// and 116, which ran off before, no longer do).
constexpr int kRunawayLogs[1] = {396};

TEST(OnlineIdentifier, AnEstimateThatRanOffIsMarkedSuspect) {
  OnlineOptions filter_alone;
  filter_alone.batch_check_first_rows = 0;
  for (int index : kRunawayLogs) {
    const CoverageLog made = MakeCoverageLog(FindCoverageCondition("outliers"), index);
    OnlineIdentifier id(made.log, filter_alone);
    for (const TrajectorySample& row : made.log.samples) id.Update(row);
    const OnlineResult& r = id.result();
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      if (!p.identifiable) continue;
      const double truth = made.truth[i];
      if (p.ci95_lo / truth < 10 && truth / p.ci95_hi < 10) continue;
      EXPECT_EQ(p.verdict, Verdict::kSuspect)
          << "log " << index << " parameter " << i << ": " << p.value << " [" << p.ci95_lo << ", "
          << p.ci95_hi << "], truth " << truth;
      EXPECT_NE(p.reason.find("times the seed"), std::string::npos) << p.reason;
    }
    // The logs still show what the test is about: c ran off.
    const ParameterEstimate& c = r.parameters[2];
    ASSERT_TRUE(c.identifiable) << "log " << index << ": " << c.reason;
    EXPECT_GT(std::max(c.ci95_lo / made.truth[2], made.truth[2] / c.ci95_hi), 10)
        << "log " << index;
  }
}

// Scene suite log 100 drawn to 1500 rows: a tall box pushed for 0.157 s at 1 kHz that
// hardly moves (1 mm, 0.03 rad). The filter ends with b = 3.9 [2.3, 6.7] against a truth
// of 1.51; the trajectory fit of its first 128 rows (the batch check) finds b = 0.70 [0.43,
// 1.15], 4.5 standard errors away (the two variances added), under the takeover's 5. One of
// the two is wrong, so the filter's b is marked suspect; before 2026-11-28 it was ok.
// (Its a and c, also off by a factor 2.5-3, stay ok: the fit determines neither, and a
// filter's estimate that no fit of its rows determines is as often right: docs/online.md.)
TEST(OnlineIdentifier, AnEstimateTheBatchChecksFitDisagreesWithIsMarkedSuspect) {
  SceneSuiteLimits limits;
  limits.max_rows = 1500;
  const SuiteLog made = MakeSuiteLog(100, kSceneSuiteSeed, limits);
  ASSERT_EQ(made.log.samples.size(), 157u) << made.Describe();
  OnlineIdentifier id(made.log, OnlineOptions{});
  for (const TrajectorySample& row : made.log.samples) id.Update(row);
  const OnlineResult& r = id.result();
  ASSERT_EQ(r.batch_checks, 1);
  ASSERT_EQ(r.batch_takeovers, 0);
  const ParameterEstimate& b = r.parameters[kB];
  ASSERT_TRUE(b.identifiable) << b.reason;
  ASSERT_GT(b.ci95_lo, made.truth[kB]) << "the case the test is about: b's interval misses";
  EXPECT_EQ(b.verdict, Verdict::kSuspect);
  EXPECT_NE(b.reason.find("first 128 rows (the last batch check) lies"), std::string::npos)
      << b.reason;
  // Without the check there is nothing to disagree with.
  OnlineOptions no_check;
  no_check.batch_check_first_rows = 0;
  OnlineIdentifier alone(made.log, no_check);
  for (const TrajectorySample& row : made.log.samples) alone.Update(row);
  EXPECT_EQ(alone.result().parameters[kB].verdict, Verdict::kOk);
}

// The same logs with the batch check (the default): the trajectory fit of the rows so far
// finds c far from the filter's, the filter takes the fit's estimate over, and ends with
// intervals that hold the truth, marked ok.
TEST(OnlineIdentifier, TheBatchCheckBringsBackAnEstimateThatRanOff) {
  for (int index : kRunawayLogs) {
    const CoverageLog made = MakeCoverageLog(FindCoverageCondition("outliers"), index);
    OnlineIdentifier id(made.log);
    for (const TrajectorySample& row : made.log.samples) id.Update(row);
    const OnlineResult& r = id.result();
    EXPECT_GE(r.batch_takeovers, 1) << "log " << index;
    EXPECT_GE(r.batch_checks, r.batch_takeovers);
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      ASSERT_TRUE(p.identifiable) << "log " << index << " parameter " << i << ": " << p.reason;
      EXPECT_EQ(p.verdict, Verdict::kOk) << "log " << index << " parameter " << i << p.reason;
      EXPECT_LE(p.ci95_lo, made.truth[i]) << "log " << index << " parameter " << i;
      EXPECT_GE(p.ci95_hi, made.truth[i]) << "log " << index << " parameter " << i;
    }
  }
}

// The check on a thread of its own: no update runs a fit, and the verdicts, applied when
// they are in, bring the same runaways back. Which row a verdict lands on depends on the
// machine's timing, and so do the last digits of the end: the test asks for what holds at
// any timing, a takeover and estimates near the truth (the filter alone ends 50 times off),
// not the intervals' exact reach.
TEST(OnlineIdentifier, TheBatchCheckOnItsOwnThreadBringsThemBackToo) {
  constexpr double kNear = 0.2;  // relative; the ordinary errors here are 0.1-3%
  OnlineOptions threaded;
  threaded.batch_check_thread = true;
  for (int index : kRunawayLogs) {
    const CoverageLog made = MakeCoverageLog(FindCoverageCondition("outliers"), index);
    OnlineIdentifier id(made.log, threaded);
    for (const TrajectorySample& row : made.log.samples) id.Update(row);
    const OnlineResult& r = id.WaitForBatchCheck();
    EXPECT_GE(r.batch_takeovers, 1) << "log " << index;
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      ASSERT_TRUE(p.identifiable) << "log " << index << " parameter " << i << ": " << p.reason;
      EXPECT_EQ(p.verdict, Verdict::kOk) << "log " << index << " parameter " << i << p.reason;
      EXPECT_LT(std::abs(p.value / made.truth[i] - 1), kNear)
          << "log " << index << " parameter " << i << ": " << p.value << ", truth "
          << made.truth[i];
    }
  }
}

// Waiting for each check's thread as soon as it starts applies each verdict where the check in
// the update would: the same answers, bit for bit.
TEST(OnlineIdentifier, WaitingForEachThreadedCheckGivesTheChecksInTheUpdateAnswers) {
  OnlineOptions threaded;
  threaded.batch_check_thread = true;
  for (int index : kRunawayLogs) {
    const CoverageLog made = MakeCoverageLog(FindCoverageCondition("outliers"), index);
    OnlineIdentifier in_update(made.log), waited(made.log, threaded);
    for (const TrajectorySample& row : made.log.samples) {
      in_update.Update(row);
      waited.Update(row);
      waited.WaitForBatchCheck();
    }
    const OnlineResult &a = in_update.result(), &b = waited.result();
    EXPECT_EQ(a.batch_checks, b.batch_checks) << "log " << index;
    EXPECT_EQ(a.batch_takeovers, b.batch_takeovers) << "log " << index;
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(a.parameters[i].value, b.parameters[i].value) << "log " << index << " " << i;
      EXPECT_EQ(a.parameters[i].ci95_lo, b.parameters[i].ci95_lo) << "log " << index << " " << i;
      EXPECT_EQ(a.parameters[i].ci95_hi, b.parameters[i].ci95_hi) << "log " << index << " " << i;
    }
  }
}

}  // namespace
}  // namespace slideid
