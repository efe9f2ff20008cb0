// Tests of one backward-Euler step: residuals, agreement of the general solver with the
// special cases and with independent formulations, sticking, energy, ECP.

#include "forward_model/step_solver.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <unsupported/Eigen/NonLinearOptimization>

#include "fixtures/random_step_cases.h"
#include "fixtures/tolerances.h"
#include "forward_model/quasi_static.h"
#include "forward_model/step_equations.h"

namespace slideid {
namespace {

// Agreement demanded between two solvers of the same step (issue: 1e-10).
constexpr double kAgreement = 1e-10;
constexpr int kRandomCases = 3000;

using testing::Case;
using testing::CaseGenerator;
using testing::kEnergyTolerance;
using testing::kIndependentTolerance;
using testing::kStepTolerance;

StepResult Solve(const Case& c, bool special_cases = true) {
  StepOptions options;
  options.use_special_cases = special_cases;
  return SolveStep(c.slider, c.friction, c.state, c.applied, c.dt_s, options);
}

Eigen::Vector4d Unknowns(const StepResult& r) { return {r.pt, r.po, r.pr, r.sigma}; }

double MaxRelativeDifference(const StepResult& a, const StepResult& b) {
  const Eigen::Vector4d x = Unknowns(a), y = Unknowns(b);
  const double scale = std::max(x.head<3>().cwiseAbs().maxCoeff(), 1e-300);
  const double sigma_scale = std::max(std::abs(x(3)), 1e-300);
  return std::max((x.head<3>() - y.head<3>()).cwiseAbs().maxCoeff() / scale,
                  std::abs(x(3) - y(3)) / sigma_scale);
}

TEST(StepSolver, ResidualOfTheFourEquationsIsTinyOverRandomGeneralCases) {
  CaseGenerator gen(1);
  int slides = 0;
  for (int i = 0; i < kRandomCases; ++i) {
    const Case c = gen.General();
    const StepResult r = Solve(c);
    ASSERT_TRUE(r.ok()) << r.message << " case " << i;
    EXPECT_LE(r.residual, kStepTolerance);
    if (r.mode == StepMode::kStick) continue;
    ++slides;
    EXPECT_GT(r.sigma, 0.0);
    const Eigen::Vector4d res =
        SlidingEquationResiduals(c.slider, c.friction, c.state, c.applied, c.dt_s, Unknowns(r));
    EXPECT_LT(res.cwiseAbs().maxCoeff(), kIndependentTolerance)
        << "case " << i << " residuals " << res.transpose();
  }
  EXPECT_GT(slides, kRandomCases / 2);  // the sample exercises sliding, not only sticking
}

TEST(StepSolver, GeneralSolverAgreesWithDecoupledRootWhenCmOnPlaneAndNoTilt) {
  CaseGenerator gen(2);
  int compared = 0;
  for (int i = 0; i < kRandomCases; ++i) {
    Case c = gen.General();
    c.slider.com_height_m = 0;
    c.applied.tx = c.applied.ty = 0;
    const StepResult fast = Solve(c, true), general = Solve(c, false);
    ASSERT_TRUE(fast.ok() && general.ok());
    if (fast.mode == StepMode::kStick) continue;
    ASSERT_EQ(fast.path, StepPath::kDecoupled);
    ASSERT_EQ(general.path, StepPath::kGeneral);
    EXPECT_LT(MaxRelativeDifference(fast, general), kAgreement) << "case " << i;
    EXPECT_LT(fast.residual, kStepTolerance);
    ++compared;
  }
  EXPECT_GT(compared, 100);
}

TEST(StepSolver, GeneralSolverAgreesWithPureTranslationClosedForm) {
  CaseGenerator gen(3);
  int compared = 0;
  for (int i = 0; i < kRandomCases; ++i) {
    Case c = gen.General();
    c.friction.e_o = c.friction.e_t;  // b = 1
    c.state.wz = 0;
    c.applied.tx = c.applied.ty = c.applied.tz = 0;
    const StepResult closed = Solve(c, true), general = Solve(c, false);
    ASSERT_TRUE(closed.ok() && general.ok());
    if (closed.mode == StepMode::kStick) continue;
    ASSERT_EQ(closed.path, StepPath::kPureTranslation);
    EXPECT_LT(MaxRelativeDifference(closed, general), kAgreement) << "case " << i;
    EXPECT_EQ(closed.state.wz, 0.0);
    // Erratum 4: |p| = e_t mu p_n, opposite to m v + p_app.
    EXPECT_NEAR(std::hypot(closed.pt, closed.po), c.friction.e_t * c.friction.mu * closed.pn,
                1e-12 * closed.pn);
    ++compared;
  }
  EXPECT_GT(compared, 100);
}

// Independent formulation 1 (model.md, convex form): for q_z = 0 and no tilt the end
// velocity minimises 1/2 v'Mv - v'(M nu + p) + a p_n sqrt(v'Dv). Damped Newton on it.
Eigen::Vector3d MinimiseConvexStep(const Case& c) {
  const ReducedFriction f = ReducedFriction::From(c.friction);
  const double m = c.slider.mass_kg, I = c.slider.inertia_kgm2, h = c.dt_s;
  const double P = f.a * h * (m * c.slider.gravity_mps2 - c.applied.fz);
  const Eigen::Vector3d M(m, m, I), D(1, f.b * f.b, f.c * f.c);
  const Eigen::Vector3d k(m * c.state.vx + h * c.applied.fx, m * c.state.vy + h * c.applied.fy,
                          I * c.state.wz + h * c.applied.tz);
  auto gradient = [&](const Eigen::Vector3d& v) -> Eigen::Vector3d {
    return M.cwiseProduct(v) - k + P * D.cwiseProduct(v) / std::sqrt(v.dot(D.cwiseProduct(v)));
  };
  // The objective is strictly convex and smooth away from 0, and the minimiser is not 0
  // (the step slides): Newton on its gradient, damped on the gradient norm (the objective
  // value itself is too flat near the minimum to line-search on below sqrt(eps)).
  Eigen::Vector3d v = k.cwiseQuotient(M);  // frictionless velocity: never the kink at 0
  for (int it = 0; it < 200; ++it) {
    const double n = std::sqrt(v.dot(D.cwiseProduct(v)));
    const Eigen::Vector3d g = gradient(v);
    Eigen::Matrix3d H = M.asDiagonal();
    H += P * (Eigen::Matrix3d(D.asDiagonal()) / n -
              D.cwiseProduct(v) * D.cwiseProduct(v).transpose() / (n * n * n));
    const Eigen::Vector3d dv = H.ldlt().solve(-g);
    double t = 1;
    while (gradient(v + t * dv).norm() > (1 - 1e-4 * t) * g.norm() && t > 1e-12) t *= 0.5;
    v += t * dv;
    if (dv.norm() <= 1e-15 * v.norm()) break;
  }
  return v;
}

TEST(StepSolver, GeneralSolverMatchesConvexMinimisationWhenDecoupled) {
  CaseGenerator gen(4);
  int compared = 0;
  for (int i = 0; i < 500; ++i) {
    Case c = gen.General();
    c.slider.com_height_m = 0;
    c.applied.tx = c.applied.ty = 0;
    const StepResult general = Solve(c, false);
    ASSERT_TRUE(general.ok());
    if (general.mode == StepMode::kStick) continue;
    const Eigen::Vector3d v = MinimiseConvexStep(c);
    const double scale = std::abs(c.state.vx) + std::abs(c.state.vy) + 1e-3;
    EXPECT_NEAR(general.state.vx, v(0), 1e-9 * scale) << "case " << i;
    EXPECT_NEAR(general.state.vy, v(1), 1e-9 * scale) << "case " << i;
    EXPECT_NEAR(general.state.wz, v(2), 1e-9 * (std::abs(c.state.wz) + 1e-2)) << "case " << i;
    ++compared;
  }
  EXPECT_GT(compared, 50);
}

// Independent formulation 2: the paper's four equations (dy_ts_1..4 with the corrected
// coupling term), unscaled, solved by MINPACK's hybrid dogleg (Eigen unsupported).
struct PaperEquations {
  const Case& c;
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& fvec) const {
    fvec = SlidingEquationResiduals(c.slider, c.friction, c.state, c.applied, c.dt_s,
                                    Eigen::Vector4d(x(0), x(1), x(2), x(3)));
    return 0;
  }
  int inputs() const { return 4; }
  int values() const { return 4; }
};

TEST(StepSolver, GeneralSolverMatchesGenericDoglegSolverWithCmHeightAndTilt) {
  CaseGenerator gen(5);
  int compared = 0;
  for (int i = 0; i < 300; ++i) {
    const Case c = gen.General();
    const StepResult general = Solve(c, false);
    ASSERT_TRUE(general.ok());
    if (general.mode == StepMode::kStick) continue;
    PaperEquations eq{c};
    Eigen::HybridNonLinearSolver<PaperEquations> dogleg(eq);
    // Started 2% away from our root: the generic solver must come back to the same point.
    Eigen::VectorXd x = Unknowns(general) * 1.02;
    dogleg.hybrd1(x, 1e-14);
    Eigen::VectorXd f(4);
    eq(x, f);
    if (f.cwiseAbs().maxCoeff() > 1e-12) continue;  // dogleg itself stalled: no verdict
    ++compared;
    StepResult other = general;
    other.pt = x(0);
    other.po = x(1);
    other.pr = x(2);
    other.sigma = x(3);
    EXPECT_LT(MaxRelativeDifference(general, other), 1e-8) << "case " << i;
  }
  EXPECT_GT(compared, 100);
}

// Issue 19: where StepEquations::UniqueSlidingRoot certifies the sliding root unique, the
// solver takes another guess and full Newton steps; the root must be the one any start
// finds. Strongly coupled steps (q_z up to 3 m, tilt and spin up to 20x), each solved again
// from random first guesses (StepOptions::initial_guess: tried first, the usual guesses
// after it if Newton fails from there).
TEST(StepSolver, WhereTheRootIsCertifiedUniqueRandomStartsFindTheSameRoot) {
  CaseGenerator gen(19);
  std::mt19937_64 rng(19);
  std::normal_distribution<double> normal;
  int certified = 0;
  for (int i = 0; i < 20000 && certified < 100; ++i) {
    Case c = gen.General();
    c.slider.com_height_m = gen.Uniform(0, 3.0);
    const double tilt = gen.LogUniform(1, 20);
    c.applied.tx *= tilt;
    c.applied.ty *= tilt;
    c.state.wz *= gen.LogUniform(1, 20);
    const StepResult r = Solve(c);
    // (Some of these exaggerated steps do not converge, certified or not, before and after
    // issue 19: not this test's subject.)
    if (!r.ok() || r.mode == StepMode::kStick) continue;
    const StepEquations eq(c.slider, ReducedFriction::From(c.friction), c.state, c.applied, c.dt_s);
    if (!eq.UniqueSlidingRoot()) continue;
    ++certified;
    for (int start = 0; start < 10; ++start) {
      Eigen::Vector4d guess(normal(rng), normal(rng), normal(rng), 0.0);
      guess.head<3>().normalize();
      guess(3) = eq.velocity_scale() * std::exp(gen.Uniform(std::log(1e-3), std::log(30.0)));
      StepOptions options;
      options.initial_guess = guess;
      const StepResult other = SolveStep(c.slider, c.friction, c.state, c.applied, c.dt_s, options);
      ASSERT_TRUE(other.ok()) << other.message << " case " << i;
      EXPECT_LT(MaxRelativeDifference(r, other), 1e-8) << "case " << i << " start " << start;
    }
  }
  EXPECT_GE(certified, 100);
}

TEST(StepSolver, FreeSlideStopsInFiniteTimeAndStaysAtRest) {
  SliderProperties slider{0.5, 2.0833e-4, 0.08, 9.8};
  FrictionParameters friction{0.31, 1, 1, 0.01};
  PlanarState s{0, 0, 0, 0.7, 0.9, 10};
  int stick_from = -1;
  for (int i = 0; i < 200; ++i) {
    const StepResult r = SolveStep(slider, friction, s, {}, 0.01);
    ASSERT_TRUE(r.ok());
    if (r.mode == StepMode::kStick && stick_from < 0) stick_from = i;
    if (stick_from >= 0) {
      EXPECT_EQ(r.mode, StepMode::kStick) << "slid again at step " << i;
      EXPECT_EQ(r.state.vx, 0.0);
      EXPECT_EQ(r.state.wz, 0.0);
      EXPECT_EQ(r.state.x, s.x);
    }
    s = r.state;
  }
  EXPECT_GT(stick_from, 10);
  EXPECT_LT(stick_from, 100);
}

TEST(StepSolver, PushInsideFrictionLimitDoesNotMoveRestingSliderAndOneOutsideDoes) {
  SliderProperties slider{1.0, 0.005, 0.05, 9.81};
  FrictionParameters friction{0.4, 1, 1, 0.03};
  const double limit = friction.mu * slider.mass_kg * slider.gravity_mps2;
  const PlanarState rest{};
  const StepResult inside = SolveStep(slider, friction, rest, {0.99 * limit, 0}, 0.01);
  ASSERT_TRUE(inside.ok());
  EXPECT_EQ(inside.mode, StepMode::kStick);
  EXPECT_EQ(inside.state.vx, 0.0);
  const StepResult outside = SolveStep(slider, friction, rest, {1.01 * limit, 0}, 0.01);
  ASSERT_TRUE(outside.ok());
  EXPECT_EQ(outside.mode, StepMode::kSlide);
  EXPECT_GT(outside.state.vx, 0.0);
  // Pure translation: the closed form gives v' = (F - mu m g) h / m exactly.
  EXPECT_NEAR(outside.state.vx, 0.01 * limit * 0.01 / slider.mass_kg, 1e-15);
}

TEST(StepSolver, KineticEnergyNeverIncreasesWithoutPush) {
  CaseGenerator gen(6);
  for (int trial = 0; trial < 200; ++trial) {
    Case c = gen.General();
    c.applied = {};
    double energy = 1e300;
    PlanarState s = c.state;
    for (int i = 0; i < 100; ++i) {
      const StepResult r = SolveStep(c.slider, c.friction, s, {}, c.dt_s);
      ASSERT_TRUE(r.ok());
      s = r.state;
      const double e = 0.5 * c.slider.mass_kg * (s.vx * s.vx + s.vy * s.vy) +
                       0.5 * c.slider.inertia_kgm2 * s.wz * s.wz;
      EXPECT_LE(e, energy * (1 + kEnergyTolerance)) << "trial " << trial << " step " << i;
      energy = e;
    }
  }
}

TEST(StepSolver, EcpIsUnderCmWhenCmOnPlaneAndAtRestWithoutPush) {
  CaseGenerator gen(7);
  for (int i = 0; i < 200; ++i) {
    Case c = gen.General();
    c.slider.com_height_m = 0;
    c.applied.tx = c.applied.ty = 0;
    const StepResult r = Solve(c);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.ecp_offset_world.norm(), 0.0);
    EXPECT_EQ(r.ecp_world, Eigen::Vector2d(r.state.x, r.state.y));
  }
  // At rest without push, with q_z > 0: nothing to resist, the ECP is under the CM.
  const SliderProperties slider{0.5, 2e-4, 0.08, 9.8};
  const StepResult rest =
      SolveStep(slider, FrictionParameters{0.3, 1, 1, 0.01}, {0.1, 0.2, 0.3}, {}, 0.01);
  ASSERT_TRUE(rest.ok());
  EXPECT_EQ(rest.mode, StepMode::kStick);
  EXPECT_EQ(rest.ecp_world, Eigen::Vector2d(0.1, 0.2));
}

TEST(StepSolver, ReducedFrictionGivesTheSameStepAsTheFourParametersItStandsFor) {
  // The paper's (mu, e_t, e_o, e_r) and its reduced (a, b, c) must give the same motion
  // (model.md, "Only three parameters matter"); only sigma scales, by e_t.
  const SliderProperties slider{0.7, 3e-4, 0.04, 9.81};
  const FrictionParameters paper{0.35, 1.4, 1.9, 0.042};
  const ReducedFriction reduced = ReducedFriction::From(paper);
  AppliedWrench push;
  push.fx = 3.0;
  push.fy = -1.0;
  push.tx = 0.02;
  push.tz = 0.05;
  const PlanarState moving{0.1, -0.2, 0.3, 0.4, 0.1, 2.0};
  const StepResult full = SolveStep(slider, paper, moving, push, 0.01);
  const StepResult fast = SolveStep(slider, reduced, moving, push, 0.01);
  ASSERT_TRUE(full.ok());
  ASSERT_TRUE(fast.ok());
  ASSERT_EQ(full.mode, StepMode::kSlide);
  EXPECT_NEAR(full.state.vx, fast.state.vx, 1e-14);
  EXPECT_NEAR(full.state.vy, fast.state.vy, 1e-14);
  EXPECT_NEAR(full.state.wz, fast.state.wz, 1e-13);
  EXPECT_NEAR(full.pr, fast.pr, 1e-16);
  EXPECT_NEAR(full.sigma, paper.e_t * fast.sigma, 1e-14);
  EXPECT_THROW(SolveStep(slider, ReducedFriction{0.3, 1.0, -0.01}, moving, push, 0.01),
               std::invalid_argument);
}

TEST(StepSolver, LiftOffIsReportedNotSolved) {
  const SliderProperties slider{1.0, 0.01, 0.05, 9.81};
  AppliedWrench lift;
  lift.fz = 9.81;
  const StepResult r = SolveStep(slider, FrictionParameters{}, {0, 0, 0, 1, 0, 0}, lift, 0.01);
  EXPECT_EQ(r.status, StepStatus::kLiftOff);
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.message.empty());
}

TEST(StepSolver, InvalidArgumentsThrowNamingTheValue) {
  const SliderProperties bad_mass{-1.0, 0.01, 0.05, 9.81};
  EXPECT_THROW(SolveStep(bad_mass, FrictionParameters{}, {}, {}, 0.01), std::invalid_argument);
  EXPECT_THROW(SolveStep({}, FrictionParameters{}, {}, {}, 0.0), std::invalid_argument);
  EXPECT_THROW(SolveStep({}, FrictionParameters{0.3, 1, 1, -0.01}, {}, {}, 0.01),
               std::invalid_argument);
  try {
    SolveStep({}, FrictionParameters{std::nan(""), 1, 1, 0.01}, {}, {}, 0.01);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mu"), std::string::npos);
  }
}

// Independent derivation of quasi-static pushing: solve the contact-point kinematics and
// the moment balance with friction wrench proportional to (v_x, v_y, c^2 w) as a 3x3 system.
TEST(QuasiStatic, ClosedFormMatchesLinearSystemOfKinematicsAndMomentBalance) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector2d r(u(rng), u(rng)), vc(10 * u(rng), 10 * u(rng));
    const double c = std::abs(u(rng)) + 1e-3;
    Eigen::Matrix3d A;
    A << 1, 0, -r.y(),         // v_c = v + w x r
        0, 1, r.x(),           //
        r.y(), -r.x(), c * c;  // c^2 w = r_x v_y - r_y v_x (friction moment balances push)
    const Eigen::Vector3d expected = A.lu().solve(Eigen::Vector3d(vc.x(), vc.y(), 0));
    const Eigen::Vector3d got = QuasiStaticTwist(r, vc, c);
    EXPECT_LT((got - expected).norm(), 1e-12 * (1 + expected.norm())) << "case " << i;
  }
  EXPECT_THROW(QuasiStaticTwist({0.1, 0}, {1, 0}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace slideid
