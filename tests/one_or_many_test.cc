// The one owner of "one log or many" (estimator/pooling.h, FitOneOrMany): the order in which
// it calls a method's core fits, what it puts into the result, and that every method's
// pooled per-log entries are that method's fit of the log alone.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "estimator/closed_form.h"
#include "estimator/equation_error.h"
#include "estimator/pooling.h"
#include "estimator/quasi_static_fit.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

// A method that records the calls and answers with a = 0.3 + 0.01 k, interval +-5%.
class RecordingMethod : public PoolableFit {
 public:
  LogResult FitAlone(int k) override {
    calls.push_back("alone " + std::to_string(k));
    LogResult r;
    r.name = "log " + std::to_string(k);
    r.parameters[0] = Estimate(0.3 + 0.01 * k);
    return r;
  }
  EstimateResult FitTogether(std::vector<LogResult>* alone) override {
    calls.push_back(alone ? "together " + std::to_string(alone->size()) : "one");
    if (alone) (*alone)[0].message = "revised";
    EstimateResult r;
    r.parameters[0] = Estimate(0.31);
    return r;
  }
  std::vector<std::string> calls;

 private:
  static ParameterEstimate Estimate(double a) {
    ParameterEstimate p;
    p.identifiable = true;
    p.value = a;
    p.stderr_value = 0.025 * a;
    p.ci95_lo = a / 1.05;
    p.ci95_hi = a * 1.05;
    return p;
  }
};

TEST(FitOneOrMany, OneLogIsFittedOnceWithoutEntries) {
  RecordingMethod method;
  const EstimateResult r = FitOneOrMany(1, &method);
  EXPECT_EQ(method.calls, std::vector<std::string>{"one"});
  EXPECT_TRUE(r.logs.empty());
  EXPECT_FALSE(r.heterogeneity[0].tested);
}

TEST(FitOneOrMany, ManyLogsAreFittedAloneInOrderThenTogether) {
  RecordingMethod method;
  const EstimateResult r = FitOneOrMany(3, &method);
  EXPECT_EQ(method.calls,
            (std::vector<std::string>{"alone 0", "alone 1", "alone 2", "together 3"}));
  ASSERT_EQ(r.logs.size(), 3u);
  EXPECT_EQ(r.logs[2].name, "log 2");
  EXPECT_EQ(r.logs[0].message, "revised");  // the method's revision is kept
  EXPECT_TRUE(r.heterogeneity[0].tested);
  EXPECT_EQ(r.heterogeneity[0].logs, 3);
  EXPECT_FALSE(r.heterogeneity[1].tested);  // b identified by none
  EXPECT_DOUBLE_EQ(r.parameters[0].value, 0.31);
}

TEST(FitOneOrMany, NoLogsIsAnError) {
  RecordingMethod method;
  EXPECT_THROW(FitOneOrMany(0, &method), std::invalid_argument);
  EXPECT_THROW(EstimateClosedForm(std::vector<Trajectory>{}, IdentifyOptions{}),
               std::invalid_argument);
}

std::uint64_t Bits(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return bits;
}

// Each cheap method's pooled entries are exactly its result on the log alone: one code path.
TEST(FitOneOrMany, PooledEntriesAreTheMethodsFitOfEachLogAlone) {
  DatasetSpec spec;  // one slider and surface per seed; logs with velocities and their noise
  spec.seed = 40;
  spec.mass_kg = {0.8, 0.8};
  spec.mu = {0.35, 0.35};
  spec.log.motion = LogMotion::kBoth;
  spec.log.noise.velocity_mps = 5e-4;
  spec.log.noise.spin_radps = 5e-3;
  std::vector<Trajectory> logs(3);
  for (int k = 0; k < 3; ++k) DrawDatasetLog(spec, k, &logs[k]);
  const EstimateResult cf = EstimateClosedForm(logs, {});
  const EstimateResult ee = EstimateEquationError(logs, {});
  ASSERT_EQ(cf.logs.size(), 3u) << cf.message;
  ASSERT_TRUE(cf.parameters[0].identifiable) << cf.message;
  ASSERT_TRUE(ee.parameters[0].identifiable) << ee.message;
  ASSERT_EQ(ee.logs.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const EstimateResult cf_alone = EstimateClosedForm(logs[k], {});
    const EstimateResult ee_alone = EstimateEquationError(logs[k], {});
    for (int i = 0; i < 3; ++i) {
      // Bit for bit (NaN for a parameter the log does not identify).
      EXPECT_EQ(Bits(cf.logs[k].parameters[i].value), Bits(cf_alone.parameters[i].value)) << k << i;
      EXPECT_EQ(Bits(ee.logs[k].parameters[i].value), Bits(ee_alone.parameters[i].value)) << k << i;
      EXPECT_EQ(ee.logs[k].parameters[i].verdict, ee_alone.parameters[i].verdict) << k << i;
    }
  }
}

TEST(FitOneOrMany, QuasiStaticSetsOfTwoSlidersAreRefusedNamingBoth) {
  WrenchTwistData light, heavy;
  light.mass_kg = 1.0;
  light.source = "light.csv";
  heavy.mass_kg = 1.5;
  heavy.source = "heavy.csv";
  try {
    EstimateQuasiStatic(std::vector<WrenchTwistData>{light, heavy}, IdentifyOptions{});
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("heavy.csv"), std::string::npos) << what;
    EXPECT_NE(what.find("light.csv"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace slideid
