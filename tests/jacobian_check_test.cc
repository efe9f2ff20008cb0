// The Jacobian checker of the derivative tests (fixtures/jacobian_check.h) on a cost whose
// derivatives are known: it passes the right ones, finds a wrong entry and says where it is.

#include "fixtures/jacobian_check.h"

#include <ceres/sized_cost_function.h>
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

namespace slideid {
namespace {

using testing::CheckJacobian;
using testing::JacobianCheck;

/// r = (x y0, sin y1) of blocks x (size 1) and y (size 2), with dr1/dy1 scaled by
/// `slope_error` (1: the true derivative). Fails to evaluate where y1 > 10.
class KnownCost : public ceres::SizedCostFunction<2, 1, 2> {
 public:
  explicit KnownCost(double slope_error) : slope_error_(slope_error) {}
  bool Evaluate(double const* const* p, double* r, double** jacobians) const override {
    const double x = p[0][0], y0 = p[1][0], y1 = p[1][1];
    if (y1 > 10) return false;
    r[0] = x * y0;
    r[1] = std::sin(y1);
    if (jacobians != nullptr) {
      if (jacobians[0] != nullptr) jacobians[0][0] = y0, jacobians[0][1] = 0;
      if (jacobians[1] != nullptr) {
        jacobians[1][0] = x, jacobians[1][1] = 0;  // row 0: d r0 / d (y0, y1)
        jacobians[1][2] = 0, jacobians[1][3] = slope_error_ * std::cos(y1);
      }
    }
    return true;
  }

 private:
  double slope_error_;
};

TEST(JacobianCheck, PassesTheTrueDerivativesAndRestoresTheParameters) {
  double x = 0.7, y[2] = {-1.3, 0.4};
  const JacobianCheck check = CheckJacobian(KnownCost(1.0), {&x, y});
  EXPECT_TRUE(check.evaluated);
  EXPECT_LE(check.worst, testing::kJacobianTolerance) << check;
  EXPECT_EQ(x, 0.7);
  EXPECT_EQ(y[0], -1.3);
  EXPECT_EQ(y[1], 0.4);
  ASSERT_EQ(check.largest_by_block.size(), 2u);
  EXPECT_EQ(check.largest_by_block[0], 1.3);
  EXPECT_EQ(check.largest_by_block[1], std::cos(0.4));
}

TEST(JacobianCheck, FindsTheWrongEntryAndSaysWhereItIs) {
  double x = 0.7, y[2] = {-1.3, 0.4};
  const JacobianCheck check = CheckJacobian(KnownCost(1.0 + 1e-4), {&x, y});
  EXPECT_GT(check.worst, testing::kSolvedJacobianTolerance);
  EXPECT_NEAR(check.worst, 1e-4 * std::cos(0.4), 1e-8);  // absolute: |derivative| < 1
  EXPECT_EQ(check.residual, 1);
  EXPECT_EQ(check.block, 1);
  EXPECT_EQ(check.parameter, 1);
  std::ostringstream said;
  said << check;
  EXPECT_NE(said.str().find("residual 1, block 1 parameter 1"), std::string::npos) << said.str();
}

TEST(JacobianCheck, AFailedEvaluationFailsTheCheck) {
  double x = 0.7, y[2] = {-1.3, 10 - 1e-7};  // y1 + the step is past 10
  const JacobianCheck check = CheckJacobian(KnownCost(1.0), {&x, y});
  EXPECT_FALSE(check.evaluated);
  EXPECT_FALSE(check.worst <= testing::kSolvedJacobianTolerance);
  EXPECT_EQ(check.block, 1);
  EXPECT_EQ(check.parameter, 1);
}

}  // namespace
}  // namespace slideid
