#pragma once
// The pre-fit check (estimator/log_check.h) for people and for programs: the text
// `identify --check` prints, and its JSON (`identify --check --json`, slideid.check), one
// object per log on one line (JSON Lines), keys in this order:
//   {"log": "a.csv", "rows": 600, "duration_s": 5.99, "rate_hz": 100, "gaps": 0,
//    "longest_gap_s": 0, "columns": {"pose": true, "velocity": false, "force": true,
//    "push_point": false, "tip": false}, "pose_noise_m": 0.0003, "angle_noise_rad": 0.003,
//    "max_push_n": 3.1, "rest_rows": 120, "rest_force_n": [0.01, -0.002] or [null, null],
//    "dead_channels": [], "rotation_range_rad": 1.4, "push_directions_rad": 0.7,
//    "slide_directions_rad": 2.1, "max_push_offset_m": 0.02 or null, "sliding_share": 0.7,
//    "failure": "", "e_t_mu": {"identifiable": true, "seed": 0.39, "relative_stderr": 0.0004,
//    "reason": ""}, "e_o_over_e_t": {...}, "e_r_over_e_t": {...},
//    "condition_number": 1200 or null (singular), "correlation": [[1, 0.1, -0.5], ...],
//    "mu_pusher": null or {the keys of a parameter, "contact_rows": 80, "sliding_rows": 30},
//    "nuisance": {"force_bias_x_n": {"identifiable": ..., ...}, ...}, "advice": ["..."],
//    "any_identifiable": true}
// A line for a log that could not be read: {"log": PATH, "error": MESSAGE}. Numbers as
// identify --json writes them (shortest round trip; null where not finite).

#include <string>

#include "estimator/log_check.h"

namespace slideid {

/// The check of one log as text: sampling, sensors, excitation, what a fit could identify,
/// and what would help. Ends with a line break.
std::string FormatCheckText(const LogCheck& check);

/// The check of one log as one JSON object (no line break), as above.
std::string FormatCheckJson(const LogCheck& check);

/// The line for a log that could not be read: {"log": ..., "error": ...}.
std::string FormatCheckErrorJson(const std::string& log, const std::string& error);

}  // namespace slideid
