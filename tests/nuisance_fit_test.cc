// Sensor nuisances of the trajectory fit (--fit-force-bias, --fit-delay): a force offset and
// a delay injected by the sensor model (datasets/sensor_model.h) are recovered, a, b, c are
// recovered as on the same logs without them, an offset a log cannot determine is reported
// as such, and the segment cost's derivatives with respect to both are exact.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "datasets/sensor_model.h"
#include "estimator/internal/segment_cost.h"
#include "estimator/trajectory_fit.h"
#include "fixtures/jacobian_check.h"
#include "forward_model/simulator.h"
#include "io/scene_file.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

// The injected defects: a force offset of a few percent of the pushes (4 to 5.5 N) and a
// delay of two log intervals.
constexpr double kBiasX_n = 0.15;
constexpr double kBiasY_n = -0.1;
constexpr double kDelay_s = 0.02;
// Noiseless exact logs. Without a delay the fit reaches the truth to 1e-6 relative, as
// without nuisances (trajectory_fit_test.cc). A delay of the exact model is a whole number
// of rows, where the cost has a kink (the logged forces are held over each row): there the
// solve converges linearly and ends once the parameters settle within 2% of their standard
// errors, which a noiseless log makes tiny; measured within 3.4e-6 relative, 1.8e-6 N and
// 5.5e-8 s. The bounds: 1e-5 relative, 1e-5 N, 1e-7 s (1e-5 of a row), and inside the
// fit's own 95% intervals.
constexpr double kExactRelTol = 1e-6;
constexpr double kKinkRelTol = 1e-5;
constexpr double kKinkBiasTol_n = 1e-5;
constexpr double kExactDelayTol_s = 1e-7;

LoggedScene DefaultExperiment() {
  return LoadScene(std::string(SLIDEID_SOURCE_DIR) + "/datasets/scenes/default_push.ini");
}

/// The default experiment simulated at the log rate (10 ms, every step logged): the fit's
/// model (one step per row, the row's force held over it) is then exact. Poses with their
/// motion-capture noise; no force noise (the fit takes forces as exact).
LoggedScene ExactExperiment() {
  LoggedScene scene = DefaultExperiment();
  scene.dt_s = 0.01;
  scene.log.log_every = 1;
  scene.log.noise.force_relative = 0.0;
  scene.log.noise.force_n = 0.0;
  return scene;
}

const Trajectory& Simulated(const LoggedScene& scene) {
  static std::vector<std::pair<double, Trajectory>> cache;  // by dt: two scenes here
  for (const auto& [dt, t] : cache) {
    if (dt == scene.dt_s) return t;
  }
  const SimulationResult sim = Simulate(scene);
  EXPECT_TRUE(sim.summary.ok()) << sim.summary.message;
  cache.emplace_back(scene.dt_s, sim.trajectory);
  return cache.back().second;
}

LogSpec WithDefects(LogSpec spec, double bias_x, double bias_y, double delay) {
  spec.noise.force_bias_x_n = bias_x;
  spec.noise.force_bias_y_n = bias_y;
  spec.noise.force_delay_s = delay;
  return spec;
}

IdentifyOptions NuisanceOptions(bool bias, DelayFit delay) {
  IdentifyOptions o;
  o.trajectory.fit_force_bias = bias;
  o.trajectory.fit_delay = delay;
  return o;
}

const NuisanceEstimate& Nuisance(const EstimateResult& r, const std::string& name) {
  for (const NuisanceEstimate& n : r.nuisance) {
    if (n.name == name) return n;
  }
  ADD_FAILURE() << "no nuisance " << name;
  static const NuisanceEstimate none;
  return none;
}

std::array<double, 3> Truth(const Scene& scene) {
  const ReducedFriction t = scene.friction.reduced();
  return {t.a, t.b, t.c};
}

bool Covers(const NuisanceEstimate& n, double truth) {
  return n.identifiable && n.ci95_lo <= truth && truth <= n.ci95_hi;
}

TEST(NuisanceFit, NoiselessExactLogRecoversForceBiasDelayAndFriction) {
  LoggedScene scene = ExactExperiment();
  scene.log.noise = NoiseSpec{};
  const auto truth = Truth(scene);
  struct Case {
    double bias_x, bias_y, delay;
  };
  // Both together, a larger offset alone, a negative delay (the stream leads) alone. (Both
  // of the last two together, -0.3 N, 0.05 N and -30 ms, stopped at 5e-6 relative in c: the
  // solve ends once the parameters settle, and at the delay's kink (the truth, a whole
  // number of rows) they settle before the last digits.)
  for (const Case& c :
       {Case{kBiasX_n, kBiasY_n, kDelay_s}, Case{-0.3, 0.05, 0.0}, Case{0.0, 0.0, -0.03}}) {
    SCOPED_TRACE(::testing::Message()
                 << "bias " << c.bias_x << ", " << c.bias_y << " delay " << c.delay);
    const Trajectory log =
        MakeLog(Simulated(scene), WithDefects(scene.log, c.bias_x, c.bias_y, c.delay));
    const EstimateResult r = EstimateTrajectory(log, NuisanceOptions(true, DelayFit::kShared));
    ASSERT_TRUE(r.converged) << r.message;
    const double rel_tol = c.delay == 0.0 ? kExactRelTol : kKinkRelTol;
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      ASSERT_TRUE(p.identifiable) << ParameterName(i);
      EXPECT_NEAR(p.value / truth[i], 1.0, rel_tol) << ParameterName(i);
      // Without noise the interval is rounding-narrow and the solve stops once the
      // parameters settle (within rel_tol): the interval must reach the truth to that.
      const double slack = rel_tol * truth[i];
      EXPECT_TRUE(p.ci95_lo - slack <= truth[i] && truth[i] <= p.ci95_hi + slack)
          << ParameterName(i) << " " << p.ci95_lo << ".." << p.ci95_hi;
    }
    const std::pair<const char*, double> injected[3] = {
        {"force_bias_x_n", c.bias_x}, {"force_bias_y_n", c.bias_y}, {"delay_s", c.delay}};
    for (const auto& [name, value] : injected) {
      const NuisanceEstimate& n = Nuisance(r, name);
      const bool delay = std::string(name) == "delay_s";
      EXPECT_NEAR(n.value, value, delay ? kExactDelayTol_s : kKinkBiasTol_n) << name;
      EXPECT_TRUE(Covers(n, value)) << name << " " << n.ci95_lo << ".." << n.ci95_hi;
    }
    EXPECT_EQ(Nuisance(r, "delay_s").log, "");  // shared
  }
}

// Monte Carlo over noisy exact logs: each is fitted twice, as it is (no defects, no
// nuisances fitted) and with the defects injected (both nuisances fitted); the same noise
// stream, so the two fits see the same poses.
//
// Measured over these 20 logs: the nuisances' 95% intervals cover the injected values in
// 16, 18 and 18 of them; a, b, c's in 18, 20, 17 with the nuisances and 17, 19, 19 without.
// Both undercover a little. For the nuisances the delay is the cause: in the exact model
// it is a whole number of log intervals, where the cost has a kink (the logged forces are
// held over each row, estimator/internal/segment_cost.h) and the intervals take its one-sided
// curvature (without a delay fitted, the offsets' intervals covered in 27 and 26 of 30).
// The bar is 15 of 20, which a 95% interval fails with probability 3e-4 and an 80% one
// with 0.37.
TEST(NuisanceFit, NoisyExactLogsRecoverBiasAndDelayAndFrictionAsWithoutThem) {
  const LoggedScene scene = ExactExperiment();
  const auto truth = Truth(scene);
  constexpr int kLogs = 20;
  constexpr int kMinCovered = 15;
  // Three more parameters cost a, b, c some accuracy: their standard errors grow by 10 to
  // 25%, and the mean absolute errors measured 1.1, 0.95 and 1.9 times those without (c,
  // which the offset's moment about the CM correlates with, pays most).
  constexpr double kMaxErrorRatio = 2.0;
  std::array<int, 3> covered_nuisance{}, covered_with{}, covered_without{};
  std::array<double, 3> error_with{}, error_without{};
  for (int k = 0; k < kLogs; ++k) {
    LogSpec spec = scene.log;
    spec.noise.seed = 100 + k;
    const EstimateResult without = EstimateTrajectory(MakeLog(Simulated(scene), spec), {});
    const EstimateResult with = EstimateTrajectory(
        MakeLog(Simulated(scene), WithDefects(spec, kBiasX_n, kBiasY_n, kDelay_s)),
        NuisanceOptions(true, DelayFit::kShared));
    ASSERT_TRUE(with.converged) << k << ": " << with.message;
    covered_nuisance[0] += Covers(Nuisance(with, "force_bias_x_n"), kBiasX_n);
    covered_nuisance[1] += Covers(Nuisance(with, "force_bias_y_n"), kBiasY_n);
    covered_nuisance[2] += Covers(Nuisance(with, "delay_s"), kDelay_s);
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = with.parameters[i];
      const ParameterEstimate& q = without.parameters[i];
      ASSERT_TRUE(p.identifiable && q.identifiable) << ParameterName(i);
      covered_with[i] += p.ci95_lo <= truth[i] && truth[i] <= p.ci95_hi;
      covered_without[i] += q.ci95_lo <= truth[i] && truth[i] <= q.ci95_hi;
      error_with[i] += std::abs(p.value / truth[i] - 1) / kLogs;
      error_without[i] += std::abs(q.value / truth[i] - 1) / kLogs;
    }
  }
  const char* names[3] = {"force_bias_x_n", "force_bias_y_n", "delay_s"};
  for (int j = 0; j < 3; ++j) {
    EXPECT_GE(covered_nuisance[j], kMinCovered)
        << names[j] << " covered in " << covered_nuisance[j] << "/" << kLogs;
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(covered_with[i], kMinCovered) << ParameterName(i);
    EXPECT_GE(covered_with[i], covered_without[i] - 2) << ParameterName(i);
    EXPECT_LE(error_with[i], kMaxErrorRatio * error_without[i])
        << ParameterName(i) << ": mean relative error " << error_with[i] << " with the defects "
        << "and nuisances, " << error_without[i] << " without";
  }
}

// The default experiment as the bundled log was made: simulated at 0.1 ms, logged at
// 100 Hz with pose and force noise. A row's force is the one at its time, held over 10 ms
// in which the push varies, so the fit's model is not exact, and the delay that best
// explains a log without any delay is not zero: -3.0 and -2.3 ms for these two noise seeds
// (2024 is the bundled log's), with force offsets of a few hundredths of a newton.
// Injected defects add to these: a delay of whole rows (the phase within the row, which
// sets the inherent offset, stays the same) and the offsets are recovered above them.
//
// The intervals are not the yardstick here: with the model not exact they undercover
// (the nuisances take up part of the mismatch, which then no longer widens the
// cluster-robust intervals; over 20 logs a's covered the truth in 8), so the tolerances
// are physical and stated.
TEST(NuisanceFit, DefaultExperimentRecoversInjectedDefectsAboveItsInherentOffsets) {
  const LoggedScene scene = DefaultExperiment();
  const auto truth = Truth(scene);
  // A fifth of the 10 ms row: the row's force noise (2% + 0.05 N) drawn afresh for the
  // shifted stream moves the delay by up to 1.2 ms (20 logs).
  constexpr double kDelayTol_s = 0.002;
  // The force noise is 0.05 N + 2% per row; the offsets moved by up to 7 mN (20 logs).
  constexpr double kBiasTol_n = 0.02;
  // a, b, c within 5% of the truth: measured within 1.5, 1 and 3.6% with the defects and
  // nuisances (within 2.3% without either).
  constexpr double kMaxRelError = 0.05;
  const IdentifyOptions options = NuisanceOptions(true, DelayFit::kShared);
  for (const std::uint64_t seed : {2024u, 7u}) {
    SCOPED_TRACE(::testing::Message() << "noise seed " << seed);
    LogSpec spec = scene.log;
    spec.noise.seed = seed;
    const EstimateResult plain = EstimateTrajectory(MakeLog(Simulated(scene), spec), options);
    const EstimateResult defect = EstimateTrajectory(
        MakeLog(Simulated(scene), WithDefects(spec, kBiasX_n, kBiasY_n, kDelay_s)), options);
    ASSERT_TRUE(plain.converged && defect.converged) << plain.message << "\n" << defect.message;
    const NuisanceEstimate& inherent = Nuisance(plain, "delay_s");
    EXPECT_LT(inherent.value, -0.001) << "the discretisation's inherent delay";
    EXPECT_GT(inherent.value, -0.005);
    const std::pair<const char*, double> injected[3] = {
        {"force_bias_x_n", kBiasX_n}, {"force_bias_y_n", kBiasY_n}, {"delay_s", kDelay_s}};
    for (const auto& [name, value] : injected) {
      const NuisanceEstimate& p = Nuisance(plain, name);
      const NuisanceEstimate& d = Nuisance(defect, name);
      ASSERT_TRUE(p.identifiable && d.identifiable) << name;
      EXPECT_NEAR(d.value - p.value, value,
                  std::string(name) == "delay_s" ? kDelayTol_s : kBiasTol_n)
          << name << ": " << d.value << " against " << p.value << " without the defects";
    }
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(defect.parameters[i].identifiable) << ParameterName(i);
      EXPECT_NEAR(defect.parameters[i].value / truth[i], 1.0, kMaxRelError) << ParameterName(i);
    }
  }
}

TEST(NuisanceFit, PerLogDelayIsReportedForItsLog) {
  LoggedScene scene = ExactExperiment();
  scene.log.noise = NoiseSpec{};
  Trajectory log = MakeLog(Simulated(scene), WithDefects(scene.log, 0.0, 0.0, 0.03));
  log.source = "late.csv";
  const EstimateResult r = EstimateTrajectory(log, NuisanceOptions(false, DelayFit::kPerLog));
  ASSERT_EQ(r.nuisance.size(), 1u);
  EXPECT_EQ(r.nuisance[0].log, "late.csv");
  EXPECT_NEAR(r.nuisance[0].value, 0.03, kExactDelayTol_s);
}

// A log pushed along one line, without rest and without rotation: friction and a force
// offset along the motion both act as constant forces against it, so the log cannot tell
// them apart. The offset is reported not identifiable, with the reason, as c is; it is held
// at zero, so a is what a fit without the offset gives.
TEST(NuisanceFit, ForceBiasAlongTheOnlyDirectionOfMotionIsReportedNotIdentifiable) {
  const Scene scene = testing::AlongOneAxis();
  LogSpec spec;
  spec.motion = LogMotion::kPoses;
  spec.noise.pose_m = 3e-4;
  spec.noise.angle_rad = 3e-3;
  spec.noise.seed = 5;
  const Trajectory log = MakeLog(testing::SimulateOrFail(scene), spec);
  IdentifyOptions options = NuisanceOptions(true, DelayFit::kNone);
  options.trajectory.segment_steps = 20;
  const EstimateResult r = EstimateTrajectory(log, options);
  const NuisanceEstimate& along = Nuisance(r, "force_bias_x_n");
  EXPECT_FALSE(along.identifiable);
  EXPECT_EQ(along.verdict, Verdict::kNotIdentifiable);
  EXPECT_TRUE(std::isnan(along.value));
  EXPECT_EQ(along.held_at, 0.0);
  // Confounded with a along the only direction of motion: held by the collinearity rule, or
  // by its standard error, depending on how close to exact the confounding falls.
  EXPECT_TRUE(along.reason.find("does not constrain it") != std::string::npos ||
              along.reason.find("only a combination") != std::string::npos)
      << along.reason;
  EXPECT_FALSE(r.parameters[kC].identifiable);  // no rotation
  const ParameterEstimate& a = r.parameters[kA];
  ASSERT_TRUE(a.identifiable);
  IdentifyOptions plain;
  plain.trajectory.segment_steps = 20;
  const ParameterEstimate without = EstimateTrajectory(log, plain).parameters[kA];
  EXPECT_NEAR(a.value, without.value, 0.5 * a.stderr_value);
  EXPECT_LE(a.ci95_lo, Truth(scene)[kA]);
  EXPECT_GE(a.ci95_hi, Truth(scene)[kA]);
}

// The segment cost's derivatives with respect to the force offset and the delay blocks (and
// the others, with them present) against central differences, on a log with a push point
// below the CM (the offset's moment about the CM has tilting parts) and a stick-slip push.
// Through the step solver: kSolvedJacobianTolerance (fixtures/jacobian_check.h).
TEST(NuisanceFit, SegmentCostJacobianWithBiasAndDelayMatchesCentralDifferences) {
  // The delay's step: a tenth of the shared one, the delay being hundredths of a second, not
  // of order one; the perturbed delays stay far from the wrench's kinks at whole log
  // intervals (the nearest is 3.7 ms away).
  constexpr double kDelayFdStep_s = 1e-7;
  // The nuisances move the trajectory: some derivative of each is above this, so the check
  // compares derivatives, not zeros.
  constexpr double kMovesTheTrajectory = 1e-6;
  const Trajectory log = testing::SimulateOrFail(testing::TiltingPush());
  for (bool use_pose : {true, false}) {
    SCOPED_TRACE(use_pose ? "poses" : "velocities");
    std::unique_ptr<ceres::CostFunction> cost(
        NewSegmentCost(log, 10, 30, 2, use_pose, SegmentNuisances{true, true}));
    ASSERT_EQ(cost->parameter_block_sizes().size(), 6u);
    double state[6] = {log.samples[10].state.x,     log.samples[10].state.y,
                       log.samples[10].state.theta, log.samples[10].state.vx * 1.01,
                       log.samples[10].state.vy,    log.samples[10].state.wz + 0.1};
    double la = std::log(0.31), lb = std::log(1.1), lc = std::log(0.028);
    // The delay away from whole log intervals (10 ms), where the wrench has kinks.
    double offset_n[2] = {0.2, -0.15}, delay_s = 0.0137;
    const double h = testing::kJacobianFdStep;
    const testing::JacobianCheck check = testing::CheckJacobian(
        *cost, {state, &la, &lb, &lc, offset_n, &delay_s}, {h, h, h, h, h, kDelayFdStep_s});
    ASSERT_TRUE(check.evaluated) << check;
    EXPECT_LE(check.worst, testing::kSolvedJacobianTolerance) << check;
    EXPECT_GT(check.largest_by_block[4], kMovesTheTrajectory) << "force offset";
    EXPECT_GT(check.largest_by_block[5], kMovesTheTrajectory) << "delay";
  }
}

}  // namespace
}  // namespace slideid
