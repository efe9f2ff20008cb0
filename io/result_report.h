#pragma once
// The identify result for people: the table identify prints, and the per-step residuals it
// writes with --residuals (CSV). The JSON form is io/result_json.h.

#include <optional>
#include <string>

#include "estimator/estimate.h"
#include "forward_model/slider.h"

namespace slideid {

/// Human-readable table: parameter, estimate, standard error, 95% CI, verdict (and the
/// truth beside it when given), each estimate's note in words, then the residuals against
/// the log's noise (with units), steps used and excluded, the fit's iterations and run time.
/// `verbose` adds each note's technical detail and the solver's own report.
std::string FormatReport(const EstimateResult& result,
                         const std::optional<ReducedFriction>& truth = std::nullopt,
                         bool verbose = false);

/// A note without its technical detail: every " (detail: ...)" part (parentheses inside
/// it matched) removed. The estimators write a note in words first, its detail after.
std::string WithoutDetail(const std::string& note);

/// Per-step residuals as CSV (row, t, the three named channels, used). Throws
/// std::runtime_error naming the path if it cannot be written; writes via a temporary file.
void WriteResidualsCsv(const EstimateResult& result, const std::string& path);

}  // namespace slideid
