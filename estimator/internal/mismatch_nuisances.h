#pragma once
// Linearised model-mismatch nuisances of the trajectory fit (estimator/trajectory_fit.h).
//
// The fit's model holds each row's logged wrench over the row's interval and takes
// `substeps` backward-Euler steps per interval. A log of a continuous motion (any real
// log, or one simulated finer than it is logged) differs from that model in two ways that
// the log's noise does not show and that more rows do not average away:
//  - discretisation: a backward-Euler step moves the pose with the step's end velocity and
//    takes the friction direction at the step's end, so where the slider accelerates or
//    turns the model's poses lead a continuous motion's by about half a step;
//  - the hold: a logger that samples the force at the row's time while the push varies
//    within the interval (it oscillates, or turns with a spinning slider) logs a force that
//    leads the interval's mean by about half a row.
// Both bias the estimate (on 100 Hz logs of a 1 kHz simulation, about 0.2% in a and 0.3%
// in c), and no covariance computed from the fit's own scores can see a bias (at the
// optimum the scores sum to zero whatever the mismatch).
//
// Each gets one nuisance parameter per log, linearised at the fit: the residuals become
// r + lambda_d (r_fine - r) + lambda_h (r_interp - r), with r_fine the residuals with twice
// the substeps and r_interp those with each row's wrench replaced by the mean of it and
// the next row's while the push stays in contact (the interval's mean to first order),
// both at the fitted states and parameters. lambda = 0 is the fit's own model; the log
// says how far towards a finer model and an interpolated hold it points (a log made at
// its own rate with the force held exactly gives lambda ~ 0, a continuous one
// lambda_d ~ 2). The trajectory fit takes one Gauss-Newton step in the parameters and the
// lambdas together, and its intervals carry the lambdas' uncertainty.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "estimator/internal/trajectory_problem.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Nuisances per log: discretisation (column 2k for log k) and force hold (2k + 1).
constexpr int kMismatchNuisances = 2;
/// "discretisation", "force hold" for index 0, 1.
const char* MismatchNuisanceName(int index);

/// A row is in contact when its horizontal force exceeds this fraction of the log's
/// largest: below it, a force channel reads the noise of an idle sensor, and the hold is
/// not interpolated across the start or end of a push (where the force jumps, and the
/// log's own row boundaries are the best guess of when).
constexpr double kContactForceFraction = 0.05;

/// `log` with each row's wrench replaced by the mean of it and the next row's wherever
/// both rows are in contact (kContactForceFraction).
Trajectory InterpolatedHold(const Trajectory& log);

/// Per segment of `problem` (in order), the residual directions of the nuisances:
/// rows x (kMismatchNuisances * num_logs), in the units of the row-loss residuals
/// (Information's `extra`), nonzero only in the segment's own log's columns. A segment
/// whose alternative residuals cannot be computed (a step fails) gets zeros there.
std::vector<Eigen::MatrixXd> MismatchDirections(const TrajectoryProblem& problem);

}  // namespace slideid
