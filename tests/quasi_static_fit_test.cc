// The quasi-static estimator (estimator/quasi_static_fit.h): pairs made by the forward model
// recover a, b, c; the result does not depend on the frame the pairs are written in (where
// the model says it must not); moments must be about the CM; what pairs cannot identify is
// said and held; bad pairs are named; intervals cover the truth.

#include "estimator/quasi_static_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "datasets/quasi_static_synth.h"
#include "forward_model/constants.h"
#include "io/zhou_tripod_import.h"
#include "io/zhou_tripod_synth.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using testing::ExpectRecovers;

// Exact pairs fit exactly up to the solver's convergence and rounding (fixtures/tolerances.h).
using testing::kExactRelTol;
// Pairs from simulated pushes average the wrench and take one twist over a push of ~10 mm
// and up to 0.12 rad, while the body twist changes along it (the contact point and the
// finger's direction turn with the slider); the mean wrench then sits slightly inside the
// limit surface and the mean normal slightly off the mean twist. Measured: 0.03 to 0.3%.
constexpr double kQuasiStaticModelRelTol = 0.01;
// The same pairs in another frame: an isotropic model (b = 1) is exactly invariant, but
// the fitted b is 1 only up to the model error above, so a, b, c move by a fraction of it.
constexpr double kRotatedSimRelTol = 0.003;

const ReducedFriction kIsotropic{0.3, 1.0, 0.04};
const ReducedFriction kAnisotropic{0.3, 1.3, 0.04};

/// Simulated pushes on the tripod block, made once per friction and seed.
const std::vector<SimulatedPush>& Pushes(const ReducedFriction& f, std::uint64_t seed,
                                         bool aim_at_cm = false) {
  static std::map<std::tuple<double, double, double, std::uint64_t, bool>,
                  std::vector<SimulatedPush>>
      cache;
  auto& entry = cache[{f.a, f.b, f.c, seed, aim_at_cm}];
  if (entry.empty()) {
    QuasiStaticSynthSpec spec = TripodSynthSpec(f, 16, seed);
    spec.aim_at_cm = aim_at_cm;
    entry = SimulateSpringPushes(spec);
  }
  return entry;
}

WrenchTwistData SimulatedPairs(const ReducedFriction& f, std::uint64_t seed,
                               PairFrame frame = PairFrame::kBody, bool aim_at_cm = false) {
  QuasiStaticSynthSpec spec = TripodSynthSpec(f, 16, seed);
  spec.aim_at_cm = aim_at_cm;
  return PairsFromPushes(spec, Pushes(f, seed, aim_at_cm), frame);
}

EstimateResult Fit(const WrenchTwistData& data, const std::vector<WrenchTwistPair>& pairs) {
  return EstimateQuasiStatic(pairs, QuasiStaticOptionsFor(data, IdentifyOptions{}));
}
EstimateResult Fit(const WrenchTwistData& data) { return Fit(data, data.Pairs()); }

double Value(const EstimateResult& r, int i) { return r.parameters[i].value; }

/// Twists spread over all directions (seeded), L-scaled spin comparable to the speed.
std::vector<Eigen::Vector3d> RandomTwists(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Vector3d> twists;
  for (int i = 0; i < n; ++i) twists.emplace_back(0.002 * g(rng), 0.002 * g(rng), 0.05 * g(rng));
  return twists;
}

SliderProperties TripodSlider() {
  SliderProperties s;
  s.mass_kg = kTripodMass_kg;
  s.inertia_kgm2 = kTripodInertiaEstimate_kgm2;
  return s;
}

/// `data` with independent Gaussian noise: relative on each force and moment component
/// (moment relative to |f| times 5 cm) and on each twist component (spin relative to the
/// speed over 5 cm).
WrenchTwistData Noisy(WrenchTwistData data, double relative, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, relative);
  for (WrenchTwistRow& row : data.rows) {
    WrenchTwistPair& p = row.pair;
    const double f = std::hypot(p.fx, p.fy), v = std::hypot(p.vx, p.vy);
    p.fx += f * g(rng);
    p.fy += f * g(rng);
    p.mz += 0.05 * f * g(rng);
    p.vx += v * g(rng);
    p.vy += v * g(rng);
    p.wz += v / 0.05 * g(rng);
  }
  return data;
}

TEST(QuasiStaticFit, ExactPairsRecoverABC) {
  for (const ReducedFriction& truth :
       {kIsotropic, kAnisotropic, ReducedFriction{0.6, 0.7, 0.015}}) {
    const WrenchTwistData data = ExactQuasiStaticPairs(RandomTwists(12, 3), TripodSlider(), truth);
    const EstimateResult r = Fit(data);
    EXPECT_EQ(r.method, EstimatorMethod::kQuasiStatic);
    EXPECT_EQ(r.steps_used, 12);
    ExpectRecovers(r, truth, "exact pairs");
  }
}

TEST(QuasiStaticFit, PairsFromSlowSimulatedPushesRecoverABC) {
  const WrenchTwistData data = SimulatedPairs(kIsotropic, 11);
  for (const SimulatedPush& p : Pushes(kIsotropic, 11)) {
    EXPECT_LT(p.max_speed_mps, 0.005) << "not quasi-static";
    EXPECT_GT(p.slide_steps, 1000);
  }
  ExpectRecovers(Fit(data), kIsotropic, "simulated pushes", kQuasiStaticModelRelTol);
}

TEST(QuasiStaticFit, WorldFramePairsRecoverAWorldFixedAnisotropy) {
  // The simulator's b is along the world axes (model.md): pairs written in the world frame
  // see it; the block turns between pushes, so body-frame pairs would not.
  const WrenchTwistData data = SimulatedPairs(kAnisotropic, 12, PairFrame::kWorld);
  ExpectRecovers(Fit(data), kAnisotropic, "world-frame pairs, b = 1.3", kQuasiStaticModelRelTol);
}

TEST(QuasiStaticFit, IsotropicExactPairsGiveTheSameABCInAnyFrame) {
  const WrenchTwistData data =
      ExactQuasiStaticPairs(RandomTwists(12, 5), TripodSlider(), kIsotropic);
  const EstimateResult base = Fit(data);
  for (double angle : {0.3, 1.1, 2.5, -2.0}) {
    std::vector<WrenchTwistPair> turned;
    for (const WrenchTwistPair& p : data.Pairs()) turned.push_back(InRotatedFrame(p, angle));
    const EstimateResult r = Fit(data, turned);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(Value(r, i) / Value(base, i), 1.0, kExactRelTol)
          << ParameterName(i) << " at " << angle << " rad";
    }
  }
}

TEST(QuasiStaticFit, SimulatedPairsGiveNearlyTheSameABCInAnotherFrame) {
  const WrenchTwistData data = SimulatedPairs(kIsotropic, 11);
  const EstimateResult base = Fit(data);
  std::vector<WrenchTwistPair> turned, half_turned;
  for (const WrenchTwistPair& p : data.Pairs()) {
    turned.push_back(InRotatedFrame(p, 0.7));
    half_turned.push_back(InRotatedFrame(p, kPi));
  }
  const EstimateResult r = Fit(data, turned);
  const EstimateResult half = Fit(data, half_turned);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(Value(r, i) / Value(base, i), 1.0, kRotatedSimRelTol) << ParameterName(i);
    // Half a turn maps the ellipsoid onto itself for any b: the same problem.
    EXPECT_NEAR(Value(half, i) / Value(base, i), 1.0, kExactRelTol) << ParameterName(i);
  }
}

TEST(QuasiStaticFit, AQuarterTurnSwapsTheAxesAsTheModelSays) {
  // Turning the frame by 90 deg swaps t and o: e_t' = e_o, so a' = a b, b' = 1 / b and
  // c' = e_r / e_o = c / b. a c = mu e_r does not change.
  const WrenchTwistData data = SimulatedPairs(kAnisotropic, 12, PairFrame::kWorld);
  const EstimateResult base = Fit(data);
  std::vector<WrenchTwistPair> turned;
  for (const WrenchTwistPair& p : data.Pairs()) turned.push_back(InRotatedFrame(p, kPi / 2));
  const EstimateResult r = Fit(data, turned);
  const double a = Value(base, kA), b = Value(base, kB), c = Value(base, kC);
  EXPECT_NEAR(Value(r, kA) / (a * b), 1.0, kRotatedSimRelTol);
  EXPECT_NEAR(Value(r, kB) * b, 1.0, kRotatedSimRelTol);
  EXPECT_NEAR(Value(r, kC) / (c / b), 1.0, kRotatedSimRelTol);
}

TEST(QuasiStaticFit, MomentsMustBeAboutTheCmAndAboutPointBringsThemThere) {
  const WrenchTwistData data = SimulatedPairs(kIsotropic, 11);
  const EstimateResult base = Fit(data);
  // The same pushes written about the block's corner (the Vicon body origin), as a writer
  // that forgot to move them would: the fit is wrong.
  const Eigen::Vector2d corner = TripodBlockVertices()[0];
  std::vector<WrenchTwistPair> at_corner, back;
  for (const WrenchTwistPair& p : data.Pairs()) {
    at_corner.push_back(AboutPoint(p, corner));
    back.push_back(AboutPoint(at_corner.back(), -corner));
  }
  const EstimateResult wrong = Fit(data, at_corner);
  EXPECT_GT(std::abs(Value(wrong, kC) / kIsotropic.c - 1.0), 0.2)
      << "c = " << Value(wrong, kC) << ": moments about the corner should spoil c";
  // Moved back to the CM by the writer's AboutPoint: the original fit.
  const EstimateResult r = Fit(data, back);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(Value(r, i) / Value(base, i), 1.0, kExactRelTol) << ParameterName(i);
  }
}

TEST(QuasiStaticFit, PureTranslationCannotIdentifyC) {
  // Every push aimed at the CM: no moment, no spin.
  const WrenchTwistData data = SimulatedPairs(kIsotropic, 13, PairFrame::kBody, true);
  for (const WrenchTwistRow& row : data.rows) {
    EXPECT_LT(std::abs(row.dtheta_rad), 1e-6) << "push " << row.push << " turned";
  }
  const EstimateResult r = Fit(data);
  EXPECT_FALSE(r.parameters[kC].identifiable);
  EXPECT_TRUE(std::isnan(r.parameters[kC].value));
  EXPECT_TRUE(std::isfinite(r.parameters[kC].held_at));
  EXPECT_FALSE(r.parameters[kC].reason.empty());
  ASSERT_TRUE(r.parameters[kA].identifiable) << r.parameters[kA].note;
  ASSERT_TRUE(r.parameters[kB].identifiable) << r.parameters[kB].note;
  EXPECT_NEAR(Value(r, kA) / kIsotropic.a, 1.0, kQuasiStaticModelRelTol);
  EXPECT_NEAR(Value(r, kB), 1.0, kQuasiStaticModelRelTol);
}

TEST(QuasiStaticFit, TwistsThatNeverLeaveOneAxisCannotIdentifyB) {
  // Translation along x only, with spin: f_y = 0 and v_y = 0 in every pair. (With 1% or 3%
  // noise on every component b is still not identifiable, by its standard error: 0.57.)
  std::mt19937_64 rng(17);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Vector3d> twists;
  for (int i = 0; i < 20; ++i) twists.emplace_back(0.002 * g(rng), 0.0, 0.05 * g(rng));
  const WrenchTwistData data = ExactQuasiStaticPairs(twists, TripodSlider(), kAnisotropic);
  const EstimateResult r = Fit(data);
  EXPECT_FALSE(r.parameters[kB].identifiable);
  EXPECT_FALSE(r.parameters[kB].reason.empty());
  ASSERT_TRUE(r.parameters[kA].identifiable) << r.parameters[kA].note;
  ASSERT_TRUE(r.parameters[kC].identifiable) << r.parameters[kC].note;
  EXPECT_NEAR(Value(r, kA) / kAnisotropic.a, 1.0, kExactRelTol);
  EXPECT_NEAR(Value(r, kC) / kAnisotropic.c, 1.0, kExactRelTol);
}

TEST(QuasiStaticFit, IntervalsCoverTheTruthOnNoisyPairs) {
  // 100 data sets of 30 exact pairs with 3% noise on every component.
  constexpr int kRuns = 100;
  // A 95% interval covers in 95 of 100 runs on average; 85 is 3.2 binomial standard
  // deviations below: a failure means the intervals are too narrow, not bad luck.
  constexpr int kMinCovered = 85;
  std::array<int, 3> covered{};
  const double truth[3] = {kAnisotropic.a, kAnisotropic.b, kAnisotropic.c};
  for (int run = 0; run < kRuns; ++run) {
    const WrenchTwistData data =
        Noisy(ExactQuasiStaticPairs(RandomTwists(30, 100 + run), TripodSlider(), kAnisotropic),
              0.03, 500 + run);
    const EstimateResult r = Fit(data);
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      ASSERT_TRUE(p.identifiable) << "run " << run << " " << ParameterName(i) << ": " << p.note;
      covered[i] += p.ci95_lo <= truth[i] && truth[i] <= p.ci95_hi;
    }
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(covered[i], kMinCovered) << ParameterName(i) << " covered in " << covered[i];
  }
}

TEST(QuasiStaticFit, BadPairsAreNamed) {
  const WrenchTwistData data =
      ExactQuasiStaticPairs(RandomTwists(5, 1), TripodSlider(), kIsotropic);
  const QuasiStaticFitOptions options = QuasiStaticOptionsFor(data, IdentifyOptions{});
  auto expect_error = [&](std::vector<WrenchTwistPair> pairs, const std::string& words) {
    try {
      EstimateQuasiStatic(pairs, options);
      ADD_FAILURE() << "no error for " << words;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  std::vector<WrenchTwistPair> pairs = data.Pairs();
  pairs[1].vx = pairs[1].vy = pairs[1].wz = 0.0;
  expect_error(pairs, "pair 2: the twist (vx, vy, wz) is zero");
  pairs = data.Pairs();
  pairs[3].fx = pairs[3].fy = pairs[3].mz = 0.0;
  expect_error(pairs, "pair 4: the applied wrench (fx, fy, mz) is zero");
  pairs = data.Pairs();
  pairs[0].fz = 100.0;
  expect_error(pairs, "pair 1: the normal force");
  pairs = data.Pairs();
  pairs[2].mz = std::nan("");
  expect_error(pairs, "pair 3: not finite");
  expect_error({data.Pairs()[0], data.Pairs()[1]}, "too few");
  QuasiStaticFitOptions no_weight = options;
  no_weight.weight_n = 0.0;
  EXPECT_THROW(EstimateQuasiStatic(data.Pairs(), no_weight), std::invalid_argument);
}

TEST(QuasiStaticFit, ResidualsNameTheirChannelsAndVanishOnExactPairs) {
  const WrenchTwistData data =
      ExactQuasiStaticPairs(RandomTwists(8, 2), TripodSlider(), kIsotropic);
  const EstimateResult r = Fit(data);
  EXPECT_EQ(r.residual_names[0], "log_wrench_ratio");
  EXPECT_EQ(r.residual_names[1], "twist_angle_rad");
  ASSERT_EQ(r.residuals.size(), 8u);
  for (const StepResidual& s : r.residuals) {
    EXPECT_LT(std::abs(s.value[0]), kExactRelTol);
    EXPECT_LT(std::abs(s.value[1]), kExactRelTol);
  }
}

}  // namespace
}  // namespace slideid
