#pragma once
// The JSON line `identify --follow` prints after a row (docs/online.md): the online
// identifier's estimate with intervals and verdicts, and any change of the friction found.

#include <string>

#include "estimator/online_identifier.h"

namespace slideid {

/// One line of JSON, no newline: {"row", "t", "started", "e_t_mu": {"value", "stderr",
/// "ci95", "interval_quantile", "verdict", "reason"}, "e_o_over_e_t", "e_r_over_e_t",
/// "variance_factor", "nis", "batch_checks", "batch_takeovers", "changes", "change" (the change
/// found at this row, or null)}. Numbers in the shortest form that reads back to the same double;
/// NaN as null.
std::string FormatOnlineJson(const OnlineResult& result);

}  // namespace slideid
