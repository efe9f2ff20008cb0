#pragma once
// One entry point for the estimators. What identify prints and writes of the result is in
// io/result_report.h (table, residuals CSV) and io/result_json.h (JSON).


#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Runs the estimator named by options.method on `log`.
EstimateResult Identify(const Trajectory& log, const EstimatorOptions& options);

}  // namespace slideid
