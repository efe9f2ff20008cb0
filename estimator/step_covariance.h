#pragma once
// Covariance of a sum of per-step scores when neighbouring steps share a sample: the cheap
// estimators' intervals (estimator/closed_form.h, estimator/equation_error.h).
//
// A step's impulse is m (v' - v): consecutive steps share a velocity sample, and with
// velocities differentiated from poses, v = (q - q_) / h, steps two apart share a pose.
// Their scores are then correlated (negatively: the noise of a shared sample enters two
// impulses with opposite signs and cancels in a sum over a sliding phase). A white-noise
// covariance ignores that and overstates the error (about 4x for the equation error's a on
// measured velocities). A truncated-kernel (Newey-West) estimate over single steps is
// unbiased but useless here: each step's score is dominated by the impulse noise that
// cancels, and the estimate of what remains varied 2-5x from one noise draw to the next.
//
// Blocks of kBlockSteps consecutive steps fix that. Within a block the shared samples
// cancel, and what a block's summed score keeps is the part that matters; only adjacent
// blocks of one sliding phase share a sample (at their boundary), and steps in different
// phases, or logs, share none. The block-level long-run covariance
//   S = sum_g S_g S_g^T + sum_{g, g+1 adjacent} (S_g S_{g+1}^T + S_{g+1} S_g^T)
// is then exact in expectation, and its noise is that of G block terms. It also holds a
// model mismatch that persists over a block (a push whose force varies within the log's
// intervals).

#include <Eigen/Core>
#include <vector>

namespace slideid {

/// Steps whose samples can be shared: measured velocities share one sample between
/// consecutive steps (lag 1); velocities differentiated from poses share a pose with the
/// step two ahead (lag 2).
constexpr int kMeasuredVelocityLag = 1;
constexpr int kDifferentiatedVelocityLag = 2;

/// Steps per block. The impulse noise that cancels within a block leaves two boundary
/// terms, while the noise that does not (the direction of sliding, force noise) grows with
/// the block: at 20 steps the latter dominates (3-10x the former per step at 2 mm/s), and
/// a 450-row log still has 10-20 blocks.
constexpr int kBlockSteps = 20;

/// Fewest blocks for a block-clustered interval; with fewer, the sum of G outer products
/// estimates the score covariance too poorly even with the t(G - 1) quantile, and the
/// interval falls back to independent steps (wider: it ignores the cancellation).
constexpr int kMinBlocks = 4;

/// Block ids of steps given by (log, row), sorted by (log, row), and whether each block
/// continues the previous one (adjacent in one sliding phase: rows within max_lag[log]). A
/// phase splits into blocks of kBlockSteps; a shorter remainder joins the previous block.
struct StepBlocks {
  std::vector<int> block;       ///< per step
  std::vector<bool> continues;  ///< per block: adjacent to the previous block
  int count = 0;
};
StepBlocks BlocksOfSteps(const std::vector<int>& log, const std::vector<int>& row,
                         const std::vector<int>& max_lag);

/// The block-level long-run covariance of sum_i s_i (rows of `scores`, n x p) above, with
/// the small-sample factor G / (G - 1). May be indefinite; callers check the diagonal.
Eigen::MatrixXd BlockScoreCovariance(const Eigen::MatrixXd& scores, const StepBlocks& blocks);

/// The cluster-robust covariance of sum_i s_i with clusters `cluster` (ids, any order,
/// independent of each other): G / (G - 1) sum_c S_c S_c^T; a zero matrix when G < 2.
/// `clusters` receives G.
Eigen::MatrixXd ClusterScoreCovariance(const Eigen::MatrixXd& scores,
                                       const std::vector<int>& cluster, int* clusters);

}  // namespace slideid
