#include "estimator/internal/mismatch_nuisances.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "estimator/internal/segment_cost.h"

namespace slideid {
namespace {

double HorizontalForce(const AppliedWrench& w) { return std::hypot(w.fx, w.fy); }

AppliedWrench Mean(const AppliedWrench& a, const AppliedWrench& b) {
  return {0.5 * (a.fx + b.fx), 0.5 * (a.fy + b.fy), 0.5 * (a.fz + b.fz),
          0.5 * (a.tx + b.tx), 0.5 * (a.ty + b.ty), 0.5 * (a.tz + b.tz)};
}

// The directions X (raw, 3 rows per log row) as the row loss sees them: its linearisation
// at the segment's raw residuals r, dr~ = g dX + 2 g'(s) r (r . dX) per row
// (RowLossScalingAt, as SegmentCost::ApplyRowLoss for the Jacobian). Taking the difference
// of robustified residuals instead would put a part of r itself into X wherever the loss's
// weight changes between the two models, and the nuisance would then fit the noise of the
// rows near the loss's scale.
void ThroughRowLoss(const RowLoss& loss, const Eigen::VectorXd& r, Eigen::MatrixXd* X) {
  if (loss.kind == RobustLoss::kNone || !(loss.scale > 0)) return;
  for (int i = 0; 3 * i < r.size(); ++i) {
    const Eigen::Vector3d row = r.segment<3>(3 * i);
    const auto [g, g_prime] = RowLossScalingAt(loss, row.squaredNorm());
    auto block = X->middleRows<3>(3 * i);
    const Eigen::RowVectorXd along = row.transpose() * block;
    block = g * block + 2.0 * g_prime * row * along;
  }
}

}  // namespace

const char* MismatchNuisanceName(int index) {
  static const char* const kNames[kMismatchNuisances] = {"discretisation", "force hold",
                                                         "push switch timing"};
  return index >= 0 && index < kMismatchNuisances ? kNames[index] : "?";
}

std::vector<RowForceChange> ClassifyForceChanges(const Trajectory& log) {
  const std::vector<TrajectorySample>& rows = log.samples;
  std::vector<RowForceChange> kind(rows.size(), RowForceChange::kNone);
  double largest = 0;
  for (const TrajectorySample& s : rows) largest = std::max(largest, HorizontalForce(s.applied));
  const double contact = kContactForceFraction * largest;
  if (!(contact > 0)) return kind;
  const auto change = [&](size_t u) {  // of the horizontal force from row u to u + 1
    return std::hypot(rows[u + 1].applied.fx - rows[u].applied.fx,
                      rows[u + 1].applied.fy - rows[u].applied.fy);
  };
  for (size_t u = 0; u + 1 < rows.size(); ++u) {
    const bool here = HorizontalForce(rows[u].applied) > contact;
    const bool next = HorizontalForce(rows[u + 1].applied) > contact;
    if (!here && !next) continue;
    if (here != next) {
      kind[u] = RowForceChange::kJump;  // a push starts or ends within the interval
      continue;
    }
    double around = 0;
    if (u > 0) around = std::max(around, change(u - 1));
    if (u + 2 < rows.size()) around = std::max(around, change(u + 1));
    kind[u] = change(u) > kJumpRatio * around + 1e-9 * largest ? RowForceChange::kJump
                                                               : RowForceChange::kSmooth;
  }
  return kind;
}

Trajectory HoldVariant(const Trajectory& log, const std::vector<RowForceChange>& kind,
                       RowForceChange which) {
  Trajectory out = log;
  for (size_t u = 0; u + 1 < log.samples.size(); ++u) {
    if (kind[u] == which)
      out.samples[u].applied = Mean(log.samples[u].applied, log.samples[u + 1].applied);
  }
  return out;
}

std::vector<Eigen::MatrixXd> MismatchDirections(const TrajectoryProblem& problem) {
  const int logs = problem.num_logs();
  const std::vector<TrajectorySegment>& segments = problem.segments();
  std::vector<int> segments_of_log(logs, 0);
  for (const TrajectorySegment& seg : segments) ++segments_of_log[seg.log];
  const auto switches = [&](int k) { return segments_of_log[k] >= kMinSwitchCorrectionSegments; };
  // Logs without a switch direction keep their own wrenches in its pass (a zero direction,
  // which the fit leaves out as undetermined); without any such log the pass is skipped.
  std::vector<Trajectory> interpolated, switched;
  interpolated.reserve(logs);
  switched.reserve(logs);
  std::vector<const Trajectory*> own, held, switch_held;
  for (int k = 0; k < logs; ++k) {
    const Trajectory& log = problem.log(k);
    const std::vector<RowForceChange> kind = ClassifyForceChanges(log);
    own.push_back(&log);
    interpolated.push_back(HoldVariant(log, kind, RowForceChange::kSmooth));
    held.push_back(&interpolated.back());
    if (switches(k)) switched.push_back(HoldVariant(log, kind, RowForceChange::kJump));
    switch_held.push_back(switches(k) ? &switched.back() : &log);
  }
  const int substeps = problem.substeps();
  const std::vector<Eigen::VectorXd> base = problem.SegmentResidualsWith(own, substeps);
  const std::vector<Eigen::VectorXd> finer = problem.SegmentResidualsWith(own, 2 * substeps);
  const std::vector<Eigen::VectorXd> hold = problem.SegmentResidualsWith(held, substeps);
  const std::vector<Eigen::VectorXd> jump =
      switched.empty() ? std::vector<Eigen::VectorXd>(segments.size())
                       : problem.SegmentResidualsWith(switch_held, substeps);

  std::vector<Eigen::MatrixXd> directions;
  for (size_t s = 0; s < segments.size(); ++s) {
    const int n = 3 * (segments[s].last_row - segments[s].first_row + 1);
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(n, kMismatchNuisances * logs);
    const int column = kMismatchNuisances * segments[s].log;
    if (base[s].size() == n) {
      if (finer[s].size() == n) X.col(column) = finer[s] - base[s];
      if (hold[s].size() == n) X.col(column + 1) = hold[s] - base[s];
      if (switches(segments[s].log) && jump[s].size() == n) X.col(column + 2) = jump[s] - base[s];
      ThroughRowLoss(segments[s].cost->row_loss(), base[s], &X);
    }
    directions.push_back(std::move(X));
  }
  return directions;
}

}  // namespace slideid
