#pragma once
// advise-push's input and output (estimator/push_advice.h): what it reads of an identify
// result (the three parameters, the residuals' size, mu_p) and the ranking it prints, as a
// table or as one JSON object on one line (--json; slideid.advise_push returns the same):
//   {"criterion": "least-known", "pose_noise_m": 0.0003, "mu_pusher": 0.25,
//    "known": {"e_t_mu": {"value": 0.4, "relative_stderr": 0.002, "from": "estimate"}, ...},
//    "candidates": 240, "failed": 0,
//    "ranking": [{"rank": 1, "outline_fraction": 0.031, "contact_m": [0.045, -0.017],
//                 "direction": [-0.97, 0.24], "angle_from_normal_deg": 11.3,
//                 "length_m": 0.08, "tip_start_m": [...], "tip_end_m": [...],
//                 "score": 0.0123, "relative_stderr_after": [0.001, 0.004, 0.0123],
//                 "stderr_after": [0.0004, 0.005, 0.0003], "information_log": [[...], ...],
//                 "moved_m": 0.06, "turned_deg": 14.2, "simulated": true, "failure": ""},
//                ...]}
// Numbers in the shortest form that reads back to the same double; not finite: null.

#include <optional>
#include <string>

#include "estimator/estimate.h"
#include "estimator/push_advice.h"
#include "forward_model/slider.h"

namespace slideid {

/// What advise-push takes from an identify result (identify --json).
struct AdviceResultInput {
  EstimateResult result;  ///< only the three parameters are read
  /// The standard deviation of one pose residual the fit saw [m]: its residual_rms (per
  /// row, over the 3 channels) over sqrt(3); absent when the result has none.
  std::optional<double> pose_noise_m;
  std::optional<double> mu_pusher;  ///< its mu_pusher's value, when identified
};

/// Reads an identify --json object. Each parameter needs "identifiable", and "value" and
/// "stderr" when identifiable ("held_at" otherwise, may be null); "residual_rms" and
/// "mu_pusher" are optional. Throws ResultJsonError (io/result_json.h) naming the JSON path
/// ("/e_t_mu/stderr") or, for a syntax error, where it is.
AdviceResultInput ParseAdviceResult(const std::string& json);

/// The top `top` candidates (all when top <= 0 or beyond them) as one JSON object, no line
/// break; `options` says how they were pushed (the tip's path is written out).
std::string FormatAdviceJson(const PushAdvice& advice, const SliderProperties& slider,
                             const ContactPatch& patch, const PushAdviceOptions& options, int top);

/// The same as a table for people: what is known, then one line per candidate with its
/// contact point, direction, length and the expected relative standard errors after it.
std::string FormatAdviceText(const PushAdvice& advice, const PushAdviceOptions& options, int top);

}  // namespace slideid
