#pragma once
// A cluster-robust (sandwich) covariance that stays honest with few clusters: the
// bias-reduced linearisation of Bell and McCaffrey (2002), "CR2", with their
// Satterthwaite degrees of freedom for Student's t (as recommended by Imbens and Kolesar,
// "Robust standard errors in small samples", 2016, and Pustejovsky and Tipton, 2018).
//
// Setting: least squares with parameters theta (p of them) whose residuals fall into
// clusters, each with its own nuisance parameters (the trajectory fit's shooting segments
// with their states) that have been projected out. Cluster c brings its information
// B_c = J_c^T J_c and its score g_c = J_c^T r_c, J_c its rows of the projected Jacobian and
// r_c its residuals; H = sum B_c. The classic sandwich H^-1 (sum g g^T) H^-1 (times
// G / (G - 1): "CR1") is biased low: the fitted residuals of a cluster are smaller than its
// errors by its leverage J_c H^-1 J_c^T, the more so the fewer the clusters. CR2 undoes
// that, cluster by cluster: r_c -> (I - J_c H^-1 J_c^T)^(-1/2) r_c, which makes the
// estimate exactly unbiased when the errors are independent with equal variance, and
// nearly so otherwise. Its t quantile takes the degrees of freedom of the chi-square
// mixture the estimate follows under a working model of independent errors (at most G - 1,
// fewer when a few clusters carry most of the information or are much noisier than the
// others: each cluster may state its own error variance). Everything is computed in p x p terms per
// cluster: J_c = U S V^T gives (I - J_c H^-1 J_c^T)^(-1/2) U = U (I - K)^(-1/2) with
// K = S V^T H^-1 V S, so the cost is O(G p^3) however many rows a cluster has.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace slideid {

/// One cluster's share of a least-squares problem (nuisances projected out).
struct ClusterShare {
  Eigen::MatrixXd information;  ///< B_c = J_c^T J_c (p x p)
  Eigen::VectorXd score;        ///< g_c = J_c^T r_c (p)
  /// The variance of the cluster's errors under the working model of the degrees of
  /// freedom (any common unit; 1 for all: equal variances). The covariance itself does not
  /// depend on it.
  double working_variance = 1.0;
};

/// The CR2 covariance and, per parameter, its degrees of freedom.
struct ClusterCovariance {
  bool ok = false;
  /// Why not ok: fewer than 2 informative clusters, or one cluster that alone determines
  /// a parameter (leverage 1: its residuals say nothing about that parameter's error).
  std::string failure;
  Eigen::MatrixXd covariance;  ///< p x p
  Eigen::VectorXd dof;         ///< Bell-McCaffrey degrees of freedom per parameter
  int clusters = 0;            ///< clusters with information
};

/// A cluster's leverage eigenvalue at or above this is 1: the cluster alone determines a
/// direction of the parameters (its residuals carry none of that direction's error).
constexpr double kMaxClusterLeverage = 1.0 - 1e-9;

/// CR2 with Bell-McCaffrey degrees of freedom from the clusters' shares and the inverse of
/// H = sum of their information (given, since the caller has it).
ClusterCovariance ClusterRobustCovariance(const std::vector<ClusterShare>& clusters,
                                          const Eigen::MatrixXd& h_inverse);

}  // namespace slideid
