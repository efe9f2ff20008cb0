// Pooled identification: many logs of one slider on one surface give one estimate with
// each log's own beside it and a verdict on whether they agree; logs of two surfaces are
// flagged and the pooled interval widened; logs of different sliders are each used with
// their own properties; per-log delays; and identify's --skip-bad end to end.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "datasets/dataset.h"
#include "estimator/identify.h"
#include "io/push_log.h"
#include "io/result_json.h"
#include "pipeline/identify_files.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

// One slider and one surface: a 0.8 kg box on a 10 x 8 cm footprint, a = 0.35, b = 1.3,
// c = 0.03 m.
constexpr double kMu = 0.35, kEo = 1.3, kEr = 0.03;

/// `count` logs of two random pushes each (80 to 220 rows at 100 Hz), simulated at the log
/// rate (the fit's model is exact) with motion-capture noise on the poses.
DatasetSpec OneSurface(int count, std::uint64_t seed, double mu = kMu, double mass_kg = 0.8) {
  DatasetSpec spec;
  spec.count = count;
  spec.seed = seed;
  spec.mass_kg = {mass_kg, mass_kg};
  spec.com_height_m = {0.03, 0.03};
  spec.patch = PatchRange::Parse("rectangle 0.1 0.08");
  spec.mu = {mu, mu};
  spec.e_t = {1.0, 1.0};
  spec.e_o = {kEo, kEo};
  spec.e_r_m = {kEr, kEr};
  spec.program.count = 2;
  spec.dt_s = 0.01;
  spec.log.log_every = 1;
  spec.log.noise.pose_m = 3e-4;
  spec.log.noise.angle_rad = 3e-3;
  return spec;
}

/// Log `index` of `spec`, named by its file.
Trajectory Draw(const DatasetSpec& spec, int index) {
  Trajectory log;
  log.source = DrawDatasetLog(spec, index, &log).file;
  return log;
}

std::vector<Trajectory> Logs(const DatasetSpec& spec) {
  std::vector<Trajectory> logs;
  for (int k = 0; k < spec.count; ++k) logs.push_back(Draw(spec, k));
  return logs;
}

std::vector<Trajectory> Logs(int count, std::uint64_t seed, double mu = kMu, double mass_kg = 0.8) {
  return Logs(OneSurface(count, seed, mu, mass_kg));
}

bool Covers(const ParameterEstimate& p, double truth) {
  return p.identifiable && p.ci95_lo <= truth && truth <= p.ci95_hi;
}

TEST(PooledFit, FiftyLogsOfOneSliderGiveOneEstimateThatRecoversTheTruthAndAgree) {
  const std::vector<Trajectory> logs = Logs(50, 11);
  for (const Trajectory& log : logs) {
    ASSERT_GE(log.samples.size(), 60u);
    ASSERT_LE(log.samples.size(), 300u);
  }
  const EstimateResult r = Identify(logs, IdentifyOptions{});
  ASSERT_TRUE(r.converged) << r.message;
  const double truth[3] = {kMu, kEo, kEr};
  // Fifty logs pin the shared parameters far better than one: the pooled estimate within
  // 0.5% of the truth (measured 0.09, 0.07 and 0.34%), and inside its interval.
  constexpr double kPooledRelTol = 0.005;
  // The logs agree: their spread beyond their own noise (DerSimonian-Laird tau) is below
  // 1% of the parameter, and most of their spread is noise (I2 below a half). Measured: tau
  // 0, I2 0 and Q at p = 1, 1 and 0.985: Q weighs each log by the standard error its own
  // interval states, whose t quantile on few degrees of freedom (5-7 segments a log) makes
  // Q conservative here. It keeps its power where logs truly differ (two surfaces, below:
  // I2 = 0.999).
  constexpr double kMaxTau = 0.01, kMaxI2 = 0.5;
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    ASSERT_TRUE(p.identifiable) << ParameterName(i);
    EXPECT_NEAR(p.value / truth[i], 1.0, kPooledRelTol) << ParameterName(i);
    EXPECT_TRUE(Covers(p, truth[i])) << ParameterName(i) << " " << p.ci95_lo << ".." << p.ci95_hi;
    const Heterogeneity& h = r.heterogeneity[i];
    EXPECT_TRUE(h.tested) << ParameterName(i);
    EXPECT_GE(h.logs, 40) << ParameterName(i);
    EXPECT_LT(h.tau_log, kMaxTau) << ParameterName(i) << ": Q = " << h.q << ", p = " << h.p_value;
    EXPECT_LT(h.i2, kMaxI2) << ParameterName(i);
  }
  // Each log's own estimate, in input order, named by its file.
  ASSERT_EQ(r.logs.size(), 50u);
  for (size_t k = 0; k < logs.size(); ++k) {
    EXPECT_EQ(r.logs[k].name, logs[k].source);
    EXPECT_FALSE(r.logs[k].skipped);
    EXPECT_EQ(r.logs[k].rows, static_cast<int>(logs[k].samples.size()));
    EXPECT_TRUE(r.logs[k].parameters[kA].identifiable) << r.logs[k].name;
  }
  // The pooled interval is narrower than any single log's.
  for (const LogResult& log : r.logs) {
    const ParameterEstimate& own = log.parameters[kA];
    EXPECT_LT(r.parameters[kA].ci95_hi - r.parameters[kA].ci95_lo, own.ci95_hi - own.ci95_lo)
        << log.name << " (" << log.rows << " rows): " << own.note
        << "; pooled: " << r.parameters[kA].note;
  }
}

// Two surfaces (a = 0.3 and 0.4) pooled as if one: the logs disagree far beyond their
// noise. The verdict says so, and the pooled interval, cluster-robust over the logs,
// widens to the spread between them.
TEST(PooledFit, LogsOfTwoSurfacesAreFlaggedAndThePooledIntervalWidened) {
  std::vector<Trajectory> logs = Logs(10, 21, 0.3);
  for (Trajectory& log : Logs(10, 22, 0.4)) {
    log.source = "other_" + log.source;
    logs.push_back(std::move(log));
  }
  const EstimateResult mixed = Identify(logs, IdentifyOptions{});
  ASSERT_TRUE(mixed.converged) << mixed.message;
  const Heterogeneity& h = mixed.heterogeneity[kA];
  ASSERT_TRUE(h.tested);
  EXPECT_FALSE(h.consistent);
  EXPECT_LT(h.p_value, 0.05);
  EXPECT_GT(h.i2, 0.9);       // almost all the spread is between the logs
  EXPECT_GT(h.tau_log, 0.1);  // log(0.4 / 0.3) / 2 = 0.14 either side of the middle
  const ParameterEstimate& a = mixed.parameters[kA];
  EXPECT_NE(a.note.find("cluster-robust (CR2) over 20 logs"), std::string::npos) << a.note;
  // One surface pooled the same way: the mixed interval is many times wider (measured 70x:
  // +-0.022 against +-0.0003).
  const EstimateResult one = Identify(Logs(20, 21, 0.3), IdentifyOptions{});
  const ParameterEstimate& a1 = one.parameters[kA];
  EXPECT_GT(a.ci95_hi - a.ci95_lo, 10 * (a1.ci95_hi - a1.ci95_lo));
  EXPECT_GT(a.value, 0.3);
  EXPECT_LT(a.value, 0.4);
}

// Logs of a 0.5 kg and a 1.5 kg slider on one surface: each fitted with its own mass and
// inertia, they agree on the surface's a, b, c. Taken with the first log's properties, the
// heavier logs would not fit.
TEST(PooledFit, LogsWithDifferentSliderPropertiesAreEachUsedWithTheirOwn) {
  std::vector<Trajectory> logs = Logs(5, 31, kMu, 0.5);
  for (Trajectory& log : Logs(5, 32, kMu, 1.5)) {
    log.source = "heavy_" + log.source;
    logs.push_back(std::move(log));
  }
  ASSERT_NE(logs.front().slider.mass_kg, logs.back().slider.mass_kg);
  const EstimateResult r = Identify(logs, IdentifyOptions{});
  ASSERT_TRUE(r.converged) << r.message;
  const double truth[3] = {kMu, kEo, kEr};
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(Covers(r.parameters[i], truth[i])) << ParameterName(i);
    EXPECT_TRUE(r.heterogeneity[i].consistent) << ParameterName(i);
  }
  std::vector<Trajectory> one_slider = logs;
  for (Trajectory& log : one_slider) log.slider = logs.front().slider;
  const EstimateResult wrong = Identify(one_slider, IdentifyOptions{});
  EXPECT_FALSE(Covers(wrong.parameters[kA], kMu) && wrong.heterogeneity[kA].consistent)
      << "one slider's properties for all should not fit";
}

// Each log's delay, or one for all: pooled fits report them per log, or once. Noiseless
// exact logs: the delays to 1e-7 s and a, b, c to 1e-5, as for one log (the delay of the
// exact model sits at a kink of the cost: nuisance_fit_test.cc).
TEST(PooledFit, PerLogDelaysAreRecoveredForTheirLogsAndASharedOneOnce) {
  constexpr double kDelayTol_s = 1e-7, kRelTol = 1e-5;
  DatasetSpec spec = OneSurface(3, 41);
  spec.log.noise = NoiseSpec{};
  const double delays[3] = {0.01, 0.03, 0.0};
  std::vector<Trajectory> logs;
  for (int k = 0; k < 3; ++k) {
    spec.log.noise.force_delay_s = delays[k];
    logs.push_back(Draw(spec, k));
  }
  IdentifyOptions options;
  options.trajectory.fit_delay = DelayFit::kPerLog;
  const EstimateResult per_log = Identify(logs, options);
  ASSERT_EQ(per_log.nuisance.size(), 3u);
  const double truth[3] = {kMu, kEo, kEr};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(per_log.nuisance[k].log, logs[k].source);
    EXPECT_NEAR(per_log.nuisance[k].value, delays[k], kDelayTol_s) << k;
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(per_log.parameters[i].value / truth[i], 1.0, kRelTol) << ParameterName(i);
  }
  // Logs 0 and 1 again, both 30 ms late: one delay for both.
  spec.log.noise.force_delay_s = 0.03;
  options.trajectory.fit_delay = DelayFit::kShared;
  const EstimateResult shared = Identify({Draw(spec, 0), logs[1]}, options);
  ASSERT_EQ(shared.nuisance.size(), 1u);
  EXPECT_EQ(shared.nuisance[0].log, "");
  EXPECT_NEAR(shared.nuisance[0].value, 0.03, kDelayTol_s);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(shared.parameters[i].value / truth[i], 1.0, kRelTol) << ParameterName(i);
  }
}

// ---- identify --skip-bad, end to end ----

using testing::ToolRun;

ToolRun RunIdentify(const std::string& args) { return testing::RunTool("identify", args); }

/// Two good logs and an unreadable one in a fresh directory; returns the directory.
std::string GoodAndBadLogs() {
  std::string dir = ::testing::TempDir() + "/pooled_XXXXXX";
  if (mkdtemp(dir.data()) == nullptr) std::abort();
  const std::vector<Trajectory> logs = Logs(2, 51);
  WritePushLog(logs[0], dir + "/a.csv");
  WritePushLog(logs[1], dir + "/c.csv");
  std::ofstream(dir + "/b.csv") << "# mass = 0.8\n# inertia = 1e-3\n# com_height = 0.03\n"
                                   "t,x,y,theta\n0,0,0,0\n0.01,zero,0,0\n";
  return dir;
}

TEST(PooledIdentifyTool, SkipBadListsTheUnreadableLogWithItsReasonInTableAndJson) {
  const std::string dir = GoodAndBadLogs();
  const std::string files =
      "--log " + dir + "/a.csv --log " + dir + "/b.csv --log " + dir + "/c.csv";
  ToolRun o = RunIdentify(files + " --skip-bad");
  ASSERT_EQ(o.code, 0) << o.all();
  EXPECT_NE(o.all().find("b.csv: skipped ("), std::string::npos) << o.all();
  EXPECT_NE(o.all().find("zero"), std::string::npos) << o.all();  // the reason names the value
  o = RunIdentify(files + " --skip-bad --json");
  ASSERT_EQ(o.code, 0) << o.all();
  const EstimateResult r = ParseResultJson(o.out.substr(o.out.find('{')));
  ASSERT_EQ(r.logs.size(), 3u);
  int skipped = 0;
  for (const LogResult& log : r.logs) {
    if (!log.skipped) continue;
    ++skipped;
    EXPECT_EQ(log.name, "b.csv");
    EXPECT_NE(log.skip_reason.find("b.csv"), std::string::npos) << log.skip_reason;
    EXPECT_NE(log.skip_reason.find("b.csv:6: column 'x'"), std::string::npos) << log.skip_reason;
  }
  EXPECT_EQ(skipped, 1);
  // --logs DIR reads the same three files, and not the manifests make-dataset and
  // import-log write beside their logs.
  std::ofstream(dir + "/truth.csv") << "file,mass\nlog_0000.csv,0.8\n";
  std::ofstream(dir + "/import_report.csv") << "file,status\n";
  o = RunIdentify("--logs " + dir + " --skip-bad");
  EXPECT_EQ(o.code, 0) << o.all();
  EXPECT_NE(o.all().find("b.csv: skipped ("), std::string::npos) << o.all();
  EXPECT_EQ(o.all().find("truth.csv"), std::string::npos) << o.all();
  EXPECT_EQ(o.all().find("import_report.csv"), std::string::npos) << o.all();
}

TEST(PooledIdentifyTool, WithoutSkipBadAnUnreadableLogFailsTheRunNamingIt) {
  const std::string dir = GoodAndBadLogs();
  const ToolRun o =
      RunIdentify("--log " + dir + "/a.csv --log " + dir + "/b.csv --log " + dir + "/c.csv");
  EXPECT_EQ(o.code, 1) << o.all();
  EXPECT_NE(o.all().find(dir + "/b.csv"), std::string::npos) << o.all();
  EXPECT_NE(o.all().find("b.csv:6: column 'x'"), std::string::npos) << o.all();
}

}  // namespace
}  // namespace slideid
