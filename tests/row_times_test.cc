#include "io/row_times.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "datasets/sensor_model.h"
#include "estimator/identify.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"
#include "io/scene_file.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

const std::string kBundledLog = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";

// The bundled log (100 Hz) with each row after the first stamped `jitter` intervals (one
// sigma) off its sampling time, as a logger that stamps rows on arrival would (in order: at
// least 0.1 ms after the row before).
Trajectory StampedOnArrival(double jitter, unsigned seed) {
  Trajectory log = ReadPushLog(kBundledLog);
  std::mt19937 rng(seed);
  std::normal_distribution<double> off(0.0, jitter * 0.01);
  for (std::size_t u = 1; u < log.samples.size(); ++u) {
    log.samples[u].t_s = std::max(log.samples[u].t_s + off(rng), log.samples[u - 1].t_s + 1e-4);
  }
  return log;
}

// Stamps jittered by 20% of the interval: the spread reads about sqrt(2) x 20%, and the
// poses' steps do not follow the intervals (slope near 0).
TEST(RowTimes, StampsJitteringAroundARegularSamplingAreToldApart) {
  const RowTimesSpread s = MeasureRowTimes(StampedOnArrival(0.2, 1));
  std::printf("stamped: spread %.3f, slope %.3f over %d moving rows\n", s.spread, s.step_slope,
              s.moving_rows);
  EXPECT_NEAR(s.spread, 0.28, 0.05);
  EXPECT_GE(s.moving_rows, kMinRowTimesMovingRows);
  EXPECT_LT(std::abs(s.step_slope), 0.2);
  EXPECT_TRUE(TimesLookStampedOnArrival(s));
  const RowTimesSpread regular = MeasureRowTimes(ReadPushLog(kBundledLog));
  EXPECT_LT(regular.spread, 1e-6);
  EXPECT_FALSE(TimesLookStampedOnArrival(regular));
}

// The bundled scene simulated at 10 kHz, logged at 1 kHz with its noise, and every 8th to
// 12th row kept: rows truly sampled at irregular times, which the model handles. Their
// steps follow their intervals (slope near 1), and the reader says nothing.
TEST(RowTimes, RowsTrulySampledAtIrregularTimesAreLeftAlone) {
  LoggedScene scene =
      LoadScene(std::string(SLIDEID_SOURCE_DIR) + "/datasets/scenes/default_push.ini");
  scene.log.log_every = 10;
  const SimulationResult sim = Simulate(scene);
  ASSERT_TRUE(sim.summary.ok()) << sim.summary.message;
  const Trajectory fine = MakeLog(sim.trajectory, scene.log);
  Trajectory irregular = fine;
  irregular.samples.clear();
  irregular.steps.clear();
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> every(8, 12);
  for (std::size_t u = 0; u < fine.samples.size(); u += every(rng)) {
    irregular.samples.push_back(fine.samples[u]);
  }
  const RowTimesSpread s = MeasureRowTimes(irregular);
  std::printf("sampled irregularly: spread %.3f, slope %.3f over %d moving rows\n", s.spread,
              s.step_slope, s.moving_rows);
  EXPECT_GT(s.spread, 0.1);
  EXPECT_GE(s.moving_rows, kMinRowTimesMovingRows);
  EXPECT_NEAR(s.step_slope, 1.0, 0.25);
  EXPECT_FALSE(TimesLookStampedOnArrival(s));
  const std::string path = testing::TempPath("irregular_rows.csv");
  WritePushLog(irregular, path);
  LogReadReport report;
  ReadPushLog(path, {}, &report);
  EXPECT_FALSE(testing::AnyLineContains(report.warnings, "stamped on arrival"));
}

// The reader warns of jittered stamps, naming the option; with it the rows go back on a
// regular grid, and the fit gives the unjittered log's estimates (within 0.1%; the grid's
// interval is the run's mean, off by the last row's jitter over 600 intervals). Without
// it, 30% of jitter moved a by up to 1% (the bundled log's standard error is 0.15%).
TEST(RowTimes, TheReaderWarnsOfJitteredStampsAndRegularTimesUndoThem) {
  const EstimateResult reference = Identify(ReadPushLog(kBundledLog), IdentifyOptions{});
  ASSERT_TRUE(reference.converged);
  for (unsigned seed : {1u, 2u}) {
    const std::string path = testing::TempPath("stamped_" + std::to_string(seed) + ".csv");
    WritePushLog(StampedOnArrival(0.3, seed), path);
    LogReadReport report;
    ReadPushLog(path, {}, &report);
    EXPECT_TRUE(testing::AnyLineContains(report.warnings, "the times look stamped on arrival"))
        << seed;
    EXPECT_TRUE(testing::AnyLineContains(report.warnings, "--regular-times")) << seed;
    LogReadOptions regular;
    regular.regular_times = true;
    LogReadReport regular_report;
    const Trajectory log = ReadPushLog(path, regular, &regular_report);
    EXPECT_FALSE(testing::AnyLineContains(regular_report.warnings, "stamped on arrival")) << seed;
    EXPECT_TRUE(testing::AnyLineContains(regular_report.notes, "rows put on a regular grid"))
        << seed;
    EXPECT_LT(MeasureRowTimes(log).spread, 1e-6);
    const EstimateResult r = Identify(log, IdentifyOptions{});
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(r.parameters[i].value / reference.parameters[i].value, 1.0, 1e-3)
          << seed << " " << ParameterName(i);
    }
  }
}

// Times logged in milliseconds (or microseconds) read as seconds: every motion a thousand
// times slower, which the fit calls too little sliding. The reader says what it looks like;
// the bundled log as it is (100 Hz) gets no such warning.
TEST(RowTimes, TimesInMillisecondsAreWarnedOf) {
  for (double scale : {1e3, 1e6}) {
    Trajectory log = ReadPushLog(kBundledLog);
    for (TrajectorySample& s : log.samples) s.t_s *= scale;
    const std::string path = testing::TempPath("milliseconds.csv");
    WritePushLog(log, path);
    LogReadReport report;
    ReadPushLog(path, {}, &report);
    EXPECT_TRUE(testing::AnyLineContains(report.warnings, "t in milliseconds or microseconds?"))
        << scale;
  }
  LogReadReport report;
  ReadPushLog(kBundledLog, {}, &report);
  EXPECT_FALSE(testing::AnyLineContains(report.warnings, "milliseconds"));
}

// Each run keeps its start and end; only the rows inside it move.
TEST(RowTimes, ARegularGridKeepsEachRunsStartAndEnd) {
  Trajectory log = StampedOnArrival(0.3, 3);
  log.samples[300].mode = SampleMode::kStart;
  log.samples[300].t_s += 1.0;
  for (std::size_t u = 301; u < log.samples.size(); ++u) log.samples[u].t_s += 1.0;
  const Trajectory before = log;
  PutRowsOnRegularTimes(&log);
  for (std::size_t u :
       {std::size_t{0}, std::size_t{299}, std::size_t{300}, log.samples.size() - 1}) {
    EXPECT_EQ(log.samples[u].t_s, before.samples[u].t_s) << u;
  }
  const double h1 = (before.samples[299].t_s - before.samples[0].t_s) / 299;
  EXPECT_NEAR(log.samples[150].t_s - log.samples[149].t_s, h1, 1e-12);
}

}  // namespace
}  // namespace slideid
