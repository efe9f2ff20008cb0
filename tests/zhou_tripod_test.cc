// The tripod logs of Zhou et al. (io/zhou_tripod_log.h, io/zhou_tripod_import.h) on
// synthetic files made by the simulator (io/zhou_tripod_synth.h): the reader names every
// defect with its line, and the importer recovers the simulated pushes' pairs, rejects the
// pushes it cannot trust with a reason, and leads to the true a, b, c.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "estimator/quasi_static_fit.h"
#include "forward_model/constants.h"
#include "io/wrench_twist_csv.h"
#include "io/zhou_tripod_import.h"
#include "io/zhou_tripod_log.h"
#include "io/zhou_tripod_synth.h"
#include "tests/estimator_test_support.h"
#include "tests/reader_test_support.h"

namespace slideid {
namespace {

using testing::TempDirectory;

constexpr double kRecomputeTol = 1e-12;
// Angles through a written quaternion and atan2: a few ulps of the shortest decimal text.
constexpr double kPoseRoundTripTol_rad = 1e-9;
// The importer's pairs against the simulation's own: the importer sees 100 Hz forces with
// 5 mN noise, 33 Hz tool poses, a tool point off the contact by the finger's deflection
// (F / k, 0.2 mm), the object's pose only at the ends (it interpolates along one constant
// twist), and it cannot tell sliding from the top of the loading ramp. Measured on two
// seeds: forces within 0.55%, moments within 0.7 mN m (of up to 0.14 N m), twist directions
// within 0.6 deg, contact points within 0.3 mm.
constexpr double kImportForceRelTol = 0.01;
constexpr double kImportMomentTol_Nm = 0.0015;
constexpr double kImportTwistAngleTol_rad = 0.02;
constexpr double kImportContactTol_m = 0.001;
// a, b, c from the imported pairs: the simulated pairs' model error (see
// quasi_static_fit_test.cc) plus the import's.
constexpr double kImportedFitRelTol = 0.015;

const ReducedFriction kTruth{0.3, 1.0, 0.04};

/// A file in a folder named like the dataset's (the folder gives the support layout).
std::string PathIn(const std::string& folder, const std::string& name) {
  const std::string dir = TempDirectory() + "/" + folder;
  std::filesystem::create_directories(dir);
  return dir + "/" + name;
}

const std::vector<SimulatedPush>& Pushes() {
  static const std::vector<SimulatedPush> pushes =
      SimulateSpringPushes(TripodSynthSpec(kTruth, 12, 21));
  return pushes;
}

const TripodLog& Log() {
  static const TripodLog log = TripodLogFromPushes(Pushes());
  return log;
}

/// A short log (2 pushes, few samples) as text, for the reader's defects.
std::string SmallLogText() {
  TripodLog log;
  for (int p = 0; p < 2; ++p) {
    TripodPush push;
    push.pre = {600.0 + p, 30.0, 10.0, 0.9, 0.01, 0.0, 0.43};
    push.post = {605.0 + p, 32.0, 10.0, 0.9, 0.01, 0.0, 0.43};
    for (int i = 0; i < 4; ++i) push.forces.push_back({100.0 + 0.01 * i, 0.1 * i, -0.2 * i, 0});
    for (int i = 0; i < 3; ++i) {
      push.robot.push_back({100.0 + 0.03 * i, {530.0 + i, -33.0, 20.0, 0.992, 0.0, 0.0, 0.123}, 0});
    }
    log.pushes.push_back(push);
  }
  std::ostringstream out;
  WriteZhouTripodLog(log, out);
  return out.str();
}
// SmallLogText's layout: line 1 "2"; push 1: pre 2, post 3, K 4, forces 5-8, M 9, robot
// 10-12; push 2: pre 13, post 14, K 15, forces 16-19, M 20, robot 21-23.

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string Join(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  return text;
}

/// Reads `text` from a file and from memory; both must fail at `line`, naming the file,
/// the column (when given) and the words.
void ExpectTripodError(const std::string& name, const std::string& text, int line,
                       const std::string& column, const std::string& words) {
  const std::string path = PathIn("defects", name);
  std::ofstream(path, std::ios::binary) << text;
  for (int source = 0; source < 2; ++source) {
    try {
      if (source == 0) {
        ReadZhouTripodLog(path);
      } else {
        ParseZhouTripodLog(text, path);
      }
      ADD_FAILURE() << name << ": no LogError";
    } catch (const LogError& e) {
      testing::ExpectNamesFileLineColumn(e, path, line, column, words);
    }
  }
}

TEST(ZhouTripodLog, RoundTripsAWrittenLogWithItsLineNumbers) {
  const std::string path = PathIn("roundtrip", "log.txt");
  WriteZhouTripodLog(Log(), path);
  const TripodLog read = ReadZhouTripodLog(path);
  ASSERT_EQ(read.pushes.size(), Log().pushes.size());
  int line = 2;
  for (std::size_t p = 0; p < read.pushes.size(); ++p) {
    const TripodPush &a = Log().pushes[p], &b = read.pushes[p];
    EXPECT_EQ(b.line, line);
    EXPECT_EQ(a.pre.x_mm, b.pre.x_mm);
    EXPECT_EQ(a.post.qz, b.post.qz);
    ASSERT_EQ(a.forces.size(), b.forces.size());
    ASSERT_EQ(a.robot.size(), b.robot.size());
    for (std::size_t i = 0; i < a.forces.size(); ++i) {
      EXPECT_EQ(a.forces[i].t_s, b.forces[i].t_s);
      EXPECT_EQ(a.forces[i].fy_n, b.forces[i].fy_n);
    }
    EXPECT_EQ(b.force_count_line, line + 2);
    EXPECT_EQ(b.forces.front().line, line + 3);
    EXPECT_EQ(b.robot_count_line, line + 3 + static_cast<int>(a.forces.size()));
    EXPECT_EQ(a.robot.back().pose.qw, b.robot.back().pose.qw);
    line += 4 + static_cast<int>(a.forces.size() + a.robot.size());
  }
  // Blank lines and tabs between records are accepted.
  std::string text = SmallLogText();
  text.insert(text.find('\n') + 1, "\n  \n");
  std::replace(text.begin(), text.end(), ' ', '\t');
  EXPECT_EQ(ParseZhouTripodLog(text, "blank.txt").pushes.size(), 2u);
}

TEST(ZhouTripodLog, ACountLargerThanItsLinesIsNamed) {
  std::vector<std::string> lines = Lines(SmallLogText());
  lines[3] = "5";  // push 1 announces 5 force samples, has 4: line 9 (M) is read as one
  ExpectTripodError("count_large.txt", Join(lines), 9, "",
                    "the force count of push 1 of 2 on line 4, 5, does not match its lines "
                    "(only 4 follow it)");
}

TEST(ZhouTripodLog, ACountSmallerThanItsLinesIsNamed) {
  std::vector<std::string> lines = Lines(SmallLogText());
  lines[3] = "3";  // push 1 announces 3 force samples, has 4: line 8 is not M
  ExpectTripodError("count_small.txt", Join(lines), 8, "",
                    "the force count of push 1 of 2 on line 4, 3, may not match its lines");
  lines = Lines(SmallLogText());
  lines[19] = "2";  // push 2 announces 2 robot poses, has 3: line 23 is left over
  ExpectTripodError("count_small_last.txt", Join(lines), 23, "",
                    "data after the last of the 2 pushes announced on line 1");
  lines = Lines(SmallLogText());
  lines[0] = "3";  // three pushes announced, two there
  ExpectTripodError("pushes_large.txt", Join(lines), 23, "",
                    "the pre-push object pose of push 3 of 3 was expected: the file is cut short");
}

TEST(ZhouTripodLog, NonNumericValuesNameTheLineAndField) {
  std::vector<std::string> lines = Lines(SmallLogText());
  lines[16] = "100.01 abc -0.2";
  ExpectTripodError("text.txt", Join(lines), 17, "fx",
                    "'abc' is not a finite number (in force sample 2 of 4 of push 2 of 2)");
  lines = Lines(SmallLogText());
  lines[1] = "600 30 10 0.9 0.01 nan 0.43";
  ExpectTripodError("nan.txt", Join(lines), 2, "qy", "'nan' is not a finite number");
  lines = Lines(SmallLogText());
  lines[8] = "three";
  ExpectTripodError("count_text.txt", Join(lines), 9, "count",
                    "is not the number of robot poses of push 1 of 2");
  lines = Lines(SmallLogText());
  lines[9] = "100 530 -33 20 0.992 0 0";  // 7 of 8 numbers
  ExpectTripodError("short_line.txt", Join(lines), 10, "",
                    "expected robot pose 1 of 3 of push 1 of 2 (8 numbers");
}

TEST(ZhouTripodLog, ATruncatedOrEmptyFileIsNamed) {
  const std::string text = SmallLogText();
  std::vector<std::string> lines = Lines(text);
  lines.resize(16);  // cut inside push 2's forces
  ExpectTripodError("truncated.txt", Join(lines), 16, "",
                    "force sample 2 of 4 of push 2 of 2 was expected: the file is cut short (or "
                    "the force count of push 2 of 2 on line 15, 4, is larger than its 1 lines)");
  // Cut in the middle of a line, as a crash leaves a file.
  const std::string cut = text.substr(0, text.find("100.01", text.find("100.01") + 1) + 3);
  ExpectTripodError("cut_mid_line.txt", cut, 17, "", "force sample 2 of 4");
  ExpectTripodError("empty.txt", "", 0, "", "the file is empty");
  ExpectTripodError("blank.txt", "\n \n", 0, "", "only blank lines");
  ExpectTripodError("zero.txt", "0\n", 1, "count", "announces 0 pushes");
  ExpectTripodError("huge.txt", "99999999999\n", 1, "count", "is not the number of pushes");
  ExpectTripodError("nul.txt", std::string("2\n600 3\0", 8), 2, "", "NUL byte");
  EXPECT_THROW(ReadZhouTripodLog(TempDirectory() + "/missing.txt"), LogError);
}

TEST(ZhouTripodLog, FileAndMemoryReadersAgreeOnEverySeedCorpusFile) {
  // Seeds named bad_ fail; the others are read.
  const testing::CorpusReads reads = testing::ExpectFileAndMemoryReadersAgree(
      "tripod", [](const std::string& path) { return ReadZhouTripodLog(path).pushes.size(); },
      [](const std::string& text, const std::string& path) {
        return ParseZhouTripodLog(text, path).pushes.size();
      });
  EXPECT_GE(reads.files, 8);
  EXPECT_GE(reads.accepted, 4);
}

TEST(ZhouTripodConventions, PosesAndForcesRoundTripThroughTheLogsFrames) {
  const Eigen::Vector3d q(0.61, -0.03, 2.4);
  const Eigen::Vector3d back = TripodObjectPose(TripodViconPose(q, 10.0));
  EXPECT_NEAR((back - q).norm(), 0.0, kRecomputeTol);
  const Eigen::Vector2d f(3.0, -1.2);
  EXPECT_NEAR((TripodToolForce(TripodSensorForce(f).x(), TripodSensorForce(f).y()) - f).norm(), 0.0,
              kRecomputeTol);
  // The tool's yaw is the quaternion's.
  TripodPose tool;
  tool.qw = std::cos(0.7);
  tool.qz = std::sin(0.7);
  EXPECT_NEAR(TripodToolYaw(tool), 1.4, kRecomputeTol);
  // Vertices: the right angle at the block origin, 0.15 m legs, CM at the centroid.
  const auto v = TripodBlockVertices();
  EXPECT_NEAR(((v[0] + v[1] + v[2]) / 3.0).norm(), 0.0, kRecomputeTol);
  EXPECT_NEAR((v[1] - v[0]).norm(), kTripodLeg_m, kRecomputeTol);
}

TEST(ZhouTripodConventions, FolderNamesGiveTheSupportsAndTheirSpread) {
  const auto s = ParseTripodSupports("wood_10_130_10_10_10_130");
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ((*s)[0], Eigen::Vector2d(-0.04, -0.04));
  EXPECT_EQ((*s)[1], Eigen::Vector2d(0.08, -0.04));
  EXPECT_EQ((*s)[2], Eigen::Vector2d(-0.04, 0.08));
  const SupportSpread spread = TripodSupportSpread(*s);
  EXPECT_NEAR(spread.rms_m, 0.08, kRecomputeTol);  // sqrt((0.0032 + 0.008 + 0.008) / 3)
  // The CM is the supports' centroid: each carries a third.
  for (double w : spread.weights) EXPECT_NEAR(w, 1.0 / 3.0, kRecomputeTol);
  EXPECT_NEAR(spread.weighted_mean_m, (std::sqrt(0.0032) + 2 * std::sqrt(0.008)) / 3.0,
              kRecomputeTol);
  EXPECT_TRUE(spread.cm_inside);
  EXPECT_TRUE(ParseTripodSupports("30_63.33_43.33_30_43.33_63.33").has_value());
  EXPECT_FALSE(ParseTripodSupports("patch").has_value());
  EXPECT_FALSE(ParseTripodSupports("10_130_10_10_10").has_value());
  EXPECT_FALSE(ParseTripodSupports("10_130_10_10_10_130_5").has_value());
  EXPECT_THROW(
      TripodSupportSpread({Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(2, 2)}),
      std::invalid_argument);
}

TEST(ZhouTripodImport, RecoversTheSimulatedPushesPairs) {
  const std::string path = PathIn("10_130_10_10_10_130", "synthetic.txt");
  WriteZhouTripodLog(Log(), path);
  TripodImportReport report;
  const WrenchTwistData data = ImportZhouTripod(path, {}, &report);
  ASSERT_EQ(report.accepted, 12) << (report.push_reports.empty() ? ""
                                                                 : report.push_reports[0].reason);
  ASSERT_EQ(data.rows.size(), 12u);
  EXPECT_EQ(data.mass_kg, kTripodMass_kg);
  EXPECT_EQ(data.supports, "-0.04 -0.04; 0.08 -0.04; -0.04 0.08");
  for (std::size_t i = 0; i < data.rows.size(); ++i) {
    const WrenchTwistRow& got = data.rows[i];
    const WrenchTwistRow& want = Pushes()[i].row;
    const std::string what = "push " + std::to_string(got.push);
    EXPECT_EQ(got.push, static_cast<int>(i + 1));
    const double f = std::hypot(want.pair.fx, want.pair.fy);
    EXPECT_LT(std::hypot(got.pair.fx - want.pair.fx, got.pair.fy - want.pair.fy),
              kImportForceRelTol * f)
        << what;
    EXPECT_NEAR(got.pair.mz, want.pair.mz, kImportMomentTol_Nm) << what;
    // Twist directions, spin scaled by the block's radius of gyration.
    const double l = std::sqrt(kTripodInertiaEstimate_kgm2 / kTripodMass_kg);
    const Eigen::Vector3d a(got.pair.vx, got.pair.vy, l * got.pair.wz);
    const Eigen::Vector3d b(want.pair.vx, want.pair.vy, l * want.pair.wz);
    EXPECT_LT(std::acos(std::min(1.0, a.normalized().dot(b.normalized()))),
              kImportTwistAngleTol_rad)
        << what;
    EXPECT_NEAR(got.dtheta_rad, want.dtheta_rad, kPoseRoundTripTol_rad) << what;
    EXPECT_NEAR(got.contact_x_m, want.contact_x_m, kImportContactTol_m) << what;
    EXPECT_NEAR(got.contact_y_m, want.contact_y_m, kImportContactTol_m) << what;
    const TripodPushReport& r = report.push_reports[i];
    EXPECT_LT(r.force_normal_angle_deg, 90.0) << what;
    EXPECT_LT(r.max_edge_distance_m, 0.001) << what;
    EXPECT_NEAR(r.onset_s, 1.5, 0.05) << what << ": the tip reaches the block at 1.5 s";
  }
  // Written, read back and fitted: the truth.
  const std::string csv = PathIn("out", "synthetic.csv");
  WriteWrenchTwistCsv(data, csv);
  const WrenchTwistData read = ReadWrenchTwistCsv(csv);
  const EstimateResult r =
      EstimateQuasiStatic(read.Pairs(), QuasiStaticOptionsFor(read, IdentifyOptions{}));
  const double truth[3] = {kTruth.a, kTruth.b, kTruth.c};
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(r.parameters[i].identifiable) << ParameterName(i);
    EXPECT_NEAR(r.parameters[i].value / truth[i], 1.0, kImportedFitRelTol) << ParameterName(i);
  }
}

/// Imports `log` (a changed copy of Log()) and returns the report.
TripodImportReport ImportChanged(const TripodLog& log) {
  TripodImportReport report;
  ImportZhouTripod(log, PathIn("10_130_10_10_10_130", "changed.txt"), {}, &report);
  return report;
}

void ExpectRejected(const TripodImportReport& report, int push, const std::string& words) {
  ASSERT_GE(static_cast<int>(report.push_reports.size()), push);
  const TripodPushReport& r = report.push_reports[push - 1];
  EXPECT_FALSE(r.accepted) << "push " << push;
  EXPECT_NE(r.reason.find(words), std::string::npos) << "push " << push << ": " << r.reason;
  // The other pushes still get through.
  EXPECT_EQ(report.accepted, report.pushes - 1);
}

TEST(ZhouTripodImport, RejectsAPushThatStartsInContact) {
  TripodLog log = Log();
  // Push 3's trace starts 1.35 s late: 0.15 s before the tip reaches the block.
  auto& forces = log.pushes[2].forces;
  forces.erase(forces.begin(), forces.begin() + 135);
  ExpectRejected(ImportChanged(log), 3, "s into the trace, less than 0.30 s");
}

TEST(ZhouTripodImport, RejectsAPushWhoseFirstSampleIsOff) {
  TripodLog log = Log();
  // Push 4's sensor reads 0.8 N more throughout, as when the finger already rests on the
  // block (or the bias jumped): its first sample, the offset, is 0.8 N off the others'.
  for (TripodForceSample& s : log.pushes[3].forces) s.fx_n += 0.8;
  const TripodImportReport report = ImportChanged(log);
  ExpectRejected(report, 4, "the first sample differs by 0.8");
  EXPECT_NE(report.push_reports[3].reason.find("line "), std::string::npos);
}

TEST(ZhouTripodImport, RejectsAForceOfTheWrongSign) {
  TripodLog log = Log();
  // Push 5's sensor reads the force on the finger instead (about its bias).
  const TripodForceSample first = log.pushes[4].forces[0];
  for (TripodForceSample& s : log.pushes[4].forces) {
    s.fx_n = 2 * first.fx_n - s.fx_n;
    s.fy_n = 2 * first.fy_n - s.fy_n;
  }
  ExpectRejected(ImportChanged(log), 5, "points out of the block");
}

TEST(ZhouTripodImport, RejectsADeadSensorAndTimesThatGoBack) {
  TripodLog log = Log();
  for (TripodForceSample& s : log.pushes[0].forces) {
    s.fx_n = log.pushes[0].forces[0].fx_n;
    s.fy_n = log.pushes[0].forces[0].fy_n;
  }
  ExpectRejected(ImportChanged(log), 1, "no contact");
  log = Log();
  std::swap(log.pushes[1].robot[5].t_s, log.pushes[1].robot[6].t_s);
  log.pushes[1].robot[6].line = 77;
  ExpectRejected(ImportChanged(log), 2, "line 77: robot pose time");
}

TEST(ZhouTripodImport, RejectsAToolPointAwayFromTheBlock) {
  TripodLog log = Log();
  for (TripodRobotSample& r : log.pushes[5].robot) r.pose.x_mm += 20.0;
  ExpectRejected(ImportChanged(log), 6, "from the block's edge");
}

TEST(ZhouTripodImport, WritesOneReportRowPerPush) {
  const std::string path = PathIn("report", "import_report.csv");
  TripodImportReport report;
  TripodLog log = Log();
  for (TripodForceSample& s : log.pushes[3].forces) s.fx_n += 0.8;
  ImportZhouTripod(log, "x/y.txt", {}, &report);
  WriteTripodImportReport(report, path);
  std::ifstream in(path);
  int rows = 0, rejected = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line.rfind("push,", 0) == 0) continue;
    ++rows;
    rejected += line.find(",rejected,") != std::string::npos;
  }
  EXPECT_EQ(rows, 12);
  EXPECT_EQ(rejected, 1);
  TripodImportOptions bad;
  bad.sliding_fraction = 1.5;
  EXPECT_THROW(ImportZhouTripod(log, "x/y.txt", bad, &report), std::invalid_argument);
}

}  // namespace
}  // namespace slideid
