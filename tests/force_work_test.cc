#include "io/force_work.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "io/push_log.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

const std::string kBundledLog = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";

// The bundled log's pushes do positive work in every row that pushes a moving contact.
TEST(ForceWork, APusherDoesPositiveWork) {
  LogReadReport report;
  const ForceWork w = MeasureForceWork(ReadPushLog(kBundledLog, {}, &report));
  EXPECT_GE(w.rows, 100);
  EXPECT_EQ(w.positive, w.rows);
  EXPECT_FALSE(testing::AnyLineContains(report.warnings, "negative work"));
}

// The same force with its sign flipped (a sensor reading the force on the pusher) does
// negative work in every such row, and the reader says so, naming the sign.
TEST(ForceWork, AFlippedForceIsWarnedOf) {
  Trajectory log = ReadPushLog(kBundledLog);
  for (TrajectorySample& s : log.samples) {
    AppliedWrench& w = s.applied;
    for (double* v : {&w.fx, &w.fy, &w.fz, &w.tx, &w.ty, &w.tz}) *v = -*v;  // r x f flips too
  }
  const ForceWork w = MeasureForceWork(log);
  EXPECT_GE(w.rows, 100);
  EXPECT_EQ(w.positive, 0);
  const std::string path = testing::TempPath("flipped_force.csv");
  WritePushLog(log, path);
  LogReadReport report;
  ReadPushLog(path, {}, &report);
  EXPECT_TRUE(testing::AnyLineContains(report.warnings, "its sign looks flipped"))
      << report.warnings.size();
  EXPECT_TRUE(testing::AnyLineContains(report.warnings, "columns 'fx', 'fy'"));
}

// A push off the CM turns the slider its way: in the bundled log the spin has the moment's
// sign in every row that pushes off the CM while it turns. A heading logged clockwise turns
// it the other way in all of them, and the reader says so; a flipped force (above), which
// flips the moment too, is told as a flipped force only.
TEST(ForceWork, AHeadingMeasuredClockwiseIsWarnedOf) {
  LogReadReport report;
  const Trajectory log = ReadPushLog(kBundledLog, {}, &report);
  const SpinWork w = MeasureSpinWork(log);
  EXPECT_GE(w.rows, 50);
  EXPECT_EQ(w.positive, w.rows);
  EXPECT_FALSE(testing::AnyLineContains(report.warnings, "turns against the applied moment"));
  Trajectory clockwise = log;
  for (TrajectorySample& s : clockwise.samples) s.state.theta = -s.state.theta;
  EXPECT_EQ(MeasureSpinWork(clockwise).positive, 0);
  const std::string path = testing::TempPath("clockwise.csv");
  WritePushLog(clockwise, path);
  LogReadReport clockwise_report;
  ReadPushLog(path, {}, &clockwise_report);
  EXPECT_TRUE(testing::AnyLineContains(clockwise_report.warnings, "theta measured clockwise"));
  Trajectory flipped_force = log;
  for (TrajectorySample& s : flipped_force.samples) {
    AppliedWrench& f = s.applied;
    for (double* v : {&f.fx, &f.fy, &f.fz, &f.tx, &f.ty, &f.tz}) *v = -*v;
  }
  const std::string force_path = testing::TempPath("flipped_force_spin.csv");
  WritePushLog(flipped_force, force_path);
  LogReadReport force_report;
  ReadPushLog(force_path, {}, &force_report);
  EXPECT_TRUE(testing::AnyLineContains(force_report.warnings, "its sign looks flipped"));
  EXPECT_FALSE(testing::AnyLineContains(force_report.warnings, "turns against"));
}

// Two ways of one reading: the bundled force rotated into the object's frame, read "in the
// object's frame", is the logged world force again, row for row.
TEST(ForceWork, TheObjectFrameReadingUndoesARotationIntoTheObjectsFrame) {
  const Trajectory world = ReadPushLog(kBundledLog);
  Trajectory body = world;
  for (TrajectorySample& s : body.samples) {
    const double c = std::cos(s.state.theta), sn = std::sin(s.state.theta);
    const double fx = s.applied.fx, fy = s.applied.fy;
    s.applied.fx = c * fx + sn * fy;
    s.applied.fy = -sn * fx + c * fy;
  }
  const ForceWork w = MeasureForceWork(world), b = MeasureForceWork(body);
  EXPECT_EQ(b.rows, w.rows);
  EXPECT_EQ(b.positive_in_object_frame, w.positive);
  EXPECT_LT(b.positive, b.rows);  // the object turns through 200 deg: the frames differ
}

}  // namespace
}  // namespace slideid
