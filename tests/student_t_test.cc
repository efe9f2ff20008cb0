// StudentT95Fast (estimator/pooling.h) against Boost's quantile (StudentT95) and tabulated
// values: the online identifier's intervals take it at every update.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "estimator/pooling.h"

namespace slideid {
namespace {

// Below the expansion's threshold it is StudentT95 itself.
TEST(StudentT95Fast, IsBoostsQuantileBelowTheExpansion) {
  for (double dof : {1.0, 2.0, 2.5, 3.0, 7.25, 19.99})
    EXPECT_EQ(StudentT95Fast(dof), StudentT95(dof)) << dof;
}

// From 20 degrees of freedom on, Fisher's expansion within the stated 2e-7 of Boost's,
// over a fine sweep up to 1e6 (the error falls as 1/dof^5: the worst is at 20; above 1e6
// StudentT95 is the normal quantile).
TEST(StudentT95Fast, ExpansionIsWithinTwoTenMillionthsOfBoostsQuantile) {
  constexpr double kStatedRelativeError = 2e-7;
  double worst = 0;
  for (double dof = kStudentT95ExpansionDof; dof <= 1e6; dof *= 1.01) {
    const double exact = StudentT95(dof);
    worst = std::max(worst, std::abs(StudentT95Fast(dof) / exact - 1));
  }
  EXPECT_LT(worst, kStatedRelativeError);
  EXPECT_GT(worst, 0);  // the sweep did reach the expansion
}

// Tabulated two-sided 95% quantiles (Abramowitz & Stegun, Table 26.10).
TEST(StudentT95Fast, MatchesTheTables) {
  EXPECT_NEAR(StudentT95Fast(2), 4.303, 5e-4);
  EXPECT_NEAR(StudentT95Fast(10), 2.228, 5e-4);
  EXPECT_NEAR(StudentT95Fast(20), 2.086, 5e-4);
  EXPECT_NEAR(StudentT95Fast(30), 2.042, 5e-4);
  EXPECT_NEAR(StudentT95Fast(120), 1.980, 5e-4);
}

}  // namespace
}  // namespace slideid
