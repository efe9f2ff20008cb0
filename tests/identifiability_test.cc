#include "estimator/identifiability.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace slideid {
namespace {

// Values the test recomputes by a different arithmetic route (explicit inverse vs LDLT).
constexpr double kRecomputeTol = 1e-12;

TEST(Identifiability, ZeroInformationFlagsThatParameter) {
  const Eigen::Matrix3d h = Eigen::Vector3d(4.0, 9.0, 0.0).asDiagonal();
  const auto v = AssessIdentifiability(h, 0.01);
  EXPECT_TRUE(v[kA].identifiable);
  EXPECT_TRUE(v[kB].identifiable);
  EXPECT_FALSE(v[kC].identifiable);
  EXPECT_TRUE(std::isnan(v[kC].stderr_log));
  EXPECT_NE(v[kC].note.find("do not depend"), std::string::npos) << v[kC].note;
  EXPECT_NEAR(v[kA].stderr_log, std::sqrt(0.01 / 4.0), kRecomputeTol);
  EXPECT_NEAR(v[kB].stderr_log, std::sqrt(0.01 / 9.0), kRecomputeTol);
}

TEST(Identifiability, NegligibleInformationFlagsThatParameter) {
  const Eigen::Matrix3d h = Eigen::Vector3d(1e-14, 1.0, 2.0).asDiagonal();
  const auto v = AssessIdentifiability(h, 0.0);
  EXPECT_FALSE(v[kA].identifiable);
  EXPECT_TRUE(v[kB].identifiable);
  EXPECT_TRUE(v[kC].identifiable);
}

TEST(Identifiability, RankDeficientInformationFlagsTheParameterThatDominatesTheNullSpace) {
  // Columns x, y and x + 0.1 y: the null direction (1, 0.1, -1) weighs c most once the
  // columns are normalised (|x + 0.1 y| > |x| = 1).
  Eigen::MatrixXd j(4, 3);
  const Eigen::Vector4d x(1, 0, 0, 0), y(0, 1, 0, 0);
  j.col(0) = x;
  j.col(1) = y;
  j.col(2) = x + 0.1 * y;
  const Eigen::Matrix3d h = j.transpose() * j;
  const auto v = AssessIdentifiability(h, 1e-4);
  EXPECT_TRUE(v[kA].identifiable);
  EXPECT_TRUE(v[kB].identifiable);
  EXPECT_FALSE(v[kC].identifiable);
  EXPECT_NE(v[kC].note.find("combination"), std::string::npos) << v[kC].note;
  // What remains is orthonormal: unit information each.
  EXPECT_NEAR(v[kA].stderr_log, 1e-2, kRecomputeTol);
  EXPECT_NEAR(v[kB].stderr_log, 1e-2, kRecomputeTol);
}

TEST(Identifiability, WellConditionedInformationGivesSqrtOfInverseDiagonal) {
  Eigen::Matrix3d j;
  j << 2.0, 0.3, -0.1, 0.4, 1.5, 0.2, -0.2, 0.1, 0.8;
  const Eigen::Matrix3d h = j.transpose() * j * 50.0;
  const double s2 = 0.02;
  const Eigen::Matrix3d inv = h.inverse();
  const auto v = AssessIdentifiability(h, s2);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(v[i].identifiable) << i << ": " << v[i].note;
    EXPECT_NEAR(v[i].stderr_log, std::sqrt(s2 * inv(i, i)), kRecomputeTol * std::sqrt(s2)) << i;
    EXPECT_TRUE(v[i].note.empty());
  }
}

TEST(Identifiability, HugeStandardErrorFlagsNotIdentifiable) {
  const Eigen::Matrix3d h = Eigen::Vector3d(100.0, 100.0, 1e-3).asDiagonal();
  const auto v = AssessIdentifiability(h, 1.0);  // se of log c = sqrt(1000) ~ 32
  EXPECT_TRUE(v[kA].identifiable);
  EXPECT_TRUE(v[kB].identifiable);
  EXPECT_FALSE(v[kC].identifiable);
  EXPECT_NE(v[kC].note.find("does not constrain"), std::string::npos) << v[kC].note;
  EXPECT_NEAR(v[kA].stderr_log, 0.1, kRecomputeTol);
}

TEST(Identifiability, HoldingAnUncorrelatedPartnerHidesNothing) {
  const Eigen::Matrix3d h = Eigen::Vector3d(100.0, 100.0, 1e-3).asDiagonal();
  const auto v = AssessIdentifiability(h, 1.0);
  ASSERT_FALSE(v[kC].identifiable);
  EXPECT_NEAR(v[kA].stderr_log_partners_free, v[kA].stderr_log, kRecomputeTol);
  EXPECT_TRUE(std::isnan(v[kC].stderr_log_partners_free));
}

TEST(Identifiability, ACorrelatedOneIsNotRescuedByHoldingItsPartner) {
  // a and b strongly (not exactly) correlated, b also weak: b's error exceeds the limit.
  // With b held, a's error is 0.1; but a moves with wherever b is held, and with b free
  // within the limit (prior variance 0.25) a's error is
  // sqrt(s2 (H + diag(0, s2 / 0.25))^-1_aa), computed here by Cramer's rule: beyond the
  // limit too (rule iv).
  Eigen::Matrix3d h;
  h << 1.0, 0.999, 0.0, 0.999, 0.9981, 0.0, 0.0, 0.0, 4.0;
  const double s2 = 0.01;
  const auto v = AssessIdentifiability(h, s2);
  EXPECT_FALSE(v[kB].identifiable);
  EXPECT_FALSE(v[kA].identifiable);
  EXPECT_NE(v[kA].note.find("determined only with a parameter"), std::string::npos) << v[kA].note;
  EXPECT_TRUE(v[kC].identifiable);
  const double bb = 0.9981 + s2 / (kMaxLogStdErr * kMaxLogStdErr);
  const double se_a = std::sqrt(s2 * bb / (1.0 * bb - 0.999 * 0.999));
  EXPECT_GT(se_a, kMaxLogStdErr);
  EXPECT_NEAR(v[kC].stderr_log, 0.05, kRecomputeTol);  // c is uncorrelated with both
}

TEST(Identifiability, AModeratelyCorrelatedOneKeepsItsValueWithTheHiddenVarianceReported) {
  // a correlated 0.6 with an undetermined c: a stays identifiable, and its error with c
  // free within the limit, sqrt(s2 (H + diag(0, 0, s2 / 0.25))^-1_aa), is reported for the
  // interval to carry.
  Eigen::Matrix3d h;
  h << 100.0, 0.0, 0.06, 0.0, 100.0, 0.0, 0.06, 0.0, 1e-4;
  const double s2 = 1.0;
  const auto v = AssessIdentifiability(h, s2);
  ASSERT_FALSE(v[kC].identifiable);
  ASSERT_TRUE(v[kA].identifiable);
  EXPECT_NEAR(v[kA].stderr_log, 0.1, kRecomputeTol);
  const double cc = 1e-4 + s2 / (kMaxLogStdErr * kMaxLogStdErr);
  const double expected = std::sqrt(s2 * cc / (100.0 * cc - 0.06 * 0.06));
  EXPECT_NEAR(v[kA].stderr_log_partners_free, expected, kRecomputeTol);
  EXPECT_GT(v[kA].stderr_log_partners_free, v[kA].stderr_log);
  EXPECT_NEAR(v[kB].stderr_log_partners_free, v[kB].stderr_log, kRecomputeTol);
}

TEST(Identifiability, InactiveParametersAreReportedHeld) {
  const Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
  const auto v = AssessIdentifiability(h, 0.01, {{true, false, true}});
  EXPECT_TRUE(v[kA].identifiable);
  EXPECT_FALSE(v[kB].identifiable);
  EXPECT_NE(v[kB].note.find("held"), std::string::npos);
  EXPECT_TRUE(v[kC].identifiable);
}

TEST(Identifiability, RejectsNonFiniteInformationAndNegativeVariance) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
  EXPECT_THROW(AssessIdentifiability(h, -1.0), std::invalid_argument);
  h(1, 1) = std::nan("");
  EXPECT_THROW(AssessIdentifiability(h, 1.0), std::invalid_argument);
}

TEST(Identifiability, LogEstimateGivesPositiveAsymmetricInterval) {
  const double value = 0.3, se = 0.2;
  const ParameterEstimate p = EstimateFromLog(std::log(value), se);
  EXPECT_TRUE(p.identifiable);
  EXPECT_NEAR(p.value, value, 1e-15);
  EXPECT_NEAR(p.stderr_value, value * se, 1e-15);
  EXPECT_NEAR(p.ci95_lo, value * std::exp(-kZ95 * se), 1e-15);
  EXPECT_NEAR(p.ci95_hi, value * std::exp(kZ95 * se), 1e-15);
  EXPECT_GT(p.ci95_lo, 0.0);
  EXPECT_GT(p.ci95_hi - p.value, p.value - p.ci95_lo);  // longer on the upper side
}

TEST(Identifiability, NotIdentifiableCarriesNaNAndHeldValue) {
  const ParameterEstimate p = NotIdentifiable(0.04, "why");
  EXPECT_FALSE(p.identifiable);
  EXPECT_TRUE(std::isnan(p.value));
  EXPECT_TRUE(std::isnan(p.stderr_value));
  EXPECT_TRUE(std::isnan(p.ci95_lo));
  EXPECT_EQ(p.held_at, 0.04);
  EXPECT_EQ(p.reason, "why");
  EXPECT_EQ(p.verdict, Verdict::kNotIdentifiable);
}

}  // namespace
}  // namespace slideid
