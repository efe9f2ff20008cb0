#include "estimator/step_covariance.h"

#include <map>

namespace slideid {

StepBlocks BlocksOfSteps(const std::vector<int>& log, const std::vector<int>& row,
                         const std::vector<int>& max_lag) {
  StepBlocks b;
  const size_t n = log.size();
  b.block.assign(n, 0);
  size_t start = 0;
  while (start < n) {
    // One sliding phase: [start, end).
    size_t end = start + 1;
    while (end < n && log[end] == log[start] && row[end] - row[end - 1] <= max_lag[log[start]]) {
      ++end;
    }
    const size_t length = end - start;
    const size_t blocks = std::max<size_t>(1, length / kBlockSteps);
    for (size_t k = 0; k < blocks; ++k) {
      b.continues.push_back(k > 0);
      const size_t first = start + k * kBlockSteps;
      const size_t last = k + 1 == blocks ? end : first + kBlockSteps;
      for (size_t i = first; i < last; ++i) b.block[i] = b.count;
      ++b.count;
    }
    start = end;
  }
  return b;
}

Eigen::MatrixXd BlockScoreCovariance(const Eigen::MatrixXd& scores, const StepBlocks& blocks) {
  const Eigen::Index p = scores.cols();
  Eigen::MatrixXd sums = Eigen::MatrixXd::Zero(blocks.count, p);
  for (Eigen::Index i = 0; i < scores.rows(); ++i) sums.row(blocks.block[i]) += scores.row(i);
  Eigen::MatrixXd cov = sums.transpose() * sums;
  for (int g = 1; g < blocks.count; ++g) {
    if (!blocks.continues[g]) continue;
    const Eigen::MatrixXd cross = sums.row(g - 1).transpose() * sums.row(g);
    cov += cross + cross.transpose();
  }
  const int g = blocks.count;
  return g >= 2 ? Eigen::MatrixXd(cov * (double(g) / (g - 1))) : cov;
}

Eigen::MatrixXd ClusterScoreCovariance(const Eigen::MatrixXd& scores,
                                       const std::vector<int>& cluster, int* clusters) {
  const Eigen::Index p = scores.cols();
  std::map<int, Eigen::VectorXd> sums;
  for (Eigen::Index i = 0; i < scores.rows(); ++i) {
    auto [it, inserted] = sums.try_emplace(cluster[i], Eigen::VectorXd::Zero(p));
    it->second += scores.row(i).transpose();
  }
  const int g = static_cast<int>(sums.size());
  *clusters = g;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(p, p);
  if (g < 2) return cov;
  for (const auto& [id, sum] : sums) cov += sum * sum.transpose();
  return cov * (double(g) / (g - 1));
}

}  // namespace slideid
