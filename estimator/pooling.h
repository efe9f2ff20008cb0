#pragma once
// Pooling many logs of one object on one surface: do they agree within their noise?
// (estimate.h, Heterogeneity). Shared by every method that pools.

#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// A log's name for pooled results: its source, or "log K".
std::string LogName(const Trajectory& log, int index);

/// One log's own result as a pooled result's entry.
LogResult AsLogResult(const EstimateResult& r, const Trajectory& log, int index);

/// Logs disagree when Cochran's Q exceeds its chi-square quantile at this level.
constexpr double kHeterogeneityAlpha = 0.05;

/// Cochran's Q test of parameter `index` over the logs that identify it (each log's
/// estimate of log(parameter), with the standard error its 95% interval states: half the
/// interval's width on the log scale over 1.96), and the
/// DerSimonian-Laird between-log spread. Not tested (tested = false) with fewer than two.
Heterogeneity TestHeterogeneity(const std::vector<LogResult>& logs, int index);

/// Student's t quantile of a two-sided 95% interval with `dof` degrees of freedom (the
/// normal quantile for dof above 1e6); dof >= 1.
double StudentT95(double dof);

}  // namespace slideid
