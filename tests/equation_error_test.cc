#include "estimator/equation_error.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/noise.h"
#include "estimator/identifiability.h"
#include "estimator/internal/equation_error_residual.h"
#include "fixtures/jacobian_check.h"
#include "io/push_log.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using testing::SimulateOrFail;

using testing::CheckJacobian;
using testing::ExpectRecovers;
using testing::ExpectWithinStandardErrors;
using testing::FullyIdentifiableScenes;
using testing::JacobianCheck;
using testing::kExactRelTol;
using testing::kJacobianTolerance;
using testing::NamedScene;
using testing::PosesOnly;

double Radius(const Scene& s) { return std::sqrt(s.slider.inertia_kgm2 / s.slider.mass_kg); }

TEST(EquationError, RecoversTruthExactlyFromNoiselessLogs) {
  for (const NamedScene& s : FullyIdentifiableScenes()) {
    const Trajectory log = SimulateOrFail(s.scene);
    const EstimateResult r = EstimateEquationError(log, {});
    EXPECT_EQ(r.method, EstimatorMethod::kEquationError);
    EXPECT_EQ(r.steps_total, static_cast<int>(log.samples.size()) - 1);
    EXPECT_GE(r.steps_used, 3);
    ExpectRecovers(r, s.scene.friction.reduced(), s.name);
    EXPECT_EQ(r.residual_names[0], "t");
    EXPECT_EQ(r.residual_names[2], "r");
    ASSERT_EQ(r.residuals.size(), static_cast<size_t>(r.steps_total));
    int used = 0;
    for (const StepResidual& res : r.residuals) {
      if (!res.used) continue;
      ++used;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(res.value[c], 0.0, kExactRelTol) << res.row;
    }
    EXPECT_EQ(used, r.steps_used);
  }
}

TEST(EquationError, RecoversTruthExactlyFromPosesOnlyLogs) {
  // The kinematic map inverts the simulator's backward-Euler pose update exactly.
  for (const NamedScene& s : FullyIdentifiableScenes()) {
    const Trajectory log = PosesOnly(SimulateOrFail(s.scene), std::string(s.name) + ".csv");
    ExpectRecovers(EstimateEquationError(log, {}), s.scene.friction.reduced(),
                   std::string(s.name) + " poses");
  }
}

TEST(EquationError, EveryLossRecoversTruthFromNoiselessLogs) {
  const Scene scene = testing::Anisotropic();
  const Trajectory log = SimulateOrFail(scene);
  for (RobustLoss loss : {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy}) {
    IdentifyOptions options;
    options.equation_error.loss = loss;
    ExpectRecovers(EstimateEquationError(log, options), scene.friction.reduced(), ToString(loss));
  }
}

TEST(EquationError, PureTranslationHoldsCAndReportsItNotIdentifiable) {
  const Scene scene = testing::PureTranslation();
  const ReducedFriction truth = scene.friction.reduced();
  const EstimateResult r = EstimateEquationError(SimulateOrFail(scene), {});
  ASSERT_TRUE(r.parameters[kA].identifiable) << r.parameters[kA].note;
  EXPECT_NEAR(r.parameters[kA].value / truth.a, 1.0, kExactRelTol);
  ASSERT_TRUE(r.parameters[kB].identifiable) << r.parameters[kB].note;  // off both axes
  EXPECT_NEAR(r.parameters[kB].value / truth.b, 1.0, kExactRelTol);
  const ParameterEstimate& c = r.parameters[kC];
  EXPECT_FALSE(c.identifiable);
  EXPECT_TRUE(std::isnan(c.value));
  EXPECT_TRUE(std::isnan(c.stderr_value));
  EXPECT_DOUBLE_EQ(c.held_at, Radius(scene));  // the seed when the closed form has none
  EXPECT_FALSE(c.reason.empty());
}

TEST(EquationError, MotionAlongOneAxisIdentifiesOnlyA) {
  const Scene scene = testing::AlongOneAxis();
  const ReducedFriction truth = scene.friction.reduced();
  const EstimateResult r = EstimateEquationError(SimulateOrFail(scene), {});
  ASSERT_TRUE(r.parameters[kA].identifiable) << r.parameters[kA].note;
  EXPECT_NEAR(r.parameters[kA].value / truth.a, 1.0, kExactRelTol);
  EXPECT_FALSE(r.parameters[kB].identifiable);
  EXPECT_FALSE(r.parameters[kC].identifiable);
  EXPECT_TRUE(std::isnan(r.parameters[kB].value));
  EXPECT_DOUBLE_EQ(r.parameters[kB].held_at, 1.0);
  EXPECT_DOUBLE_EQ(r.parameters[kC].held_at, Radius(scene));
}

// Noise as in closed_form_test: velocity 0.002 m/s, spin 0.02 rad/s.
NoiseSpec VelocityNoise(std::uint64_t seed) {
  NoiseSpec noise;
  noise.velocity_mps = 0.002;
  noise.spin_radps = 0.02;
  noise.seed = seed;
  return noise;
}

// Per step the impulse noise is ~10% of a (closed_form_test). Each estimate must lie within
// kNoiseSigmas of its reported standard errors, which must be below kMaxNoisyRelStdErr.
// TiltingPush spins slowly: its rotational impulses are about 3 times their noise, too few
// for c (the per-step directions are then biased, not just noisy), which the fit must say.
constexpr double kNoiseSigmas = 4.0;
constexpr double kMaxNoisyRelStdErr = 0.05;
// The 95% intervals must cover the truth for at least this fraction of seeds (a nominal
// 95% interval would miss the mark 80% of 50 seeds with probability < 1e-4).
constexpr double kMinCoverage = 0.8;
// Errors-in-variables: the measured v of a step shares its noise with p = m (v' - v). On
// FreeSlideWithSpin this biases a by ~ -0.1% (50 seeds) before the SIMEX correction; bound
// the mean error well below the reported standard error.
constexpr double kMaxMeanRelError = 0.005;

TEST(EquationError, NoisyLogsGiveEstimatesWithinTheirStandardErrors) {
  for (const NamedScene& s : FullyIdentifiableScenes()) {
    const ReducedFriction truth = s.scene.friction.reduced();
    const Trajectory clean = SimulateOrFail(s.scene);
    const bool slow_spin = std::string(s.name) == "TiltingPush";
    for (int seed = 1; seed <= 10; ++seed) {
      const std::string what = std::string(s.name) + " seed " + std::to_string(seed);
      const EstimateResult r = EstimateEquationError(AddNoise(clean, VelocityNoise(seed)), {});
      EXPECT_TRUE(r.converged) << what << ": " << r.message;
      ReducedFriction checked = truth;
      if (slow_spin) {
        const ParameterEstimate& c = r.parameters[kC];
        EXPECT_FALSE(c.identifiable) << what;
        EXPECT_NE(c.reason.find("rotational friction impulse"), std::string::npos) << c.reason;
        EstimateResult ab = r;
        ab.parameters[kC] = r.parameters[kA];  // check a and b below, c was declined
        checked.c = truth.a;
        ExpectWithinStandardErrors(ab, checked, kMaxNoisyRelStdErr, kNoiseSigmas, what);
        continue;
      }
      ExpectWithinStandardErrors(r, truth, kMaxNoisyRelStdErr, kNoiseSigmas, what);
    }
  }
}

TEST(EquationError, NoisyIntervalsCoverTheTruthForMostSeeds) {
  // Observed: the intervals cover the truth for 50 of 50 seeds. This log is one sliding
  // phase of 45 steps, too few blocks for the block covariance (step_covariance.h), so the
  // interval is the white-noise one: consecutive impulses m (v' - v) share a velocity
  // sample, their noise largely cancels in the fit, and that interval is conservative
  // (tests/cheap_methods_test.cc checks the calibrated intervals of longer logs).
  const Scene scene = testing::FreeSlideWithSpin();
  const ReducedFriction truth = scene.friction.reduced();
  const double expected[3] = {truth.a, truth.b, truth.c};
  const Trajectory clean = SimulateOrFail(scene);
  constexpr int kSeeds = 50;
  int covered[3] = {0, 0, 0};
  double mean_error[3] = {0, 0, 0};
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const EstimateResult r = EstimateEquationError(AddNoise(clean, VelocityNoise(seed)), {});
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      ASSERT_TRUE(p.identifiable) << "seed " << seed << " " << ParameterName(i);
      covered[i] += p.ci95_lo <= expected[i] && expected[i] <= p.ci95_hi;
      mean_error[i] += (p.value / expected[i] - 1.0) / kSeeds;
    }
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(covered[i], kMinCoverage * kSeeds) << ParameterName(i);
    EXPECT_LE(std::abs(mean_error[i]), kMaxMeanRelError) << ParameterName(i);
  }
}

TEST(EquationError, NoisyPureTranslationStillCannotIdentifyC) {
  const Trajectory clean = SimulateOrFail(testing::PureTranslation());
  for (int seed = 1; seed <= 5; ++seed) {
    const EstimateResult r = EstimateEquationError(AddNoise(clean, VelocityNoise(seed)), {});
    EXPECT_TRUE(r.parameters[kA].identifiable);
    EXPECT_TRUE(r.parameters[kB].identifiable);
    EXPECT_FALSE(r.parameters[kC].identifiable) << r.parameters[kC].value;
  }
}

// A closed-form residual (automatic derivatives) of order-one log-parameters: the shared step
// and tolerance of fixtures/jacobian_check.h, at 200 random observations.
TEST(EquationError, AutoDiffJacobianMatchesCentralDifferences) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    StepObservation o;
    o.pn = 0.05 + 0.1 * (u(rng) + 1.0);
    o.ecp_velocity << u(rng), u(rng), 10.0 * u(rng);
    o.friction_impulse << 0.1 * u(rng), 0.1 * u(rng), 0.003 * u(rng);
    const double radius = 0.03 + 0.02 * (u(rng) + 1.0);
    std::unique_ptr<ceres::CostFunction> cost(EquationErrorResidual::Create(o, radius));
    double theta[3] = {std::log(0.3) + u(rng), u(rng), std::log(0.03) + u(rng)};
    const JacobianCheck check = CheckJacobian(*cost, {&theta[0], &theta[1], &theta[2]});
    EXPECT_LE(check.worst, kJacobianTolerance) << "trial " << trial << ": " << check;
  }
}

TEST(EquationError, ResidualMatchesTheModelAtTheTruth) {
  // Independent route: p_model = -a p_n (v_t, b^2 v_o, c^2 v_r) / |v|_D (model.md).
  StepObservation o;
  o.pn = 0.1;
  o.ecp_velocity << 0.4, -0.3, 5.0;
  const double a = 0.3, b = 1.4, c = 0.05, radius = 0.04;
  const double s = std::sqrt(0.16 + b * b * 0.09 + c * c * 25.0);
  o.friction_impulse << -a * o.pn * 0.4 / s, a * o.pn * b * b * 0.3 / s,
      -a * o.pn * c * c * 5.0 / s;
  const EquationErrorResidual f(o, radius);
  const double la = std::log(a), lb = std::log(b), lc = std::log(c);
  double r[3];
  ASSERT_TRUE(f(&la, &lb, &lc, r));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(r[k], 0.0, 1e-15);
  const double lb2 = std::log(2 * b);
  ASSERT_TRUE(f(&la, &lb2, &lc, r));
  EXPECT_GT(std::abs(r[1]), 1e-3);
}

TEST(EquationError, SliderAtRestIsTooLittleSliding) {
  const Trajectory log = SimulateOrFail(testing::BaseScene());  // at rest, no push
  const EstimateResult r = EstimateEquationError(log, {});
  EXPECT_EQ(r.status, TerminationStatus::kTooLittleExcitation);
  EXPECT_NE(r.message.find("too little sliding"), std::string::npos) << r.message;
}

TEST(EquationError, RejectsInvalidOptions) {
  IdentifyOptions options;
  options.equation_error.loss_scale_sigmas = 0;
  EXPECT_THROW(EstimateEquationError(SimulateOrFail(testing::FreeSlideWithSpin()), options),
               std::invalid_argument);
}

}  // namespace
}  // namespace slideid
