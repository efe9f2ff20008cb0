#include "estimator/identify.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "estimator/closed_form.h"
#include "estimator/equation_error.h"
#include "estimator/trajectory_fit.h"

namespace slideid {
namespace {

std::string Number(double v, const char* fmt = "%.6g") {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

std::string JsonNumber(double v) { return std::isfinite(v) ? Number(v, "%.17g") : "null"; }

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

double TruthOf(const ReducedFriction& t, int i) { return i == kA ? t.a : i == kB ? t.b : t.c; }

}  // namespace

EstimateResult Identify(const Trajectory& log, const EstimatorOptions& options) {
  switch (options.method) {
    case EstimatorMethod::kClosedForm: return EstimateClosedForm(log, options);
    case EstimatorMethod::kEquationError: return EstimateEquationError(log, options);
    case EstimatorMethod::kTrajectory: return EstimateTrajectory(log, options);
    case EstimatorMethod::kQuasiStatic:
      throw std::invalid_argument("the quasi-static method fits wrench-twist pairs "
                                  "(EstimateQuasiStatic), not a push log");
  }
  throw std::invalid_argument("unknown estimator method");
}

std::string FormatReport(const EstimateResult& r, const std::optional<ReducedFriction>& truth) {
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "%-14s %12s %12s %27s  %-12s%s\n", "parameter", "estimate",
                "std. error", "95% CI", "identifiable", truth ? "  truth (log metadata)" : "");
  out << "method: " << ToString(r.method) << "\n" << line;
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    const std::string ci =
        p.identifiable ? "[" + Number(p.ci95_lo) + ", " + Number(p.ci95_hi) + "]" : "-";
    std::snprintf(line, sizeof line, "%-14s %12s %12s %27s  %-12s", ParameterName(i),
                  Number(p.value).c_str(), Number(p.stderr_value).c_str(), ci.c_str(),
                  p.identifiable ? "yes" : "no");
    out << line;
    if (truth) out << "  " << Number(TruthOf(*truth, i));
    out << "\n";
    if (!p.note.empty()) {
      out << "    " << (p.identifiable ? "note: " : "not identifiable: ") << p.note << "\n";
    }
  }
  out << "(e_t_mu = e_t mu; e_o_over_e_t = e_o/e_t; e_r_over_e_t = e_r/e_t [m])\n";
  out << "steps: " << r.steps_used << " used of " << r.steps_total;
  for (const auto& [reason, count] : r.steps_excluded) {
    out << "; " << count << " excluded (" << reason << ")";
  }
  out << "\nfinal cost " << Number(r.final_cost) << ", " << r.iterations << " iterations, "
      << Number(r.seconds, "%.3f") << " s" << (r.converged ? "" : "  (NOT CONVERGED)") << "\n";
  if (!r.message.empty()) out << "solver: " << r.message << "\n";
  return out.str();
}

std::string FormatJson(const EstimateResult& r) {
  std::ostringstream out;
  out << "{";
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    out << JsonString(ParameterName(i)) << ": {\"value\": "
        << (p.identifiable ? JsonNumber(p.value) : "null")
        << ", \"stderr\": " << (p.identifiable ? JsonNumber(p.stderr_value) : "null")
        << ", \"ci95\": [" << (p.identifiable ? JsonNumber(p.ci95_lo) : "null") << ", "
        << (p.identifiable ? JsonNumber(p.ci95_hi) : "null")
        << "], \"identifiable\": " << (p.identifiable ? "true" : "false")
        << ", \"held_at\": " << (p.identifiable ? "null" : JsonNumber(p.held_at))
        << ", \"note\": " << JsonString(p.note) << "}, ";
  }
  int excluded = 0;
  std::string reasons;
  for (const auto& [reason, count] : r.steps_excluded) {
    excluded += count;
    reasons += (reasons.empty() ? "" : ", ") + JsonString(reason) + ": " + std::to_string(count);
  }
  out << "\"method\": " << JsonString(ToString(r.method)) << ", \"steps_used\": " << r.steps_used
      << ", \"steps_total\": " << r.steps_total << ", \"steps_excluded\": " << excluded
      << ", \"steps_excluded_by_reason\": {" << reasons << "}, \"seconds\": "
      << JsonNumber(r.seconds) << ", \"iterations\": " << r.iterations
      << ", \"final_cost\": " << JsonNumber(r.final_cost)
      << ", \"converged\": " << (r.converged ? "true" : "false")
      << ", \"message\": " << JsonString(r.message) << "}";
  return out.str();
}

void WriteResidualsCsv(const EstimateResult& r, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error(path + ": cannot write residuals");
    out << "# per-step residuals of the " << ToString(r.method) << " fit\n";
    out << "row,t," << r.residual_names[0] << "," << r.residual_names[1] << ","
        << r.residual_names[2] << ",used\n";
    for (const StepResidual& s : r.residuals) {
      out << s.row << "," << Number(s.t_s, "%.17g") << "," << Number(s.value[0], "%.17g") << ","
          << Number(s.value[1], "%.17g") << "," << Number(s.value[2], "%.17g") << ","
          << (s.used ? 1 : 0) << "\n";
    }
    if (!out.flush()) throw std::runtime_error(path + ": cannot write residuals");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write residuals");
  }
}

}  // namespace slideid
