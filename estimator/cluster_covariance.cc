#include "estimator/cluster_covariance.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace slideid {
namespace {

// Directions of a cluster's information below this fraction of its largest eigenvalue, or
// of the total information's trace, carry nothing (a segment that does not feel a
// parameter): they are left out of its leverage.
constexpr double kRelativeRank = 1e-10;
constexpr double kAbsoluteRank = 1e-14;

// One cluster's CR2 factors in the scaled parameters: the score adjustment T (g -> T g)
// and, for the degrees of freedom, Y = V S F S V^T and Y2 = V S F^2 S V^T with
// F = (I - K)^(-1/2), so that for a parameter combination a the cluster's column of the
// Satterthwaite matrix is w = Y a with squared norm a^T Y2 a.
struct Factors {
  bool informative = false;
  bool full_leverage = false;
  Eigen::MatrixXd T, Y, Y2;
  Eigen::MatrixXd B;    // the cluster's information, scaled
  double variance = 1;  // its working variance
};

Factors ClusterFactors(const Eigen::MatrixXd& B, const Eigen::MatrixXd& Hinv, double trace_h) {
  Factors f;
  const int p = static_cast<int>(B.rows());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (B + B.transpose()));
  const double largest = eig.eigenvalues().maxCoeff();
  std::vector<int> kept;
  for (int i = 0; i < p; ++i) {
    const double l = eig.eigenvalues()(i);
    if (l > kRelativeRank * largest && l > kAbsoluteRank * trace_h) kept.push_back(i);
  }
  if (kept.empty()) return f;
  f.informative = true;
  const int r = static_cast<int>(kept.size());
  Eigen::MatrixXd V(p, r);
  Eigen::VectorXd s(r);
  for (int j = 0; j < r; ++j) {
    V.col(j) = eig.eigenvectors().col(kept[j]);
    s(j) = std::sqrt(eig.eigenvalues()(kept[j]));
  }
  const Eigen::MatrixXd VS = V * s.asDiagonal();
  const Eigen::MatrixXd K = VS.transpose() * Hinv * VS;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> leverage(0.5 * (K + K.transpose()));
  const Eigen::VectorXd gamma = leverage.eigenvalues();
  if (gamma.maxCoeff() >= kMaxClusterLeverage) {
    f.full_leverage = true;
    return f;
  }
  const Eigen::MatrixXd& Q = leverage.eigenvectors();
  Eigen::VectorXd root(r), inverse(r);
  for (int j = 0; j < r; ++j) {
    const double one_minus = 1.0 - std::max(0.0, gamma(j));
    inverse(j) = 1.0 / one_minus;
    root(j) = std::sqrt(inverse(j));
  }
  const Eigen::MatrixXd F = Q * root.asDiagonal() * Q.transpose();
  const Eigen::MatrixXd F2 = Q * inverse.asDiagonal() * Q.transpose();
  f.T = VS * F * s.cwiseInverse().asDiagonal() * V.transpose();
  f.Y = VS * F * VS.transpose();
  f.Y2 = VS * F2 * VS.transpose();
  return f;
}

}  // namespace

ClusterCovariance ClusterRobustCovariance(const std::vector<ClusterShare>& clusters,
                                          const Eigen::MatrixXd& h_inverse) {
  ClusterCovariance out;
  const int p = static_cast<int>(h_inverse.rows());
  if (p == 0) {
    out.failure = "no parameters";
    return out;
  }
  // Scale the parameters to unit information so that rank decisions do not depend on
  // their units (log-parameters, newtons, seconds).
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(p, p);
  for (const ClusterShare& c : clusters) H += c.information;
  Eigen::VectorXd d(p);
  for (int k = 0; k < p; ++k) d(k) = H(k, k) > 0 ? std::sqrt(H(k, k)) : 1.0;
  const Eigen::MatrixXd Hinv = d.asDiagonal() * h_inverse * d.asDiagonal();
  const double trace_h =
      (d.cwiseInverse().asDiagonal() * H * d.cwiseInverse().asDiagonal()).trace();

  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  std::vector<Factors> factors;
  bool full_leverage = false;
  for (const ClusterShare& c : clusters) {
    const Eigen::MatrixXd B =
        d.cwiseInverse().asDiagonal() * c.information * d.cwiseInverse().asDiagonal();
    Factors f = ClusterFactors(B, Hinv, trace_h);
    full_leverage = full_leverage || f.full_leverage;
    if (!f.informative || f.full_leverage) continue;
    const Eigen::VectorXd g = f.T * (d.cwiseInverse().asDiagonal() * c.score);
    meat += g * g.transpose();
    f.B = B;
    f.variance = c.working_variance > 0 ? c.working_variance : 1.0;
    factors.push_back(std::move(f));
  }
  out.clusters = static_cast<int>(factors.size()) + (full_leverage ? 1 : 0);
  if (out.clusters < 2) {
    out.failure = "fewer than 2 clusters with information";
    return out;
  }
  if (full_leverage) {
    out.failure = "one cluster alone determines a parameter (leverage 1)";
    return out;
  }
  const Eigen::MatrixXd V = Hinv * meat * Hinv;
  out.covariance = d.cwiseInverse().asDiagonal() * V * d.cwiseInverse().asDiagonal();

  // Bell-McCaffrey degrees of freedom of each parameter under the working model of
  // independent errors with each cluster's own variance s_c^2 (S = diag(s_c^2)):
  // (tr A)^2 / ||A||_F^2 with A = diag(s_c^2 |v_c|^2) - S W^T H^-1 W - W^T H^-1 W S
  // + W^T Q W, Q = H^-1 (sum s_c^2 B_c) H^-1. A = D + L with L = P1 Q1^T of rank 3p
  // (P1 = [S W^T, W^T, W^T], Q1 = [-W^T H^-1, -S W^T H^-1, W^T Q]), so that
  // ||A||^2 = ||D||^2 + 2 sum_c D_cc L_cc + tr((P1^T P1)(Q1^T Q1)): O(G p^2).
  Eigen::MatrixXd Omega = Eigen::MatrixXd::Zero(p, p);
  for (const Factors& f : factors) Omega += f.variance * f.B;
  const Eigen::MatrixXd Q = Hinv * Omega * Hinv;
  out.dof.resize(p);
  for (int k = 0; k < p; ++k) {
    const Eigen::VectorXd a = Hinv.col(k);
    double trace = 0, diagonal2 = 0, cross = 0;
    Eigen::MatrixXd Pg = Eigen::MatrixXd::Zero(3 * p, 3 * p), Qg = Pg;
    Eigen::VectorXd pc(3 * p), qc(3 * p);
    for (const Factors& f : factors) {
      const double s2 = f.variance;
      const double dc = s2 * a.dot(f.Y2 * a);
      const Eigen::VectorXd w = f.Y * a;
      const Eigen::VectorXd Hw = Hinv * w;
      const double lcc = -2.0 * s2 * w.dot(Hw) + w.dot(Q * w);
      trace += dc + lcc;
      diagonal2 += dc * dc;
      cross += dc * lcc;
      pc << s2 * w, w, w;
      qc << -Hw, -s2 * Hw, Q * w;
      Pg += pc * pc.transpose();
      Qg += qc * qc.transpose();
    }
    const double frobenius2 = diagonal2 + 2.0 * cross + (Pg * Qg).trace();
    out.dof(k) = frobenius2 > 0 && trace > 0 ? trace * trace / frobenius2 : 1.0;
    out.dof(k) = std::clamp(out.dof(k), 1.0, double(out.clusters - 1));
  }
  out.ok = true;
  return out;
}

}  // namespace slideid
