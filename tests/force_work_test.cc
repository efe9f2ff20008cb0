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
