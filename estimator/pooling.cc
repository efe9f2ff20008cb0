#include "estimator/pooling.h"

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>

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

}  // namespace slideid
