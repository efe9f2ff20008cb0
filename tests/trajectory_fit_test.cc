// The trajectory estimator: generate with the simulator, identify, compare with the truth.

#include "estimator/trajectory_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numeric>
#include <random>

#include "datasets/noise.h"
#include "datasets/sensor_model.h"
#include "estimator/closed_form.h"
#include "estimator/internal/gauss_newton_step.h"
#include "estimator/internal/segment_cost.h"
#include "estimator/internal/trajectory_problem.h"
#include "fixtures/jacobian_check.h"
#include "io/scene_file.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using testing::SimulateOrFail;

// Noiseless logs: the fit must reach the truth to kExactRelTol (fixtures/tolerances.h).
using testing::kExactRelTol;

std::array<double, 3> Truth(const Scene& scene) {
  const ReducedFriction r = scene.friction.reduced();
  return {r.a, r.b, r.c};
}

IdentifyOptions Options(int segment = 50) {
  IdentifyOptions o;
  o.trajectory.segment_steps = segment;
  return o;
}

void ExpectRecovers(const Scene& scene, const Trajectory& log, const IdentifyOptions& options) {
  const EstimateResult r = EstimateTrajectory(log, options);
  ASSERT_TRUE(r.converged) << r.message;
  const auto truth = Truth(scene);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(r.parameters[i].identifiable) << ParameterName(i) << ": " << r.parameters[i].note;
    EXPECT_NEAR(r.parameters[i].value / truth[i], 1.0, kExactRelTol) << ParameterName(i);
  }
}

TEST(TrajectoryFit, RecoversEveryParameterFromNoiselessLogsOfEveryScene) {
  for (const Scene& scene : {testing::FreeSlideWithSpin(), testing::PushedSlider(),
                             testing::TiltingPush(), testing::Anisotropic()}) {
    SCOPED_TRACE(scene.pushes.empty() ? "free" : "pushed");
    ExpectRecovers(scene, SimulateOrFail(scene), Options(20));
  }
}

TEST(TrajectoryFit, LeavingOutTheResidualsChangesNothingElse) {
  const Trajectory log = SimulateOrFail(testing::PushedSlider());
  IdentifyOptions options = Options(20);
  const EstimateResult kept = EstimateTrajectory(log, options);
  options.keep_residuals = false;
  const EstimateResult left_out = EstimateTrajectory(log, options);
  ASSERT_TRUE(kept.converged) << kept.message;
  EXPECT_FALSE(kept.residuals.empty());
  EXPECT_TRUE(left_out.residuals.empty());
  EXPECT_EQ(left_out.residual_names, kept.residual_names);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(left_out.parameters[i].value, kept.parameters[i].value) << ParameterName(i);
    EXPECT_EQ(left_out.parameters[i].stderr_value, kept.parameters[i].stderr_value);
  }
  EXPECT_EQ(left_out.final_cost, kept.final_cost);
}

TEST(TrajectoryFit, RecoversFromAVelocityOnlyLog) {
  const Scene scene = testing::TiltingPush();
  Trajectory log = SimulateOrFail(scene);
  log.measured.pose = false;
  ExpectRecovers(scene, log, Options(25));
}

// A short pushed log is cut into kMinRobustSegments segments for a cluster-robust
// interval; a free slide keeps segments of kMinAutoSegment_s (TrajectorySegmentSteps).
TEST(TrajectoryFit, AShortFreeSlideIsNotCutIntoShortSegments) {
  const TrajectoryOptions defaults;
  EXPECT_EQ(TrajectorySegmentSteps(100, 0.01, defaults, /*free_slide=*/false), 19);
  EXPECT_EQ(TrajectorySegmentSteps(100, 0.01, defaults, /*free_slide=*/true), 35);
  EXPECT_EQ(TrajectorySegmentSteps(4000, 0.01, defaults, /*free_slide=*/true),
            TrajectorySegmentSteps(4000, 0.01, defaults, /*free_slide=*/false));
  Trajectory log = SimulateOrFail(testing::FreeSlideWithSpin());
  EXPECT_TRUE(IsFreeSlide(log));
  log.samples[3].applied.fx = 0.1;
  EXPECT_FALSE(IsFreeSlide(log));
}

TEST(TrajectoryFit, RecoversWithSubstepsFromACoarselySampledLog) {
  // Simulated at 2 ms, logged every 5th step: 10 ms rows; 5 substeps reproduce the model.
  Scene scene = testing::FreeSlideWithSpin();
  scene.dt_s = 0.002;
  const Trajectory fine = SimulateOrFail(scene);
  Trajectory coarse = fine;
  coarse.samples.clear();
  for (size_t i = 0; i < fine.samples.size(); i += 5) coarse.samples.push_back(fine.samples[i]);
  IdentifyOptions options = Options(10);
  options.trajectory.substeps = 5;
  ExpectRecovers(scene, coarse, options);
}

/// `log` with rows [first, first + count) removed, as a motion-capture gap leaves it; with
/// `mark`, the row after the hole starts a run (forward_model/trajectory.h).
Trajectory WithHole(const Trajectory& log, int first, int count, bool mark) {
  Trajectory out = log;
  out.samples.erase(out.samples.begin() + first, out.samples.begin() + first + count);
  out.steps.clear();  // the simulated steps would no longer match the rows
  if (mark) out.samples[first].mode = SampleMode::kStart;
  out.measured.mode = mark;
  return out;
}

// A hole in a noiseless poses-only log. Marked, no segment and no step spans it and the
// fit is exact; unmarked, the fit takes one step across it with the force of the row before
// and lands away from the truth: the mark is what keeps the answer right.
TEST(TrajectoryFit, AMarkedGapEndsTheSegmentsAndTheFitStaysExact) {
  const Scene scene = testing::PushedSlider();
  const Trajectory clean = testing::PosesOnly(SimulateOrFail(scene), "gap");
  const int rows = static_cast<int>(clean.samples.size());
  ASSERT_GT(rows, 90);
  const Trajectory marked = WithHole(clean, 40, 15, true);
  ASSERT_EQ(Runs(marked).size(), 2u);
  ExpectRecovers(scene, marked, Options(20));
  TrajectoryProblem problem({&marked}, Options(20));
  for (const TrajectorySegment& seg : problem.segments()) {
    EXPECT_TRUE(seg.last_row < 40 || seg.first_row >= 40) << seg.first_row;
  }
  const Trajectory unmarked = WithHole(clean, 40, 15, false);
  const EstimateResult across = EstimateTrajectory(unmarked, Options(20));
  const auto truth = Truth(scene);
  double worst = 0;
  for (int i = 0; i < 3; ++i) {
    worst = std::max(worst, std::abs(across.parameters[i].value / truth[i] - 1));
  }
  EXPECT_GT(worst, 100 * kExactRelTol);
}

// The cheap methods leave out the step across the hole (and, poses only, the step after it,
// whose start velocity is unknown) and say so.
TEST(TrajectoryFit, TheClosedFormSeedLeavesOutTheStepAcrossAGap) {
  const Scene scene = testing::PushedSlider();
  const Trajectory clean = SimulateOrFail(scene);
  const EstimateResult r = EstimateClosedForm(WithHole(clean, 40, 15, true), Options());
  bool across = false;
  for (const auto& [reason, count] : r.steps_excluded) {
    across = across || (reason == "across a gap in the log" && count == 1);
  }
  EXPECT_TRUE(across);
}

TEST(TrajectoryFit, PureTranslationReportsSpinParameterNotIdentifiableAndRecoversA) {
  const Scene scene = testing::PureTranslation();
  const EstimateResult r = EstimateTrajectory(SimulateOrFail(scene), Options(20));
  EXPECT_FALSE(r.parameters[kC].identifiable);
  EXPECT_TRUE(std::isnan(r.parameters[kC].value));
  ASSERT_TRUE(r.parameters[kA].identifiable);
  EXPECT_NEAR(r.parameters[kA].value / Truth(scene)[0], 1.0, kExactRelTol);
}

TEST(TrajectoryFit, MotionAlongOneAxisReportsBAndCNotIdentifiable) {
  const Scene scene = testing::AlongOneAxis();
  const EstimateResult r = EstimateTrajectory(SimulateOrFail(scene), Options(20));
  EXPECT_FALSE(r.parameters[kB].identifiable);
  EXPECT_FALSE(r.parameters[kC].identifiable);
  ASSERT_TRUE(r.parameters[kA].identifiable);
  EXPECT_NEAR(r.parameters[kA].value / Truth(scene)[0], 1.0, kExactRelTol);
}

// Typical motion capture: 0.3 mm on position, 3 mrad on yaw; poses only.
NoiseSpec MotionCapture(std::uint64_t seed) {
  NoiseSpec n;
  n.pose_m = 3e-4;
  n.angle_rad = 3e-3;
  n.seed = seed;
  return n;
}

Trajectory NoisyPosesOnly(const Trajectory& clean, std::uint64_t seed) {
  Trajectory noisy = AddNoise(clean, MotionCapture(seed));
  noisy.measured.velocity = false;
  return noisy;
}

TEST(TrajectoryFit, IsMoreAccurateThanTheClosedFormSeedOnNoisyLogs) {
  const Scene scene = testing::FreeSlideWithSpin();
  const Trajectory clean = SimulateOrFail(scene);
  const auto truth = Truth(scene);
  double err_fit = 0, err_seed = 0;
  constexpr int kLogs = 20;
  for (int k = 0; k < kLogs; ++k) {
    const Trajectory noisy = NoisyPosesOnly(clean, 1000 + k);
    const EstimateResult fit = EstimateTrajectory(noisy, Options(20));
    EstimateResult seed;
    try {
      seed = EstimateClosedForm(noisy, Options());
    } catch (const std::exception&) {
      err_seed += 1.0;  // the closed form could not even give an answer
      continue;
    }
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(fit.parameters[i].identifiable);
      err_fit += std::abs(fit.parameters[i].value / truth[i] - 1);
      err_seed +=
          seed.parameters[i].identifiable ? std::abs(seed.parameters[i].value / truth[i] - 1) : 1.0;
    }
  }
  EXPECT_LT(err_fit, 0.5 * err_seed) << "mean relative error: fit " << err_fit / (3 * kLogs)
                                     << ", closed form " << err_seed / (3 * kLogs);
}

TEST(TrajectoryFit, NinetyFivePercentIntervalsCoverTheTruthInAtLeastNinetyPercentOfLogs) {
  const Scene scene = testing::FreeSlideWithSpin();
  const Trajectory clean = SimulateOrFail(scene);
  const auto truth = Truth(scene);
  constexpr int kLogs = 100;
  std::array<int, 3> covered{};
  for (int k = 0; k < kLogs; ++k) {
    const EstimateResult r = EstimateTrajectory(NoisyPosesOnly(clean, 5000 + k), Options(20));
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(r.parameters[i].identifiable)
          << k << " " << i << ": " << r.parameters[i].reason << " | " << r.parameters[i].note;
      if (r.parameters[i].ci95_lo <= truth[i] && truth[i] <= r.parameters[i].ci95_hi) {
        ++covered[i];
      }
    }
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(covered[i], 90) << ParameterName(i) << " covered in " << covered[i] << "/100";
  }
}

// The segment cost simulates through the step solver: kSolvedJacobianTolerance, with the
// shared step (fixtures/jacobian_check.h).
TEST(TrajectoryFit, SegmentCostJacobianMatchesCentralDifferences) {
  const Scene scene = testing::TiltingPush();
  const Trajectory log = SimulateOrFail(scene);
  for (bool use_pose : {true, false}) {
    SCOPED_TRACE(use_pose ? "poses" : "velocities");
    std::unique_ptr<ceres::CostFunction> cost(NewSegmentCost(log, 10, 30, 2, use_pose));
    double state[6] = {log.samples[10].state.x,     log.samples[10].state.y,
                       log.samples[10].state.theta, log.samples[10].state.vx * 1.01,
                       log.samples[10].state.vy,    log.samples[10].state.wz + 0.1};
    double la = std::log(0.31), lb = std::log(1.1), lc = std::log(0.028);
    const testing::JacobianCheck check = testing::CheckJacobian(*cost, {state, &la, &lb, &lc});
    EXPECT_LE(check.worst, testing::kSolvedJacobianTolerance) << check;
  }
}

TEST(TrajectoryFit, SegmentCostReusesTheResidualsOfThePointItJustSimulatedAndNoOther) {
  const Trajectory log = SimulateOrFail(testing::TiltingPush());
  std::unique_ptr<ceres::CostFunction> cost(NewSegmentCost(log, 10, 40, 1, true));
  std::unique_ptr<ceres::CostFunction> fresh(NewSegmentCost(log, 10, 40, 1, true));
  const TrajectorySample& s = log.samples[10];
  double state[6] = {s.state.x, s.state.y, s.state.theta, s.state.vx, s.state.vy, s.state.wz};
  double la = std::log(0.31), lb = std::log(1.1), lc = std::log(0.028);
  double* blocks[] = {state, &la, &lb, &lc};
  const int n = cost->num_residuals();
  std::vector<double> at_p(n), at_q(n), again(n), reference(n), with_jacobian(n), j0(6 * n), ja(n),
      jb(n), jc(n);
  double* jac[] = {j0.data(), ja.data(), jb.data(), jc.data()};
  ASSERT_TRUE(cost->Evaluate(blocks, at_p.data(), nullptr));
  lc = std::log(0.029);  // another point: simulated, not the last residuals
  ASSERT_TRUE(cost->Evaluate(blocks, at_q.data(), nullptr));
  ASSERT_TRUE(fresh->Evaluate(blocks, reference.data(), nullptr));
  // (A fresh cost starts its step solver cold: the same residuals up to rounding.)
  for (int i = 0; i < n; ++i) EXPECT_NEAR(at_q[i], reference[i], 1e-12) << i;
  EXPECT_NE(at_q, at_p);
  ASSERT_TRUE(cost->Evaluate(blocks, again.data(), nullptr));  // the same point again
  EXPECT_EQ(again, at_q);
  // With derivatives it always simulates; the residuals are those of the point.
  ASSERT_TRUE(cost->Evaluate(blocks, with_jacobian.data(), jac));
  for (int i = 0; i < n; ++i) EXPECT_NEAR(with_jacobian[i], at_q[i], 1e-12) << i;
}

TEST(TrajectoryFit, HeadsAreEachSegmentsFirstIntervalsAndShareThePointOfTheProblem) {
  const Trajectory log = SimulateOrFail(testing::PushedSlider());
  TrajectoryProblem problem({&log}, Options(30));
  // 0.15 s of a 100 Hz log, 15 intervals, or at least 12.
  const std::unique_ptr<TrajectoryProblem> heads = problem.Heads(0.15, 12);
  const int steps = IntervalsIn(0.15, MedianInterval(log));
  ASSERT_EQ(steps, 15);
  const std::unique_ptr<TrajectoryProblem> at_least = problem.Heads(0.05, 12);
  for (size_t k = 0; k < problem.segments().size(); ++k) {  // 0.05 s would be 5 intervals
    const TrajectorySegment& seg = problem.segments()[k];
    EXPECT_EQ(at_least->segments()[k].last_row, std::min(seg.last_row, seg.first_row + 12));
  }
  ASSERT_EQ(heads->segments().size(), problem.segments().size());
  int head_rows = 0;
  for (size_t k = 0; k < problem.segments().size(); ++k) {
    const TrajectorySegment& seg = problem.segments()[k];
    const TrajectorySegment& head = heads->segments()[k];
    EXPECT_EQ(head.first_row, seg.first_row);
    EXPECT_EQ(head.last_row, std::min(seg.last_row, seg.first_row + steps));
    EXPECT_EQ(head.state, seg.state);
    head_rows += head.last_row - head.first_row + 1;
  }
  EXPECT_DOUBLE_EQ(problem.HeadsFraction(0.15, 12), double(head_rows) / problem.Rows());
  TrajectoryProblem::Point moved = heads->point();
  moved.global[0] += 0.1;
  moved.states.back()[3] += 0.01;
  problem.set_point(moved);
  EXPECT_EQ(problem.global(0), moved.global[0]);
  EXPECT_EQ(problem.segments().back().state, moved.states.back());
}

// The seed stage fits the segments' heads; where the heads hold no sliding (a push that
// starts after them) they say nothing of the friction, and the fit must still find it.
TEST(TrajectoryFit, RecoversTheTruthWhenTheSegmentHeadsAreAtRest) {
  Scene scene = testing::PushedSlider();
  scene.initial = {0, 0, 0, 0, 0, 0};
  scene.pushes[0].start_s = 0.3;
  scene.duration_s = 2.0;
  const Trajectory log = SimulateOrFail(scene);
  const IdentifyOptions options = Options(99);  // 100-row segments: rows 0-20 at rest
  TrajectoryProblem problem({&log}, options);
  ASSERT_LE(problem.HeadsFraction(0.1, 20), 0.5);
  ExpectRecovers(scene, log, options);
}

TEST(TrajectoryFit, LogWithoutMotionEndsWithTooLittleExcitationSayingSo) {
  Scene scene = testing::BaseScene();  // at rest, no push
  scene.duration_s = 0.3;
  const EstimateResult r = EstimateTrajectory(SimulateOrFail(scene), Options(10));
  EXPECT_EQ(r.status, TerminationStatus::kTooLittleExcitation);
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.message.find("too little sliding"), std::string::npos) << r.message;
}

// Two exact factorisations of a well-conditioned 24 x 15 system (random normal entries)
// agree to rounding times its condition number: far below this relative difference, which
// a wrong block, sign or index would exceed by orders of magnitude.
constexpr double kFactorisationRelTol = 1e-12;

// The settle rule's Gauss-Newton step as the fit builds it (each segment's state
// marginalised by MarginaliseState, the shares summed, GaussNewtonMoves) must be the exact
// step of the whole problem solved at once: the least-squares solution of J d = -r over
// every state and free global, by QR of the stacked Jacobian; its decrease, the fall of
// |r + J d|^2. With a global held, its column leaves J and its move must be 0.
TEST(TrajectoryFit, GaussNewtonMovesAreTheStepOfTheWholeProblem) {
  constexpr int kSegments = 2, kRows = 12, kGlobals = 3, kStates = 6 * kSegments;
  std::mt19937 rng(19);
  std::normal_distribution<double> normal;
  const auto random = [&](int rows, int cols) {
    return Eigen::MatrixXd(rows, cols).unaryExpr([&](double) { return normal(rng); }).eval();
  };
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(kSegments * kRows, kStates + kGlobals);
  for (int k = 0; k < kSegments; ++k) {
    J.block(k * kRows, 6 * k, kRows, 6) = random(kRows, 6);
    J.block(k * kRows, kStates, kRows, kGlobals) = random(kRows, kGlobals);
  }
  const Eigen::VectorXd r = random(kSegments * kRows, 1);
  for (const std::vector<bool>& free : {std::vector<bool>{true, true, true}, {true, false, true}}) {
    LastGaussNewton at{Eigen::MatrixXd::Zero(kGlobals, kGlobals), Eigen::VectorXd::Zero(kGlobals),
                       r.squaredNorm(), static_cast<int>(r.size()), 0};
    for (int k = 0; k < kSegments; ++k) {
      Eigen::MatrixXd Jk(kRows, 6 + kGlobals);
      Jk << J.block(k * kRows, 6 * k, kRows, 6), J.block(k * kRows, kStates, kRows, kGlobals);
      const Eigen::VectorXd rk = r.segment(k * kRows, kRows);
      const StateMarginal share = MarginaliseState(Jk.transpose() * Jk, Jk.transpose() * rk);
      at.fisher += share.h;
      at.gradient += share.gradient;
      at.state_decrease += share.state_decrease;
    }
    const GaussNewtonStep step = GaussNewtonMoves(at, free);
    ASSERT_EQ(step.moves.size(), free.size());
    // J's columns of the states and the free globals (no Eigen 3.4 indexing: 3.3 builds it).
    std::vector<int> kept(kStates);
    std::iota(kept.begin(), kept.end(), 0);
    for (int i = 0; i < kGlobals; ++i) {
      if (free[i]) kept.push_back(kStates + i);
    }
    Eigen::MatrixXd Jf(J.rows(), static_cast<Eigen::Index>(kept.size()));
    for (size_t c = 0; c < kept.size(); ++c) Jf.col(c) = J.col(kept[c]);
    const Eigen::VectorXd d = Jf.colPivHouseholderQr().solve(-r);
    const double decrease = r.squaredNorm() - (r + Jf * d).squaredNorm();
    EXPECT_NEAR(step.decrease, decrease, kFactorisationRelTol * decrease);
    const double largest = d.tail(d.size() - kStates).cwiseAbs().maxCoeff();
    for (int i = 0, column = kStates; i < kGlobals; ++i) {
      const double expected = free[i] ? std::abs(d(column++)) : 0.0;
      EXPECT_NEAR(step.moves[i], expected, kFactorisationRelTol * largest) << i;
    }
  }
}

// The fit's last solve may end on a predicted step only where it is settled both ways:
// every free global's move within kSettledFraction of its standard error, and a decrease
// of at most kSettledDecrease mean squares. Consistent standard errors (sqrt(s^2 / f) for
// a diagonal information f) make a settled globals' step lower the sum of squares by a few
// 1e-4 mean squares at most, so, as in the fit, a large decrease can only come from the
// states (state_decrease): the states still creeping must keep the solve going.
TEST(TrajectoryFit, PredictedStepEndsTheSolveOnlyWhenItsMovesAndDecreaseAreSmall) {
  const Eigen::Vector3d f(4e6, 1e4, 9e8);  // information of a, b, c, different scales
  LastGaussNewton at{f.asDiagonal().toDenseMatrix(), Eigen::Vector3d::Zero(), 2.0, 1000, 0};
  const double mean_square = at.sum_squares / at.residuals;
  std::vector<double> se(3);
  for (int i = 0; i < 3; ++i) se[i] = std::sqrt(mean_square / f(i));
  // Gradient f_i * move_i: the Gauss-Newton step moves global i by move_i.
  const auto moving = [&](double a_se, double b_se, double c_se) {
    const Eigen::Vector3d moves(a_se * se[0], b_se * se[1], c_se * se[2]);
    return Eigen::Vector3d(f.cwiseProduct(moves));
  };
  const std::vector<bool> all_free = {true, true, true};
  const double half = 0.5 * kSettledFraction;
  at.gradient = moving(half, -half, half);
  EXPECT_TRUE(PredictedStepSettled(at, all_free, se, kSettledFraction));
  at.state_decrease = 0.5 * kSettledDecrease * mean_square;
  EXPECT_TRUE(PredictedStepSettled(at, all_free, se, kSettledFraction));
  at.state_decrease = 2.0 * kSettledDecrease * mean_square;  // the states still creep
  EXPECT_FALSE(PredictedStepSettled(at, all_free, se, kSettledFraction));
  at.state_decrease = 0;
  at.gradient = moving(half, 3 * half, half);  // b would still move 0.03 standard errors
  EXPECT_FALSE(PredictedStepSettled(at, all_free, se, kSettledFraction));
  // ... unless b is held: the rule looks at the free globals' moves only.
  EXPECT_TRUE(PredictedStepSettled(at, {true, false, true}, se, kSettledFraction));
}

}  // namespace
}  // namespace slideid

namespace slideid {
namespace {

// The default experiment (datasets/scenes/default_push.ini) is simulated at 0.1 ms and
// logged at 100 Hz with pose and force noise: the fit's model (one step per log interval,
// logged forces taken as exact) does not match the data exactly, and the mismatch makes
// the residuals correlated within segments. White-noise intervals then miss the truth
// (on the bundled log by 4.6 standard errors in a); the cluster-robust covariance must
// hold it in at least 90% of logs, and every interval must say that it is cluster-robust.
// 100 logs (30 could not tell 90% from 83%: a binomial 95% band of +-13%). Measured: 91,
// 97 and 100% for a, b, c, with a mismatch correction of about -1% in a.
struct DefaultExperiment {
  LoggedScene scene;
  Trajectory simulated;
  std::array<double, 3> truth;
};

// datasets/scenes/default_push.ini, simulated (at 0.1 ms) but not yet logged.
DefaultExperiment SimulateDefaultExperiment() {
  DefaultExperiment e;
  e.scene = LoadScene(std::string(SLIDEID_SOURCE_DIR) + "/datasets/scenes/default_push.ini");
  e.simulated = SimulateOrFail(e.scene);
  const ReducedFriction t = e.scene.friction.reduced();
  e.truth = {t.a, t.b, t.c};
  return e;
}

TEST(TrajectoryFit, IntervalsStayHonestUnderModelMismatchOfACoarseNoisyLog) {
  const DefaultExperiment e = SimulateDefaultExperiment();
  const LoggedScene& scene = e.scene;
  const std::array<double, 3>& truth = e.truth;
  constexpr int kLogs = 100;
  std::array<int, 3> covered{}, robust{};
  LogSpec spec = scene.log;
  for (int k = 0; k < kLogs; ++k) {
    spec.noise.seed = 100 + k;
    const EstimateResult r = EstimateTrajectory(MakeLog(e.simulated, spec), {});
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      ASSERT_TRUE(p.identifiable);
      covered[i] += p.ci95_lo <= truth[i] && truth[i] <= p.ci95_hi;
      robust[i] += p.note.find("cluster-robust") != std::string::npos;
    }
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(covered[i], 90) << ParameterName(i) << " covered in " << covered[i] << "/100";
    EXPECT_EQ(robust[i], kLogs) << ParameterName(i);
  }
}

// TrajectoryOptions::correct_mismatch = false: no mismatch directions at all (it once read
// past an empty table), the estimate is the fit's own, and no note claims a correction.
TEST(TrajectoryFit, WithoutTheMismatchCorrectionTheFitIsItsOwnAndSaysSo) {
  const DefaultExperiment e = SimulateDefaultExperiment();
  const Trajectory log = MakeLog(e.simulated, e.scene.log);
  IdentifyOptions options;
  options.trajectory.correct_mismatch = false;
  const EstimateResult plain = EstimateTrajectory(log, options);
  const EstimateResult corrected = EstimateTrajectory(log, {});
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = plain.parameters[i];
    ASSERT_TRUE(p.identifiable) << ParameterName(i) << ": " << p.reason;
    EXPECT_NEAR(p.value / e.truth[i], 1.0, 0.05) << ParameterName(i);
    EXPECT_EQ(p.note.find("corrected"), std::string::npos) << p.note;
    EXPECT_NE(corrected.parameters[i].note.find("corrected for model mismatch"), std::string::npos)
        << corrected.parameters[i].note;
  }
}

}  // namespace
}  // namespace slideid

namespace slideid {
namespace {

// Ceres calls a solve cut off by the iteration limit "usable"; it is not converged.
TEST(TrajectoryFit, SolveCutOffByTheIterationLimitIsNotConverged) {
  const Trajectory log = NoisyPosesOnly(SimulateOrFail(testing::TiltingPush()), 77);
  IdentifyOptions options = Options(25);
  options.trajectory.max_iterations = 1;
  EXPECT_FALSE(EstimateTrajectory(log, options).converged);
  options.trajectory.max_iterations = 100;
  EXPECT_TRUE(EstimateTrajectory(log, options).converged);
}

}  // namespace
}  // namespace slideid
