#pragma once
// One entry point for the estimators, and the reports identify prints and writes.

#include <optional>
#include <string>

#include "estimator/estimate.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Runs the estimator named by options.method on `log`.
EstimateResult Identify(const Trajectory& log, const EstimatorOptions& options);

/// Human-readable table: parameter, estimate, standard error, 95% CI, identifiable (and the
/// truth beside it when given), then steps used and excluded, cost, iterations, run time.
std::string FormatReport(const EstimateResult& result,
                         const std::optional<ReducedFriction>& truth = std::nullopt);

/// One JSON object: e_t_mu, e_o_over_e_t, e_r_over_e_t as {"value", "stderr", "ci95",
/// "identifiable"} (null where not identifiable), method, steps_used, steps_excluded,
/// seconds, and more (iterations, final_cost, converged, message).
std::string FormatJson(const EstimateResult& result);

/// Per-step residuals as CSV (row, t, the three named channels, used). Throws
/// std::runtime_error naming the path if it cannot be written; writes via a temporary file.
void WriteResidualsCsv(const EstimateResult& result, const std::string& path);

}  // namespace slideid
