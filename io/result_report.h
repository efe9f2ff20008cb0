#pragma once
// The identify result for people: the table identify prints, and the per-step residuals it
// writes with --residuals (CSV). The JSON form is io/result_json.h.

#include <optional>
#include <string>

#include "estimator/estimate.h"
#include "forward_model/slider.h"

namespace slideid {

/// Human-readable table: parameter, estimate, standard error, 95% CI, identifiable (and the
/// truth beside it when given), then steps used and excluded, cost, iterations, run time.
std::string FormatReport(const EstimateResult& result,
                         const std::optional<ReducedFriction>& truth = std::nullopt);

/// Per-step residuals as CSV (row, t, the three named channels, used). Throws
/// std::runtime_error naming the path if it cannot be written; writes via a temporary file.
void WriteResidualsCsv(const EstimateResult& result, const std::string& path);

}  // namespace slideid
