#include "io/push_log.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "forward_model/constants.h"
#include "forward_model/simulator.h"
#include "tests/estimator_test_support.h"
#include "tests/reader_test_support.h"

namespace slideid {
namespace {

using testing::TempDirectory;
using testing::WriteFile;

// Tolerance for values the test recomputes by a different arithmetic route than the reader.
constexpr double kRecomputeTol = 1e-12;

/// A fresh directory for this test process's files.
bool FileExists(const std::string& path) { return std::ifstream(path).good(); }

using testing::ReadText;

constexpr const char* kSliderMeta = "# mass = 0.5\n# inertia = 2e-4\n# com_height = 0.08\n";

/// Reads `content` as a log named `name` and checks the LogError names the file, the line
/// and (when given) the column.
void ExpectLogError(const std::string& name, const std::string& content, int line,
                    const std::string& column = "", const LogReadOptions& options = {}) {
  const std::string path = WriteFile(name, content);
  try {
    ReadPushLog(path, options);
    ADD_FAILURE() << name << ": no LogError";
  } catch (const LogError& e) {
    const std::string what = e.what();
    testing::ExpectNamesFileAndLine(e, path, line);
    if (!column.empty()) {
      EXPECT_NE(what.find("column '" + column + "'"), std::string::npos) << what;
      EXPECT_EQ(e.column(), column) << what;
    }
  }
}

/// A trajectory with every column group and awkward values (no short decimal forms).
Trajectory FullTrajectory() {
  Trajectory tr;
  tr.slider = {0.5 + 1.0 / 3.0, 2.0833333333333332e-4, 0.08 + 1e-17, 9.8 + 1.0 / 7.0};
  tr.patch = ContactPatch::Rectangle(0.05, 0.05);
  tr.true_friction = FrictionParameters{0.31, 1.0 / 3.0, 1.1, 0.0123456789};
  tr.measured = {true, true, true, true, true, true, true};
  for (int u = 0; u < 6; ++u) {
    TrajectorySample s;
    s.t_s = 0.01 * u + 1e-19 * u;
    s.state = {std::sqrt(2.0) * u, -std::sqrt(3.0) * u, 1.7 * u, 0.1 / 3 * u, -0.7 * u, 9.1};
    s.push_point_world = Eigen::Vector3d(s.state.x - 0.025, s.state.y + 1.0 / 300, 0.05);
    // As a scene or the reader forms it: r x f plus a residual moment. (An arbitrary total
    // is reproduced only to an ulp of |r x f|: see TotalMomentsRoundTripToAnUlpOfRCrossF.)
    const Eigen::Vector3d r =
        *s.push_point_world - Eigen::Vector3d(s.state.x, s.state.y, tr.slider.com_height_m);
    s.applied = WrenchFromForceAt(0.3 * u, -0.2 / 3.0, -0.5 * u, r.x(), r.y(), r.z());
    s.applied.tx += 1e-3 / 7.0;
    s.applied.ty += -2e-3 / 3.0;
    s.applied.tz += 5e-4 * u;
    s.mode = u == 0 ? SampleMode::kStart : (u % 2 ? SampleMode::kSlide : SampleMode::kStick);
    tr.samples.push_back(s);
    StepRecord step;
    step.ecp_world = {0.017482644676537 * u, -1.0 / 11.0};
    step.pt = -0.006500247901168545 * u;
    step.po = 1.0 / 13.0;
    step.pr = -1.3871455217168605e-05;
    step.sigma = 1.087763339137281 * u;
    tr.steps.push_back(step);
  }
  return tr;
}

/// FullTrajectory as a file, with further metadata.
PushLogFile FullLogFile() {
  return PushLogFile{FullTrajectory(), "", {{"noise", "pose 1e-4"}, {"scene", "example1"}}};
}

TEST(PushLog, RoundTripReproducesEveryColumnBitExactly) {
  const PushLogFile in_file = FullLogFile();
  const Trajectory& in = in_file.log;
  const std::string path = TempDirectory() + "/round_trip.csv";
  WritePushLog(in_file, path);
  EXPECT_FALSE(FileExists(path + ".tmp"));
  const PushLogFile out_file = ReadPushLogFile(path);
  const Trajectory& out = out_file.log;

  EXPECT_EQ(out.slider.mass_kg, in.slider.mass_kg);
  EXPECT_EQ(out.slider.inertia_kgm2, in.slider.inertia_kgm2);
  EXPECT_EQ(out.slider.com_height_m, in.slider.com_height_m);
  EXPECT_EQ(out.slider.gravity_mps2, in.slider.gravity_mps2);
  ASSERT_TRUE(out.patch.has_value());
  EXPECT_EQ(out.patch->Spec(), in.patch->Spec());
  ASSERT_TRUE(out.true_friction.has_value());
  EXPECT_EQ(out.true_friction->mu, in.true_friction->mu);
  EXPECT_EQ(out.true_friction->e_t, in.true_friction->e_t);
  EXPECT_EQ(out.true_friction->e_o, in.true_friction->e_o);
  EXPECT_EQ(out.true_friction->e_r, in.true_friction->e_r);
  EXPECT_EQ(out_file.extra_metadata, in_file.extra_metadata);
  ASSERT_EQ(out.samples.size(), in.samples.size());
  ASSERT_EQ(out.steps.size(), in.steps.size());
  for (std::size_t u = 0; u < in.samples.size(); ++u) {
    const TrajectorySample& a = in.samples[u];
    const TrajectorySample& b = out.samples[u];
    SCOPED_TRACE(u);
    EXPECT_EQ(b.t_s, a.t_s);
    EXPECT_EQ(b.state.x, a.state.x);
    EXPECT_EQ(b.state.y, a.state.y);
    EXPECT_EQ(b.state.theta, a.state.theta);
    EXPECT_EQ(b.state.vx, a.state.vx);
    EXPECT_EQ(b.state.vy, a.state.vy);
    EXPECT_EQ(b.state.wz, a.state.wz);
    EXPECT_EQ(b.applied.fx, a.applied.fx);
    EXPECT_EQ(b.applied.fy, a.applied.fy);
    EXPECT_EQ(b.applied.fz, a.applied.fz);
    EXPECT_EQ(b.applied.tx, a.applied.tx);
    EXPECT_EQ(b.applied.ty, a.applied.ty);
    EXPECT_EQ(b.applied.tz, a.applied.tz);
    ASSERT_TRUE(b.push_point_world.has_value());
    EXPECT_EQ(*b.push_point_world, *a.push_point_world);
    EXPECT_EQ(b.mode, a.mode);
    EXPECT_EQ(out.steps[u].ecp_world, in.steps[u].ecp_world);
    EXPECT_EQ(out.steps[u].pt, in.steps[u].pt);
    EXPECT_EQ(out.steps[u].po, in.steps[u].po);
    EXPECT_EQ(out.steps[u].pr, in.steps[u].pr);
    EXPECT_EQ(out.steps[u].sigma, in.steps[u].sigma);
  }
  // Writing what was read gives the same file again.
  std::ostringstream first, second;
  WritePushLog(in_file, first);
  WritePushLog(out_file, second);
  EXPECT_EQ(first.str(), second.str());
  EXPECT_EQ(first.str(), ReadText(path));
}

TEST(PushLog, TotalMomentsRoundTripToAnUlpOfRCrossF) {
  // A total moment not formed as (r x f) + residual need not be representable that way:
  // the reader's sum is rounded at the scale of |r x f|.
  Trajectory tr = FullTrajectory();
  for (TrajectorySample& s : tr.samples) {
    s.applied.tx = 1e-3 / 7.0;
    s.applied.ty = -2e-3 / 3.0;
    s.applied.tz = 5e-4 * s.t_s;
  }
  std::ostringstream out;
  WritePushLog(tr, out);
  const Trajectory back = ReadPushLog(WriteFile("total_moments.csv", out.str()));
  constexpr double kUlpOfRCrossF = 1e-17;  // |r x f| < 0.05 N m here; its ulp < 1e-17
  for (std::size_t u = 0; u < tr.samples.size(); ++u) {
    EXPECT_NEAR(back.samples[u].applied.tx, tr.samples[u].applied.tx, kUlpOfRCrossF);
    EXPECT_NEAR(back.samples[u].applied.ty, tr.samples[u].applied.ty, kUlpOfRCrossF);
    EXPECT_NEAR(back.samples[u].applied.tz, tr.samples[u].applied.tz, kUlpOfRCrossF);
  }
}

TEST(PushLog, GoldenExampleReadsRowsMetadataAndTruth) {
  const std::string golden = "/work/shared/data/golden/example1_square.csv";
  if (!FileExists(golden)) GTEST_SKIP() << golden << " absent";
  LogReadReport report;
  const Trajectory tr = ReadPushLog(golden, {}, &report);
  EXPECT_EQ(tr.samples.size(), 46u);
  EXPECT_EQ(tr.slider.mass_kg, 0.5);
  EXPECT_EQ(tr.slider.gravity_mps2, 9.8);
  EXPECT_EQ(tr.slider.com_height_m, 0.08);
  ASSERT_TRUE(tr.true_friction.has_value());
  EXPECT_EQ(tr.true_friction->mu, 0.31);
  EXPECT_EQ(tr.true_friction->e_r, 0.01);
  EXPECT_FALSE(report.velocities_from_poses);
  EXPECT_TRUE(report.unknown_columns.empty());
  EXPECT_EQ(tr.samples[0].mode, SampleMode::kStart);
  EXPECT_EQ(tr.samples[0].state.wz, 10.0);
  EXPECT_EQ(tr.samples[1].state.x, 0.006869995041976629);
  EXPECT_EQ(tr.samples[1].mode, SampleMode::kSlide);
  EXPECT_TRUE(tr.measured.pose && tr.measured.velocity && tr.measured.force &&
              tr.measured.step_info);
  EXPECT_FALSE(tr.measured.push_point || tr.measured.moments || tr.measured.fz);
}

TEST(PushLog, ColumnsInShuffledOrderAreFoundByName) {
  const std::string path = WriteFile("shuffled.csv", std::string(kSliderMeta) +
                                                         "wz,fy,theta,extra,t,y,vy,x,vx,fx\n"
                                                         "3,0.2,0.1,99,0,2,5,1,4,0.1\n"
                                                         "6,0.4,0.2,99,0.5,2.5,5.5,1.5,4.5,0.3\n");
  LogReadReport report;
  const Trajectory tr = ReadPushLog(path, {}, &report);
  ASSERT_EQ(tr.samples.size(), 2u);
  const TrajectorySample& s = tr.samples[1];
  EXPECT_EQ(s.t_s, 0.5);
  EXPECT_EQ(s.state.x, 1.5);
  EXPECT_EQ(s.state.y, 2.5);
  EXPECT_EQ(s.state.theta, 0.2);
  EXPECT_EQ(s.state.vx, 4.5);
  EXPECT_EQ(s.state.vy, 5.5);
  EXPECT_EQ(s.state.wz, 6.0);
  EXPECT_EQ(s.applied.fx, 0.3);
  EXPECT_EQ(s.applied.fy, 0.4);
  EXPECT_EQ(report.unknown_columns, std::vector<std::string>{"extra"});
}

TEST(PushLog, AbsentOptionalColumnsReadAsZeroAndModesDefault) {
  const std::string path =
      WriteFile("minimal.csv", std::string(kSliderMeta) + "t,vx,vy,wz\n0,1,2,3\n0.1,1,2,3\n");
  const Trajectory tr = ReadPushLog(path);
  ASSERT_EQ(tr.samples.size(), 2u);
  for (const TrajectorySample& s : tr.samples) {
    EXPECT_TRUE(s.applied.IsZero());
    EXPECT_FALSE(s.push_point_world.has_value());
    EXPECT_EQ(s.state.x, 0.0);
    EXPECT_EQ(s.state.theta, 0.0);
  }
  EXPECT_TRUE(tr.steps.empty());  // no step columns: no steps, read as zeros
  EXPECT_EQ(StepAt(tr, 1).sigma, 0.0);
  EXPECT_EQ(StepAt(tr, 1).ecp_world, Eigen::Vector2d::Zero());
  EXPECT_EQ(tr.samples[0].mode, SampleMode::kStart);
  EXPECT_EQ(tr.samples[1].mode, SampleMode::kSlide);
  EXPECT_FALSE(tr.measured.pose);
  EXPECT_FALSE(tr.measured.force);
  EXPECT_FALSE(tr.measured.step_info);
  EXPECT_EQ(tr.slider.gravity_mps2, 9.81);
  EXPECT_FALSE(tr.true_friction.has_value());
}

TEST(PushLog, PosesOnlyGiveBackwardEulerVelocities) {
  const std::string path = WriteFile("poses.csv", std::string(kSliderMeta) +
                                                      "t,x,y,theta\n0,0,0,0\n0.1,0.01,-0.02,0.05\n"
                                                      "0.3,0.03,-0.02,0.01\n");
  LogReadReport report;
  const Trajectory tr = ReadPushLog(path, {}, &report);
  EXPECT_TRUE(report.velocities_from_poses);
  EXPECT_FALSE(tr.measured.velocity);
  ASSERT_EQ(tr.samples.size(), 3u);
  EXPECT_EQ(tr.samples[0].state.vx, 0.0);
  EXPECT_EQ(tr.samples[0].state.wz, 0.0);
  EXPECT_NEAR(tr.samples[1].state.vx, 0.1, kRecomputeTol);
  EXPECT_NEAR(tr.samples[1].state.vy, -0.2, kRecomputeTol);
  EXPECT_NEAR(tr.samples[1].state.wz, 0.5, kRecomputeTol);
  EXPECT_NEAR(tr.samples[2].state.vx, 0.1, kRecomputeTol);
  EXPECT_NEAR(tr.samples[2].state.vy, 0.0, kRecomputeTol);
  EXPECT_NEAR(tr.samples[2].state.wz, -0.2, kRecomputeTol);
}

// A motion-capture gap: rows marked `start` after the first begin a new run. The hole
// before one is no interval (47 median intervals here, an error when unmarked), the run's
// first velocity from poses is unknown (0), and the writer keeps the marks.
TEST(PushLog, RowsMarkedStartAfterAGapSplitTheLogIntoRuns) {
  const std::string rows =
      "0,0,0,0\n0.01,0.001,0,0.01\n0.02,0.002,0,0.02\n0.03,0.003,0,0.03\n"
      "0.5,0.05,0.01,0.5\n0.51,0.052,0.01,0.51\n0.52,0.054,0.01,0.52\n";
  std::string marked = std::string(kSliderMeta) + "t,x,y,theta,mode\n";
  const char* modes[] = {"start", "slide", "slide", "slide", "start", "slide", "slide"};
  std::istringstream lines(rows);
  std::string line;
  for (int u = 0; std::getline(lines, line); ++u) marked += line + "," + modes[u] + "\n";
  LogReadReport report;
  const Trajectory tr = ReadPushLog(WriteFile("runs.csv", marked), {}, &report);
  EXPECT_TRUE(tr.measured.mode);
  EXPECT_FALSE(tr.measured.step_info);  // the mode column alone carries no ECP or impulses
  const std::vector<std::pair<int, int>> runs = {{0, 3}, {4, 6}};
  EXPECT_EQ(Runs(tr), runs);
  EXPECT_EQ(tr.samples[4].state.vx, 0.0);  // unknown: no step joins rows 3 and 4
  EXPECT_EQ(tr.samples[4].state.wz, 0.0);
  EXPECT_NEAR(tr.samples[5].state.vx, 0.2, kRecomputeTol);
  EXPECT_NEAR(tr.samples[3].state.wz, 1.0, kRecomputeTol);
  bool noted = false;
  for (const auto& note : report.notes) noted = noted || note.find("2 runs") != std::string::npos;
  EXPECT_TRUE(noted);
  EXPECT_TRUE(report.warnings.empty());

  const std::string back_path = TempDirectory() + "/runs_back.csv";
  WritePushLog(tr, back_path);
  const Trajectory back = ReadPushLog(back_path);
  EXPECT_EQ(Runs(back), runs);
  EXPECT_FALSE(back.measured.step_info);

  // Unmarked, the same hole is an error that says how to mark it.
  ExpectLogError("unmarked_gap.csv", std::string(kSliderMeta) + "t,x,y,theta\n" + rows, 9, "t");
  try {
    ReadPushLog(TempDirectory() + "/unmarked_gap.csv");
  } catch (const LogError& e) {
    EXPECT_NE(std::string(e.what()).find("mark the row after the gap 'start'"), std::string::npos)
        << e.what();
  }
}

// Motion-capture dropouts written as empty or NaN cells: an error that names the line and
// column and says what to do; with missing_as_gaps (identify --missing-as-gaps) the rows go
// and the row after each dropout starts a run, as a marked gap would. "1.2abc" and "inf"
// stay errors: they are not a missing value.
TEST(PushLog, RowsWithMissingCellsAreErrorsOrGapsWhenAskedFor) {
  const std::string text = std::string(kSliderMeta) + "t,x,y,theta\n" +
                           "0,0,0,0\n0.01,0.001,0,0.01\n0.02,0.002,0,0.02\n0.03,,,\n"
                           "0.04,NaN,0,0.04\n0.05,0.005,0,0.05\n0.06,0.006,0,0.06\n"
                           "0.07,0.007,-nan,0.07\n0.08,0.008,0,0.08\n0.09,0.009,0,0.09\n";
  ExpectLogError("dropouts.csv", text, 8, "x");
  try {
    ReadPushLog(TempDirectory() + "/dropouts.csv");
  } catch (const LogError& e) {
    EXPECT_NE(std::string(e.what()).find("--missing-as-gaps"), std::string::npos) << e.what();
  }
  LogReadOptions gaps;
  gaps.missing_as_gaps = true;
  LogReadReport report;
  const Trajectory tr = ReadPushLog(TempDirectory() + "/dropouts.csv", gaps, &report);
  ASSERT_EQ(tr.samples.size(), 7u);
  const std::vector<std::pair<int, int>> runs = {{0, 2}, {3, 4}, {5, 6}};
  EXPECT_EQ(Runs(tr), runs);
  EXPECT_EQ(tr.samples[3].t_s, 0.05);
  EXPECT_EQ(tr.samples[3].state.vx, 0.0);  // a run's first velocity from poses is unknown
  EXPECT_NEAR(tr.samples[4].state.vx, 0.1, kRecomputeTol);
  EXPECT_TRUE(testing::AnyLineContains(report.notes, "3 rows with a missing cell dropped"));
  for (const char* bad : {"1.2abc", "inf"}) {
    std::string other = text;
    other.replace(other.find("NaN"), 3, bad);
    ExpectLogError("not_missing.csv", other, 9, "x", gaps);
  }
}

TEST(PushLog, PushPointAddsRCrossFIncludingTiltingMoments) {
  // CM at (1, 2, 0.08); force (3, -1, 0.5) at (0.9, 2.2, 0.15): r = (-0.1, 0.2, 0.07).
  const std::string path =
      WriteFile("push_point.csv", std::string(kSliderMeta) +
                                      "t,x,y,theta,fx,fy,fz,px,py,pz,tx,ty,tz\n"
                                      "0,1,2,0,3,-1,0.5,0.9,2.2,0.15,0.01,0.02,0.03\n");
  const Trajectory tr = ReadPushLog(path);
  const AppliedWrench& w = tr.samples[0].applied;
  const Eigen::Vector3d r(-0.1, 0.2, 0.07), f(3, -1, 0.5);
  const Eigen::Vector3d expected = r.cross(f) + Eigen::Vector3d(0.01, 0.02, 0.03);
  EXPECT_NEAR(w.tx, expected.x(), kRecomputeTol);  // ry fz - rz fy = 0.1 + 0.07
  EXPECT_NEAR(w.ty, expected.y(), kRecomputeTol);  // rz fx - rx fz = 0.21 + 0.05
  EXPECT_NEAR(w.tz, expected.z(), kRecomputeTol);
  EXPECT_NEAR(w.tx, 0.18, kRecomputeTol);
  EXPECT_NEAR(w.ty, 0.28, kRecomputeTol);
  EXPECT_NEAR(w.tz, 0.1 - 0.6 + 0.03, kRecomputeTol);
  EXPECT_EQ(w.fz, 0.5);
  ASSERT_TRUE(tr.samples[0].push_point_world.has_value());
  EXPECT_EQ(*tr.samples[0].push_point_world, Eigen::Vector3d(0.9, 2.2, 0.15));
}

TEST(PushLog, RowWithoutPushPointIsWrittenAtTheCentreOfMass) {
  Trajectory tr = FullTrajectory();
  tr.samples[2].push_point_world.reset();
  std::ostringstream out;
  WritePushLog(tr, out);
  const std::string path = WriteFile("no_push_point.csv", out.str());
  const Trajectory back = ReadPushLog(path);
  ASSERT_TRUE(back.samples[2].push_point_world.has_value());
  const TrajectorySample& s = tr.samples[2];
  EXPECT_EQ(*back.samples[2].push_point_world,
            Eigen::Vector3d(s.state.x, s.state.y, tr.slider.com_height_m));
  EXPECT_EQ(back.samples[2].applied.tx, s.applied.tx);
  EXPECT_EQ(back.samples[2].applied.tz, s.applied.tz);
}

TEST(PushLog, ThetaWrappedAcrossPiIsUnwrapped) {
  const std::string path =
      WriteFile("wrapped.csv", std::string(kSliderMeta) +
                                   "t,x,y,theta\n0,0,0,3.0\n0.1,0,0,3.1\n"
                                   "0.2,0,0,-3.1\n0.3,0,0,-3.0\n0.4,0,0,3.1\n");
  LogReadReport report;
  const Trajectory tr = ReadPushLog(path, {}, &report);
  EXPECT_EQ(tr.samples[0].state.theta, 3.0);
  EXPECT_EQ(tr.samples[1].state.theta, 3.1);
  EXPECT_NEAR(tr.samples[2].state.theta, 2 * kPi - 3.1, kRecomputeTol);
  EXPECT_NEAR(tr.samples[3].state.theta, 2 * kPi - 3.0, kRecomputeTol);
  EXPECT_NEAR(tr.samples[4].state.theta, 3.1, kRecomputeTol);
  EXPECT_NEAR(tr.samples[2].state.wz, (2 * kPi - 6.2) / 0.1, kRecomputeTol / 0.1);
  bool noted = false;
  for (const auto& note : report.notes) {
    noted = noted || note.find("unwrapped") != std::string::npos;
  }
  EXPECT_TRUE(noted);
}

TEST(PushLog, CrlfLineEndingsAndUtf8BomAreAccepted) {
  const std::string path =
      WriteFile("crlf_bom.csv",
                "\xEF\xBB\xBF# mass = 0.5\r\n# inertia = 2e-4\r\n# com_height = 0.08\r\n"
                "\r\nt,x,y,theta,mode\r\n0,0,0,0,start\r\n\r\n0.1,1,2,3,stick\r\n");
  const Trajectory tr = ReadPushLog(path);
  EXPECT_EQ(tr.slider.mass_kg, 0.5);
  ASSERT_EQ(tr.samples.size(), 2u);
  EXPECT_EQ(tr.samples[1].state.theta, 3.0);
  EXPECT_EQ(tr.samples[1].mode, SampleMode::kStick);
}

TEST(PushLog, OverridesBeatMetadata) {
  const std::string path = WriteFile(
      "overrides.csv", std::string(kSliderMeta) + "# gravity = 9.8\nt,x,y,theta\n0,0,0,0\n");
  LogReadOptions options;
  options.overrides.mass_kg = 2.0;
  options.overrides.gravity_mps2 = 1.62;
  const Trajectory tr = ReadPushLog(path, options);
  EXPECT_EQ(tr.slider.mass_kg, 2.0);
  EXPECT_EQ(tr.slider.gravity_mps2, 1.62);
  EXPECT_EQ(tr.slider.inertia_kgm2, 2e-4);
}

TEST(PushLog, OverridesSupplyMissingMetadata) {
  const std::string path = WriteFile("no_meta.csv", "t,x,y,theta\n0,0,0,0\n");
  LogReadOptions options;
  options.overrides = {1.0, 0.01, 0.0, std::nullopt};
  EXPECT_EQ(ReadPushLog(path, options).slider.mass_kg, 1.0);
  options = {};
  options.require_slider_properties = false;
  EXPECT_EQ(ReadPushLog(path, options).samples.size(), 1u);
}

TEST(PushLog, CommentsAndExtraMetadataArePreservedInOrder) {
  const std::string path = WriteFile(
      "extra.csv", std::string("# A prose comment, with x = y inside it.\n") + kSliderMeta +
                       "# scene = push_1\n# noise = 1e-4\n# patch = disk 0.03\nt,x,y,theta\n"
                       "0,0,0,0\n# a comment between rows\n0.1,0,0,0\n");
  const PushLogFile file = ReadPushLogFile(path);
  const std::vector<std::pair<std::string, std::string>> expected = {{"scene", "push_1"},
                                                                     {"noise", "1e-4"}};
  EXPECT_EQ(file.extra_metadata, expected);
  EXPECT_EQ(file.patch_spec, "disk 0.03");
  ASSERT_TRUE(file.log.patch.has_value());
  EXPECT_EQ(file.log.patch->Spec(), ContactPatch::Disk(0.03).Spec());
  EXPECT_EQ(file.log.samples.size(), 2u);
}

// The patch is written as the file had it while it still describes the log's patch (a log
// written back is the log read), and as the patch now is once it changed.
TEST(PushLog, PatchTextIsKeptWhileItDescribesThePatch) {
  const std::string text = std::string(kSliderMeta) + "# patch = rectangle 0.050  5e-2\n" +
                           "# scene = push_1\nt,x,y,theta\n0,0,0,0\n0.1,0,0,0\n";
  PushLogFile file = ParsePushLogFile(text, "patch.csv");
  std::ostringstream again;
  WritePushLog(file, again);
  EXPECT_NE(again.str().find("# patch = rectangle 0.050  5e-2\n"), std::string::npos);
  std::ostringstream twice;
  WritePushLog(ParsePushLogFile(again.str(), "again.csv"), twice);
  EXPECT_EQ(twice.str(), again.str());  // a log written back is the log read, byte for byte
  file.log.patch = ContactPatch::Disk(0.03);
  std::ostringstream changed;
  WritePushLog(file, changed);
  EXPECT_NE(changed.str().find("# patch = " + ContactPatch::Disk(0.03).Spec() + "\n"),
            std::string::npos);
  file.log.patch.reset();
  EXPECT_EQ(PatchText(file), "");
}

TEST(PushLog, EveryMalformedLogRaisesLogErrorNamingFileLineAndColumn) {
  const std::string meta = kSliderMeta;  // three lines
  ExpectLogError("empty.csv", "", 0);
  ExpectLogError("comments_only.csv", meta, 0);
  ExpectLogError("header_only.csv", meta + "t,x,y,theta\n", 4);
  ExpectLogError("no_header.csv", meta + "0,0,0,0\n", 4);
  ExpectLogError("no_group.csv", meta + "t,fx,fy\n0,0,0\n", 4);
  ExpectLogError("partial_pose.csv", meta + "t,x,y\n0,0,0\n", 4, "theta");
  ExpectLogError("no_t.csv", meta + "x,y,theta\n0,0,0\n", 4, "t");
  ExpectLogError("duplicate.csv", meta + "t,x,y,theta,x\n0,0,0,0,0\n", 4, "x");
  ExpectLogError("non_numeric.csv", meta + "t,x,y,theta\n0,0,0,0\n0.1,abc,0,0\n", 6, "x");
  ExpectLogError("trailing.csv", meta + "t,x,y,theta\n0,0,1.2abc,0\n", 5, "y");
  ExpectLogError("empty_cell.csv", meta + "t,x,y,theta\n0,0,,0\n", 5, "y");
  ExpectLogError("nan.csv", meta + "t,x,y,theta\n0,0,0,nan\n", 5, "theta");
  ExpectLogError("inf.csv", meta + "t,x,y,theta\n\n0,0,0,0\n0.1,inf,0,0\n", 7, "x");
  ExpectLogError("too_few.csv", meta + "t,x,y,theta\n0,0,0\n", 5);
  ExpectLogError("too_many.csv", meta + "t,x,y,theta\n0,0,0,0\n0.1,0,0,0,0\n", 6);
  ExpectLogError("t_equal.csv", meta + "t,x,y,theta\n0,0,0,0\n0.1,0,0,0\n0.1,0,0,0\n", 7, "t");
  ExpectLogError("t_back.csv", meta + "t,x,y,theta\n0.2,0,0,0\n0.1,0,0,0\n", 6, "t");
  ExpectLogError("bad_mode.csv", meta + "t,x,y,theta,mode\n0,0,0,0,slid\n", 5, "mode");
  ExpectLogError("px_no_pose.csv", meta + "t,vx,vy,wz,px,py,pz\n0,0,0,0,0,0,0\n", 4, "px");
  ExpectLogError("crlf_bom_error.csv",
                 "\xEF\xBB\xBF# mass = 0.5\r\n# inertia = 2e-4\r\n# com_height = 0\r\n"
                 "t,x,y,theta\r\n0,0,0,0\r\n0.1,0,0,x\r\n",
                 6, "theta");
  // m g = 0.5 * 9.81 = 4.905 N.
  ExpectLogError("lift.csv", meta + "t,x,y,theta,fz\n0,0,0,0,1\n0.1,0,0,0,4.905\n", 6, "fz");
}

TEST(PushLog, MissingOrInvalidSliderPropertiesRaiseLogError) {
  const std::string rows = "t,x,y,theta\n0,0,0,0\n";
  ExpectLogError("no_mass.csv", "# inertia = 2e-4\n# com_height = 0.08\n" + rows, 0);
  try {
    ReadPushLog(WriteFile("no_mass2.csv", "# inertia = 2e-4\n# com_height = 0\n" + rows));
    ADD_FAILURE() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_NE(std::string(e.what()).find("mass"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--mass"), std::string::npos) << e.what();
  }
  ExpectLogError("negative_height.csv", "# mass = 1\n# inertia = 1\n# com_height = -0.01\n" + rows,
                 3);
  ExpectLogError("zero_mass.csv", "# mass = 0\n# inertia = 1\n# com_height = 0\n" + rows, 1);
  ExpectLogError("bad_gravity.csv", std::string(kSliderMeta) + "# gravity = nan\n" + rows, 4);
  LogReadOptions options;
  options.overrides.com_height_m = -1.0;
  ExpectLogError("bad_override.csv", std::string(kSliderMeta) + rows, 0, "", options);
}

TEST(PushLog, UnreadableFileRaisesLogErrorNamingIt) {
  const std::string path = TempDirectory() + "/missing.csv";
  try {
    ReadPushLog(path);
    ADD_FAILURE() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": cannot", 0), 0u) << e.what();
    EXPECT_EQ(std::string(e.what()).find(":0:"), std::string::npos) << e.what();  // no line
  }
}

TEST(PushLog, FailedWriteThrowsNamingThePathAndLeavesNoFile) {
  const std::string path = TempDirectory() + "/no_such_dir/log.csv";
  try {
    WritePushLog(FullTrajectory(), path);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_FALSE(FileExists(path));
  EXPECT_FALSE(FileExists(path + ".tmp"));
}

TEST(PushLog, WriterKeepsNonZeroForcesEvenWhenTheirGroupIsOff) {
  Trajectory tr = FullTrajectory();
  tr.measured = {true, false, false, false, false, false, false};
  std::ostringstream out;
  WritePushLog(tr, out);
  const Trajectory back = ReadPushLog(WriteFile("forced_groups.csv", out.str()));
  EXPECT_TRUE(back.measured.force && back.measured.fz && back.measured.moments);
  EXPECT_FALSE(back.measured.push_point || back.measured.velocity || back.measured.step_info);
  for (std::size_t u = 0; u < tr.samples.size(); ++u) {
    EXPECT_EQ(back.samples[u].applied.fz, tr.samples[u].applied.fz);
    EXPECT_EQ(back.samples[u].applied.ty, tr.samples[u].applied.ty);
  }
}

TEST(PushLog, WriterRejectsMetadataThatWouldNotReadBack) {
  PushLogFile file = FullLogFile();
  file.extra_metadata.emplace_back("mass", "2");
  std::ostringstream out;
  EXPECT_THROW(WritePushLog(file, out), std::invalid_argument);
  file.extra_metadata.back() = {"two words", "x"};
  EXPECT_THROW(WritePushLog(file, out), std::invalid_argument);
}

}  // namespace
}  // namespace slideid

namespace slideid {
namespace {

// Theta in degrees gets a warning as positions in millimetres do (issue 17): the bundled
// log with its theta in degrees, unwrapped and wrapped to (-180, 180]; a disk thrown with
// 14 rad/s of spin in radians gets none.
std::string WithThetaInDegrees(const std::string& text, bool wrap) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  int column = -1;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || column < 0) {
      if (!line.empty() && line[0] != '#') {
        std::istringstream header(line);
        std::string name;
        for (int i = 0; std::getline(header, name, ','); ++i)
          if (name == "theta") column = i;
      }
      out << line << "\n";
      continue;
    }
    std::istringstream cells(line);
    std::string cell;
    for (int i = 0; std::getline(cells, cell, ','); ++i) {
      double value = std::stod(cell);
      if (i == column) {
        value *= 180.0 / kPi;
        if (wrap) value = std::remainder(value, 360.0);
        cell = std::to_string(value);
      }
      out << (i ? "," : "") << cell;
    }
    out << "\n";
  }
  return out.str();
}

std::vector<std::string> Warnings(const std::string& text) {
  LogReadReport report;
  ParsePushLog(text, "log.csv", LogReadOptions{}, &report);
  return report.warnings;
}

bool Says(const std::vector<std::string>& warnings, const std::string& what) {
  for (const std::string& w : warnings) {
    if (w.find(what) != std::string::npos) return true;
  }
  return false;
}

TEST(PushLogDegrees, ThetaInDegreesIsWarnedOf) {
  std::ifstream in(std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(text.empty());
  EXPECT_FALSE(Says(Warnings(text), "degrees"));
  const std::vector<std::string> unwrapped = Warnings(WithThetaInDegrees(text, false));
  EXPECT_TRUE(Says(unwrapped, "theta looks like degrees")) << unwrapped.size();
  const std::vector<std::string> wrapped = Warnings(WithThetaInDegrees(text, true));
  EXPECT_TRUE(Says(wrapped, "theta looks like degrees")) << wrapped.size();
}

TEST(PushLogDegrees, AFastSpinInRadiansIsNotWarnedOf) {
  Scene scene;
  scene.slider = {0.5, 6.25e-4, 0.02, 9.81};
  scene.friction = FrictionParameters{0.3, 1.0, 1.0, 0.02};
  scene.patch = ContactPatch::Disk(0.05);
  scene.initial.vx = 1.2;
  scene.initial.wz = 25.0;  // a hard throw's spin
  scene.dt_s = 1e-3;
  scene.duration_s = 0.8;
  const SimulationResult sim = Simulate(scene);
  ASSERT_TRUE(sim.summary.ok()) << sim.summary.message;
  std::ostringstream out;
  WritePushLog(sim.trajectory, out);
  EXPECT_FALSE(Says(Warnings(out.str()), "degrees"));
}

}  // namespace
}  // namespace slideid
