#include "io/online_json.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

namespace slideid {
namespace {

using nlohmann::json;

json Number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

json Parameter(const ParameterEstimate& p) {
  json out = {{"value", Number(p.value)},
              {"stderr", Number(p.stderr_value)},
              {"ci95", json::array({Number(p.ci95_lo), Number(p.ci95_hi)})},
              {"interval_quantile", p.identifiable ? Number(p.interval_quantile) : json(nullptr)},
              {"verdict", ToString(p.verdict)}};
  if (!p.identifiable) out["held_at"] = Number(p.held_at);
  if (!p.reason.empty()) out["reason"] = p.reason;
  return out;
}

json Change(const FrictionChange& c) {
  return {{"row", c.row},
          {"t", Number(c.t_s)},
          {"detected_row", c.detected_row},
          {"statistic", Number(c.statistic)},
          {"ratio", json::array({Number(c.ratio[0]), Number(c.ratio[1]), Number(c.ratio[2])})},
          {"confirmed", c.confirmed}};
}

}  // namespace

std::string FormatOnlineJson(const OnlineResult& r) {
  json out = {{"row", r.rows - 1}, {"t", Number(r.t_s)}, {"started", r.started}};
  for (int i = 0; i < 3; ++i) out[ParameterName(i)] = Parameter(r.parameters[i]);
  if (r.mu_pusher_examined) {
    json mu = Parameter(r.mu_pusher);
    if (std::isfinite(r.mu_pusher_lower_bound)) mu["lower_bound"] = r.mu_pusher_lower_bound;
    mu["contact_rows"] = r.mu_pusher_contact_rows;
    mu["sliding_rows"] = r.mu_pusher_sliding_rows;
    out["mu_pusher"] = mu;
  }
  out["variance_factor"] = Number(r.variance_factor);
  out["interval_variance_factors"] =
      json::array({Number(r.interval_variance_factors[0]), Number(r.interval_variance_factors[1]),
                   Number(r.interval_variance_factors[2])});
  out["force_noise_fraction"] = Number(r.force_noise_fraction);
  out["nis"] = Number(r.nis);
  out["batch_checks"] = r.batch_checks;
  out["batch_takeovers"] = r.batch_takeovers;
  out["changes"] = r.changes.size();
  out["confirmed_changes"] = std::count_if(r.changes.begin(), r.changes.end(),
                                           [](const FrictionChange& c) { return c.confirmed; });
  out["withdrawn_changes"] = r.withdrawn_changes;
  out["change"] = r.change_detected ? Change(r.changes.back()) : json(nullptr);
  return out.dump();
}

}  // namespace slideid
