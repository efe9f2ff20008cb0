// Pictures of an identification (plot-fit): the forest plot's data and script, the PNG,
// the errors, and the tool end to end on identify --json of pooled logs.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "io/push_log.h"
#include "io/result_json.h"
#include "plots/fit_plot.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using testing::HaveGnuplot;
using testing::ReadText;

ParameterEstimate Estimate(double value, double half_width, Verdict verdict = Verdict::kOk) {
  ParameterEstimate p;
  p.identifiable = true;
  p.verdict = verdict;
  p.value = value;
  p.stderr_value = half_width / kZ95;
  p.ci95_lo = value - half_width;
  p.ci95_hi = value + half_width;
  return p;
}

/// A pooled result of three logs and a skipped one: log "far.csv" misses the pooled a,
/// "doubt.csv" has a suspect b, and a disagrees.
EstimateResult Pooled() {
  EstimateResult r;
  r.parameters = {Estimate(0.35, 0.01), Estimate(1.3, 0.02), Estimate(0.03, 0.001)};
  const char* names[3] = {"near.csv", "far.csv", "doubt.csv"};
  const double a[3] = {0.351, 0.40, 0.349};
  for (int k = 0; k < 3; ++k) {
    LogResult log;
    log.name = names[k];
    log.rows = 100 + k;
    log.parameters = {Estimate(a[k], 0.01),
                      Estimate(1.3, 0.05, k == 2 ? Verdict::kSuspect : Verdict::kOk),
                      Estimate(0.03, 0.002)};
    r.logs.push_back(log);
  }
  LogResult skipped;
  skipped.name = "broken.csv";
  skipped.skipped = true;
  skipped.skip_reason = "broken.csv:3: column 'x': 'zero' is not a number";
  r.logs.push_back(skipped);
  r.heterogeneity[kA] = {true, 3, 25.0, 3.7e-6, 0.92, 0.07, false};
  r.heterogeneity[kB] = {true, 3, 0.5, 0.78, 0.0, 0.0, true};
  r.heterogeneity[kC] = {true, 3, 0.2, 0.9, 0.0, 0.0, true};
  return r;
}

std::string TempDir(const std::string& name) {
  std::string dir = ::testing::TempDir() + name + "_XXXXXX";
  if (mkdtemp(dir.data()) == nullptr) std::abort();
  return dir;
}

TEST(FitPlot, DataMarksTheLogsThatMissThePooledValueAndTheSuspectOnes) {
  const std::string dir = TempDir("fit_plot_data");
  WriteFitPlotData(Pooled(), dir);
  const std::string a = ReadText(dir + "/p0.dat");
  // Rows from the top: near.csv is row 3, far.csv row 2 (red), doubt.csv row 1.
  EXPECT_NE(a.find("\n3 0.351 0.341 0.361 0x1f4e9a 0\n"), std::string::npos) << a;
  EXPECT_NE(a.find("\n2 0.4 0.39 0.41 0xd62728 0\n"), std::string::npos) << a;
  const std::string b = ReadText(dir + "/p1.dat");
  EXPECT_NE(b.find("\n1 1.3 1.25 1.35 0x1f4e9a 1\n"), std::string::npos) << b;  // suspect
  EXPECT_EQ(a.find("broken"), std::string::npos);  // skipped logs have no row
}

TEST(FitPlot, ScriptHasAPanelPerParameterTheLogNamesAndTheVerdicts) {
  FitPlotOptions o;
  o.out_png = "/tmp/fit.png";
  o.title = "fit.json";
  const std::string script = FitPlotScript(Pooled(), o, "/data");
  EXPECT_NE(script.find("set output '/tmp/fit.png'"), std::string::npos);
  for (const char* panel : {"'/data/p0.dat'", "'/data/p1.dat'", "'/data/p2.dat'"}) {
    EXPECT_NE(script.find(panel), std::string::npos) << panel;
  }
  for (const char* name : {"\"near.csv\" 3", "\"far.csv\" 2", "\"doubt.csv\" 1", "\"pooled\" 0"}) {
    EXPECT_NE(script.find(name), std::string::npos) << name;
  }
  EXPECT_NE(script.find("the logs DISAGREE (p = 3.7e-06)"), std::string::npos) << script;
  EXPECT_NE(script.find("the logs agree (p = 0.78)"), std::string::npos);
  EXPECT_NE(script.find("skipped (unreadable): broken.csv"), std::string::npos);
  // The pooled interval shaded, its value dashed, and the diamond.
  EXPECT_NE(script.find("rect from 0.34, graph 0 to 0.36, graph 1"), std::string::npos);
  EXPECT_NE(script.find("polygon from 0.34,0 to 0.35,0.4 to 0.36,0"), std::string::npos);
  // Automatic height: at least the minimum, growing with the logs.
  EXPECT_EQ(FitPlotHeight(Pooled(), o), kFitPlotMinHeightPx);
  EstimateResult many = Pooled();
  many.logs.resize(100, many.logs[0]);
  EXPECT_GT(FitPlotHeight(many, o), 100 * kFitPlotRowPx);
}

TEST(FitPlot, WideSpreadsGetALogAxisAndOneLogsResultDrawsItsEstimate) {
  FitPlotOptions o;
  o.out_png = "x.png";
  EstimateResult r = Pooled();
  r.logs[0].parameters[kC] = Estimate(0.05, 0.045);  // 0.005 .. 0.095: a factor 19
  const std::string script = FitPlotScript(r, o, "/d");
  const size_t c_panel = script.find("# ---- e_r_over_e_t");
  ASSERT_NE(c_panel, std::string::npos);
  EXPECT_NE(script.find("set logscale x", c_panel), std::string::npos);
  EXPECT_NE(script.substr(0, c_panel).find("unset logscale x"), std::string::npos);
  EstimateResult one;
  one.parameters = Pooled().parameters;
  const std::string single = FitPlotScript(one, o, "/d");
  EXPECT_NE(single.find("\"estimate\" 0"), std::string::npos);
  EXPECT_NE(single.find("one log"), std::string::npos);
}

TEST(FitPlot, NothingIdentifiedOrBadOptionsAreErrors) {
  FitPlotOptions o;
  o.out_png = ::testing::TempDir() + "/never.png";
  EXPECT_THROW(PlotFit(EstimateResult{}, o), std::invalid_argument);
  o.width_px = 10;
  EXPECT_THROW(PlotFit(Pooled(), o), std::invalid_argument);
  o.width_px = 800;
  o.gnuplot = "/nonexistent/gnuplot";
  try {
    PlotFit(Pooled(), o);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("gnuplot-nox"), std::string::npos) << e.what();
  }
}

TEST(FitPlot, WritesAPng) {
  if (!HaveGnuplot()) GTEST_SKIP() << "gnuplot not installed";
  FitPlotOptions o;
  o.out_png = ::testing::TempDir() + "/fit_plot_test.png";
  o.width_px = 900;
  std::remove(o.out_png.c_str());
  PlotFit(Pooled(), o);
  const std::string png = ReadText(o.out_png);
  ASSERT_GT(png.size(), 1000u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
}

// ---- the tool ----

int RunCommand(const std::string& command, std::string* output = nullptr) {
  const char* bin = std::getenv("SLIDEID_BIN_DIR");
  const std::string out = ::testing::TempDir() + "/plot_fit_output_" + std::to_string(getpid());
  const std::string cmd =
      std::string(bin ? bin : "build/bin") + "/" + command + " > " + out + " 2>&1";
  const int status = std::system(cmd.c_str());
  if (output) *output = ReadText(out);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(PlotFitTool, DrawsWhatIdentifyFoundForPooledLogs) {
  if (!HaveGnuplot()) GTEST_SKIP() << "gnuplot not installed";
  const std::string dir = TempDir("plot_fit_tool");
  Scene scene = testing::PushedSlider();
  WritePushLog(testing::SimulateOrFail(scene), dir + "/a.csv");
  scene.pushes[0].force_n = 2.9;
  WritePushLog(testing::SimulateOrFail(scene), dir + "/b.csv");
  std::string out;
  ASSERT_EQ(RunCommand("identify --logs " + dir + " --json", &out), 0) << out;
  std::ofstream(dir + "/fit.json") << out;
  ASSERT_EQ(RunCommand("plot-fit " + dir + "/fit.json --out " + dir + "/fit.png --width 800", &out),
            0)
      << out;
  EXPECT_EQ(ReadText(dir + "/fit.png").substr(1, 3), "PNG");
  EXPECT_NE(out.find("wrote " + dir + "/fit.png"), std::string::npos);
}

TEST(PlotFitTool, ExitCodesSayWhatWentWrong) {
  const std::string dir = TempDir("plot_fit_codes");
  std::ofstream(dir + "/fit.json") << FormatJson(Pooled());
  std::ofstream(dir + "/bad.json") << "{\"e_t_mu\": 3}";
  EXPECT_EQ(RunCommand("plot-fit --help"), 0);
  EXPECT_EQ(RunCommand("plot-fit " + dir + "/fit.json"), 2);  // no --out
  EXPECT_EQ(RunCommand("plot-fit --out x.png"), 2);           // no result
  EXPECT_EQ(RunCommand("plot-fit " + dir + "/fit.json --out x.png --width 5"), 2);
  std::string out;
  EXPECT_EQ(RunCommand("plot-fit /nonexistent.json --out x.png", &out), 1);
  EXPECT_NE(out.find("/nonexistent.json"), std::string::npos) << out;
  EXPECT_EQ(RunCommand("plot-fit " + dir + "/bad.json --out x.png", &out), 1);
  EXPECT_NE(out.find("bad.json"), std::string::npos) << out;
  EXPECT_EQ(
      RunCommand("plot-fit " + dir + "/fit.json --out " + dir + "/g.png --gnuplot /nonexistent/gp",
                 &out),
      4);
  EXPECT_NE(out.find("gnuplot-nox"), std::string::npos) << out;
}

}  // namespace
}  // namespace slideid
