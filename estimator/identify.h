#pragma once
// One entry point for the estimators, and the reports identify prints and writes.

#include <optional>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Runs the estimator named by options.method on `log`. Throws std::invalid_argument for
/// invalid options; what the log cannot tell is the result's status.
EstimateResult Identify(const Trajectory& log, const IdentifyOptions& options);

/// The same over several logs of one slider on one surface: (a, b, c) shared by all, each
/// log with its own slider properties; result.logs has each log on its own and
/// result.heterogeneity whether they agree.
EstimateResult Identify(const std::vector<Trajectory>& logs, const IdentifyOptions& options);

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
