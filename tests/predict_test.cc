// Prediction (prediction/predict.h): a push replayed from its first state with a friction,
// by the pusher's path or by the logged force, and its errors against the log.

#include "prediction/predict.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <string>

#include "datasets/sensor_model.h"
#include "fixtures/pushed_square.h"
#include "forward_model/constants.h"
#include "forward_model/simulator.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

/// The fixture's square pushed 63 mm at 50 mm/s, 18 deg off the edge's normal: the tip
/// slides along the edge for part of the push.
Scene PushedSquare() {
  testing::SquarePush push;
  push.angle_rad = std::atan2(0.02, 0.06);
  push.distance_m = std::hypot(0.06, 0.02);
  return testing::PushedSquareScene(push);
}

Trajectory Logged(const Scene& scene, int every) {
  LogSpec spec;
  spec.log_every = every;
  spec.motion = LogMotion::kPoses;
  return MakeLog(testing::SimulateOrFail(scene), spec);
}

// The truth and the simulation's own step reproduce the log: the pusher drive repeats what
// made it (to the solver's tolerance), and so does the force drive of a log that holds each
// step's force.
TEST(Predict, TheTruthReproducesItsOwnLogByEitherDrive) {
  const Scene scene = PushedSquare();
  const ReducedFriction truth = scene.friction.reduced();
  Trajectory log = testing::SimulateOrFail(scene);
  log.measured.velocity = true;  // the simulator's own start velocity (0)
  PredictionOptions options;
  options.register_tip = false;  // the geometry that made the log, to the last bit
  const Prediction pusher = PredictPush(log, truth, 0.25, options);
  ASSERT_TRUE(pusher.summary.ok()) << pusher.summary.message;
  EXPECT_GT(pusher.summary.tip_slide_steps, 10);
  EXPECT_LT(pusher.errors.final_position_m, 1e-9);
  EXPECT_LT(pusher.errors.final_rotation_rad, 1e-9);
  EXPECT_FALSE(pusher.errors.parting_time_s.has_value());
  options.drive = PredictionDrive::kForce;
  const Prediction force = PredictPush(log, truth, std::nullopt, options);
  ASSERT_TRUE(force.summary.ok()) << force.summary.message;
  EXPECT_LT(force.errors.final_position_m, 1e-9);
  EXPECT_LT(force.errors.final_rotation_rad, 1e-9);
}

// A 100 Hz log of the 1 ms simulation, predicted at the log's rate with 10 substeps: the
// pusher's path alone gives the motion back. A wrong friction, or a wrong mu_p, lands
// farther away than the truth.
TEST(Predict, TheTruthPredictsBetterThanAWrongFriction) {
  const Scene scene = PushedSquare();
  const Trajectory log = Logged(scene, 10);
  const ReducedFriction truth = scene.friction.reduced();
  PredictionOptions options;
  options.substeps = 10;
  const Prediction right = PredictPush(log, truth, 0.25, options);
  ASSERT_TRUE(right.summary.ok()) << right.summary.message;
  EXPECT_LT(right.errors.final_position_m, 2e-4);
  EXPECT_LT(right.errors.final_rotation_rad, 0.2 * kPi / 180);
  ReducedFriction low_c = truth;
  low_c.c *= 0.7;
  const Prediction wrong_c = PredictPush(log, low_c, 0.25, options);
  EXPECT_GT(wrong_c.errors.final_rotation_rad, 5 * right.errors.final_rotation_rad);
  const Prediction wrong_mu_p = PredictPush(log, truth, 0.6, options);
  EXPECT_GT(wrong_mu_p.errors.final_position_m + 0.05 * wrong_mu_p.errors.final_rotation_rad,
            5 * (right.errors.final_position_m + 0.05 * right.errors.final_rotation_rad));
}

// The logged tip 1.5 mm off the outline (a registration error between motion capture and
// the robot, as on the MIT pushes): as logged, the tip pushes air; registered to the rows
// where the log pushes, it predicts as the true tip does.
TEST(Predict, TheTipIsRegisteredToTheOutlineWhereTheLogPushes) {
  const Scene scene = PushedSquare();
  Trajectory log = Logged(scene, 10);
  for (TrajectorySample& s : log.samples) *s.tip_world += Eigen::Vector2d(-0.0015, 0.0);
  const ReducedFriction truth = scene.friction.reduced();
  PredictionOptions options;
  options.substeps = 10;
  const Prediction registered = PredictPush(log, truth, 0.25, options);
  EXPECT_NEAR(registered.tip_radius_m, 0.00475 + 0.0015, 2e-4);
  EXPECT_LT(registered.errors.final_position_m, 1e-3);
  options.register_tip = false;
  const Prediction as_logged = PredictPush(log, truth, 0.25, options);
  EXPECT_EQ(as_logged.tip_radius_m, 0.00475);
  EXPECT_GT(as_logged.errors.final_position_m, 3 * registered.errors.final_position_m);
}

// A 150 ms hole in the record (rows left out, the next marked start): the prediction steps
// across it at the log's rate, following the tip's path, and lands where the full log does.
TEST(Predict, AGapInTheRecordIsSteppedAtTheLogsRate) {
  const Scene scene = PushedSquare();
  const Trajectory full = Logged(scene, 10);
  Trajectory holed = full;
  holed.samples.erase(holed.samples.begin() + 30, holed.samples.begin() + 45);
  holed.samples[30].mode = SampleMode::kStart;
  PredictionOptions options;
  options.substeps = 10;
  const ReducedFriction truth = scene.friction.reduced();
  const Prediction whole = PredictPush(full, truth, 0.25, options);
  const Prediction across = PredictPush(holed, truth, 0.25, options);
  ASSERT_TRUE(across.summary.ok()) << across.summary.message;
  EXPECT_EQ(across.summary.steps, whole.summary.steps);  // 10 per 10 ms, the hole included
  EXPECT_NEAR(across.errors.final_position_m, whole.errors.final_position_m, 1e-6);
}

// The quasi-static model is the dynamic one's slow limit: a push at 2 mm/s, sticking and
// sliding at the tip, anisotropic friction, no CM height; the two drives land within 2% of
// the displacement and 1 deg of each other. At 300 mm/s they part: the slider slides on
// after the tip stops (v^2 / (2 a g) = 15 mm), which a model without inertia cannot do.
TEST(Predict, TheQuasiStaticModelIsTheSlowLimitOfTheDynamicOne) {
  for (const double speed : {0.002, 0.3}) {
    Scene scene = PushedSquare();
    scene.slider.com_height_m = 0;
    const Eigen::Vector2d start(-0.045 - 0.00475, 0.02);
    scene.pusher->path =
        PusherPath::Polyline(0.0, start, {start + Eigen::Vector2d(0.03, 0.012)}, {speed});
    scene.duration_s = scene.pusher->path.end_s() + 0.05;
    scene.dt_s = speed < 0.01 ? 1e-2 : 1e-3;
    Trajectory log = testing::SimulateOrFail(scene);
    const ReducedFriction truth = scene.friction.reduced();
    PredictionOptions options;
    options.register_tip = false;
    options.drive = PredictionDrive::kQuasiStatic;
    options.substeps = 4;
    const Prediction qs = PredictPush(log, truth, 0.25, options);
    ASSERT_TRUE(qs.summary.ok()) << qs.summary.message;
    SCOPED_TRACE(::testing::Message() << "speed " << speed);
    if (speed < 0.01) {
      EXPECT_LT(qs.errors.final_position_fraction, 0.02);
      EXPECT_LT(qs.errors.final_rotation_rad, 1.0 * kPi / 180);
    } else {
      EXPECT_GT(qs.errors.final_position_fraction, 0.1);
    }
  }
}

// The errors against a trajectory shifted by a known amount from some row on.
TEST(Predict, ErrorsAreTheDistancesAtTheRowsAndTheFirstRowPastAThreshold) {
  Trajectory log;
  log.measured.tip = true;
  for (int u = 0; u <= 10; ++u) {
    TrajectorySample s;
    s.t_s = 0.1 * u;
    s.state.x = 0.01 * u;  // 100 mm over the log
    s.tip_world = Eigen::Vector2d(0.01 * u - 0.05, 0.0);
    log.samples.push_back(s);
  }
  Trajectory predicted = log;
  for (int u = 6; u <= 10; ++u) {
    predicted.samples[u].state.y = 0.002 * (u - 5);  // 2 mm per row from row 6
    predicted.samples[u].state.theta = 0.01 * (u - 5);
  }
  const PredictionErrors e = CompareWithLog(log, predicted, PredictionOptions{});
  EXPECT_NEAR(e.final_position_m, 0.010, 1e-15);
  EXPECT_NEAR(e.final_rotation_rad, 0.05, 1e-15);
  EXPECT_NEAR(e.travel_m, 0.1, 1e-15);
  EXPECT_EQ(e.travel_of, "tip");
  EXPECT_NEAR(e.final_position_per_100mm_m, 0.010, 1e-15);
  EXPECT_NEAR(e.logged_displacement_m, 0.1, 1e-15);
  EXPECT_NEAR(e.final_position_fraction, 0.1, 1e-14);
  EXPECT_NEAR(e.mean_position_m, 0.002 * (1 + 2 + 3 + 4 + 5) / 11, 1e-15);
  ASSERT_TRUE(e.parting_time_s.has_value());
  EXPECT_NEAR(*e.parting_time_s, 0.8, 1e-12);  // row 8: 6 mm, the first past 5 mm
}

TEST(Predict, ALogThatCannotBeDrivenThatWaySaysWhatIsMissing) {
  const Scene scene = PushedSquare();
  Trajectory log = Logged(scene, 10);
  log.source = "push.csv";
  const ReducedFriction f{0.3, 1.2, 0.035};
  auto message = [&](const Trajectory& l, std::optional<double> mu_p, PredictionDrive drive) {
    PredictionOptions o;
    o.drive = drive;
    try {
      PredictPush(l, f, mu_p, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(log, std::nullopt, PredictionDrive::kPusher).find("mu_p"), std::string::npos);
  Trajectory no_tip = log;
  no_tip.measured.tip = false;
  EXPECT_NE(message(no_tip, 0.25, PredictionDrive::kPusher)
                .find("push.csv: the pusher drive needs "
                      "the tip's path"),
            std::string::npos);
  Trajectory no_radius = log;
  no_radius.tip_radius_m.reset();
  EXPECT_NE(message(no_radius, 0.25, PredictionDrive::kPusher).find("tip_radius"),
            std::string::npos);
  Trajectory no_patch = log;
  no_patch.patch.reset();
  EXPECT_NE(message(no_patch, 0.25, PredictionDrive::kPusher).find("patch"), std::string::npos);
  Trajectory no_force = log;
  for (TrajectorySample& s : no_force.samples) s.applied = AppliedWrench{};
  EXPECT_NE(message(no_force, std::nullopt, PredictionDrive::kForce).find("no"), std::string::npos);
}

// The tool: a friction from identify's JSON or from options, the table or JSON, the
// predicted log written, usage errors exit 2.
TEST(PredictTool, PredictsFromOptionsAndWritesTheTrajectory) {
  const Scene scene = PushedSquare();
  const std::string log_path = testing::TempPath("predict_push.csv");
  WritePushLog(Logged(scene, 10), log_path);
  const std::string out = testing::TempPath("predicted.csv");
  const testing::ToolRun run =
      testing::RunTool("predict", "--log " + log_path +
                                      " --mu 0.3 --b 1.2 --c 0.035 --mu-pusher 0.25 "
                                      "--substeps 10 --json --out " +
                                      out);
  ASSERT_EQ(run.code, 0) << run.all();
  EXPECT_NE(run.all().find("\"drive\":\"pusher\""), std::string::npos) << run.all();
  EXPECT_NE(run.all().find("\"final_position_m\""), std::string::npos) << run.all();
  const Trajectory predicted = ReadPushLog(out);
  EXPECT_GT(predicted.samples.size(), 100u);
  EXPECT_EQ(testing::RunTool("predict", "--log " + log_path + " --b 1 --c 0.03").code, 2);
  EXPECT_EQ(
      testing::RunTool("predict", "--log " + log_path + " --mu 0.3 --b 1 --c 0.03 --drive sideways")
          .code,
      2);
  // No mu_p for the pusher drive: bad input, naming it.
  const testing::ToolRun no_mu_p =
      testing::RunTool("predict", "--log " + log_path + " --mu 0.3 --b 1 --c 0.03");
  EXPECT_EQ(no_mu_p.code, 1);
  EXPECT_NE(no_mu_p.all().find("mu_p"), std::string::npos) << no_mu_p.all();
  // A log that cannot be driven that way is named by its path (it was "the log").
  Trajectory no_tip = Logged(scene, 10);
  no_tip.measured.tip = false;
  const std::string no_tip_path = testing::TempPath("predict_no_tip.csv");
  WritePushLog(no_tip, no_tip_path);
  const testing::ToolRun named =
      testing::RunTool("predict", "--log " + no_tip_path +
                                      " --mu 0.3 --b 1 --c 0.03 --mu-pusher 0.25 --drive pusher");
  EXPECT_EQ(named.code, 1);
  EXPECT_NE(named.err.find("predict: error: " + no_tip_path + ": the pusher drive needs"),
            std::string::npos)
      << named.err;
  // A limit that keeps the run finite, as identify's: a billion substeps ran for days.
  const testing::ToolRun substeps = testing::RunTool(
      "predict", "--log " + log_path + " --mu 0.3 --b 1 --c 0.03 --mu-pusher 0.25 --substeps 1001");
  EXPECT_EQ(substeps.code, 2);
  EXPECT_NE(substeps.err.find("substeps must be 1 to 1000"), std::string::npos) << substeps.err;
}

// A log with a motion-capture dropout (a row with empty cells): predict names the line and
// column and says what to do, as identify does; with --missing-as-gaps (the reader's
// option, shared by the tools that read logs) it predicts the push from the other rows, as
// far off as from the whole log. validate and plot-log take the same options.
TEST(PredictTool, ALogWithADropoutIsAnErrorOrAGapWhenAskedFor) {
  const Scene scene = PushedSquare();
  const std::string whole_path = testing::TempPath("predict_whole.csv");
  WritePushLog(Logged(scene, 10), whole_path);
  std::ifstream in(whole_path);
  std::string text, line;
  int data_rows = 0;
  while (std::getline(in, line)) {
    const bool data = !line.empty() && line[0] != '#' && std::isdigit(line[0]);
    if (data && ++data_rows == 40) {  // the time kept, every other cell empty
      line = line.substr(0, line.find(',')) +
             std::string(std::count(line.begin(), line.end(), ','), ',');
    }
    text += line + "\n";
  }
  const std::string path = testing::WriteFile("predict_dropout.csv", text);
  const std::string friction = " --mu 0.3 --b 1.2 --c 0.035 --mu-pusher 0.25 --json";
  const testing::ToolRun failed = testing::RunTool("predict", "--log " + path + friction);
  EXPECT_EQ(failed.code, 1) << failed.all();
  EXPECT_NE(failed.err.find("--missing-as-gaps"), std::string::npos) << failed.err;
  const testing::ToolRun gaps =
      testing::RunTool("predict", "--log " + path + friction + " --missing-as-gaps");
  ASSERT_EQ(gaps.code, 0) << gaps.all();
  const testing::ToolRun whole = testing::RunTool("predict", "--log " + whole_path + friction);
  ASSERT_EQ(whole.code, 0) << whole.all();
  auto final_error = [](const std::string& json) {
    const std::size_t at = json.find("\"final_position_m\":");
    return at == std::string::npos ? -1.0 : std::stod(json.substr(at + 19));
  };
  EXPECT_GT(final_error(whole.out), 0) << whole.out;
  EXPECT_NEAR(final_error(gaps.out), final_error(whole.out), 1e-3) << gaps.out;
  for (const char* tool : {"validate", "plot-log"}) {
    const testing::ToolRun help = testing::RunTool(tool, "--help");
    EXPECT_NE(help.out.find("--missing-as-gaps"), std::string::npos) << tool;
    EXPECT_NE(help.out.find("--regular-times"), std::string::npos) << tool;
  }
}

}  // namespace
}  // namespace slideid
