// Plots of logs: the gnuplot script and data, the PNG, a clear error without gnuplot, the
// replay of a fit, and the plot-log tool end to end.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "datasets/sensor_model.h"
#include "estimator/identify.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"
#include "io/result_json.h"
#include "plots/log_plot.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using testing::HaveGnuplot;
using testing::ReadText;

std::string Source(const std::string& rel) { return std::string(SLIDEID_SOURCE_DIR) + "/" + rel; }

/// A pushed slider with ECP columns, as simulate writes it.
Trajectory PushedLog() {
  Trajectory t = testing::SimulateOrFail(testing::PushedSlider());
  return t;
}

TEST(PlotLog, ScriptDrawsPathPatchEcpPushAndVelocities) {
  PlotOptions o;
  o.out_png = "/tmp/x.png";
  const Trajectory log = PushedLog();
  const std::string script = PlotScript(log, nullptr, o, "/data");
  EXPECT_NE(script.find("set terminal pngcairo size 1400,900"), std::string::npos);
  EXPECT_NE(script.find("set output '/tmp/x.png'"), std::string::npos);
  EXPECT_NE(script.find("set multiplot"), std::string::npos);
  EXPECT_NE(script.find("'/data/patch.dat'"), std::string::npos);
  EXPECT_NE(script.find("'/data/ecp.dat'"), std::string::npos);
  EXPECT_NE(script.find("'/data/push.dat'"), std::string::npos);
  EXPECT_NE(script.find("set size ratio -1"), std::string::npos);  // equal axes for the path
  for (const char* axis : {"vx [m/s]", "vy [m/s]", "wz [rad/s]"}) {
    EXPECT_NE(script.find(axis), std::string::npos) << axis;
  }
  EXPECT_EQ(script.find("fit.dat"), std::string::npos);
  EXPECT_NE(script.find("truth: a = 0.3"), std::string::npos);
  // With a fit: the replay is overlaid on the path and every velocity panel.
  const std::string with_fit = PlotScript(log, &log, o, "/data", "fit: a = 1");
  size_t count = 0;
  for (size_t at = with_fit.find("fit.dat"); at != std::string::npos;
       at = with_fit.find("fit.dat", at + 1)) {
    ++count;
  }
  EXPECT_EQ(count, 4u);
}

// A prediction overlaid: its path, velocities and patches, named in the legends.
TEST(PlotLog, APredictionIsOverlaidWithItsPatches) {
  PlotOptions o;
  o.out_png = "/tmp/x.png";
  o.overlay_name = "prediction";
  o.overlay_patches = true;
  const Trajectory log = PushedLog();
  Trajectory shifted = log;
  for (TrajectorySample& s : shifted.samples) s.state.theta += 0.1;
  const std::string script = PlotScript(log, &shifted, o, "/data", "prediction: p.csv");
  EXPECT_NE(script.find("'/data/fit_patch.dat'"), std::string::npos);
  EXPECT_NE(script.find("'patch (prediction)'"), std::string::npos);
  EXPECT_NE(script.find("'CM (prediction)'"), std::string::npos);
  EXPECT_EQ(script.find("'fit'"), std::string::npos);
  const std::string dir = testing::TempPath("overlay");
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  WritePlotData(log, &shifted, o, dir);
  // The overlay's outlines: as many as the log's, at its turned poses.
  const std::string logged = ReadText(dir + "/patch.dat"),
                    predicted = ReadText(dir + "/fit_patch.dat");
  EXPECT_GT(predicted.size(), 100u);
  EXPECT_NE(predicted, logged);
}

TEST(PlotLog, PatchSnapshotsArePlacedAtThePose) {
  Trajectory log = PushedLog();
  log.samples.resize(3);
  log.samples[2].state = {1.0, 2.0, 1.5707963267948966, 0, 0, 0};
  log.patch = ContactPatch::Rectangle(0.2, 0.1);
  PlotOptions o;
  o.out_png = "x.png";
  o.snapshot_every = 2;
  char dir[] = "/tmp/plot_test_XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  WritePlotData(log, nullptr, o, dir);
  const std::string patch = ReadText(std::string(dir) + "/patch.dat");
  // Rotated by 90 degrees: the body corner (0.1, 0.05) lands at (1 - 0.05, 2 + 0.1).
  EXPECT_NE(patch.find("0.95 2.1\n"), std::string::npos) << patch;
  std::system((std::string("rm -rf ") + dir).c_str());
}

TEST(PlotLog, WritesAPng) {
  if (!HaveGnuplot()) GTEST_SKIP() << "gnuplot not installed";
  PlotOptions o;
  o.out_png = ::testing::TempDir() + "/plot_log_test.png";
  o.width_px = 600;
  o.height_px = 400;
  std::remove(o.out_png.c_str());
  PlotLog(PushedLog(), nullptr, o);
  const std::string png = ReadText(o.out_png);
  ASSERT_GT(png.size(), 1000u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
}

TEST(PlotLog, MissingGnuplotIsAClearError) {
  PlotOptions o;
  o.out_png = ::testing::TempDir() + "/never.png";
  o.gnuplot = "/nonexistent/gnuplot";
  try {
    PlotLog(PushedLog(), nullptr, o);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/gnuplot"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gnuplot-nox"), std::string::npos) << e.what();
  }
}

TEST(PlotLog, ParsesIdentifyJsonWithHeldValuesForUnidentifiable) {
  EstimateResult r;
  for (int i = 0; i < 3; ++i) {
    r.parameters[i].identifiable = true;
    r.parameters[i].value = 0.1 * (i + 1);
    r.parameters[i].stderr_value = 0.01;
  }
  r.parameters[kC] = ParameterEstimate{};
  r.parameters[kC].held_at = 0.025;
  const ReducedFriction f = ParseIdentifyJson(FormatJson(r));
  EXPECT_EQ(f.a, 0.1);
  EXPECT_EQ(f.b, 0.2);
  EXPECT_EQ(f.c, 0.025);
  EXPECT_THROW(ParseIdentifyJson("{\"e_t_mu\": {\"value\": 0.3}}"), std::invalid_argument);
}

TEST(ReplayLog, ReplaysALogWithItsOwnParametersAndWrenches) {
  const Trajectory log = PushedLog();
  const SimulationResult r = ReplayLog(log, *log.true_friction);
  ASSERT_TRUE(r.summary.ok()) << r.summary.message;
  ASSERT_EQ(r.trajectory.samples.size(), log.samples.size());
  // Same steps except for the rounding of t_{u+1} - t_u against dt.
  for (size_t u = 0; u < log.samples.size(); ++u) {
    EXPECT_NEAR(r.trajectory.samples[u].state.x, log.samples[u].state.x, 1e-9) << u;
    EXPECT_NEAR(r.trajectory.samples[u].state.theta, log.samples[u].state.theta, 1e-9) << u;
  }
  // A coarse log replayed with substeps comes close to the fine simulation it was cut from.
  Scene scene = testing::PushedSlider();
  scene.dt_s = 0.001;
  LogSpec every10;
  every10.log_every = 10;
  const Trajectory coarse = MakeLog(testing::SimulateOrFail(scene), every10);
  const SimulationResult sub = ReplayLog(coarse, scene.friction, 10);
  ASSERT_TRUE(sub.summary.ok());
  // The replay holds each row's force over its 10 ms; the push's cosine (2 N, period 0.2 s)
  // moves by up to 2 pi 2 N 0.01 s / 0.2 s = 0.6 N within that time, and the push turns
  // with the slider: over the 5 cm path the CM ends some millimetres off (measured 4.8 mm).
  constexpr double kHeldForceDrift_m = 1e-2;
  EXPECT_NEAR(sub.trajectory.samples.back().state.x, coarse.samples.back().state.x,
              kHeldForceDrift_m);
}

// ---- the tool ----

int RunTool(const std::string& tool, const std::string& args, std::string* output = nullptr) {
  const char* bin = std::getenv("SLIDEID_BIN_DIR");
  // One file per process: ctest runs the tests of this file side by side, and a shared
  // file let one test read another's output (seen under the sanitizers).
  const std::string out =
      ::testing::TempDir() + "/plot_tool_output_" + std::to_string(getpid()) + ".txt";
  const std::string cmd =
      std::string(bin ? bin : "build/bin") + "/" + tool + " " + args + " > " + out + " 2>&1";
  const int status = std::system(cmd.c_str());
  if (output) *output = ReadText(out);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(PlotLogTool, DrawsTheDefaultLogWithItsFit) {
  if (!HaveGnuplot()) GTEST_SKIP() << "gnuplot not installed";
  const std::string log = Source("datasets/logs/default_push.csv");
  const std::string json = ::testing::TempDir() + "/default_fit.json";
  const std::string png = ::testing::TempDir() + "/default_fit.png";
  std::remove(png.c_str());
  const char* bin = std::getenv("SLIDEID_BIN_DIR");
  ASSERT_EQ(std::system((std::string(bin ? bin : "build/bin") + "/identify --log " + log +
                         " --json > " + json + " 2> /dev/null")
                            .c_str()),
            0);
  std::string out;
  ASSERT_EQ(RunTool("plot-log",
                    log + " --out " + png + " --fit " + json +
                        " --width 700 "
                        "--height 450",
                    &out),
            0)
      << out;
  EXPECT_EQ(ReadText(png).substr(1, 3), "PNG");
}

TEST(PlotLogTool, ExitCodesSayWhatWentWrong) {
  const std::string log = Source("datasets/logs/default_push.csv");
  EXPECT_EQ(RunTool("plot-log", "--help"), 0);
  EXPECT_EQ(RunTool("plot-log", log), 2);                             // no --out
  EXPECT_EQ(RunTool("plot-log", "--out x.png"), 2);                   // no log
  EXPECT_EQ(RunTool("plot-log", "/nonexistent.csv --out x.png"), 1);  // unreadable log
  std::string out;
  EXPECT_EQ(RunTool("plot-log",
                    log + " --out " + ::testing::TempDir() +
                        "/g.png --gnuplot "
                        "/nonexistent/gnuplot",
                    &out),
            4);
  EXPECT_NE(out.find("gnuplot-nox"), std::string::npos) << out;
  // A limit that keeps the replay finite, as identify's and predict's (a billion substeps
  // per row ran for days).
  EXPECT_EQ(RunTool("plot-log", log + " --out x.png --substeps 1000000000", &out), 2);
  EXPECT_NE(out.find("--substeps must be 1 to 1000"), std::string::npos) << out;
  // A bad --fit file is named, and nesting deeper than a recursive dump goes is no crash.
  const std::string deep = ::testing::TempDir() + "/deep_fit_" + std::to_string(getpid()) + ".json";
  std::ofstream(deep) << std::string(200000, '[') << std::string(200000, ']');
  EXPECT_EQ(RunTool("plot-log", log + " --out x.png --fit " + deep, &out), 1);
  EXPECT_NE(out.find(deep + ": identify JSON: expected an object"), std::string::npos) << out;
}

}  // namespace
}  // namespace slideid
