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
//  - the switches: where a push starts, ends or gives way to the next within an interval,
//    the logged rows say only that it happened somewhere in it.
// Each gets one nuisance parameter per log, linearised at the fit: the residuals become
// r + lambda_d (r_fine - r) + lambda_h (r_interp - r) + lambda_s (r_switch - r), with
// r_fine the residuals with twice the substeps, r_interp those with each row's wrench
// replaced by the mean of it and the next row's where the force varies smoothly (the
// interval's mean to first order), and r_switch the same at the jumps (a switch at the
// interval's middle), all at the fitted states and parameters. lambda = 0 is the fit's own model;
// the log says how far towards a finer model and an interpolated hold it points (a log made at its
// own rate with the force held exactly gives lambda ~ 0, a continuous one lambda_d ~ 2). The
// trajectory fit takes one Gauss-Newton step in the parameters and the lambdas together, and its
// intervals carry the lambdas' uncertainty.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "estimator/internal/trajectory_problem.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Nuisances per log k: discretisation (column 3k), force hold (3k + 1) and push switch
/// timing (3k + 2).
constexpr int kMismatchNuisances = 3;
/// "discretisation", "force hold", "push switch timing" for index 0, 1, 2.
const char* MismatchNuisanceName(int index);

/// A row is in contact when its horizontal force exceeds this fraction of the log's
/// largest: below it, a force channel reads the noise of an idle sensor, and the hold is
/// not interpolated across the start or end of a push (where the force jumps, and the
/// log's own row boundaries are the best guess of when).
constexpr double kContactForceFraction = 0.05;

/// How the force changes from a row to the next, within the interval the row's wrench is
/// held over.
enum class RowForceChange {
  kNone,    ///< no contact in either row
  kSmooth,  ///< both in contact, the change no larger than kJumpRatio times those beside it
  kJump,    ///< a push starts, ends or is replaced by another within the interval
};
/// A change of the force between two rows beyond this many times the changes beside it is a
/// jump (one push ends and the next starts within the interval), not a force varying
/// within it. The two get a nuisance each: with one for both (the mean of the two rows
/// wherever both were in contact), the jumps' timing dominated its direction, and on long
/// pushed logs of a 5-10x finer simulation the correction left a biased by -0.3% and c
/// by +0.9% (5 standard errors, scene suite logs 168, 356, 466; 0.02% and 0.1% with two).
constexpr double kJumpRatio = 3.0;
/// Per row, the change from it to the next (the last row: kNone).
std::vector<RowForceChange> ClassifyForceChanges(const Trajectory& log);

/// Per row, whether a variant of the log's wrenches holds the mean of the row's and the next
/// row's over the row's interval (SegmentCost::SetHeldRows): the rows of kind `which` (`kind`:
/// ClassifyForceChanges of the log). For kSmooth, the interval's mean to first order; for
/// kJump, a switch at the interval's middle.
std::vector<char> HeldRows(const std::vector<RowForceChange>& kind, RowForceChange which);

/// The push switches' timing (the third nuisance) has a direction only on logs of this many
/// segments: it matters on long pushed logs (scene suite log 230, 6613 rows: a -0.55%, 4.4
/// standard errors, without it), and on 300-row logs of 8 segments a third nuisance fitted
/// their noise (the coverage suite's `users`: a's interval covered 89.5%). Elsewhere its
/// direction is zero, and the fit leaves it out as undetermined.
constexpr int kMinSwitchCorrectionSegments = 16;

/// Per segment of `problem`, the residual directions of the nuisances:
/// rows x (kMismatchNuisances * num_logs), in the units of the row-loss residuals
/// (Information's `extra`), nonzero only in the segment's own log's columns. A segment
/// whose alternative residuals cannot be computed (a step fails) gets zeros there, and so
/// does the switch column of a log of fewer than kMinSwitchCorrectionSegments segments.
/// Computed a segment at a time (operator(), safe to call concurrently), at the problem's
/// current point, so that the directions of every segment (72 bytes a row) are never held
/// at once. The problem must outlive this.
class MismatchDirections {
 public:
  explicit MismatchDirections(const TrajectoryProblem& problem);
  /// Segment `s`'s directions.
  Eigen::MatrixXd operator()(int s) const;

 private:
  bool Switches(int log) const;

  const TrajectoryProblem& problem_;
  std::vector<int> segments_of_log_;
  std::vector<std::vector<char>> smooth_, jumps_;  // HeldRows per log (jumps_: when Switches)
};

}  // namespace slideid
