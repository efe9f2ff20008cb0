#pragma once
// One entry point for the estimators. What identify prints and writes of the result is in
// io/result_report.h (table, residuals CSV) and io/result_json.h (JSON).

#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Runs the estimator named by options.method on `log`. Throws std::invalid_argument for
/// invalid options; what the log cannot tell is the result's status.
EstimateResult Identify(const Trajectory& log, const IdentifyOptions& options);

/// The same over several logs of one slider on one surface: (a, b, c) shared by all, each
/// log with its own slider properties; result.logs has each log on its own and
/// result.heterogeneity whether they agree.
EstimateResult Identify(const std::vector<Trajectory>& logs, const IdentifyOptions& options);

}  // namespace slideid
