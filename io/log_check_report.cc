#include "io/log_check_report.h"

#include <cmath>
#include <sstream>

#include "forward_model/number_format.h"
#include "io/internal/json_line.h"

namespace slideid {
namespace {

using json_line::Json;
using json_line::NumberOrNull;

constexpr double kDeg = 180.0 / 3.14159265358979323846;

// ---- text ----

std::string Sampling(const LogCheck& c) {
  std::string s = Printf("%d rows over %.3g s at %.4g Hz", c.rows, c.duration_s, c.rate_hz);
  s += c.gaps == 0 ? "; no gaps"
                   : Printf("; %d gap%s, the longest %.3g s", c.gaps, c.gaps == 1 ? "" : "s",
                            c.longest_gap_s);
  return s;
}

std::string Sensors(const LogCheck& c) {
  std::string s;
  if (c.has_pose) {
    s += std::isfinite(c.pose_noise_m) ? Printf("poses (noise %.3g mm, %.3g mrad)",
                                                1000 * c.pose_noise_m, 1000 * c.angle_noise_rad)
                                       : "poses";
  }
  if (c.has_velocity) s += std::string(s.empty() ? "" : ", ") + "velocities";
  if (c.has_force) {
    s += std::string(s.empty() ? "" : ", ") + Printf("force (largest %.3g N)", c.max_push_n);
  } else {
    s += std::string(s.empty() ? "" : ", ") + "no force (a free slide)";
  }
  if (c.has_push_point) s += ", push points";
  if (c.has_tip) s += ", the pusher tip's path";
  return s;
}

std::string Rest(const LogCheck& c) {
  if (c.rest_rows == 0) return "never at rest";
  std::string s = Printf("at rest in %d rows", c.rest_rows);
  if (c.has_force && std::isfinite(c.rest_force_x_n)) {
    s += Printf(", where the force channel reads (%.3g, %.3g) N (median)", c.rest_force_x_n,
                c.rest_force_y_n);
  }
  return s;
}

std::string Excitation(const LogCheck& c) {
  std::string s = Printf("slides %.0f%% of the time; turns through %.1f deg", 100 * c.sliding_share,
                         c.rotation_range_rad * kDeg);
  s += Printf("; slides along directions of its own spanning %.0f deg",
              c.slide_directions_rad * kDeg);
  if (std::isfinite(c.max_push_offset_m)) {
    s += Printf(
        "; pushed in directions of its own spanning %.0f deg, passing up to %.3g mm "
        "from the CM",
        c.push_directions_rad * kDeg, 1000 * c.max_push_offset_m);
  } else {
    s += "; never pushed";
  }
  return s;
}

std::string Outlook(const char* name, const ParameterOutlook& p) {
  if (!p.identifiable) return Printf("  %-14s no     %s\n", name, p.reason);
  return Printf("  %-14s yes    about %s (one sigma), from the seed %.4g\n", name,
                p.relative_stderr < 0.001 ? Printf("%.2g%%", 100 * p.relative_stderr)
                                          : Printf("%.1f%%", 100 * p.relative_stderr),
                p.seed);
}

std::string Correlations(const LogCheck& c) {
  if (!std::isfinite(c.correlation[0][1])) return "correlations: - (J^T J is singular)";
  return Printf("correlations of the estimates: a-b %.2f, a-c %.2f, b-c %.2f", c.correlation[0][1],
                c.correlation[0][2], c.correlation[1][2]);
}

// ---- JSON ----

Json OutlookJson(const ParameterOutlook& p) {
  Json j = Json::object();
  j["identifiable"] = p.identifiable;
  j["seed"] = NumberOrNull(p.seed);
  j["relative_stderr"] = NumberOrNull(p.relative_stderr);
  j["reason"] = p.reason;
  return j;
}

}  // namespace

std::string FormatCheckText(const LogCheck& c) {
  std::ostringstream out;
  out << "check of " << (c.name.empty() ? "the log" : c.name) << " (nothing fitted)\n";
  out << "  sampling:   " << Sampling(c) << "\n";
  out << "  sensors:    " << Sensors(c) << "\n";
  out << "  rest:       " << Rest(c) << "\n";
  for (const std::string& dead : c.dead_channels) out << "  DEAD:       " << dead << "\n";
  out << "  excitation: " << Excitation(c) << "\n";
  out << "what the fit could identify (its own rules, applied to J^T J at its seed):\n";
  if (!c.failure.empty()) {
    out << "  nothing: " << c.failure << "\n";
  } else {
    for (int i = 0; i < 3; ++i) out << Outlook(ParameterName(i), c.parameters[i]);
    if (c.mu_pusher_examined) {
      out << Outlook("mu_pusher", c.mu_pusher);
    }
    for (const auto& [name, p] : c.nuisances) out << Outlook(name.c_str(), p);
    out << "  cond(J^T J) = "
        << (std::isfinite(c.condition_number) ? Printf("%.3g", c.condition_number)
                                              : std::string("infinite (singular)"))
        << " over log a, log b, log c; " << Correlations(c) << "\n";
  }
  if (c.advice.empty()) {
    out << "what would help: nothing stands out\n";
  } else {
    out << "what would help:\n";
    for (const std::string& a : c.advice) out << "  - " << a << "\n";
  }
  return out.str();
}

std::string FormatCheckJson(const LogCheck& c) {
  Json j = Json::object();
  j["log"] = c.name;
  j["rows"] = c.rows;
  j["duration_s"] = NumberOrNull(c.duration_s);
  j["rate_hz"] = NumberOrNull(c.rate_hz);
  j["gaps"] = c.gaps;
  j["longest_gap_s"] = NumberOrNull(c.longest_gap_s);
  j["columns"] = Json{{"pose", c.has_pose},
                      {"velocity", c.has_velocity},
                      {"force", c.has_force},
                      {"push_point", c.has_push_point},
                      {"tip", c.has_tip}};
  j["pose_noise_m"] = NumberOrNull(c.pose_noise_m);
  j["angle_noise_rad"] = NumberOrNull(c.angle_noise_rad);
  j["max_push_n"] = NumberOrNull(c.max_push_n);
  j["rest_rows"] = c.rest_rows;
  j["rest_force_n"] = Json::array({NumberOrNull(c.rest_force_x_n), NumberOrNull(c.rest_force_y_n)});
  j["dead_channels"] = c.dead_channels;
  j["rotation_range_rad"] = NumberOrNull(c.rotation_range_rad);
  j["push_directions_rad"] = NumberOrNull(c.push_directions_rad);
  j["slide_directions_rad"] = NumberOrNull(c.slide_directions_rad);
  j["max_push_offset_m"] = NumberOrNull(c.max_push_offset_m);
  j["sliding_share"] = NumberOrNull(c.sliding_share);
  j["failure"] = c.failure;
  for (int i = 0; i < 3; ++i) j[ParameterName(i)] = OutlookJson(c.parameters[i]);
  j["condition_number"] = NumberOrNull(c.condition_number);
  Json correlation = Json::array();
  for (const auto& row : c.correlation) {
    correlation.push_back(
        Json::array({NumberOrNull(row[0]), NumberOrNull(row[1]), NumberOrNull(row[2])}));
  }
  j["correlation"] = correlation;
  if (c.mu_pusher_examined) {
    Json mu = OutlookJson(c.mu_pusher);
    mu["contact_rows"] = c.tip_contact_rows;
    mu["sliding_rows"] = c.tip_sliding_rows;
    j["mu_pusher"] = mu;
  } else {
    j["mu_pusher"] = nullptr;
  }
  Json nuisance = Json::object();
  for (const auto& [name, p] : c.nuisances) nuisance[name] = OutlookJson(p);
  j["nuisance"] = nuisance;
  j["advice"] = c.advice;
  j["any_identifiable"] = c.AnyIdentifiable();
  std::string out;
  json_line::Print(j, &out);
  return out;
}

std::string FormatCheckErrorJson(const std::string& log, const std::string& error) {
  Json j = Json::object();
  j["log"] = log;
  j["error"] = error;
  std::string out;
  json_line::Print(j, &out);
  return out;
}

}  // namespace slideid
