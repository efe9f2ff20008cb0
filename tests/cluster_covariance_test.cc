// The small-sample cluster-robust covariance (CR2 with Bell-McCaffrey degrees of freedom):
// on linear models with few clusters, each with its own intercept projected out (as the
// trajectory fit's segments have their states), its intervals must hold the truth 95% of
// the time, where the classic sandwich (CR1) with t(G - 1) falls short.

#include "estimator/cluster_covariance.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "estimator/pooling.h"

namespace slideid {
namespace {

constexpr int kParameters = 2;
const Eigen::Vector2d kTruth(0.7, -1.3);

/// One least-squares problem: G clusters of `rows` rows, regressors drawn per row (cluster
/// `lever` has regressors `lever_scale` times larger: unbalanced leverage), each cluster
/// with its own intercept; errors with standard deviation `sigma` plus, when `shared` > 0,
/// a random slope per cluster (errors correlated within a cluster).
struct Problem {
  std::vector<ClusterShare> shares;
  Eigen::MatrixXd h_inverse;
  Eigen::Vector2d estimate;
};

Problem Draw(std::mt19937_64& rng, int clusters, int rows, double lever_scale, double shared) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Eigen::MatrixXd> X(clusters);
  std::vector<Eigen::VectorXd> y(clusters);
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  for (int c = 0; c < clusters; ++c) {
    X[c].resize(rows, kParameters);
    y[c].resize(rows);
    const double scale = c == 0 ? lever_scale : 1.0;
    const Eigen::Vector2d slope_error(shared * normal(rng), shared * normal(rng));
    for (int i = 0; i < rows; ++i) {
      X[c](i, 0) = scale * normal(rng);
      X[c](i, 1) = scale * (0.5 * X[c](i, 0) / scale + normal(rng));
      y[c](i) = X[c].row(i).dot(kTruth + slope_error) + normal(rng) + 3.0;  // + intercept
    }
    // Project the cluster's intercept out (its own nuisance parameter).
    X[c].rowwise() -= X[c].colwise().mean();
    y[c].array() -= y[c].mean();
    H += X[c].transpose() * X[c];
    b += X[c].transpose() * y[c];
  }
  Problem p;
  p.h_inverse = H.inverse();
  p.estimate = p.h_inverse * b;
  for (int c = 0; c < clusters; ++c) {
    const Eigen::VectorXd r = y[c] - X[c] * p.estimate;
    p.shares.push_back({X[c].transpose() * X[c], X[c].transpose() * r});
  }
  return p;
}

struct Coverage {
  int cr2 = 0, cr1 = 0, runs = 0;
  double mean_dof = 0;
};

Coverage Simulate(int clusters, int rows, double lever_scale, double shared, int runs) {
  std::mt19937_64 rng(12345);
  Coverage c;
  for (int run = 0; run < runs; ++run) {
    const Problem p = Draw(rng, clusters, rows, lever_scale, shared);
    const ClusterCovariance v = ClusterRobustCovariance(p.shares, p.h_inverse);
    EXPECT_TRUE(v.ok) << v.failure;
    if (!v.ok) return c;
    Eigen::Matrix2d meat = Eigen::Matrix2d::Zero();
    for (const ClusterShare& s : p.shares) meat += s.score * s.score.transpose();
    const Eigen::Matrix2d cr1 =
        p.h_inverse * meat * p.h_inverse * (double(clusters) / (clusters - 1));
    for (int k = 0; k < kParameters; ++k) {
      const double error = std::abs(p.estimate(k) - kTruth(k));
      c.cr2 += error <= StudentT95(v.dof(k)) * std::sqrt(v.covariance(k, k));
      c.cr1 += error <= StudentT95(clusters - 1) * std::sqrt(cr1(k, k));
      c.mean_dof += v.dof(k) / (kParameters * runs);
    }
    c.runs += kParameters;
  }
  return c;
}

// 4000 intervals: a true 95% covers 95% +- 0.34% (one binomial standard error); the band
// below is about 3 of those, and CR1 is known to fall below it with 6 clusters.
constexpr int kRuns = 2000;
constexpr double kLow = 0.94, kHigh = 0.96;

TEST(ClusterCovariance, CoversNinetyFivePercentWithSixBalancedClusters) {
  const Coverage c = Simulate(6, 10, 1.0, 0.0, kRuns);
  EXPECT_GE(double(c.cr2) / c.runs, kLow);
  EXPECT_LE(double(c.cr2) / c.runs, kHigh);
  EXPECT_LT(c.cr1, c.cr2);  // the classic sandwich claims more than it knows
  EXPECT_LE(c.mean_dof, 5.0 + 1e-12);
}

TEST(ClusterCovariance, StaysHonestWhenOneClusterCarriesMostOfTheInformation) {
  // One cluster's regressors 4x larger: 16x the information of each other one. Its
  // leverage makes CR1 cover far too rarely; CR2's degrees of freedom drop to match, and
  // err on the side of caution (Satterthwaite's approximation of the chi-square mixture is
  // conservative when one cluster dominates: 98.6% here).
  const Coverage c = Simulate(8, 10, 4.0, 0.0, kRuns);
  EXPECT_GE(double(c.cr2) / c.runs, kLow);
  EXPECT_LE(double(c.cr2) / c.runs, 0.99);
  EXPECT_LT(double(c.cr1) / c.runs, kLow);
  EXPECT_LT(c.mean_dof, 4.0);  // far below G - 1 = 7
}

TEST(ClusterCovariance, CoversWhenErrorsAreCorrelatedWithinClusters) {
  // A random slope per cluster: the white-noise covariance would claim far too much; the
  // sandwich sees it. The working model of the degrees of freedom is then only
  // approximate, hence a wider band.
  const Coverage c = Simulate(10, 20, 1.0, 0.3, kRuns);
  EXPECT_GE(double(c.cr2) / c.runs, 0.93);
  EXPECT_LE(double(c.cr2) / c.runs, 0.97);
}

TEST(ClusterCovariance, IsUnbiasedUnderIndependentErrors) {
  // E[CR2] = sigma^2 H^-1 exactly when the errors are independent with equal variance
  // (sigma = 1 here): the mean over many draws of the same design is within a few of its
  // standard errors of it.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int clusters = 5, rows = 8;
  std::vector<Eigen::MatrixXd> X;  // one fixed design, unbalanced (cluster 0 2x larger)
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  for (int c = 0; c < clusters; ++c) {
    Eigen::MatrixXd x(rows, kParameters);
    for (int i = 0; i < rows; ++i) {
      for (int k = 0; k < kParameters; ++k) x(i, k) = (c == 0 ? 2.0 : 1.0) * normal(rng);
    }
    x.rowwise() -= x.colwise().mean();
    H += x.transpose() * x;
    X.push_back(x);
  }
  const Eigen::Matrix2d Hinv = H.inverse();
  constexpr int kDraws = 20000;
  Eigen::Matrix2d mean = Eigen::Matrix2d::Zero();
  Eigen::Vector2d second = Eigen::Vector2d::Zero();
  for (int d = 0; d < kDraws; ++d) {
    std::vector<Eigen::VectorXd> e;
    Eigen::Vector2d b = Eigen::Vector2d::Zero();
    for (const Eigen::MatrixXd& x : X) {
      Eigen::VectorXd v(rows);
      for (int i = 0; i < rows; ++i) v(i) = normal(rng);
      v.array() -= v.mean();
      b += x.transpose() * v;
      e.push_back(v);
    }
    const Eigen::Vector2d beta = Hinv * b;
    std::vector<ClusterShare> shares;
    for (int c = 0; c < clusters; ++c) {
      shares.push_back({X[c].transpose() * X[c], X[c].transpose() * (e[c] - X[c] * beta)});
    }
    const ClusterCovariance v = ClusterRobustCovariance(shares, Hinv);
    ASSERT_TRUE(v.ok);
    mean += v.covariance / kDraws;
    second += v.covariance.diagonal().cwiseAbs2() / kDraws;
  }
  for (int k = 0; k < kParameters; ++k) {
    const double sd = std::sqrt((second(k) - mean(k, k) * mean(k, k)) / kDraws);
    EXPECT_NEAR(mean(k, k), Hinv(k, k), 4 * sd) << k;
  }
}

TEST(ClusterCovariance, SaysWhyWhenItCannotBeComputed) {
  std::mt19937_64 rng(3);
  Problem p = Draw(rng, 1, 10, 1.0, 0.0);
  ClusterCovariance v = ClusterRobustCovariance(p.shares, p.h_inverse);
  EXPECT_FALSE(v.ok);
  EXPECT_NE(v.failure.find("fewer than 2 clusters"), std::string::npos) << v.failure;

  // A cluster that alone determines a direction: only it moves the second parameter.
  p = Draw(rng, 4, 10, 1.0, 0.0);
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  for (size_t c = 0; c < p.shares.size(); ++c) {
    ClusterShare& s = p.shares[c];
    if (c > 0) {
      s.information.row(1).setZero();
      s.information.col(1).setZero();
      s.score(1) = 0;
    }
    H += s.information;
  }
  v = ClusterRobustCovariance(p.shares, H.inverse());
  EXPECT_FALSE(v.ok);
  EXPECT_NE(v.failure.find("leverage 1"), std::string::npos) << v.failure;
}

}  // namespace
}  // namespace slideid
