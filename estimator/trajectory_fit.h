#pragma once
// The trajectory (output-error) estimator: Ceres robust least squares of the simulated
// trajectory against the measured one over the whole log.
//
// The log is cut into shooting segments of EstimatorOptions::segment_steps intervals. Each
// segment's initial state (x, y, theta, v_x, v_y, w_z) is a parameter block of its own and
// (log a, log b, log c) are shared, the structure of bundle adjustment, solved with Ceres'
// Schur complement (segments eliminated first). Within a segment the forward model is
// simulated from the segment's state with the logged applied wrench, substeps per log
// interval, sticking included; the residuals are the measured poses (or velocities, for a
// log without poses) minus the simulated ones. Segments are independent shooting intervals:
// each measurement enters once, and the interval between two segments is not used.
// Derivatives through each step are exact (estimator/step_sensitivity.h).

#include <ceres/cost_function.h>

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Fits (a, b, c) to `log` (slider properties set; rows strictly increasing in time).
/// Seeds from the equation-error estimate (or the closed form, or defaults). Throws
/// std::invalid_argument for a log too short or with too little sliding.
EstimateResult EstimateTrajectory(const Trajectory& log, const EstimatorOptions& options);

/// The cost of one shooting segment (rows first_row..last_row of `log`, which must outlive
/// it): parameter blocks (x, y, theta, v_x, v_y, w_z) at first_row, log a, log b, log c;
/// 3 residuals per row (poses, or velocities when use_pose is false, the angular channel
/// times the radius of gyration). Exposed for derivative checks.
ceres::CostFunction* NewSegmentCost(const Trajectory& log, int first_row, int last_row,
                                    int substeps, bool use_pose);

}  // namespace slideid
