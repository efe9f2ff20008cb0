// Cross-validation (prediction/validate.h) on synthetic pusher-driven logs of one slider with
// known friction: the folds' pooled fits find it, predict the held-out pushes nearly as well
// as the pushes' own fits, and better than the textbook friction.

#include "prediction/validate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "fixtures/pushed_square.h"
#include "forward_model/constants.h"
#include "plots/validate_plot.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

const ReducedFriction kTruth = testing::SquarePush{}.friction;
constexpr double kMuP = 0.3;  // testing::PushOfSet's

/// Push k of the fixture's set, logged at 100 Hz with noise, named push<k>.csv.
Trajectory Push(int k) {
  Trajectory log =
      testing::NoisyPushLog(testing::PushedSquareScene(testing::PushOfSet(k)), 100 + k);
  log.source = "push" + std::to_string(k) + ".csv";
  return log;
}

std::vector<Trajectory> Pushes(int n) {
  std::vector<Trajectory> logs;
  for (int k = 0; k < n; ++k) logs.push_back(Push(k));
  return logs;
}

const MethodValidation& Method(const ValidationResult& r, const std::string& name) {
  for (const MethodValidation& m : r.methods) {
    if (m.method == name) return m;
  }
  throw std::logic_error("no method " + name);
}

TEST(Validate, TextbookCIsTheMeanDistanceOverThePatch) {
  // Square of side s: s (sqrt(2) + asinh(1)) / 6; disk: 2R/3; ring: 2/3 (R^3 - r^3)/(R^2 - r^2).
  EXPECT_NEAR(TextbookFriction(ContactPatch::Rectangle(0.09, 0.09)).c,
              0.09 * (std::sqrt(2.0) + std::asinh(1.0)) / 6, 2e-5);
  EXPECT_NEAR(TextbookFriction(ContactPatch::Disk(0.05)).c, 2 * 0.05 / 3, 5e-5);
  EXPECT_NEAR(TextbookFriction(ContactPatch::Ring(0.05, 0.04)).c,
              2.0 / 3 * (0.05 * 0.05 * 0.05 - 0.04 * 0.04 * 0.04) / (0.05 * 0.05 - 0.04 * 0.04),
              2e-4);
  EXPECT_EQ(TextbookFriction(ContactPatch::Disk(0.05)).a, 0.25);
  EXPECT_EQ(TextbookFriction(ContactPatch::Disk(0.05)).b, 1.0);
}

// Leave-one-out over 6 pushes: every fold's pooled fit is near the truth and predicts its
// held-out push within a millimetre and a degree; the own fits within a few; the textbook
// friction lands farther.
TEST(Validate, LeaveOneOutFindsTheFrictionAndPredictsHeldOutPushes) {
  const std::vector<Trajectory> logs = Pushes(6);
  ValidationOptions options;
  options.threads = 2;
  const ValidationResult r = Validate(logs, options);
  ASSERT_EQ(r.folds, 6);
  ASSERT_EQ(r.fold_fits.size(), 6u);
  for (const FoldFit& f : r.fold_fits) {
    ASSERT_TRUE(f.ok) << f.error;
    ASSERT_EQ(f.held_out.size(), 1u);
    EXPECT_NEAR(f.friction.a / kTruth.a, 1.0, 0.03) << f.fold;
    EXPECT_NEAR(f.friction.b / kTruth.b, 1.0, 0.1) << f.fold;
    EXPECT_NEAR(f.friction.c / kTruth.c, 1.0, 0.1) << f.fold;
    EXPECT_EQ(f.mu_pusher_from, "fit");
    EXPECT_NEAR(f.mu_pusher, kMuP, 0.02);
  }
  const MethodValidation& folds = Method(r, "folds");
  const MethodValidation& own = Method(r, "own fit");
  const MethodValidation& textbook = Method(r, "textbook");
  const MethodValidation& quasi = Method(r, "quasi-static");
  EXPECT_EQ(folds.failed, 0);
  EXPECT_EQ(quasi.failed, 0);
  EXPECT_EQ(quasi.pushes.size(), logs.size());
  for (size_t i = 0; i < folds.pushes.size(); ++i) {
    EXPECT_EQ(folds.pushes[i].fold, static_cast<int>(i));
    EXPECT_EQ(folds.pushes[i].log, logs[i].source);
  }
  EXPECT_LT(folds.final_position_m.worst, 1e-3);
  EXPECT_LT(folds.final_rotation_rad.worst, 1.0 * kPi / 180);
  // One 50 mm push determines less than five pooled: its own fit is no oracle for every
  // push (a tip that sticks there gives mu_p only as a lower bound), measured 1.6 mm.
  EXPECT_LT(own.final_position_m.median, 3e-3);
  EXPECT_GT(textbook.final_position_m.median + 0.05 * textbook.final_rotation_rad.median,
            2 * (folds.final_position_m.median + 0.05 * folds.final_rotation_rad.median));
  // The summary is the order statistics of the pushes.
  std::vector<double> position;
  for (const PushPrediction& p : folds.pushes) position.push_back(p.errors.final_position_m);
  std::sort(position.begin(), position.end());
  EXPECT_DOUBLE_EQ(folds.final_position_m.worst, position.back());
  EXPECT_DOUBLE_EQ(folds.final_position_m.median, 0.5 * (position[2] + position[3]));
}

// K folds deal the logs round-robin; the force drive needs no mu_p.
TEST(Validate, KFoldsDealTheLogsRoundRobinAndTheForceDriveWorks) {
  const std::vector<Trajectory> logs = Pushes(6);
  ValidationOptions options;
  options.folds = 3;
  options.own_fit = false;
  options.textbook = false;
  options.prediction.drive = PredictionDrive::kForce;
  const ValidationResult r = Validate(logs, options);
  ASSERT_EQ(r.folds, 3);
  ASSERT_EQ(r.methods.size(), 1u);
  for (const FoldFit& f : r.fold_fits) {
    ASSERT_EQ(f.held_out.size(), 2u);
    EXPECT_EQ(f.held_out[0], logs[f.fold].source);
    EXPECT_EQ(f.held_out[1], logs[f.fold + 3].source);
  }
  EXPECT_EQ(r.methods[0].failed, 0);
}

TEST(Validate, TooFewLogsOrBadOptionsAreRejected) {
  const std::vector<Trajectory> one = Pushes(1);
  EXPECT_THROW(Validate(one, ValidationOptions{}), std::invalid_argument);
  ValidationOptions bad;
  bad.folds = 1;
  EXPECT_THROW(Validate(Pushes(2), bad), std::invalid_argument);
}

TEST(Validate, ThePlotDrawsEachFrictionsPushesAndQuartiles) {
  const ValidationResult r = Validate(Pushes(3), ValidationOptions{});
  const std::string dir = testing::TempPath("validate_plot");
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  ValidationPlotOptions options;
  options.out_png = "/tmp/v.png";
  options.title = "t";
  const std::string script = ValidationPlotScript(r, dir, options);
  for (const char* m : {"\"folds\" 0", "\"quasi-static\" 1", "\"own fit\" 2", "\"textbook\" 3"}) {
    EXPECT_NE(script.find(m), std::string::npos) << m;
  }
  EXPECT_NE(script.find("final rotation error [deg]"), std::string::npos);
  // One point per predicted push and method, one summary row per method.
  std::istringstream points(testing::ReadText(dir + "/errors.dat"));
  int rows = 0;
  for (std::string line; std::getline(points, line);) rows += !line.empty() && line[0] != '#';
  EXPECT_EQ(rows, 3 * 4);
}

TEST(ValidateTool, WritesTheSummaryTheTableAndTheJson) {
  const std::string dir = testing::TempPath("validate_logs");
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  for (int k = 0; k < 4; ++k) WritePushLog(Push(k), dir + "/push" + std::to_string(k) + ".csv");
  const std::string csv = testing::TempPath("validate.csv"),
                    json = testing::TempPath("validate.json");
  const testing::ToolRun run =
      testing::RunTool("validate", "--logs " + dir + " --folds 2 --csv " + csv + " --json " + json);
  ASSERT_EQ(run.code, 0) << run.all();
  EXPECT_NE(run.out.find("4 logs, 2 folds"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("textbook"), std::string::npos) << run.out;
  EXPECT_NE(testing::ReadText(csv).find("folds,\""), std::string::npos);
  EXPECT_NE(testing::ReadText(json).find("\"fold_fits\""), std::string::npos);
  EXPECT_EQ(testing::RunTool("validate", "--logs " + dir + " --folds 2 --leave-one-out").code, 2);
  EXPECT_EQ(testing::RunTool("validate", "--folds 2").code, 2);
}

// A log of absurd magnitudes among good ones (the bundled log with '# inertia = 1e-300'):
// its folds fail and say so, the others are predicted, and Ceres' pages about residual blocks
// evaluating to NaN stay out of the output. validate died with "AssessIdentifiability:
// information matrix is not finite" and printed those pages.
TEST(ValidateTool, ALogOfAbsurdMagnitudesFailsItsFoldsWithoutNaNPages) {
  const std::string dir = testing::NewDir("validate_absurd");
  const std::string text =
      testing::ReadText(std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv");
  const auto at = text.find("# inertia = ");
  ASSERT_NE(at, std::string::npos);
  const std::string absurd =
      text.substr(0, at) + "# inertia = 1e-300" + text.substr(text.find('\n', at));
  for (const char* name : {"a.csv", "b.csv"}) std::ofstream(dir + "/" + name) << text;
  std::ofstream(dir + "/c.csv") << absurd;
  const testing::ToolRun run = testing::RunTool("validate", "--logs " + dir + " --drive force");
  EXPECT_EQ(run.code, 0) << run.all();
  EXPECT_NE(run.out.find("3 logs, 3 folds"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("did not converge"), std::string::npos) << run.out;
  EXPECT_EQ(run.err.find("Residual Block"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("nan"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace slideid
