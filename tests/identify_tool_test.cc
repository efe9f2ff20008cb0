// The identify tool end to end: simulate -> CSV -> identify, its table, JSON, residuals
// file and exit codes.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "datasets/quasi_static_synth.h"
#include "io/push_log.h"
#include "io/wrench_twist_csv.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

struct Output {
  int exit_code;
  std::string out;
};

Output RunIdentify(const std::string& args) {
  const char* bin = std::getenv("SLIDEID_BIN_DIR");
  // ctest runs tests in parallel processes: one output file per process.
  const std::string out_file =
      ::testing::TempDir() + "/identify_stdout_" + std::to_string(getpid()) + ".txt";
  const std::string cmd =
      std::string(bin ? bin : "build/bin") + "/identify " + args + " > " + out_file + " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(out_file);
  std::stringstream text;
  text << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, text.str()};
}

std::string WriteLog(const Trajectory& log, const std::string& name) {
  const std::string path = ::testing::TempDir() + "/" + name;
  WritePushLog(log, path);
  return path;
}

// The value of "key": in a flat JSON object (the tool's own output format).
std::string JsonField(const std::string& json, const std::string& key) {
  const size_t at = json.find("\"" + key + "\":");
  if (at == std::string::npos) return "";
  size_t start = at + key.size() + 3;
  while (json[start] == ' ') ++start;
  size_t end = start;
  int depth = 0;
  for (; end < json.size(); ++end) {
    const char c = json[end];
    if (c == '{' || c == '[') ++depth;
    if (c == '}' || c == ']') {
      if (depth == 0) break;
      --depth;
    }
    if (c == ',' && depth == 0) break;
  }
  return json.substr(start, end - start);
}

TEST(IdentifyTool, PrintsEstimatesBesideTheTruthForEveryMethod) {
  const std::string log = WriteLog(testing::SimulateOrFail(testing::PushedSlider()), "pushed.csv");
  for (const char* method : {"closed-form", "equation-error", "trajectory"}) {
    const Output o = RunIdentify("--log " + log + " --method " + method);
    ASSERT_EQ(o.exit_code, 0) << o.out;
    EXPECT_NE(o.out.find(std::string("method: ") + method), std::string::npos) << o.out;
    EXPECT_NE(o.out.find("e_t_mu"), std::string::npos);
    EXPECT_NE(o.out.find("truth"), std::string::npos);
    EXPECT_NE(o.out.find("95% CI"), std::string::npos);
    EXPECT_NE(o.out.find("steps:"), std::string::npos);
  }
}

// Output a person can read (issue 20): the bundled log's table says in words how each
// interval was made, gives the residuals with units, counts the fit's iterations over all
// its stages, and keeps the solver's own report (whose iteration count is of its last
// solve alone) and each note's technical detail for --verbose.
TEST(IdentifyTool, TheTableSpeaksInWordsAndKeepsTheDetailForVerbose) {
  const std::string log = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";
  const Output plain = RunIdentify("--log " + log);
  ASSERT_EQ(plain.exit_code, 0) << plain.out;
  EXPECT_NE(plain.out.find("note: the interval allows for correlated residuals within each of 15 "
                           "pieces of the log;"),
            std::string::npos)
      << plain.out;
  EXPECT_EQ(plain.out.find("t quantile"), std::string::npos) << plain.out;
  EXPECT_EQ(plain.out.find("(detail:"), std::string::npos) << plain.out;
  EXPECT_EQ(plain.out.find("Ceres Solver Report"), std::string::npos) << plain.out;
  EXPECT_NE(plain.out.find(" mm RMS per row of poses"), std::string::npos) << plain.out;
  EXPECT_NE(plain.out.find("against the log's own noise of 0.446 mm (ratio 0.87"),
            std::string::npos)
      << plain.out;
  EXPECT_NE(plain.out.find(" solver iterations over all its stages, final cost "),
            std::string::npos)
      << plain.out;

  const Output verbose = RunIdentify("--log " + log + " --verbose");
  ASSERT_EQ(verbose.exit_code, 0) << verbose.out;
  EXPECT_NE(verbose.out.find("pieces of the log (detail: cluster-robust (CR2) over 15 segments, "
                             "t quantile "),
            std::string::npos)
      << verbose.out;
  EXPECT_NE(verbose.out.find("solver: Ceres Solver Report: Iterations: "), std::string::npos)
      << verbose.out;
}

TEST(IdentifyTool, JsonHasTheDocumentedKeysAndNullForUnidentifiable) {
  const Scene scene = testing::PureTranslation();
  const std::string log = WriteLog(testing::SimulateOrFail(scene), "translation.csv");
  const Output o = RunIdentify("--log " + log + " --json");
  ASSERT_EQ(o.exit_code, 0) << o.out;
  for (const char* key : {"e_t_mu", "e_o_over_e_t", "e_r_over_e_t", "method", "steps_used",
                          "steps_excluded", "seconds"}) {
    EXPECT_FALSE(JsonField(o.out, key).empty()) << key << " missing in " << o.out;
  }
  const std::string c = JsonField(o.out, "e_r_over_e_t");
  EXPECT_EQ(JsonField(c, "value"), "null") << c;
  EXPECT_EQ(JsonField(c, "stderr"), "null") << c;
  EXPECT_EQ(JsonField(c, "identifiable"), "false") << c;
  const std::string a = JsonField(o.out, "e_t_mu");
  EXPECT_EQ(JsonField(a, "identifiable"), "true");
  EXPECT_NEAR(std::stod(JsonField(a, "value")), scene.friction.reduced().a, 1e-6);
  EXPECT_EQ(JsonField(o.out, "method"), "\"trajectory\"");
}

TEST(IdentifyTool, WritesResidualsFileWithOneRowPerResidualRow) {
  const std::string log =
      WriteLog(testing::SimulateOrFail(testing::FreeSlideWithSpin()), "free.csv");
  const std::string res = ::testing::TempDir() + "/residuals.csv";
  std::remove(res.c_str());
  ASSERT_EQ(RunIdentify("--log " + log + " --segment 20 --residuals " + res).exit_code, 0);
  std::ifstream in(res);
  ASSERT_TRUE(in.good());
  std::string line;
  int rows = 0;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.rfind("row,t,", 0) == 0)
      header = true;
    else if (!line.empty() && line[0] != '#')
      ++rows;
  }
  EXPECT_TRUE(header);
  EXPECT_GT(rows, 40);
}

// Under a push the friction estimate depends on the mass (a free slide's would not: Coulomb
// friction decelerates every mass alike).
TEST(IdentifyTool, OverridesReplaceMetadataAndWrongMassChangesTheEstimate) {
  const Scene scene = testing::PushedSlider();
  const std::string log = WriteLog(testing::SimulateOrFail(scene), "pushed_override.csv");
  const Output right = RunIdentify("--log " + log + " --json --mass 1.0");
  const Output wrong = RunIdentify("--log " + log + " --json --mass 2.0");
  ASSERT_EQ(right.exit_code, 0);
  ASSERT_EQ(wrong.exit_code, 0) << wrong.out;
  EXPECT_NEAR(std::stod(JsonField(JsonField(right.out, "e_t_mu"), "value")), 0.3, 1e-6);
  EXPECT_GT(std::abs(std::stod(JsonField(JsonField(wrong.out, "e_t_mu"), "value")) - 0.3), 1e-3);
}

TEST(IdentifyTool, ExitCodesAndMessagesForBadInput) {
  EXPECT_EQ(RunIdentify("--help").exit_code, 0);
  EXPECT_EQ(RunIdentify("--version").exit_code, 0);
  EXPECT_EQ(RunIdentify("").exit_code, 2);
  EXPECT_EQ(RunIdentify("--log x.csv --method magic").exit_code, 2);
  EXPECT_EQ(RunIdentify("--log x.csv --segment 1").exit_code, 2);
  EXPECT_EQ(RunIdentify("--bogus").exit_code, 2);
  const Output missing = RunIdentify("--log /nonexistent/pushes.csv");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.out.find("/nonexistent/pushes.csv"), std::string::npos) << missing.out;
  // A log whose slider never moves cannot identify anything: say so, exit 1.
  Scene rest = testing::BaseScene();
  rest.duration_s = 0.2;
  const std::string still = WriteLog(testing::SimulateOrFail(rest), "still.csv");
  for (const char* method : {"closed-form", "equation-error", "trajectory"}) {
    const Output o = RunIdentify("--log " + still + " --method " + method);
    EXPECT_EQ(o.exit_code, 1) << method << ": " << o.out;
    EXPECT_NE(o.out.find("too little sliding"), std::string::npos) << method << ": " << o.out;
  }
}

// The bundled log's poses are too noisy for the cheap methods' per-step impulses: each of a,
// b, c is not identifiable. Every method then exits 1 (README, "Exit codes"), as the
// trajectory fit does for a log that determines nothing; the cheap ones exited 0.
TEST(IdentifyTool, EveryMethodExitsOneWhenNothingIsIdentifiable) {
  const std::string log = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";
  for (const char* method : {"closed-form", "equation-error"}) {
    for (const char* json : {"", " --json"}) {
      const Output o = RunIdentify("--log " + log + " --method " + method + json);
      EXPECT_EQ(o.exit_code, 1) << method << json << ": " << o.out;
      EXPECT_NE(o.out.find("identify: error: " + log +
                           ": no friction parameter is identifiable: "
                           "the friction impulse of a step is only"),
                std::string::npos)
          << method << ": " << o.out;
      // The result is printed first, each parameter's reason with it (--json: its keys).
      EXPECT_NE(o.out.find("not identifiable"), std::string::npos) << method << json;
      if (*json) EXPECT_NE(o.out.find("\"e_r_over_e_t\""), std::string::npos) << o.out;
    }
  }
  EXPECT_EQ(RunIdentify("--log " + log).exit_code, 0);  // the trajectory fit identifies all
}

/// Exact quasi-static pairs of a 1.5 kg slider (a = 0.3, b = 1.2, c = 0.04 m), as a file.
std::string WritePairs(const std::string& name) {
  SliderProperties slider;
  slider.mass_kg = 1.5;
  slider.inertia_kgm2 = 2e-3;
  std::vector<Eigen::Vector3d> twists;
  for (int i = 0; i < 8; ++i) {
    twists.emplace_back(0.002 * std::cos(i), 0.002 * std::sin(1.7 * i), 0.04 * std::cos(2.3 * i));
  }
  const std::string path = ::testing::TempDir() + "/" + name;
  WriteWrenchTwistCsv(ExactQuasiStaticPairs(twists, slider, {0.3, 1.2, 0.04}), path);
  return path;
}

TEST(IdentifyTool, QuasiStaticFitsWrenchTwistPairs) {
  const std::string pairs = WritePairs("pairs.csv");
  Output o = RunIdentify("--log " + pairs + " --method quasi-static");
  ASSERT_EQ(o.exit_code, 0) << o.out;
  EXPECT_NE(o.out.find("method: quasi-static"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("truth"), std::string::npos) << o.out;
  o = RunIdentify("--log " + pairs + " --method quasi-static --json");
  ASSERT_EQ(o.exit_code, 0) << o.out;
  EXPECT_EQ(JsonField(o.out, "method"), "\"quasi-static\"") << o.out;
  EXPECT_NEAR(std::stod(JsonField(JsonField(o.out, "e_o_over_e_t"), "value")), 1.2, 1e-6);
  // Options the method does not use are usage errors; a push log is not pairs.
  EXPECT_EQ(RunIdentify("--log " + pairs + " --method quasi-static --segment 10").exit_code, 2);
  const std::string log = WriteLog(testing::SimulateOrFail(testing::PushedSlider()), "qs.csv");
  o = RunIdentify("--log " + log + " --method quasi-static");
  EXPECT_EQ(o.exit_code, 1) << o.out;
  EXPECT_NE(o.out.find("column 'mz': missing"), std::string::npos) << o.out;
}

TEST(IdentifyTool, QuasiStaticNamesTheRowOfAZeroTwist) {
  const std::string path = ::testing::TempDir() + "/zero_twist_pairs.csv";
  std::ofstream(path) << "# mass = 1\nfx,fy,mz,vx,vy,wz\n1,0,0,1,0,0\n2,1,0,0,0,0\n";
  const Output o = RunIdentify("--log " + path + " --method quasi-static");
  EXPECT_EQ(o.exit_code, 1) << o.out;
  EXPECT_NE(o.out.find(path + ":4: column 'vx': the twist (vx, vy, wz) is zero"), std::string::npos)
      << o.out;
}

}  // namespace
}  // namespace slideid
