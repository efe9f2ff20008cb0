// A log whose pose is that of a tracked frame, not the CM: the `cm_offset` metadata (the CM
// in that frame) moves each pose, and each logged velocity, to the CM as the log is read
// (io/push_log.h, docs/log-format.md). Motion capture tracks a rigid body whose origin is
// where its markers put it; the MIT push dataset's triangles are 3-14 mm off their CM.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "estimator/identify.h"
#include "forward_model/planar_state.h"
#include "io/push_log.h"
#include "tests/estimator_test_support.h"
#include "tests/reader_test_support.h"

namespace slideid {
namespace {

const std::string kBundledLog = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";

/// The CM in the tracked frame [m, body axes]: 2 cm ahead and 1 cm to the right.
const Eigen::Vector2d kOffset(0.02, -0.01);

/// `file` as a lab that tracks a frame offset from the CM would log it: each pose (and
/// velocity) that of the frame whose origin lies at -R(theta) offset from the CM, the force
/// and its push point as they were (the moment r x f is the reader's to take), with the
/// offset in the metadata when `with_key`.
PushLogFile InTrackedFrame(PushLogFile file, bool with_key) {
  for (TrajectorySample& s : file.log.samples) {
    PlanarState& q = s.state;
    const double c = std::cos(q.theta), sn = std::sin(q.theta);
    const double rx = c * kOffset.x() - sn * kOffset.y(), ry = sn * kOffset.x() + c * kOffset.y();
    q.x -= rx;
    q.y -= ry;
    q.vx += q.wz * ry;
    q.vy -= q.wz * rx;
    if (s.push_point_world) {
      const Eigen::Vector3d& p = *s.push_point_world;
      s.applied = WrenchFromForceAt(s.applied.fx, s.applied.fy, s.applied.fz, p.x() - q.x,
                                    p.y() - q.y, p.z() - file.log.slider.com_height_m);
    }
  }
  if (with_key) file.extra_metadata.emplace_back("cm_offset", "0.02 -0.01");
  return file;
}

void ExpectTheReaderMovesTheLogToTheCm(const PushLogFile& cm);

TEST(CmOffset, TheReaderMovesPosesAndVelocitiesToTheCm) {
  // The bundled log: poses only (velocities from their differences) and push points. And
  // the same with the velocities logged, which move by w x (R offset).
  const PushLogFile poses = ReadPushLogFile(kBundledLog);
  ASSERT_TRUE(poses.log.measured.push_point && !poses.log.measured.velocity);
  PushLogFile with_velocities = poses;
  with_velocities.log.measured.velocity = true;
  for (const PushLogFile& cm : {poses, with_velocities}) {
    ExpectTheReaderMovesTheLogToTheCm(cm);
  }
}

void ExpectTheReaderMovesTheLogToTheCm(const PushLogFile& cm) {
  const std::string path = testing::TempPath("tracked_frame.csv");
  WritePushLog(InTrackedFrame(cm, true), path);
  LogReadReport report;
  const PushLogFile read = ReadPushLogFile(path, {}, &report);
  ASSERT_EQ(read.log.samples.size(), cm.log.samples.size());
  for (std::size_t u = 0; u < cm.log.samples.size(); ++u) {
    const TrajectorySample &a = read.log.samples[u], &b = cm.log.samples[u];
    EXPECT_NEAR(a.state.x, b.state.x, 1e-15) << "row " << u;
    EXPECT_NEAR(a.state.y, b.state.y, 1e-15) << "row " << u;
    EXPECT_NEAR(a.state.vx, b.state.vx, 1e-12) << "row " << u;
    EXPECT_NEAR(a.state.vy, b.state.vy, 1e-12) << "row " << u;
    // The moment of the force at the push point, about the CM, not the tracked origin.
    EXPECT_NEAR(a.applied.tz, b.applied.tz, 1e-14) << "row " << u;
  }
  EXPECT_TRUE(testing::AnyLineContains(report.notes, "poses moved to the CM"));
  // Written back, the log holds the CM's poses and no offset: read again, it is the same.
  const std::string again = testing::TempPath("tracked_frame_again.csv");
  WritePushLog(read, again);
  EXPECT_EQ(testing::ReadText(again).find("cm_offset"), std::string::npos);
  EXPECT_EQ(ReadPushLog(again).samples.back().state.x, read.log.samples.back().state.x);
}

TEST(CmOffset, BadOffsetsAreErrorsNamingTheLine) {
  const std::string meta = "# mass = 0.5\n# inertia = 2e-4\n# com_height = 0.08\n";
  const std::string rows = "t,x,y,theta\n0,0,0,0\n0.01,0.001,0,0.01\n";
  for (const char* value : {"0.01", "0.01 x", "0.01 0.02 0.03", "nan 0"}) {
    const std::string path =
        testing::WriteFile("bad_offset.csv", meta + "# cm_offset = " + value + "\n" + rows);
    try {
      ReadPushLog(path);
      ADD_FAILURE() << value << ": no error";
    } catch (const LogError& e) {
      testing::ExpectNamesFileAndLine(e, path, 4);
      EXPECT_NE(std::string(e.what()).find("two numbers DX DY"), std::string::npos) << e.what();
    }
  }
  const std::string twice = testing::WriteFile(
      "twice_offset.csv", meta + "# cm_offset = 0 0\n# cm_offset = 0.01, 0\n" + rows);
  EXPECT_THROW(ReadPushLog(twice), LogError);
  const std::string no_pose = testing::WriteFile(
      "offset_without_pose.csv", meta + "# cm_offset = 0.01 0\nt,vx,vy,wz\n0,0,0,0\n0.01,0,0,0\n");
  try {
    ReadPushLog(no_pose);
    ADD_FAILURE() << "no error";
  } catch (const LogError& e) {
    EXPECT_NE(std::string(e.what()).find("needs the pose columns"), std::string::npos) << e.what();
  }
}

TEST(CmOffset, TheFitOfATrackedFrameLogWithItsOffsetIsTheCmLogsFit) {
  // The bundled log (a = 0.4, b = 1.3, c = 0.03 m) as a lab tracking a frame 22 mm from the
  // CM would log it. With the offset the fit is the CM log's to rounding; without it the
  // model reads the frame's motion as the CM's and its pushes' moments about the wrong
  // point: measured when written, a 3.9% and c 6.7% off, many standard errors from the truth.
  const PushLogFile cm = ReadPushLogFile(kBundledLog);
  const std::string with = testing::TempPath("tracked_with_offset.csv");
  const std::string without = testing::TempPath("tracked_without_offset.csv");
  WritePushLog(InTrackedFrame(cm, true), with);
  WritePushLog(InTrackedFrame(cm, false), without);
  const EstimateResult reference = Identify(cm.log, IdentifyOptions{});
  const EstimateResult moved = Identify(ReadPushLog(with), IdentifyOptions{});
  const EstimateResult frame = Identify(ReadPushLog(without), IdentifyOptions{});
  const double truth[3] = {0.4, 1.3, 0.03};
  int far = 0;
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate &r = reference.parameters[i], &m = moved.parameters[i];
    ASSERT_TRUE(r.identifiable && m.identifiable) << i;
    EXPECT_NEAR(m.value / r.value, 1, 1e-6) << i;
    EXPECT_LE(r.ci95_lo, truth[i]) << i;
    EXPECT_GE(r.ci95_hi, truth[i]) << i;
    const ParameterEstimate& f = frame.parameters[i];
    far += f.identifiable && std::abs(f.value - truth[i]) > 5 * r.stderr_value;
    std::printf("parameter %d: CM log %.6g, tracked frame with offset %.6g, without %.6g\n", i,
                r.value, m.value, f.value);
  }
  EXPECT_GE(far, 1);
}

}  // namespace
}  // namespace slideid
