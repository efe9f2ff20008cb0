#include "estimator/pooling.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "estimator/log_diagnostics.h"

namespace slideid {

std::string LogName(const Trajectory& log, int index) {
  return log.source.empty() ? "log " + std::to_string(index) : log.source;
}

LogResult AsLogResult(const EstimateResult& r, const Trajectory& log, int index) {
  LogResult lr;
  lr.name = LogName(log, index);
  lr.rows = static_cast<int>(log.samples.size());
  lr.steps_used = r.steps_used;
  lr.status = r.status;
  lr.message = r.message;
  lr.parameters = r.parameters;
  return lr;
}

EstimateResult FitOneOrMany(int logs, PoolableFit* method) {
  if (logs < 1) throw std::invalid_argument("no logs to fit");
  if (logs == 1) return method->FitTogether(nullptr);
  const auto start = std::chrono::steady_clock::now();
  std::vector<LogResult> alone;
  for (int k = 0; k < logs; ++k) alone.push_back(method->FitAlone(k));
  EstimateResult result = method->FitTogether(&alone);
  result.logs = std::move(alone);
  for (int i = 0; i < 3; ++i) result.heterogeneity[i] = TestHeterogeneity(result.logs, i);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

namespace {

class PushLogsFit : public PoolableFit {
 public:
  PushLogsFit(const std::vector<const Trajectory*>& logs, const PushLogsCore& core)
      : logs_(logs), core_(core) {}
  LogResult FitAlone(int k) override { return AsLogResult(core_({logs_[k]}), *logs_[k], k); }
  EstimateResult FitTogether(std::vector<LogResult>*) override { return core_(logs_); }

 private:
  const std::vector<const Trajectory*>& logs_;
  const PushLogsCore& core_;
};

}  // namespace

EstimateResult FitOneOrMany(const std::vector<const Trajectory*>& logs, const PushLogsCore& core) {
  PushLogsFit method(logs, core);
  return FitOneOrMany(static_cast<int>(logs.size()), &method);
}

std::optional<EstimateResult> DeadSensorResult(const std::vector<const Trajectory*>& logs,
                                               EstimatorMethod method) {
  for (size_t k = 0; k < logs.size(); ++k) {
    const std::optional<std::string> dead = DiagnoseLog(*logs[k]).dead_force_channel;
    if (!dead) continue;
    EstimateResult r;
    r.method = method;
    r.status = TerminationStatus::kTooLittleExcitation;
    r.converged = false;
    r.message = (logs.size() > 1 ? LogName(*logs[k], static_cast<int>(k)) + ": " : "") + *dead;
    for (const Trajectory* log : logs) {
      r.steps_total += std::max(0, static_cast<int>(log->samples.size()) - 1);
    }
    return r;
  }
  return std::nullopt;
}

std::vector<const Trajectory*> Pointers(const std::vector<Trajectory>& logs) {
  std::vector<const Trajectory*> pointers;
  for (const Trajectory& log : logs) pointers.push_back(&log);
  return pointers;
}

Heterogeneity TestHeterogeneity(const std::vector<LogResult>& logs, int index) {
  Heterogeneity h;
  double sw = 0, sw2 = 0, swy = 0;
  std::vector<std::pair<double, double>> yw;  // log value, weight
  for (const LogResult& log : logs) {
    if (log.skipped) continue;
    const ParameterEstimate& p = log.parameters[index];
    if (!p.identifiable || !(p.value > 0) || !(p.stderr_value > 0)) continue;
    // The log's uncertainty as its own 95% interval states it (half its width on the log
    // scale over z): a standard error estimated from a few segments is itself noisy, which
    // the interval's t quantile allows for, and 1/se^2 weights from it alone would put the
    // logs whose error happened to come out small far from the rest (Q then rejects
    // agreeing logs). Without a finite interval, the standard error as it is.
    const bool bounded = p.ci95_lo > 0 && std::isfinite(p.ci95_hi) && p.ci95_hi > p.ci95_lo;
    const double se_log =
        bounded ? std::log(p.ci95_hi / p.ci95_lo) / (2.0 * kZ95) : p.stderr_value / p.value;
    const double w = 1.0 / (se_log * se_log);
    yw.emplace_back(std::log(p.value), w);
    sw += w;
    sw2 += w * w;
    swy += w * std::log(p.value);
  }
  h.logs = static_cast<int>(yw.size());
  if (h.logs < 2) return h;
  h.tested = true;
  const double mean = swy / sw;
  double q = 0;
  for (const auto& [y, w] : yw) q += w * (y - mean) * (y - mean);
  const int dof = h.logs - 1;
  h.q = q;
  h.p_value = boost::math::cdf(boost::math::complement(boost::math::chi_squared(dof), q));
  h.i2 = q > dof ? (q - dof) / q : 0.0;
  const double denominator = sw - sw2 / sw;
  h.tau_log = denominator > 0 && q > dof ? std::sqrt((q - dof) / denominator) : 0.0;
  h.consistent = h.p_value >= kHeterogeneityAlpha;
  return h;
}

double StudentT95(double dof) {
  if (dof > 1e6) return kZ95;
  return boost::math::quantile(boost::math::complement(boost::math::students_t(dof), 0.025));
}

double StudentT95Fast(double dof) {
  if (dof < kStudentT95ExpansionDof) return StudentT95(dof);
  // Fisher (1926); Abramowitz & Stegun 26.7.5: t = z + g1/v + g2/v^2 + g3/v^3 + g4/v^4.
  const double z = kZ95, z2 = z * z, z3 = z2 * z, z5 = z3 * z2, z7 = z5 * z2, z9 = z7 * z2;
  const double g1 = (z3 + z) / 4;
  const double g2 = (5 * z5 + 16 * z3 + 3 * z) / 96;
  const double g3 = (3 * z7 + 19 * z5 + 17 * z3 - 15 * z) / 384;
  const double g4 = (79 * z9 + 776 * z7 + 1482 * z5 - 1920 * z3 - 945 * z) / 92160;
  const double u = 1 / dof;
  return z + u * (g1 + u * (g2 + u * (g3 + u * g4)));
}

}  // namespace slideid
