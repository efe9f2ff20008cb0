// The identify result JSON (io/result_json.h): its documented layout, exact round trips of
// every field it carries (random bit patterns included), null for what is not a number, the
// JSON identify itself prints, and errors that name the JSON path.

#include "io/result_json.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "io/push_log.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

std::uint64_t Bits(double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

/// Same double bit for bit, or both NaN (JSON null carries no NaN payload).
void ExpectSameDouble(double expected, double actual, const std::string& what) {
  if (std::isnan(expected)) {
    EXPECT_TRUE(std::isnan(actual)) << what << ": " << actual;
  } else {
    EXPECT_EQ(Bits(expected), Bits(actual)) << what << ": " << expected << " read as " << actual;
  }
}

/// Every field FormatJson writes; `expected` must hold NaN where FormatJson writes null.
void ExpectSameResult(const EstimateResult& expected, const EstimateResult& actual) {
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& e = expected.parameters[i];
    const ParameterEstimate& a = actual.parameters[i];
    const std::string name = ParameterName(i);
    EXPECT_EQ(e.identifiable, a.identifiable) << name;
    ExpectSameDouble(e.value, a.value, name + " value");
    ExpectSameDouble(e.stderr_value, a.stderr_value, name + " stderr");
    ExpectSameDouble(e.ci95_lo, a.ci95_lo, name + " ci95_lo");
    ExpectSameDouble(e.ci95_hi, a.ci95_hi, name + " ci95_hi");
    if (e.identifiable) {
      ExpectSameDouble(e.interval_quantile, a.interval_quantile, name + " interval_quantile");
    }
    ExpectSameDouble(e.held_at, a.held_at, name + " held_at");
    EXPECT_EQ(e.note, a.note) << name;
    EXPECT_EQ(e.verdict, a.verdict) << name;
    EXPECT_EQ(e.reason, a.reason) << name;
  }
  EXPECT_EQ(expected.method, actual.method);
  EXPECT_EQ(expected.status, actual.status);
  ExpectSameDouble(expected.log_noise, actual.log_noise, "log_noise");
  ExpectSameDouble(expected.residual_rms, actual.residual_rms, "residual_rms");
  ASSERT_EQ(expected.nuisance.size(), actual.nuisance.size());
  for (size_t k = 0; k < expected.nuisance.size(); ++k) {
    const NuisanceEstimate& e = expected.nuisance[k];
    const NuisanceEstimate& a = actual.nuisance[k];
    EXPECT_EQ(e.name, a.name);
    EXPECT_EQ(e.log, a.log);
    EXPECT_EQ(e.identifiable, a.identifiable);
    EXPECT_EQ(e.verdict, a.verdict);
    EXPECT_EQ(e.reason, a.reason);
    ExpectSameDouble(e.value, a.value, e.name + " value");
    ExpectSameDouble(e.stderr_value, a.stderr_value, e.name + " stderr");
    ExpectSameDouble(e.ci95_lo, a.ci95_lo, e.name + " lo");
    ExpectSameDouble(e.ci95_hi, a.ci95_hi, e.name + " hi");
    ExpectSameDouble(e.held_at, a.held_at, e.name + " held_at");
  }
  ASSERT_EQ(expected.logs.size(), actual.logs.size());
  for (size_t k = 0; k < expected.logs.size(); ++k) {
    const LogResult& e = expected.logs[k];
    const LogResult& a = actual.logs[k];
    EXPECT_EQ(e.name, a.name);
    EXPECT_EQ(e.skipped, a.skipped);
    EXPECT_EQ(e.skip_reason, a.skip_reason);
    EXPECT_EQ(e.rows, a.rows);
    EXPECT_EQ(e.steps_used, a.steps_used);
    EXPECT_EQ(e.status, a.status);
    EXPECT_EQ(e.message, a.message);
    for (int i = 0; i < 3; ++i) {
      ExpectSameDouble(e.parameters[i].value, a.parameters[i].value, e.name + " value");
      ExpectSameDouble(e.parameters[i].ci95_lo, a.parameters[i].ci95_lo, e.name + " lo");
      EXPECT_EQ(e.parameters[i].verdict, a.parameters[i].verdict);
    }
  }
  for (int i = 0; i < 3; ++i) {
    const Heterogeneity& e = expected.heterogeneity[i];
    const Heterogeneity& a = actual.heterogeneity[i];
    EXPECT_EQ(e.tested, a.tested);
    EXPECT_EQ(e.logs, a.logs);
    EXPECT_EQ(e.consistent, a.consistent);
    ExpectSameDouble(e.q, a.q, "q");
    ExpectSameDouble(e.p_value, a.p_value, "p");
    ExpectSameDouble(e.i2, a.i2, "i2");
    ExpectSameDouble(e.tau_log, a.tau_log, "tau");
  }
  EXPECT_EQ(expected.steps_total, actual.steps_total);
  EXPECT_EQ(expected.steps_used, actual.steps_used);
  EXPECT_EQ(expected.steps_excluded, actual.steps_excluded);
  ExpectSameDouble(expected.final_cost, actual.final_cost, "final_cost");
  EXPECT_EQ(expected.iterations, actual.iterations);
  ExpectSameDouble(expected.seconds, actual.seconds, "seconds");
  EXPECT_EQ(expected.converged, actual.converged);
  EXPECT_EQ(expected.message, actual.message);
}

ParameterEstimate Identified(double value, double stderr_value, const std::string& note = "") {
  ParameterEstimate p;
  p.identifiable = true;
  p.value = value;
  p.stderr_value = stderr_value;
  p.ci95_lo = value - kZ95 * stderr_value;
  p.ci95_hi = value + kZ95 * stderr_value;
  p.verdict = Verdict::kOk;
  p.note = note;
  return p;
}

ParameterEstimate Held(double held_at, const std::string& reason) {
  ParameterEstimate p;
  p.held_at = held_at;
  p.reason = reason;
  return p;
}

EstimateResult Simple() {
  EstimateResult r;
  r.method = EstimatorMethod::kTrajectory;
  r.parameters[kA] = Identified(0.25, 0.5);
  r.parameters[kA].ci95_lo = -0.75;
  r.parameters[kA].ci95_hi = 1.25;
  r.parameters[kB] = Identified(1.5, 0.125, "error widened 2x");
  r.parameters[kB].ci95_lo = 1.25;
  r.parameters[kB].ci95_hi = 1.75;
  r.parameters[kC] = Held(0.03125, "no rotation");
  r.steps_total = 300;
  r.steps_used = 295;
  r.Exclude("sticking", 3);
  r.Exclude("between shooting segments", 2);
  r.seconds = 0.5;
  r.iterations = 12;
  r.final_cost = 2.0;
  r.converged = true;
  r.message = "done";
  return r;
}

TEST(ResultJson, KeepsTheDocumentedKeysOrderAndLayout) {
  EXPECT_EQ(
      FormatJson(Simple()),
      "{\"e_t_mu\": {\"value\": 0.25, \"stderr\": 0.5, \"ci95\": [-0.75, 1.25], "
      "\"interval_quantile\": 1.959963984540054, \"identifiable\": true, \"verdict\": \"ok\", "
      "\"reason\": \"\", \"held_at\": null, "
      "\"note\": \"\"}, "
      "\"e_o_over_e_t\": {\"value\": 1.5, \"stderr\": 0.125, \"ci95\": [1.25, 1.75], "
      "\"interval_quantile\": 1.959963984540054, \"identifiable\": true, \"verdict\": \"ok\", "
      "\"reason\": \"\", \"held_at\": null, "
      "\"note\": \"error widened 2x\"}, "
      "\"e_r_over_e_t\": {\"value\": null, \"stderr\": null, \"ci95\": [null, null], "
      "\"interval_quantile\": null, \"identifiable\": false, \"verdict\": \"not identifiable\", "
      "\"reason\": \"no rotation\", \"held_at\": 0.03125, \"note\": \"\"}, "
      "\"method\": \"trajectory\", \"status\": \"converged\", \"steps_used\": 295, "
      "\"steps_total\": 300, "
      "\"steps_excluded\": 5, \"steps_excluded_by_reason\": {\"sticking\": 3, "
      "\"between shooting segments\": 2}, \"seconds\": 0.5, \"iterations\": 12, "
      "\"final_cost\": 2.0, \"converged\": true, \"message\": \"done\", "
      "\"log_noise\": null, \"residual_rms\": null, \"nuisance\": {}, \"logs\": [], "
      "\"heterogeneity\": {"
      "\"e_t_mu\": {\"tested\": false, \"logs\": 0, \"q\": null, \"p_value\": null, "
      "\"i2\": null, \"tau_log\": null, \"consistent\": true}, "
      "\"e_o_over_e_t\": {\"tested\": false, \"logs\": 0, \"q\": null, \"p_value\": null, "
      "\"i2\": null, \"tau_log\": null, \"consistent\": true}, "
      "\"e_r_over_e_t\": {\"tested\": false, \"logs\": 0, \"q\": null, \"p_value\": null, "
      "\"i2\": null, \"tau_log\": null, \"consistent\": true}}, \"mu_pusher\": null}");
}

TEST(ResultJson, BatchLinesWrapTheResultOrTheErrorWithTheFileFirst) {
  const EstimateResult result = Simple();
  const std::string json = FormatJson(result);
  const std::string body = json.substr(1, json.size() - 2);
  EXPECT_EQ(FormatBatchLine("a \"b\".csv", &result, "", {"a.csv:3: gap"}),
            "{\"file\": \"a \\\"b\\\".csv\", \"ok\": true, " + body +
                ", \"warnings\": [\"a.csv:3: gap\"]}");
  EXPECT_EQ(FormatBatchLine("a.csv", nullptr, "a.csv:6: bad", {}),
            "{\"file\": \"a.csv\", \"ok\": false, \"error\": \"a.csv:6: bad\"}");
  EXPECT_EQ(
      FormatBatchLine("a.csv", &result, "a.csv: no", {"ignored"}),
      "{\"file\": \"a.csv\", \"ok\": false, \"error\": \"a.csv: no\", \"result\": " + json + "}");
  EXPECT_THROW(FormatBatchLine("a.csv", nullptr, "", {}), std::invalid_argument);
}

TEST(ResultJson, ReadsBackPooledLogsNuisancesAndVerdicts) {
  EstimateResult r = Simple();
  r.status = TerminationStatus::kConvergedWithCaveats;
  r.parameters[kA].verdict = Verdict::kSuspect;
  r.parameters[kA].reason = "residuals 5 times the log's own noise";
  r.log_noise = 3e-4;
  r.residual_rms = 1.0 / 3.0;
  NuisanceEstimate bias;
  bias.name = "force_bias_x_n";
  bias.log = "push \"1\".csv";
  bias.identifiable = true;
  bias.verdict = Verdict::kOk;
  bias.value = -0.25;
  bias.stderr_value = 0.01;
  bias.ci95_lo = -0.27;
  bias.ci95_hi = -0.23;
  NuisanceEstimate delay;
  delay.name = "delay_s";
  delay.held_at = 0.0;
  delay.reason = "not determined";
  r.nuisance = {bias, delay};
  LogResult a;
  a.name = "a.csv";
  a.rows = 61;
  a.steps_used = 55;
  a.status = TerminationStatus::kConverged;
  a.parameters = Simple().parameters;
  LogResult b;
  b.name = "b.csv";
  b.skipped = true;
  b.skip_reason = "b.csv:3: column 'x': not a number";
  r.logs = {a, b};
  r.heterogeneity[kA].tested = true;
  r.heterogeneity[kA].logs = 2;
  r.heterogeneity[kA].q = 7.5;
  r.heterogeneity[kA].p_value = 0.006;
  r.heterogeneity[kA].i2 = 0.87;
  r.heterogeneity[kA].tau_log = 0.2;
  r.heterogeneity[kA].consistent = false;
  const std::string text = FormatJson(r);
  const EstimateResult back = ParseResultJson(text);
  ExpectSameResult(r, back);
  EXPECT_EQ(FormatJson(back), text);
}

TEST(ResultJson, ReadsBackEveryFieldBitForBitAtTheExtremesOfDouble) {
  EstimateResult r = Simple();
  r.method = EstimatorMethod::kEquationError;
  r.parameters[kA] = Identified(1.0 / 3.0, DBL_TRUE_MIN, "denormal error");
  r.parameters[kA].ci95_lo = -DBL_MAX;
  r.parameters[kA].ci95_hi = DBL_MAX;
  r.parameters[kB] = Identified(0.1 + 0.2, DBL_MIN);
  r.parameters[kB].ci95_lo = -0.0;
  r.parameters[kC] = Held(std::nextafter(0.03, 1.0),
                          "quotes \" backslash \\ newline \n tab \t bell \x07 utf-8 \xc3\xa9 /");
  r.seconds = 1e-300;
  r.final_cost = 123456789012345678.0;
  r.iterations = INT_MAX;
  r.steps_total = INT_MAX;
  r.converged = false;
  r.message = "Ceres Solver Report: Iterations: 14, Termination: NO_CONVERGENCE";
  const std::string json = FormatJson(r);
  const EstimateResult back = ParseResultJson(json);
  ExpectSameResult(r, back);
  EXPECT_EQ(FormatJson(back), json);
  EXPECT_EQ(json.find('\n'), std::string::npos) << "one line: " << json;
}

TEST(ResultJson, ReadsBackRandomBitPatternsExactly) {
  std::mt19937_64 rng(20240917);
  const auto any_double = [&] {  // any finite double, every exponent and mantissa
    for (;;) {
      const std::uint64_t bits = rng();
      double v;
      std::memcpy(&v, &bits, sizeof v);
      if (std::isfinite(v)) return v;
    }
  };
  for (int trial = 0; trial < 500; ++trial) {
    EstimateResult r;
    r.method = static_cast<EstimatorMethod>(trial % 3);
    for (int i = 0; i < 3; ++i) {
      if ((rng() & 3) != 0) {
        r.parameters[i] = Identified(any_double(), any_double());
        r.parameters[i].ci95_lo = any_double();
        r.parameters[i].ci95_hi = any_double();
        // Student's t quantiles from 1 degree of freedom (12.7) down to z.
        r.parameters[i].interval_quantile =
            kZ95 + std::uniform_real_distribution<double>(0.0, 11.0)(rng);
      } else {
        r.parameters[i] = Held(any_double(), "held");
      }
    }
    r.steps_total = static_cast<int>(rng() % 1000000);
    r.steps_used = static_cast<int>(rng() % 1000000);
    if (rng() & 1) r.Exclude("sticking", static_cast<int>(rng() % 1000));
    r.seconds = any_double();
    r.final_cost = any_double();
    r.iterations = static_cast<int>(rng() % 1000);
    r.converged = (rng() & 1) != 0;
    const std::string json = FormatJson(r);
    const EstimateResult back = ParseResultJson(json);
    ExpectSameResult(r, back);
    ASSERT_EQ(FormatJson(back), json) << "trial " << trial;
    if (HasFailure()) FAIL() << "trial " << trial << ": " << json;
  }
}

TEST(ResultJson, WritesNullForWhatIsNotANumberAndReadsItAsNaN) {
  EstimateResult r = Simple();
  r.parameters[kA].value = kNaN;         // a failed fit: identifiable, but no number
  r.parameters[kA].stderr_value = kInf;  // JSON has no infinity either
  r.parameters[kC].value = 0.5;          // not identifiable: its value is never written
  r.final_cost = -kInf;
  const std::string json = FormatJson(r);
  EXPECT_EQ(json.find("nan"), std::string::npos) << json;
  EXPECT_EQ(json.find("inf"), std::string::npos) << json;
  EXPECT_NE(json.find("\"e_t_mu\": {\"value\": null, \"stderr\": null, \"ci95\": [-0.75"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find("\"final_cost\": null"), std::string::npos) << json;
  const EstimateResult back = ParseResultJson(json);
  EXPECT_TRUE(back.parameters[kA].identifiable);
  EXPECT_TRUE(std::isnan(back.parameters[kA].value));
  EXPECT_TRUE(std::isnan(back.parameters[kA].stderr_value));
  EXPECT_TRUE(std::isnan(back.parameters[kC].value));
  EXPECT_EQ(back.parameters[kC].held_at, 0.03125);
  EXPECT_TRUE(std::isnan(back.final_cost));
  EXPECT_EQ(FormatJson(back), json);
}

/// ResultJsonError's message from `parse` on `json`, or "" when it parses.
template <typename Parse>
std::string ErrorOf(Parse parse, const std::string& json) {
  try {
    parse(json);
  } catch (const ResultJsonError& e) {
    return e.what();
  }
  return "";
}

std::string ResultError(const std::string& json) {
  return ErrorOf([](const std::string& j) { ParseResultJson(j); }, json);
}

std::string Replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) ADD_FAILURE() << "'" << from << "' not in " << text;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(ResultJson, BadJsonNamesThePathOrTheLineAndColumn) {
  const std::string good = FormatJson(Simple());
  const std::string truncated = ResultError(good.substr(0, 60));
  EXPECT_NE(truncated.find("identify JSON: parse error at line 1, column"), std::string::npos)
      << truncated;
  EXPECT_NE(ResultError("[1, 2]").find("expected an object"), std::string::npos);
  EXPECT_EQ(ResultError(Replaced(good, "\"steps_used\"", "\"steps_usd\"")),
            "identify JSON: no \"steps_used\"");
  EXPECT_EQ(ResultError(Replaced(good, "[1.25, 1.75]", "[1.25, \"x\"]")),
            "identify JSON: /e_o_over_e_t/ci95/1: expected a number or null, got \"x\"");
  EXPECT_EQ(ResultError(Replaced(good, "[1.25, 1.75]", "[1.25]")),
            "identify JSON: /e_o_over_e_t/ci95: expected [lo, hi], got [1.25]");
  EXPECT_EQ(ResultError(Replaced(good, "\"identifiable\": true", "\"identifiable\": 1")),
            "identify JSON: /e_t_mu/identifiable: expected true or false, got 1");
  EXPECT_EQ(ResultError(Replaced(good, "\"trajectory\"", "\"magic\"")),
            "identify JSON: /method: unknown method 'magic' (closed-form, equation-error, "
            "trajectory, quasi-static)");
  EXPECT_EQ(ResultError(Replaced(good, "\"iterations\": 12", "\"iterations\": -1")),
            "identify JSON: /iterations: expected an integer from 0 to 2147483647, got -1");
  EXPECT_EQ(ResultError(Replaced(good, "\"iterations\": 12", "\"iterations\": 12.5")),
            "identify JSON: /iterations: expected an integer from 0 to 2147483647, got 12.5");
  EXPECT_EQ(ResultError(Replaced(good, "\"sticking\": 3", "\"sticking\": 4")),
            "identify JSON: /steps_excluded: 5 is not the sum of steps_excluded_by_reason (6)");
  EXPECT_EQ(ResultError(Replaced(good, "\"note\": \"\"", "\"note\": null")),
            "identify JSON: /e_t_mu/note: expected a string, got null");
  EXPECT_EQ(ResultError(Replaced(good, "\"interval_quantile\": 1.959963984540054",
                                 "\"interval_quantile\": 1.5")),
            "identify JSON: /e_t_mu/interval_quantile: expected a quantile of at least 1.96, "
            "got 1.5");
  EXPECT_EQ(ResultError(Replaced(good, "\"interval_quantile\": 1.959963984540054",
                                 "\"interval_quantile\": \"t\"")),
            "identify JSON: /e_t_mu/interval_quantile: expected a number or null, got \"t\"");
}

// A result file nested deeper than a recursive dump can go (a broken or hostile writer), or
// with a number beyond a double: an error naming what is wrong, never a crash (the message
// once quoted the whole value through nlohmann's recursive dump: a stack overflow).
TEST(ResultJson, DeeplyNestedOrOverflowingJsonIsAnErrorNotACrash) {
  const int depth = 200000;
  const std::string deep = std::string(depth, '[') + std::string(depth, ']');
  EXPECT_EQ(ResultError(deep),
            "identify JSON: expected an object, got " + std::string(40, '[') + "...");
  const std::string deep_member =
      "{\"e_t_mu\": " + std::string(depth, '[') + std::string(depth, ']') + "}";
  EXPECT_EQ(ResultError(deep_member),
            "identify JSON: /e_t_mu: expected an object, got " + std::string(40, '[') + "...");
  // Short values are quoted whole, as before.
  EXPECT_EQ(ResultError("{\"e_t_mu\": [[1], {\"a\": 2}]}"),
            "identify JSON: /e_t_mu: expected an object, got [[1],{\"a\":2}]");
  const std::string good = FormatJson(Simple());
  EXPECT_EQ(ResultError(Replaced(good, "\"iterations\": 12", "\"iterations\": 1e999")),
            "identify JSON: number overflow parsing '1e999'");
  try {
    ParseIdentifyJson("{\"e_t_mu\": 1e999}");
    ADD_FAILURE() << "1e999 read";
  } catch (const ResultJsonError& e) {
    EXPECT_EQ(std::string(e.what()), "identify JSON: number overflow parsing '1e999'");
  }
}

// Results written before intervals carried their quantile read as z-based ones.
TEST(ResultJson, AResultWithoutTheIntervalQuantileReadsAsZ) {
  EstimateResult r = Simple();
  r.parameters[kB].interval_quantile = 2.262157162740992;  // Student's t, 9 dof
  const std::string json = FormatJson(r);
  ASSERT_NE(json.find("\"interval_quantile\": 2.262157162740992"), std::string::npos) << json;
  EXPECT_EQ(ParseResultJson(json).parameters[kB].interval_quantile, 2.262157162740992);
  std::string old = json;
  for (std::size_t at; (at = old.find("\"interval_quantile\": ")) != std::string::npos;) {
    old.erase(at, old.find(", ", at) + 2 - at);
  }
  ASSERT_EQ(old.find("interval_quantile"), std::string::npos) << old;
  const EstimateResult back = ParseResultJson(old);
  for (int i = 0; i < 2; ++i) EXPECT_EQ(back.parameters[i].interval_quantile, kZ95);
  ExpectSameDouble(r.parameters[kB].value, back.parameters[kB].value, "b value");
}

std::string IdentifyError(const std::string& json) {
  return ErrorOf([](const std::string& j) { ParseIdentifyJson(j); }, json);
}

TEST(ResultJson, ParseIdentifyJsonTakesValuesOrHeldValuesAndNamesWhatIsWrong) {
  const ReducedFriction f = ParseIdentifyJson(FormatJson(Simple()));
  EXPECT_EQ(f.a, 0.25);
  EXPECT_EQ(f.b, 1.5);
  EXPECT_EQ(f.c, 0.03125);
  // Only the three parameter objects are needed (a hand-written fit).
  const ReducedFriction hand = ParseIdentifyJson(
      "{\"e_t_mu\": {\"value\": 0.3}, \"e_o_over_e_t\": {\"value\": 1.2},"
      " \"e_r_over_e_t\": {\"value\": null, \"held_at\": 0.02}}");
  EXPECT_EQ(hand.a, 0.3);
  EXPECT_EQ(hand.b, 1.2);
  EXPECT_EQ(hand.c, 0.02);
  EXPECT_EQ(IdentifyError("{\"e_t_mu\": {\"value\": 0.3}}"), "identify JSON: no \"e_o_over_e_t\"");
  EXPECT_EQ(IdentifyError("{\"e_t_mu\": {\"value\": -0.3}, \"e_o_over_e_t\": {}, "
                          "\"e_r_over_e_t\": {}}"),
            "identify JSON: \"e_t_mu\" has neither a value nor a held_at value");
  EXPECT_EQ(IdentifyError("{\"e_t_mu\": 0.3}"),
            "identify JSON: /e_t_mu: expected an object, got 0.3");
  EXPECT_EQ(IdentifyError("{\"e_t_mu\": {\"value\": \"0.3\"}}"),
            "identify JSON: /e_t_mu/value: expected a number or null, got \"0.3\"");
  EXPECT_NE(IdentifyError("{\"e_t_mu\": {\"value\": 0.3").find("parse error at line 1"),
            std::string::npos);
  EXPECT_NE(IdentifyError("").find("parse error"), std::string::npos);
}

/// Standard output of identify with `args`, and its exit code.
std::string IdentifyStdout(const std::string& args, int* exit_code) {
  const testing::ToolRun r = testing::RunTool("identify", args);
  *exit_code = r.code;
  return r.out;
}

TEST(ResultJson, WhatIdentifyPrintsReadsBackExactlyForEveryMethod) {
  const std::string pushed = ::testing::TempDir() + "/result_json_pushed.csv";
  WritePushLog(testing::SimulateOrFail(testing::PushedSlider()), pushed);
  const std::string translation = ::testing::TempDir() + "/result_json_translation.csv";
  WritePushLog(testing::SimulateOrFail(testing::PureTranslation()), translation);  // c held
  int held = 0;  // parameters not identifiable: their nulls and held_at read back too
  for (const std::string& log : {pushed, translation}) {
    for (const char* method : {"closed-form", "equation-error", "trajectory"}) {
      int code = -1;
      const std::string out =
          IdentifyStdout("--log " + log + " --json --method " + std::string(method), &code);
      ASSERT_EQ(code, 0) << log << " " << method;
      ASSERT_FALSE(out.empty());
      ASSERT_EQ(out.back(), '\n');
      const std::string json = out.substr(0, out.size() - 1);
      const EstimateResult read = ParseResultJson(json);
      EXPECT_EQ(FormatJson(read), json) << method;
      for (const ParameterEstimate& p : read.parameters) held += !p.identifiable;
    }
  }
  EXPECT_GT(held, 0);
}

}  // namespace
}  // namespace slideid
