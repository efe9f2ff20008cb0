#include "estimator/internal/mismatch_nuisances.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "estimator/internal/segment_cost.h"

namespace slideid {
namespace {

double HorizontalForce(const AppliedWrench& w) { return std::hypot(w.fx, w.fy); }

// The directions X (raw, 3 rows per log row) as the row loss sees them: its linearisation
// at the segment's raw residuals r, dr~ = g dX + 2 g'(s) r (r . dX) per row
// (RowLossScalingAt, as SegmentCost::ApplyRowLoss for the Jacobian). Taking the difference
// of robustified residuals instead would put a part of r itself into X wherever the loss's
// weight changes between the two models, and the nuisance would then fit the noise of the
// rows near the loss's scale.
void ThroughRowLoss(const RowLoss& loss, const Eigen::VectorXd& r, Eigen::MatrixXd* X) {
  if (!loss.active()) return;
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

std::vector<char> HeldRows(const std::vector<RowForceChange>& kind, RowForceChange which) {
  std::vector<char> held(kind.size(), 0);
  // The last row has no next row to take a mean with (ClassifyForceChanges: kNone).
  for (size_t u = 0; u + 1 < kind.size(); ++u) held[u] = kind[u] == which;
  return held;
}

MismatchDirections::MismatchDirections(const TrajectoryProblem& problem)
    : problem_(problem), segments_of_log_(problem.num_logs(), 0) {
  const int logs = problem.num_logs();
  for (const TrajectorySegment& seg : problem.segments()) ++segments_of_log_[seg.log];
  // Which rows each variant holds at the mean of theirs and the next row's wrench: a byte per
  // row, where copies of the logs with their wrenches replaced took a whole log each. A log
  // without a switch direction gets no switch pass (a zero direction, which the fit leaves
  // out as undetermined).
  smooth_.resize(logs);
  jumps_.resize(logs);
  for (int k = 0; k < logs; ++k) {
    const std::vector<RowForceChange> kind = ClassifyForceChanges(problem.log(k));
    smooth_[k] = HeldRows(kind, RowForceChange::kSmooth);
    if (Switches(k)) jumps_[k] = HeldRows(kind, RowForceChange::kJump);
  }
}

bool MismatchDirections::Switches(int log) const {
  return segments_of_log_[log] >= kMinSwitchCorrectionSegments;
}

Eigen::MatrixXd MismatchDirections::operator()(int s) const {
  const TrajectorySegment& seg = problem_.segments()[s];
  const int substeps = problem_.substeps();
  const int n = 3 * (seg.last_row - seg.first_row + 1);
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(n, kMismatchNuisances * problem_.num_logs());
  const int column = kMismatchNuisances * seg.log;
  // The fit's own model at this point: Information() evaluated the segment's cost here just
  // before asking, so its cache answers without a simulation.
  const Eigen::VectorXd base = problem_.SegmentResiduals(s);
  if (base.size() != n) return X;
  const Eigen::VectorXd finer = problem_.SegmentResidualsWith(s, nullptr, 2 * substeps);
  if (finer.size() == n) X.col(column) = finer - base;
  // A variant holding none of the segment's rows differently is its own model: a zero
  // direction, without simulating it (on a smoothly pushed log, the switches' everywhere).
  auto variant = [&](const std::vector<char>& held, int col) {
    if (!seg.cost->Holds(held)) return;
    const Eigen::VectorXd r = problem_.SegmentResidualsWith(s, &held, substeps);
    if (r.size() == n) X.col(col) = r - base;
  };
  variant(smooth_[seg.log], column + 1);
  if (Switches(seg.log)) variant(jumps_[seg.log], column + 2);
  ThroughRowLoss(seg.cost->row_loss(), base, &X);
  return X;
}

}  // namespace slideid
