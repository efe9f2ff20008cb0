#pragma once
// What the tests share beyond the fixtures (scenes and tolerances, fixtures/): GoogleTest
// helpers that simulate a scene, write and read back poses-only logs, and check that an
// estimate recovers the truth.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "fixtures/synthetic_scenes.h"
#include "fixtures/tolerances.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"

namespace slideid::testing {

/// The simulated trajectory of `scene`, with a test failure when the simulation fails.
inline Trajectory SimulateOrFail(const Scene& scene) {
  const SimulationResult r = Simulate(scene);
  EXPECT_TRUE(r.summary.ok()) << r.summary.message;
  return r.trajectory;
}

/// A path in a directory made once per test process (ctest runs processes in parallel).
inline std::string TempPath(const std::string& name) {
  static const std::string dir = [] {
    std::string pattern = ::testing::TempDir() + "slideid_test_XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    return pattern;
  }();
  return dir + "/" + name;
}

/// A new, empty directory under GoogleTest's temporary directory, named `name` and a unique
/// suffix (one per call, unlike TempPath's directory).
inline std::string NewDir(const std::string& name) {
  std::string dir = ::testing::TempDir() + name + "_XXXXXX";
  if (mkdtemp(dir.data()) == nullptr) std::abort();
  return dir;
}

/// The directory TempPath's files go in (made once per test process).
inline std::string TempDirectory() {
  const std::string probe = TempPath("");
  return probe.substr(0, probe.size() - 1);  // without the trailing '/'
}

/// Writes `content`, bytes as given, to TempPath(name); returns the path.
inline std::string WriteFile(const std::string& name, const std::string& content) {
  const std::string path = TempPath(name);
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

/// The whole content of a file ("" when it cannot be read).
inline std::string ReadText(const std::string& path) {
  std::ostringstream text;
  text << std::ifstream(path, std::ios::binary).rdbuf();
  return text.str();
}

/// Whether any of `lines` (a reader's warnings or notes, say) contains `what`.
inline bool AnyLineContains(const std::vector<std::string>& lines, const std::string& what) {
  for (const std::string& line : lines) {
    if (line.find(what) != std::string::npos) return true;
  }
  return false;
}

/// Whether gnuplot runs here (the plotting tests skip without it).
inline bool HaveGnuplot() { return std::system("gnuplot --version > /dev/null 2>&1") == 0; }

/// What a tool run printed and returned.
struct ToolRun {
  int code = -1;  ///< exit code (-1: it did not exit normally)
  std::string out, err;
  /// Standard output, then standard error: where a message may be either.
  std::string all() const { return out + err; }
};

/// Runs the built tool `tool` (from SLIDEID_BIN_DIR, else build/bin) with `args` (shell
/// words), standard input from /dev/null, its two streams captured in files of this
/// process's TempPath.
inline ToolRun RunTool(const std::string& tool, const std::string& args) {
  static int runs = 0;
  const char* bin = std::getenv("SLIDEID_BIN_DIR");
  const std::string stem = TempPath("run" + std::to_string(++runs));
  const std::string cmd = std::string(bin ? bin : "build/bin") + "/" + tool + " " + args + " > " +
                          stem + ".out 2> " + stem + ".err < /dev/null";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ReadText(stem + ".out"),
          ReadText(stem + ".err")};
}

/// The log with velocities dropped, written and read back: the reader derives them from
/// the poses, as it does for a motion-capture log.
inline Trajectory PosesOnly(const Trajectory& log, const std::string& name) {
  Trajectory poses = log;
  poses.measured.velocity = false;
  const std::string path = TempPath(name);
  WritePushLog(poses, path);
  LogReadReport report;
  Trajectory read = ReadPushLog(path, {}, &report);
  EXPECT_TRUE(report.velocities_from_poses);
  return read;
}

/// Every parameter identifiable, within `rel_tol` of the truth, inside a positive CI.
inline void ExpectRecovers(const EstimateResult& r, const ReducedFriction& truth,
                           const std::string& what, double rel_tol = kExactRelTol) {
  EXPECT_TRUE(r.converged) << what << ": " << r.message;
  const double expected[3] = {truth.a, truth.b, truth.c};
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    ASSERT_TRUE(p.identifiable) << what << " " << ParameterName(i) << ": " << p.note;
    EXPECT_NEAR(p.value / expected[i], 1.0, rel_tol)
        << what << " " << ParameterName(i) << " = " << p.value << ", truth " << expected[i];
    EXPECT_GT(p.ci95_lo, 0.0);
    EXPECT_LE(p.ci95_lo, p.value);
    EXPECT_GE(p.ci95_hi, p.value);
  }
}

/// Every parameter identifiable, its standard error at most `max_rel_stderr` of the truth,
/// and the estimate within `n_sigmas` of its standard errors of the truth.
inline void ExpectWithinStandardErrors(const EstimateResult& r, const ReducedFriction& truth,
                                       double max_rel_stderr, double n_sigmas,
                                       const std::string& what) {
  const double expected[3] = {truth.a, truth.b, truth.c};
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    ASSERT_TRUE(p.identifiable) << what << " " << ParameterName(i);
    EXPECT_LE(p.stderr_value / expected[i], max_rel_stderr) << what << " " << ParameterName(i);
    EXPECT_LE(std::abs(p.value - expected[i]), n_sigmas * p.stderr_value)
        << what << " " << ParameterName(i) << " = " << p.value << " +- " << p.stderr_value
        << ", truth " << expected[i];
  }
}

}  // namespace slideid::testing
