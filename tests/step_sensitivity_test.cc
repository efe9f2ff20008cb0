// Derivative checks: the implicit-function derivatives of a step against central finite
// differences of the solver itself, and the solver's analytic Jacobian against autodiff.

#include "estimator/step_sensitivity.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "forward_model/step_equations.h"

namespace slideid {
namespace {

// Central differences of a step converged to 1e-12 relative: truncation ~ d^2, rounding
// ~ 1e-12 / d; d = 1e-5 relative balances both near 1e-7 relative error.
constexpr double kRelativeStep = 1e-5;
constexpr double kTolerance = 2e-5;

struct StepCase {
  SliderProperties slider;
  ReducedFriction abc;
  PlanarState state;
  AppliedWrench applied;
  double h;
};

StepCase RandomSetup(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  StepCase s;
  s.slider = {1.0 + 0.5 * u(rng), 2e-3 * (1.2 + u(rng)), 0.04 * (1 + u(rng)), 9.81};
  s.abc = {0.3 * (1.5 + u(rng)), 1.0 + 0.4 * u(rng), 0.03 * (1.5 + u(rng))};
  s.state = {0, 0, 0, 0.8 * u(rng), 0.8 * u(rng), 8 * u(rng)};
  s.applied = {3 * u(rng), 3 * u(rng), 2 * u(rng), 0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng)};
  s.h = 0.01;
  return s;
}

Eigen::Vector3d EndVelocity(const StepCase& s) {
  const StepResult r = SolveStep(s.slider, s.abc.ToFrictionParameters(), s.state, s.applied, s.h);
  EXPECT_TRUE(r.ok());
  return {r.state.vx, r.state.vy, r.state.wz};
}

TEST(StepSensitivity, ImplicitDerivativesMatchCentralDifferencesOfTheSolver) {
  std::mt19937_64 rng(11);
  int checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const StepCase s = RandomSetup(rng);
    StepSensitivity sens;
    ASSERT_TRUE(SolveStepWithSensitivity(s.slider, s.abc, s.state, s.applied, s.h, &sens));
    if (sens.step.mode == StepMode::kStick) continue;
    Eigen::Matrix<double, 3, 6> numeric;
    for (int j = 0; j < 6; ++j) {
      StepCase plus = s, minus = s;
      double d;
      if (j < 3) {
        double* vp[] = {&plus.state.vx, &plus.state.vy, &plus.state.wz};
        double* vm[] = {&minus.state.vx, &minus.state.vy, &minus.state.wz};
        d = kRelativeStep * (j < 2 ? 1.0 : 10.0);
        *vp[j] += d;
        *vm[j] -= d;
      } else {
        double* pp[] = {&plus.abc.a, &plus.abc.b, &plus.abc.c};
        double* pm[] = {&minus.abc.a, &minus.abc.b, &minus.abc.c};
        d = kRelativeStep;  // in log-parameter
        *pp[j - 3] *= std::exp(d);
        *pm[j - 3] *= std::exp(-d);
      }
      const StepResult rp =
          SolveStep(plus.slider, plus.abc.ToFrictionParameters(), plus.state, plus.applied, plus.h);
      const StepResult rm = SolveStep(minus.slider, minus.abc.ToFrictionParameters(), minus.state,
                                      minus.applied, minus.h);
      if (rp.mode != StepMode::kSlide || rm.mode != StepMode::kSlide) goto next_trial;
      numeric.col(j) = (EndVelocity(plus) - EndVelocity(minus)) / (2 * d);
    }
    {
      Eigen::Matrix<double, 3, 6> analytic;
      analytic << sens.dnu_dnu, sens.dnu_dlogabc;
      const double scale = numeric.cwiseAbs().maxCoeff() + 1e-3;
      EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff() / scale, kTolerance)
          << "trial " << trial << "\nanalytic\n"
          << analytic << "\nnumeric\n"
          << numeric;
      ++checked;
    }
  next_trial:;
  }
  EXPECT_GT(checked, 100);
}

// The hand-written partials of the scaled equations against automatic differentiation of
// the same equations (ceres::Jet): two computations of every derivative, wrench included.
TEST(StepSensitivity, HandWrittenPartialsEqualAutodiffIncludingTheWrench) {
  std::mt19937_64 rng(23);
  int sliding = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const StepCase s = RandomSetup(rng);
    StepSensitivity fast, slow;
    ASSERT_TRUE(SolveStepWithSensitivity(s.slider, s.abc, s.state, s.applied, s.h, &fast, {},
                                         /*with_wrench=*/true));
    if (fast.step.mode == StepMode::kStick) continue;
    ++sliding;
    slow.step = fast.step;
    ASSERT_TRUE(StepSensitivityByAutodiff(s.slider, s.abc, s.state, s.applied, s.h, &slow, true));
    Eigen::Matrix<double, 3, 11> a, b;
    a << fast.dnu_dnu, fast.dnu_dlogabc, fast.dnu_dwrench;
    b << slow.dnu_dnu, slow.dnu_dlogabc, slow.dnu_dwrench;
    // Both are exact up to rounding of the same 4x4 solve: 1e-10 relative to the largest.
    EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-10 * (b.cwiseAbs().maxCoeff() + 1.0))
        << "trial " << trial << "\nhand\n"
        << a << "\nautodiff\n"
        << b;
    // Without the wrench the same step gives the same first six columns.
    StepSensitivity plain;
    ASSERT_TRUE(SolveStepWithSensitivity(s.slider, s.abc, s.state, s.applied, s.h, &plain));
    EXPECT_EQ(plain.dnu_dnu, fast.dnu_dnu);
    EXPECT_EQ(plain.dnu_dlogabc, fast.dnu_dlogabc);
  }
  EXPECT_GT(sliding, 200);
}

TEST(StepSensitivity, StickingStepHasZeroDerivatives) {
  const SliderProperties slider{1.0, 2e-3, 0.03, 9.81};
  StepSensitivity sens;
  ASSERT_TRUE(
      SolveStepWithSensitivity(slider, {0.3, 1, 0.03}, {0, 0, 0, 0.001, 0, 0}, {}, 0.01, &sens));
  EXPECT_EQ(sens.step.mode, StepMode::kStick);
  EXPECT_EQ(sens.dnu_dnu.norm(), 0.0);
  EXPECT_EQ(sens.dnu_dlogabc.norm(), 0.0);
}

TEST(StepEquations, AnalyticJacobianMatchesAutodiff) {
  std::mt19937_64 rng(12);
  using Jet = ceres::Jet<double, 4>;
  for (int trial = 0; trial < 200; ++trial) {
    const StepCase s = RandomSetup(rng);
    const StepEquations eq(s.slider, s.abc, s.state, s.applied, s.h);
    std::uniform_real_distribution<double> u(-1, 1);
    const Eigen::Vector4d z(u(rng), u(rng), u(rng), 0.5 + 0.4 * u(rng));
    Eigen::Vector4d f;
    Eigen::Matrix4d jac;
    eq.Evaluate(z, &f, &jac);
    StepTerms<Jet> t;
    const StepTerms<double>& d = eq.terms();
    t.m = Jet(d.m);
    t.I = Jet(d.I);
    t.qz = Jet(d.qz);
    t.pn = Jet(d.pn);
    t.a = Jet(d.a);
    t.b = Jet(d.b);
    t.c = Jet(d.c);
    t.ptx = Jet(d.ptx);
    t.pty = Jet(d.pty);
    t.k = d.k.cast<Jet>();
    Eigen::Matrix<Jet, 4, 1> zj;
    for (int i = 0; i < 4; ++i) zj(i) = Jet(z(i), i);
    const Eigen::Matrix<Jet, 4, 1> fj = ScaledStepResidual(t, zj, eq.velocity_scale());
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(fj(i).a, f(i), 1e-15 * (1 + std::abs(f(i))));
      for (int j = 0; j < 4; ++j) {
        EXPECT_NEAR(fj(i).v(j), jac(i, j), 1e-12 * (1 + std::abs(jac(i, j))))
            << "trial " << trial << " entry " << i << "," << j;
      }
    }
  }
}

}  // namespace
}  // namespace slideid
