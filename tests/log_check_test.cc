// The check before fitting (estimator/log_check.h, identify --check): what it says of a log,
// and that its verdicts agree with the full fit's on logs that identify everything and on
// logs that do not.

#include "estimator/log_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "fixtures/check_agreement.h"
#include "fixtures/check_cases.h"
#include "fixtures/synthetic_scenes.h"
#include "io/log_check_report.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using testing::SimulateOrFail;

bool Mentions(const LogCheck& c, const std::string& text) {
  for (const std::string& a : c.advice) {
    if (a.find(text) != std::string::npos) return true;
  }
  return false;
}

std::string Advice(const LogCheck& c) {
  std::string all;
  for (const std::string& a : c.advice) all += a + "\n";
  return all;
}

// The CI-sized agreement run: 60 drawn logs (fixtures/check_cases.h), about 0.6 s. The
// larger run is benchmarks/check_agreement.cc (400 logs: 97.8%; docs/identify.md).
constexpr int kAgreementLogs = 60;
// The share of verdicts (3 per log) on which the check and the fit must agree.
constexpr double kMinAgreement = 0.95;
// Of the parameters the fit finds not identifiable, the share the check must call so too:
// a check that called everything identifiable would agree on most verdicts of logs that
// identify everything, and be useless exactly where it is needed.
constexpr double kMinAgreementWhereTheFitSaysNo = 0.9;

TEST(LogCheck, AgreesWithTheFitOnLogsThatIdentifyEverythingAndOnLogsThatDoNot) {
  testing::AgreementTally tally;
  for (int k = 0; k < kAgreementLogs; ++k) {
    const testing::CheckCase c = testing::MakeCheckCase(k);
    tally.Add(testing::CompareCheckWithFit(c.log, IdentifyOptions{}),
              "case " + std::to_string(k) + " (" + c.description + ")");
  }
  std::string disagreements;
  for (const std::string& d : tally.disagreements) disagreements += "\n  " + d;
  EXPECT_GE(tally.Share(), kMinAgreement)
      << tally.agreed << " of " << tally.verdicts << disagreements;
  int fit_no = 0, check_yes_fit_no = 0;
  for (int i = 0; i < 3; ++i) {
    fit_no += tally.fit_no[i];
    check_yes_fit_no += tally.check_yes_fit_no[i];
  }
  // The draw holds both kinds: pushes through the CM and slides without spin leave c (and
  // some b) to the noise.
  ASSERT_GE(fit_no, 20) << disagreements;
  EXPECT_GE(1.0 - double(check_yes_fit_no) / fit_no, kMinAgreementWhereTheFitSaysNo)
      << check_yes_fit_no << " of " << fit_no << disagreements;
}

TEST(LogCheck, APushThroughTheCmLeavesCUnidentifiedAndSaysWhatWouldHelp) {
  const Trajectory log = SimulateOrFail(testing::PureTranslation());
  const LogCheck c = CheckLog(log, IdentifyOptions{});
  EXPECT_TRUE(c.failure.empty()) << c.failure;
  EXPECT_TRUE(c.parameters[kA].identifiable) << c.parameters[kA].reason;
  EXPECT_FALSE(c.parameters[kC].identifiable);
  EXPECT_FALSE(c.parameters[kC].reason.empty());
  EXPECT_NEAR(c.max_push_offset_m, 0.0, 1e-9);
  EXPECT_NEAR(c.rotation_range_rad, 0.0, 1e-9);
  EXPECT_TRUE(Mentions(c, "c is not identifiable: every push passes within 0 mm of the CM"))
      << Advice(c);
  EXPECT_TRUE(Mentions(c, "push off-centre or turn the object")) << Advice(c);
  EXPECT_NEAR(c.rate_hz, 100.0, 1e-6);
  EXPECT_EQ(c.gaps, 0);
}

TEST(LogCheck, MotionAlongOneAxisLeavesBUnidentifiedAndSaysSo) {
  const LogCheck c = CheckLog(SimulateOrFail(testing::AlongOneAxis()), IdentifyOptions{});
  EXPECT_TRUE(c.parameters[kA].identifiable);
  EXPECT_FALSE(c.parameters[kB].identifiable);
  EXPECT_LT(c.slide_directions_rad, 1e-6);
  EXPECT_TRUE(
      Mentions(c, "b is not identifiable: the object slides along one direction of its own"))
      << Advice(c);
}

TEST(LogCheck, AFreeSlideWithSpinIdentifiesAllThreeWithFiniteConditionAndCorrelations) {
  const LogCheck c = CheckLog(SimulateOrFail(testing::FreeSlideWithSpin()), IdentifyOptions{});
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(c.parameters[i].identifiable) << ParameterName(i) << ": " << c.parameters[i].reason;
    EXPECT_GT(c.parameters[i].relative_stderr, 0.0);
    EXPECT_LT(c.parameters[i].relative_stderr, 0.5);
    EXPECT_NEAR(c.correlation[i][i], 1.0, 1e-9);
    for (int j = 0; j < 3; ++j) {
      EXPECT_LE(std::abs(c.correlation[i][j]), 1.0 + 1e-9);
      EXPECT_NEAR(c.correlation[i][j], c.correlation[j][i], 1e-12);
    }
  }
  EXPECT_GE(c.condition_number, 1.0);
  EXPECT_TRUE(std::isfinite(c.condition_number));
  EXPECT_FALSE(c.has_force);
  EXPECT_TRUE(std::isnan(c.max_push_offset_m));  // never pushed
  EXPECT_GT(c.rotation_range_rad, 1.0);
  EXPECT_GT(c.sliding_share, 0.5);
}

TEST(LogCheck, ADeadForceChannelIdentifiesNothingAndNamesTheChannel) {
  Trajectory log = SimulateOrFail(testing::PushedSlider());
  for (TrajectorySample& s : log.samples) {
    s.applied.fx = 2.0;
    s.applied.fy = 0.0;
    s.applied.tz = 0.0;
  }
  const LogCheck c = CheckLog(log, IdentifyOptions{});
  EXPECT_FALSE(c.AnyIdentifiable());
  EXPECT_NE(c.failure.find("force channel constant"), std::string::npos) << c.failure;
  ASSERT_EQ(c.dead_channels.size(), 1u);
  EXPECT_TRUE(Mentions(c, "check the sensor")) << Advice(c);
}

TEST(LogCheck, CountsGaps) {
  Trajectory log = SimulateOrFail(testing::PushedSlider());
  // A hole of 15 rows: the rows after it start a new run.
  log.samples.erase(log.samples.begin() + 40, log.samples.begin() + 55);
  log.steps.clear();  // the simulated steps would no longer match the rows
  log.samples[40].mode = SampleMode::kStart;
  const LogCheck c = CheckLog(log, IdentifyOptions{});
  EXPECT_EQ(c.gaps, 1);
  EXPECT_NEAR(c.longest_gap_s, 0.16, 1e-9);
  EXPECT_TRUE(Mentions(c, "the log has 1 gap (longest 0.16 s)")) << Advice(c);
}

// The bundled log rests between its pushes (its force channel reads 0 there); an offset of
// the channel shows while it rests.
TEST(LogCheck, ReportsWhatTheForceChannelReadsWhileTheObjectRests) {
  Trajectory log = ReadPushLog(std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv");
  const LogCheck clean = CheckLog(log, IdentifyOptions{});
  ASSERT_GE(clean.rest_rows, 50);
  EXPECT_NEAR(clean.rest_force_x_n, 0.0, 1e-12);
  EXPECT_FALSE(Mentions(clean, "while the object rests")) << Advice(clean);
  for (TrajectorySample& s : log.samples) s.applied.fx += 0.3;
  const LogCheck offset = CheckLog(log, IdentifyOptions{});
  EXPECT_NEAR(offset.rest_force_x_n, 0.3, 1e-12);
  EXPECT_NEAR(offset.rest_force_y_n, 0.0, 1e-12);
  EXPECT_TRUE(Mentions(offset, "the force channel reads (0.3, 0) N while the object rests"))
      << Advice(offset);
  EXPECT_TRUE(Mentions(offset, "--fit-force-bias")) << Advice(offset);
}

TEST(LogCheck, RejectsAnotherMethod) {
  IdentifyOptions options;
  options.method = EstimatorMethod::kClosedForm;
  EXPECT_THROW(CheckLog(SimulateOrFail(testing::PushedSlider()), options), std::invalid_argument);
}

TEST(LogCheck, JsonCarriesTheVerdictsAndTheAdvice) {
  const LogCheck c = CheckLog(SimulateOrFail(testing::PureTranslation()), IdentifyOptions{});
  const std::string line = FormatCheckJson(c);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(line);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(j[ParameterName(i)]["identifiable"].get<bool>(), c.parameters[i].identifiable);
  }
  EXPECT_EQ(j["advice"].size(), c.advice.size());
  EXPECT_EQ(j["rows"].get<int>(), c.rows);
  EXPECT_TRUE(j["mu_pusher"].is_null());
  EXPECT_TRUE(j["any_identifiable"].get<bool>());
  const std::string text = FormatCheckText(c);
  EXPECT_NE(text.find("e_r_over_e_t   no"), std::string::npos) << text;
  EXPECT_NE(text.find("cond(J^T J) = "), std::string::npos) << text;
}

TEST(LogCheck, ToolChecksEachLogFitsNothingAndExitsByWhatItFound) {
  const std::string good = testing::TempPath("check_good.csv");
  WritePushLog(SimulateOrFail(testing::FreeSlideWithSpin()), good);
  const testing::ToolRun ok = testing::RunTool("identify", "--check --log " + good);
  EXPECT_EQ(ok.code, 0) << ok.all();
  EXPECT_NE(ok.out.find("check of check_good.csv (nothing fitted)"), std::string::npos) << ok.out;
  EXPECT_EQ(ok.out.find("std. error"), std::string::npos) << ok.out;  // no table: nothing fitted

  const std::string bad = testing::WriteFile("check_bad.csv", "t,x,y,theta\n0,0,0,zero\n");
  const testing::ToolRun json =
      testing::RunTool("identify", "--check --json --log " + good + " --log " + bad);
  EXPECT_EQ(json.code, 1) << json.all();
  const std::vector<std::string> lines = [&] {
    std::vector<std::string> v;
    std::stringstream in(json.out);
    for (std::string l; std::getline(in, l);) v.push_back(l);
    return v;
  }();
  ASSERT_EQ(lines.size(), 2u) << json.out;
  EXPECT_TRUE(nlohmann::json::parse(lines[0])["any_identifiable"].get<bool>());
  EXPECT_NE(nlohmann::json::parse(lines[1])["error"].get<std::string>().find("check_bad.csv"),
            std::string::npos);
  EXPECT_NE(json.err.find("1 of 2 logs cannot be read or are expected to identify nothing"),
            std::string::npos)
      << json.err;

  const testing::ToolRun usage =
      testing::RunTool("identify", "--check --method closed-form --log " + good);
  EXPECT_EQ(usage.code, 2) << usage.all();
  EXPECT_NE(usage.err.find("--check"), std::string::npos) << usage.err;
}

}  // namespace
}  // namespace slideid
