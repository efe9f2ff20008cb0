#include "estimator/closed_form.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/noise.h"
#include "io/push_log.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using testing::SimulateOrFail;

using testing::ExpectRecovers;
using testing::ExpectWithinStandardErrors;
using testing::FullyIdentifiableScenes;
using testing::NamedScene;
using testing::PosesOnly;
using testing::kExactRelTol;

TEST(ClosedForm, RecoversTruthExactlyFromNoiselessLogs) {
  for (const NamedScene& s : FullyIdentifiableScenes()) {
    const Trajectory log = SimulateOrFail(s.scene);
    const EstimateResult r = EstimateClosedForm(log, {});
    EXPECT_EQ(r.method, EstimatorMethod::kClosedForm);
    EXPECT_EQ(r.steps_total, static_cast<int>(log.samples.size()) - 1);
    EXPECT_GE(r.steps_used, 3);
    ExpectRecovers(r, ReducedFriction::From(s.scene.friction), s.name);
  }
}

TEST(ClosedForm, RecoversTruthExactlyFromPosesOnlyLogs) {
  // Velocities from the backward-Euler kinematic map equal the simulator's (its pose update
  // is backward Euler), so only the first step (start velocity unknown) is lost.
  for (const NamedScene& s : FullyIdentifiableScenes()) {
    const Trajectory log = PosesOnly(SimulateOrFail(s.scene), std::string(s.name) + ".csv");
    const EstimateResult r = EstimateClosedForm(log, {});
    ExpectRecovers(r, ReducedFriction::From(s.scene.friction), std::string(s.name) + " poses");
    bool unknown_start = false;
    for (const auto& [reason, count] : r.steps_excluded) {
      if (reason == "start velocity unknown") unknown_start = (count == 1);
    }
    EXPECT_TRUE(unknown_start) << s.name;
  }
}

TEST(ClosedForm, ExcludesStickingStepsAndSaysSo) {
  const Trajectory log = SimulateOrFail(testing::TiltingPush());
  int stuck = 0;
  for (const TrajectorySample& sample : log.samples) stuck += sample.mode == SampleMode::kStick;
  ASSERT_GT(stuck, 0) << "the scene is meant to stick-slip";
  const EstimateResult r = EstimateClosedForm(log, {});
  int excluded_sticking = 0;
  for (const auto& [reason, count] : r.steps_excluded) {
    if (reason == "sticking") excluded_sticking = count;
  }
  EXPECT_EQ(excluded_sticking, stuck);
  ASSERT_EQ(r.residuals.size(), static_cast<size_t>(r.steps_total));
  int used = 0;
  for (const StepResidual& res : r.residuals) {
    used += res.used;
    if (res.used) {
      EXPECT_NEAR(res.value[kA], 0.0, kExactRelTol) << "row " << res.row;
    }
  }
  EXPECT_EQ(used, r.steps_used);
  EXPECT_EQ(r.residual_names[kA], "a_step_rel");
}

TEST(ClosedForm, PureTranslationCannotIdentifyC) {
  const Scene scene = testing::PureTranslation();
  const ReducedFriction truth = ReducedFriction::From(scene.friction);
  const EstimateResult r = EstimateClosedForm(SimulateOrFail(scene), {});
  ASSERT_TRUE(r.parameters[kA].identifiable) << r.parameters[kA].note;
  EXPECT_NEAR(r.parameters[kA].value / truth.a, 1.0, kExactRelTol);
  // The velocity leaves both axes, so b is determined.
  ASSERT_TRUE(r.parameters[kB].identifiable) << r.parameters[kB].note;
  EXPECT_NEAR(r.parameters[kB].value / truth.b, 1.0, kExactRelTol);
  EXPECT_FALSE(r.parameters[kC].identifiable);
  EXPECT_TRUE(std::isnan(r.parameters[kC].value));
  EXPECT_FALSE(r.parameters[kC].reason.empty());
  EXPECT_EQ(r.parameters[kC].verdict, Verdict::kNotIdentifiable);
}

TEST(ClosedForm, MotionAlongOneAxisIdentifiesOnlyA) {
  const Scene scene = testing::AlongOneAxis();
  const ReducedFriction truth = ReducedFriction::From(scene.friction);
  const EstimateResult r = EstimateClosedForm(SimulateOrFail(scene), {});
  ASSERT_TRUE(r.parameters[kA].identifiable) << r.parameters[kA].note;
  EXPECT_NEAR(r.parameters[kA].value / truth.a, 1.0, kExactRelTol);
  EXPECT_FALSE(r.parameters[kB].identifiable);
  EXPECT_FALSE(r.parameters[kC].identifiable);
  EXPECT_TRUE(std::isnan(r.parameters[kB].value));
  EXPECT_TRUE(std::isnan(r.parameters[kC].value));
}

TEST(ClosedForm, SliderAtRestIsTooLittleSliding) {
  Scene scene = testing::BaseScene();  // starts at rest, no push
  const Trajectory log = SimulateOrFail(scene);
  const EstimateResult r = EstimateClosedForm(log, {});
  EXPECT_EQ(r.status, TerminationStatus::kTooLittleExcitation);
  EXPECT_NE(r.message.find("too little sliding"), std::string::npos) << r.message;
}

// Noise: velocity 0.002 m/s and spin 0.02 rad/s (a good motion-capture rig after
// differentiation). Per step, p = m (v' - v) carries sqrt(2) m 0.002 = 0.0028 N s of noise
// against p_n = 0.098 N s, i.e. ~10% of a = 0.3; the median of ~45 steps then has a standard
// error of ~1.25 * 10% / sqrt(45) ~ 2%. Each estimate must lie within kNoiseSigmas of its own
// reported standard errors of the truth, and that standard error must be small enough
// (kMaxNoisyRelStdErr) for the check to mean something.
constexpr double kNoiseSigmas = 4.0;
constexpr double kMaxNoisyRelStdErr = 0.05;

NoiseSpec VelocityNoise(std::uint64_t seed) {
  NoiseSpec noise;
  noise.velocity_mps = 0.002;
  noise.spin_radps = 0.02;
  noise.seed = seed;
  return noise;
}

TEST(ClosedForm, NoisyLogsGiveEstimatesWithinTheirStandardErrors) {
  for (const NamedScene& s : FullyIdentifiableScenes()) {
    const ReducedFriction truth = ReducedFriction::From(s.scene.friction);
    const Trajectory clean = SimulateOrFail(s.scene);
    for (int seed = 1; seed <= 10; ++seed) {
      const EstimateResult r = EstimateClosedForm(AddNoise(clean, VelocityNoise(seed)), {});
      ExpectWithinStandardErrors(r, truth, kMaxNoisyRelStdErr, kNoiseSigmas,
                                 std::string(s.name) + " seed " + std::to_string(seed));
    }
  }
}

TEST(ClosedForm, NoisyStraightLineStillCannotIdentifyBOrC) {
  // Velocity noise puts v_o and v_r at noise level, below kDivisorFraction of the speed.
  const Trajectory clean = SimulateOrFail(testing::AlongOneAxis());
  for (int seed = 1; seed <= 5; ++seed) {
    const EstimateResult r = EstimateClosedForm(AddNoise(clean, VelocityNoise(seed)), {});
    EXPECT_TRUE(r.parameters[kA].identifiable);
    EXPECT_FALSE(r.parameters[kB].identifiable) << r.parameters[kB].value;
    EXPECT_FALSE(r.parameters[kC].identifiable) << r.parameters[kC].value;
  }
}

TEST(ClosedForm, RejectsInvalidOptions) {
  IdentifyOptions options;
  options.closed_form.divisor_fraction = 0;
  EXPECT_THROW(EstimateClosedForm(SimulateOrFail(testing::FreeSlideWithSpin()), options),
               std::invalid_argument);
}

}  // namespace
}  // namespace slideid
