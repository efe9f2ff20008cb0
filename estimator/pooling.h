#pragma once
// Pooling many logs of one object on one surface: "one log or many" once for every method
// (FitOneOrMany), and whether the logs agree within their noise (estimate.h,
// Heterogeneity).

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// A log's name for pooled results: its source, or "log K".
std::string LogName(const Trajectory& log, int index);

/// One log's own result as a pooled result's entry.
LogResult AsLogResult(const EstimateResult& r, const Trajectory& log, int index);

/// What a method supplies to be fitted over one log or many: its core fits. Options are
/// valid and every log usable by the time FitOneOrMany calls them.
class PoolableFit {
 public:
  virtual ~PoolableFit() = default;
  /// Log `k` fitted on its own, as an entry of the pooled result (AsLogResult). Called for
  /// every log, in order, before FitTogether.
  virtual LogResult FitAlone(int k) = 0;
  /// Every log fitted together, or the only one. `alone` holds the logs' own entries (null
  /// for one log); the method may revise them (the trajectory fit refits a log from the
  /// pooled estimate when that ends lower).
  virtual EstimateResult FitTogether(std::vector<LogResult>* alone) = 0;
};

/// One log or many, the same for every method: one log is fitted together with nothing
/// else (no per-log entries); several are each fitted alone, then together, and the result
/// gets every log's entry, the heterogeneity test of each parameter and the total time.
/// Throws std::invalid_argument for no logs.
EstimateResult FitOneOrMany(int logs, PoolableFit* method);

/// A method whose core fits any list of push logs together, and a log alone as a list of
/// one (the closed form, the equation error).
using PushLogsCore = std::function<EstimateResult(const std::vector<const Trajectory*>&)>;

/// FitOneOrMany of such a method over `logs`.
EstimateResult FitOneOrMany(const std::vector<const Trajectory*>& logs, const PushLogsCore& core);

/// The result for the first of `logs` whose force channel never changes while the object
/// moves (LogDiagnostics::dead_force_channel): a dead sensor, whatever the method (it would
/// read as too little sliding, or fit nonsense). kTooLittleExcitation, the log named when
/// there are several; none when every channel is alive.
std::optional<EstimateResult> DeadSensorResult(const std::vector<const Trajectory*>& logs,
                                               EstimatorMethod method);

/// Pointers to each of `logs`, for the cores.
std::vector<const Trajectory*> Pointers(const std::vector<Trajectory>& logs);

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

/// The same in constant time for a caller that needs it at every update (the online
/// identifier's intervals): from kStudentT95ExpansionDof degrees of freedom on, Fisher's
/// expansion of the quantile in 1/dof to the fourth order, within 2e-7 (relative) of
/// StudentT95 there and closer above; below, StudentT95 itself.
double StudentT95Fast(double dof);
constexpr double kStudentT95ExpansionDof = 20;

}  // namespace slideid
