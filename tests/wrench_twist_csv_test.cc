// Wrench-twist pairs: the frame changes and limit-surface relations of
// forward_model/wrench_twist_pair.h, and the CSV format of io/wrench_twist_csv.h (round
// trip, and an error naming the file, line and column for each kind of bad input).

#include "io/wrench_twist_csv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>

#include "forward_model/constants.h"
#include "tests/estimator_test_support.h"
#include "tests/reader_test_support.h"

namespace slideid {
namespace {

using testing::TempDirectory;
using testing::WriteFile;

// Values recomputed by another arithmetic route than the code under test: rounding only.
constexpr double kRecomputeTol = 1e-12;

WrenchTwistData SampleData() {
  WrenchTwistData d;
  d.mass_kg = 1.518;
  d.gravity_mps2 = 9.81;
  d.inertia_kgm2 = 1.9e-3;
  d.supports = "-0.04 -0.04; 0.08 -0.04; -0.04 0.08";
  d.source = "a test";
  d.true_friction = FrictionParameters{0.3, 1.0, 1.2, 0.04};
  d.extra_metadata = {{"surface", "hardboard"}};
  WrenchTwistRow r;
  r.push = 3;
  r.pair = {3.1, 0.1 / 3.0, 0.25, 0.13, 1.2e-3, -4e-4, 0.018};
  r.duration_s = 4.9;
  r.dx_m = 0.0059;
  r.dy_m = -0.0019;
  r.dtheta_rad = 0.088;
  r.contact_x_m = -0.019;
  r.contact_y_m = 0.068;
  r.peak_force_n = 4.15;
  r.samples = 492;
  d.rows.push_back(r);
  WrenchTwistRow unknown;  // diagnostics unknown
  unknown.push = 4;
  unknown.pair = {-1.0, 2.0, 0.0, -0.05, -1e-3, 2e-3, -0.01};
  d.rows.push_back(unknown);
  return d;
}

constexpr const char* kMeta = "# mass = 1.5\n";
constexpr const char* kHeader = "push,fx,fy,mz,vx,vy,wz,duration\n";

void ExpectCsvError(const std::string& name, const std::string& content, int line,
                    const std::string& column, const std::string& words) {
  const std::string path = WriteFile(name, content);
  try {
    ReadWrenchTwistCsv(path);
    ADD_FAILURE() << name << ": no LogError";
  } catch (const LogError& e) {
    testing::ExpectNamesFileLineColumn(e, path, line, column, words);
  }
  // The memory reader says the same.
  EXPECT_THROW(ParseWrenchTwistCsv(content, name), LogError) << name;
}

TEST(WrenchTwistPair, RotatedFrameTurnsForcesAndVelocitiesAndKeepsMomentAndSpin) {
  const WrenchTwistPair p{1.0, 2.0, 0.5, 0.3, -0.4, 0.7, 0.9};
  const WrenchTwistPair q = InRotatedFrame(p, kPi / 2);
  // Axes turned by +90 deg: the old x axis is the new -y axis.
  EXPECT_NEAR(q.fx, 2.0, kRecomputeTol);
  EXPECT_NEAR(q.fy, -1.0, kRecomputeTol);
  EXPECT_NEAR(q.vx, 0.7, kRecomputeTol);
  EXPECT_NEAR(q.vy, 0.4, kRecomputeTol);
  EXPECT_EQ(q.mz, p.mz);
  EXPECT_EQ(q.wz, p.wz);
  EXPECT_EQ(q.fz, p.fz);
  const WrenchTwistPair back = InRotatedFrame(q, -kPi / 2);
  EXPECT_NEAR(back.fx, p.fx, kRecomputeTol);
  EXPECT_NEAR(back.vy, p.vy, kRecomputeTol);
}

TEST(WrenchTwistPair, AboutPointMovesTheMomentAndTheVelocityAsARigidBodyDoes) {
  const WrenchTwistPair p{1.0, 2.0, 0.0, 0.3, -0.4, 0.7, 0.9};
  const Eigen::Vector2d r(0.05, -0.02);
  const WrenchTwistPair q = AboutPoint(p, r);
  // m_P = m_O - r x f; v_P = v_O + w x r.
  EXPECT_NEAR(q.mz, 0.3 - (0.05 * 2.0 - (-0.02) * 1.0), kRecomputeTol);
  EXPECT_NEAR(q.vx, -0.4 - 0.9 * (-0.02), kRecomputeTol);
  EXPECT_NEAR(q.vy, 0.7 + 0.9 * 0.05, kRecomputeTol);
  // And back: about -r from the new point is the original.
  const WrenchTwistPair back = AboutPoint(q, -r);
  EXPECT_NEAR(back.mz, p.mz, kRecomputeTol);
  EXPECT_NEAR(back.vx, p.vx, kRecomputeTol);
  EXPECT_NEAR(back.vy, p.vy, kRecomputeTol);
}

TEST(WrenchTwistPair, QuasiStaticWrenchLiesOnTheEllipsoidAndItsNormalIsTheTwist) {
  const ReducedFriction f{0.35, 1.3, 0.04};
  const double n = 14.9;
  const Eigen::Vector3d twist(0.002, -0.001, 0.03);
  const Eigen::Vector3d w = QuasiStaticWrench(twist, f, n);
  const double norm = std::pow(w.x() / (f.a * n), 2) + std::pow(w.y() / (f.a * f.b * n), 2) +
                      std::pow(w.z() / (f.a * f.c * n), 2);
  EXPECT_NEAR(norm, 1.0, kRecomputeTol);
  const Eigen::Vector3d normal = LimitSurfaceNormal(w, f);
  EXPECT_NEAR(normal.normalized().dot(twist.normalized()), 1.0, kRecomputeTol);
  EXPECT_THROW(QuasiStaticWrench(Eigen::Vector3d::Zero(), f, n), std::invalid_argument);
  EXPECT_THROW(QuasiStaticWrench(twist, f, 0.0), std::invalid_argument);
}

TEST(WrenchTwistPair, BodyTwistFromPoseChangeInvertsTheExponentialAtAnyTurn) {
  for (double w : {0.0, 1e-6, 1e-4, 0.1, -0.5, 2.0, 3.0}) {
    const Eigen::Vector3d twist(0.01, -0.003, w);
    const Eigen::Vector3d d = PoseChangeFromBodyTwist(twist, 1.0);
    const Eigen::Vector3d back = BodyTwistFromPoseChange(d.head<2>(), d.z());
    EXPECT_NEAR((back - twist).norm(), 0.0, kRecomputeTol) << "w = " << w;
  }
  // A straight push: the displacement is the velocity.
  const Eigen::Vector3d straight = BodyTwistFromPoseChange(Eigen::Vector2d(0.01, 0.002), 0.0);
  EXPECT_EQ(straight, Eigen::Vector3d(0.01, 0.002, 0.0));
}

TEST(WrenchTwistCsv, RoundTripsEveryValueExactly) {
  const WrenchTwistData d = SampleData();
  const std::string path = TempDirectory() + "/round.csv";
  WriteWrenchTwistCsv(d, path);
  const WrenchTwistData r = ReadWrenchTwistCsv(path);
  EXPECT_EQ(r.mass_kg, d.mass_kg);
  EXPECT_EQ(r.gravity_mps2, d.gravity_mps2);
  ASSERT_TRUE(r.inertia_kgm2.has_value());
  EXPECT_EQ(*r.inertia_kgm2, *d.inertia_kgm2);
  EXPECT_FALSE(r.com_height_m.has_value());
  EXPECT_EQ(r.supports, d.supports);
  EXPECT_EQ(r.source, d.source);
  ASSERT_TRUE(r.true_friction.has_value());
  EXPECT_EQ(r.true_friction->e_o, 1.2);
  ASSERT_EQ(r.extra_metadata.size(), 1u);
  EXPECT_EQ(r.extra_metadata[0].second, "hardboard");
  ASSERT_EQ(r.rows.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const WrenchTwistRow &a = d.rows[i], &b = r.rows[i];
    EXPECT_EQ(a.push, b.push);
    EXPECT_EQ(a.pair.fx, b.pair.fx);
    EXPECT_EQ(a.pair.fy, b.pair.fy);
    EXPECT_EQ(a.pair.fz, b.pair.fz);
    EXPECT_EQ(a.pair.mz, b.pair.mz);
    EXPECT_EQ(a.pair.vx, b.pair.vx);
    EXPECT_EQ(a.pair.vy, b.pair.vy);
    EXPECT_EQ(a.pair.wz, b.pair.wz);
    EXPECT_EQ(a.samples, b.samples);
    for (auto [x, y] : {std::pair{a.duration_s, b.duration_s},
                        {a.dx_m, b.dx_m},
                        {a.dy_m, b.dy_m},
                        {a.dtheta_rad, b.dtheta_rad},
                        {a.contact_x_m, b.contact_x_m},
                        {a.contact_y_m, b.contact_y_m},
                        {a.peak_force_n, b.peak_force_n}}) {
      if (std::isnan(x)) {
        EXPECT_TRUE(std::isnan(y));
      } else {
        EXPECT_EQ(x, y);
      }
    }
  }
  EXPECT_EQ(r.rows[0].line, 13);  // 1 prose line, 10 metadata lines, the header
}

TEST(WrenchTwistCsv, FindsColumnsByNameInAnyOrderAndNotesUnknownOnes) {
  const std::string text = std::string(kMeta) +
                           "wz,vy,vx,mz,fy,fx,comment\n0.01,0.002,0.001,0.1,1,3,hello\n"
                           "0.02,0.001,0.001,0.1,1,3,\n0.02,0.001,0.003,0.1,1,3,x\n";
  WrenchTwistReadReport report;
  const WrenchTwistData d = ParseWrenchTwistCsv(text, "any_order.csv", {}, &report);
  ASSERT_EQ(d.rows.size(), 3u);
  EXPECT_EQ(d.rows[0].pair.fx, 3.0);
  EXPECT_EQ(d.rows[0].pair.wz, 0.01);
  EXPECT_EQ(d.rows[0].push, 0);
  EXPECT_TRUE(std::isnan(d.rows[0].duration_s));
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_NE(report.notes[0].find("comment"), std::string::npos);
}

TEST(WrenchTwistCsv, OverridesReplaceTheMetadataAndAMissingMassIsAnError) {
  const std::string text = std::string(kMeta) + kHeader + "1,3,1,0.1,0.001,0.002,0.01,4\n";
  SliderOverrides o;
  o.mass_kg = 2.0;
  o.gravity_mps2 = 9.8;
  const WrenchTwistData d = ParseWrenchTwistCsv(text, "o.csv", o);
  EXPECT_EQ(d.mass_kg, 2.0);
  EXPECT_EQ(d.WeightN(), 2.0 * 9.8);
  ExpectCsvError("no_mass.csv", std::string(kHeader) + "1,3,1,0.1,0.001,0.002,0.01,4\n", 0, "",
                 "mass is not known");
}

TEST(WrenchTwistCsv, ZeroTwistOrZeroWrenchIsAnErrorNamingTheRow) {
  const std::string ok = "1,3,1,0.1,0.001,0.002,0.01,4\n";
  ExpectCsvError("zero_twist.csv", std::string(kMeta) + kHeader + ok + "2,3,1,0.1,0,0,0,4\n", 4,
                 "vx", "twist (vx, vy, wz) is zero");
  ExpectCsvError("zero_wrench.csv", std::string(kMeta) + kHeader + ok + ok + "3,0,0,0,1,0,0,4\n", 5,
                 "fx", "wrench (fx, fy, mz) is zero");
  // A pure moment, or a pure spin, is a valid pair.
  EXPECT_NO_THROW(
      ParseWrenchTwistCsv(std::string(kMeta) + kHeader + "1,0,0,0.1,0,0,0.01,4\n", "spin.csv"));
}

TEST(WrenchTwistCsv, BadCellsAndShapesNameTheLineAndColumn) {
  const std::string ok = "1,3,1,0.1,0.001,0.002,0.01,4\n";
  ExpectCsvError("text.csv", std::string(kMeta) + kHeader + ok + "2,3,abc,0.1,0.001,0.002,0.01,4\n",
                 4, "fy", "'abc' is not a finite number");
  ExpectCsvError("nan.csv", std::string(kMeta) + kHeader + "2,3,1,nan,0.001,0.002,0.01,4\n", 3,
                 "mz", "'nan' is not a finite number");
  ExpectCsvError("empty_required.csv",
                 std::string(kMeta) + kHeader + "2,,1,0.1,0.001,0.002,0.01,4\n", 3, "fx",
                 "empty; a number is required");
  ExpectCsvError("push.csv", std::string(kMeta) + kHeader + "2.5,3,1,0.1,0.001,0.002,0.01,4\n", 3,
                 "push", "not a whole number");
  ExpectCsvError("fields.csv", std::string(kMeta) + kHeader + "2,3,1,0.1,0.001,0.002\n", 3, "",
                 "expected 8 fields");
  ExpectCsvError("duration.csv", std::string(kMeta) + kHeader + "2,3,1,0.1,0.001,0.002,0.01,0\n", 3,
                 "duration", "must be > 0");
  ExpectCsvError("lift.csv", std::string(kMeta) + "fx,fy,fz,mz,vx,vy,wz\n3,1,20,0.1,1,0,0\n", 3,
                 "fz", "lifts the slider");
  ExpectCsvError("missing.csv", std::string(kMeta) + "fx,fy,mz,vx,vy\n3,1,0.1,1,0\n", 2, "wz",
                 "missing");
  ExpectCsvError("twice.csv", std::string(kMeta) + "fx,fy,mz,vx,vy,wz,fx\n3,1,0.1,1,0,0,3\n", 2,
                 "fx", "given twice");
  ExpectCsvError("header.csv", std::string(kMeta) + "3,1,0.1,1,0,0\n", 2, "", "must be the header");
  ExpectCsvError("meta.csv", "# mass = heavy\n" + std::string(kHeader) + ok, 1, "",
                 "not a finite number");
  ExpectCsvError("bad_mass.csv", "# mass = -1\n" + std::string(kHeader) + ok, 1, "", "must be > 0");
  ExpectCsvError("no_rows.csv", std::string(kMeta) + kHeader, 2, "", "not followed by any data");
  ExpectCsvError("empty.csv", "", 0, "", "the file is empty");
  ExpectCsvError("comments.csv", "# only a comment\n", 0, "", "only comments");
}

TEST(WrenchTwistCsv, AFileThatCannotBeReadIsALogErrorNamingIt) {
  EXPECT_THROW(ReadWrenchTwistCsv(TempDirectory() + "/does_not_exist.csv"), LogError);
  EXPECT_THROW(ReadWrenchTwistCsv(TempDirectory()), LogError);
  const std::string nul =
      WriteFile("nul.csv", std::string(kMeta) + kHeader + std::string("1,3\0,1\n", 7));
  EXPECT_THROW(ReadWrenchTwistCsv(nul), LogError);
}

TEST(WrenchTwistCsv, FileAndMemoryReadersAgreeOnEverySeedCorpusFile) {
  const testing::CorpusReads reads = testing::ExpectFileAndMemoryReadersAgree(
      "pairs", [](const std::string& path) { return ReadWrenchTwistCsv(path).rows.size(); },
      [](const std::string& text, const std::string& path) {
        return ParseWrenchTwistCsv(text, path).rows.size();
      });
  EXPECT_GE(reads.files, 8);
}

TEST(WrenchTwistCsv, TheWriterRefusesNonFiniteValuesAndBadMetadata) {
  WrenchTwistData d = SampleData();
  d.rows[1].pair.vx = std::nan("");
  EXPECT_THROW(WriteWrenchTwistCsv(d, TempDirectory() + "/nan.csv"), std::invalid_argument);
  d = SampleData();
  d.extra_metadata.push_back({"mass", "2"});
  std::ostringstream out;
  EXPECT_THROW(WriteWrenchTwistCsv(d, out), std::invalid_argument);
  d = SampleData();
  d.source = "two\nlines";
  EXPECT_THROW(WriteWrenchTwistCsv(d, out), std::invalid_argument);
  EXPECT_THROW(WriteWrenchTwistCsv(SampleData(), TempDirectory() + "/no/such/dir.csv"),
               std::runtime_error);
}

}  // namespace
}  // namespace slideid
