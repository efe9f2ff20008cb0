#include "estimator/mismatch_nuisances.h"

#include <algorithm>
#include <cmath>

namespace slideid {
namespace {

double HorizontalForce(const AppliedWrench& w) { return std::hypot(w.fx, w.fy); }

AppliedWrench Mean(const AppliedWrench& a, const AppliedWrench& b) {
  return {0.5 * (a.fx + b.fx), 0.5 * (a.fy + b.fy), 0.5 * (a.fz + b.fz),
          0.5 * (a.tx + b.tx), 0.5 * (a.ty + b.ty), 0.5 * (a.tz + b.tz)};
}

}  // namespace

const char* MismatchNuisanceName(int index) {
  return index == 0 ? "discretisation" : "force hold";
}

Trajectory InterpolatedHold(const Trajectory& log) {
  Trajectory out = log;
  double largest = 0;
  for (const TrajectorySample& s : log.samples) largest = std::max(largest, HorizontalForce(s.applied));
  const double contact = kContactForceFraction * largest;
  if (!(contact > 0)) return out;
  for (size_t u = 0; u + 1 < log.samples.size(); ++u) {
    const AppliedWrench& here = log.samples[u].applied;
    const AppliedWrench& next = log.samples[u + 1].applied;
    if (HorizontalForce(here) > contact && HorizontalForce(next) > contact) {
      out.samples[u].applied = Mean(here, next);
    }
  }
  return out;
}

std::vector<Eigen::MatrixXd> MismatchDirections(const TrajectoryProblem& problem) {
  const int logs = problem.num_logs();
  std::vector<const Trajectory*> own;
  std::vector<Trajectory> interpolated;
  interpolated.reserve(logs);
  for (int k = 0; k < logs; ++k) {
    own.push_back(&problem.log(k));
    interpolated.push_back(InterpolatedHold(problem.log(k)));
  }
  std::vector<const Trajectory*> held;
  for (const Trajectory& t : interpolated) held.push_back(&t);
  const int substeps = problem.substeps();
  const std::vector<Eigen::VectorXd> base = problem.SegmentResidualsWith(own, substeps);
  const std::vector<Eigen::VectorXd> finer = problem.SegmentResidualsWith(own, 2 * substeps);
  const std::vector<Eigen::VectorXd> hold = problem.SegmentResidualsWith(held, substeps);

  std::vector<Eigen::MatrixXd> directions;
  const std::vector<TrajectorySegment>& segments = problem.segments();
  for (size_t s = 0; s < segments.size(); ++s) {
    const int n = 3 * (segments[s].last_row - segments[s].first_row + 1);
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(n, kMismatchNuisances * logs);
    const int column = kMismatchNuisances * segments[s].log;
    if (base[s].size() == n) {
      if (finer[s].size() == n) X.col(column) = finer[s] - base[s];
      if (hold[s].size() == n) X.col(column + 1) = hold[s] - base[s];
    }
    directions.push_back(std::move(X));
  }
  return directions;
}

}  // namespace slideid
