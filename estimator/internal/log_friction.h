#pragma once
// Where (a, b, c) meet Ceres. The least-squares fits work in log a, log b, log c (positive
// by construction, a relative step alike for all three), each a parameter block of one
// value: blocks 1-3 of a SegmentCost (segment_cost.h), global parameters 0-2 of a
// TrajectoryProblem (trajectory_problem.h), the theta of the equation-error and
// quasi-static fits, the online identifier's log-friction state. What comes before the
// solver (the seeds) and after it (estimates, replays) carries a ReducedFriction; these are
// the conversions between the two. Internal to the estimator.

#include <algorithm>
#include <cmath>

#include "forward_model/slider.h"

namespace slideid {

/// Search range of (a, b, c [m]): mu e_t from 1e-4 (ice) to 10, an anisotropy within 1e3
/// either way, a spin-resistance length from 1e-6 m to 10 m. Beyond these the step's
/// parameters under- or overflow (exp of the log-parameter).
constexpr ReducedFriction kFrictionLowerBound{1e-4, 1e-3, 1e-6};
constexpr ReducedFriction kFrictionUpperBound{10.0, 1e3, 10.0};

/// (a, b, c) brought inside the search range.
inline ReducedFriction ClampToSearchRange(const ReducedFriction& f) {
  return {std::clamp(f.a, kFrictionLowerBound.a, kFrictionUpperBound.a),
          std::clamp(f.b, kFrictionLowerBound.b, kFrictionUpperBound.b),
          std::clamp(f.c, kFrictionLowerBound.c, kFrictionUpperBound.c)};
}

/// log a, log b, log c, written to log_abc[0..2].
inline void ToLogParameters(const ReducedFriction& f, double* log_abc) {
  log_abc[0] = std::log(f.a);
  log_abc[1] = std::log(f.b);
  log_abc[2] = std::log(f.c);
}
/// (a, b, c) from log a, log b, log c at log_abc[0..2].
inline ReducedFriction FromLogParameters(const double* log_abc) {
  return {std::exp(log_abc[0]), std::exp(log_abc[1]), std::exp(log_abc[2])};
}
/// (a, b, c) from three parameter blocks of one value each, log a, log b, log c, as Ceres
/// hands them to a cost function (blocks[0] is log a's).
inline ReducedFriction FromLogBlocks(double const* const* blocks) {
  return {std::exp(blocks[0][0]), std::exp(blocks[1][0]), std::exp(blocks[2][0])};
}

}  // namespace slideid
