#pragma once
// The identify result as JSON (`identify --json`; `plot-log --fit` reads it), written and
// read with nlohmann-json. One object on one line:
//   {"e_t_mu": {"value": 0.31, "stderr": 0.00012, "ci95": [0.3098, 0.3102],
//    "interval_quantile": 1.959963984540054, "identifiable": true, "verdict": "ok", "reason": "",
//    "held_at": null, "note": "..."},
//   "e_o_over_e_t": {...}, "e_r_over_e_t": {...}, "method": "trajectory",
//   "status": "converged", "steps_used": 295, "steps_total": 300, "steps_excluded": 5,
//   "steps_excluded_by_reason": {"sticking": 5}, "seconds": 0.006, "iterations": 12,
//   "final_cost": 1.2e-05, "converged": true, "message": "...", "log_noise": 0.0004,
//   "residual_rms": 0.00042,
//   "nuisance": {"force_bias_x_n": [{"log": "a.csv", "value": ..., "stderr": ...,
//                "ci95": [..], "identifiable": true, "verdict": "ok", "reason": "",
//                "held_at": null}], ...},
//   "logs": [{"name": "a.csv", "skipped": false, "skip_reason": "", "rows": 60,
//             "steps_used": 55, "status": "converged", "message": "...",
//             "e_t_mu": {...}, "e_o_over_e_t": {...}, "e_r_over_e_t": {...}}, ...],
//   "heterogeneity": {"e_t_mu": {"tested": true, "logs": 12, "q": 30.1, "p_value": 0.001,
//                     "i2": 0.63, "tau_log": 0.12, "consistent": false}, ...},
//   "mu_pusher": null, or for logs with the tip's path {the keys of a parameter,
//                "lower_bound": 0.21 or null}}
// Keys in this order, ", " and ": " between items. Numbers are written in the shortest form
// that reads back to the same double; a number that is not finite is written as null and
// read back as NaN. A parameter that is not identifiable has null value, stderr, ci95 and
// interval_quantile, and its held_at; an identifiable one has a null held_at.
// interval_quantile (ParameterEstimate::interval_quantile: Student's t where the interval's
// variance is read from few degrees of freedom, else z) is optional when read: results
// written without it read as z.

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/slider.h"

namespace slideid {

/// Bad result JSON: the message names the JSON path ("/e_t_mu/ci95/1") or, for a syntax
/// error, the line and column. An std::invalid_argument, as ParseIdentifyJson always threw.
class ResultJsonError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// One JSON object (no line break), with the keys above: "logs" is empty and every
/// heterogeneity untested unless the fit pooled several logs; "nuisance" is empty unless
/// nuisances were fitted. Residuals are not in it (identify --residuals writes them).
std::string FormatJson(const EstimateResult& result);

/// One line of a batch's JSON lines (identify --batch; slideid.identify_file gives the same
/// object, with "error_type" added to a failure), for `file`. A file identified:
///   {"file": ..., "ok": true, the keys of FormatJson(*result), "warnings": [...]}.
/// A file that failed, with `error` saying why (naming the file):
///   {"file": ..., "ok": false, "error": ..., "result": FormatJson(*result)}
/// where "result" is there when a fit ran but must not be used (`result` not null). The
/// order of keys as written here. Throws std::invalid_argument if there is neither a result
/// nor an error.
/// With `sha256` (io/file_hash.h) not empty, "sha256" follows "file": what the batch read
/// (identify --batch --resume knows a log by its path and this hash).
std::string FormatBatchLine(const std::string& file, const EstimateResult* result,
                            const std::string& error, const std::vector<std::string>& warnings,
                            const std::string& sha256 = "");

/// What a resumed batch needs of one of its lines: the file, its hash ("" when the line has
/// none: the file could not be read) and whether it was identified.
struct BatchLineKey {
  std::string file, sha256;
  bool ok = false;
};

/// The key of a batch line, or nullopt when `line` is not a JSON object with a string
/// "file" and a boolean "ok" (a torn or foreign line). Never throws.
std::optional<BatchLineKey> ParseBatchLineKey(std::string_view line);

/// Reads what FormatJson wrote: every key it writes is required (others are ignored).
/// FormatJson(ParseResultJson(FormatJson(r))) == FormatJson(r), and every field it carries
/// reads back bit for bit (nulls as NaN); residuals and residual_names keep their defaults.
/// Throws ResultJsonError.
EstimateResult ParseResultJson(const std::string& json);

/// The parameters of an `identify --json` result: each parameter's value, or its held_at
/// value when it has no positive value (not identifiable). Needs only the three parameter
/// objects. Throws ResultJsonError naming what is missing or malformed.
ReducedFriction ParseIdentifyJson(const std::string& json);

}  // namespace slideid
