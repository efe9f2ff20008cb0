#include "io/result_report.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "forward_model/number_format.h"
#include "io/atomic_file.h"

namespace slideid {
namespace {

std::string Number(double v, const char* fmt = "%.6g") {
  return std::isfinite(v) ? Printf(fmt, v) : "-";
}

/// Every digit, for files read back; "-" as Number writes for a value not finite.
std::string ExactCell(double v) { return std::isfinite(v) ? ExactNumber(v) : "-"; }

double TruthOf(const ReducedFriction& t, int i) { return i == kA ? t.a : i == kB ? t.b : t.c; }

// Residuals within this many times the log's noise: the fit explains the log down to its
// noise (plausibility.h marks a fit suspect beyond kMismatchRatio = 3).
constexpr double kFitsNoiseRatio = 1.5;

}  // namespace

namespace {

std::string Interval(double lo, double hi) {
  return std::isfinite(lo) ? "[" + Number(lo) + ", " + Number(hi) + "]" : "-";
}

void ReportReasons(std::ostringstream& out, Verdict verdict, const std::string& reason,
                   const std::string& note, bool verbose) {
  if (!reason.empty()) out << "    " << ToString(verdict) << ": " << reason << "\n";
  const std::string shown = verbose ? note : WithoutDetail(note);
  if (!shown.empty()) out << "    note: " << shown << "\n";
}

// The residual RMS in words with its unit, from the channels the method names.
std::string ResidualLine(const EstimateResult& r) {
  const std::string& channel = r.residual_names[0];
  auto ends_with = [&](const std::string& suffix) {
    return channel.size() > suffix.size() &&
           channel.compare(channel.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  double scale = 1;
  std::string unit, what = "per row";
  if (ends_with("_mps")) {
    scale = 1000;
    unit = " mm/s";
    what = "per row of velocities (x, y and the spin times the radius of gyration)";
  } else if (ends_with("_m")) {
    scale = 1000;
    unit = " mm";
    what = "per row of poses (x, y and the heading times the radius of gyration)";
  } else {
    what = "per row (dimensionless: friction impulses over the normal impulse)";
  }
  const double ratio = r.residual_rms / r.log_noise;
  return "residuals: " + Number(scale * r.residual_rms, "%.3g") + unit + " RMS " + what +
         ", against the log's own noise of " + Number(scale * r.log_noise, "%.3g") + unit +
         " (ratio " + Number(ratio, "%.2f") +
         (ratio <= kFitsNoiseRatio ? ": the fit explains the log down to its noise)\n"
                                   : ": the model leaves more than the noise)\n");
}

// How the fit ended: its iterations in words; the solver's own report under --verbose (its
// iteration count is of the last solve alone), what follows it (second starts, ...) always.
std::string SolverLines(const EstimateResult& r, bool verbose) {
  std::string out = "fit: " + std::to_string(r.iterations) +
                    " solver iterations over all its stages, final cost " + Number(r.final_cost) +
                    " (of its last solve: half the sum of its squared, robustified residuals), " +
                    Number(r.seconds, "%.3f") + " s" + (r.converged ? "" : "  (NOT CONVERGED)") +
                    "\n";
  if (r.message.empty()) return out;
  const std::string ceres = "Ceres Solver Report";
  if (verbose || r.message.compare(0, ceres.size(), ceres) != 0) {
    return out + "solver: " + r.message + "\n";
  }
  const size_t rest = r.message.find("; ");
  if (rest != std::string::npos) out += "solver: " + r.message.substr(rest + 2) + "\n";
  return out;
}

void ReportLogs(std::ostringstream& out, const EstimateResult& r) {
  out << "\nper log (each fitted on its own):\n";
  out << Printf("  %-36s %6s  %-26s %-26s %-26s %s\n", "log", "rows", "e_t_mu [95% CI]",
                "e_o_over_e_t [95% CI]", "e_r_over_e_t [95% CI]", "status");
  for (const LogResult& log : r.logs) {
    if (log.skipped) {
      out << "  " << log.name << ": skipped (" << log.skip_reason << ")\n";
      continue;
    }
    std::string cells[3];
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = log.parameters[i];
      cells[i] = p.identifiable ? Number(p.value, "%.4g") + " " + Interval(p.ci95_lo, p.ci95_hi)
                                : "not identifiable";
      if (p.verdict == Verdict::kSuspect) cells[i] += " ?";
    }
    std::string name = log.name;
    if (name.size() > 36) name = "..." + name.substr(name.size() - 33);
    out << Printf("  %-36s %6d  %-26s %-26s %-26s %s\n", name, log.rows, cells[0], cells[1],
                  cells[2], ToString(log.status));
  }
  out << "  (? = suspect)\nagreement of the logs (Cochran's Q; tau = between-log spread of the "
         "log-parameter):\n";
  for (int i = 0; i < 3; ++i) {
    const Heterogeneity& h = r.heterogeneity[i];
    out << "  " << ParameterName(i) << ": ";
    if (!h.tested) {
      out << "not tested (fewer than two logs identify it)\n";
      continue;
    }
    out << Printf("%s (%d logs, Q = %.3g, p = %.3g, I2 = %.0f%%, tau = %.3g)\n",
                  h.consistent ? "consistent within their noise" : "the logs DISAGREE", h.logs, h.q,
                  h.p_value, 100 * h.i2, h.tau_log);
  }
}

}  // namespace

std::string WithoutDetail(const std::string& note) {
  std::string out;
  const std::string marker = " (detail: ";
  size_t from = 0;
  while (true) {
    const size_t at = note.find(marker, from);
    out += note.substr(from, at == std::string::npos ? std::string::npos : at - from);
    if (at == std::string::npos) return out;
    int depth = 1;
    size_t k = at + marker.size();
    for (; k < note.size() && depth > 0; ++k) depth += note[k] == '(' ? 1 : note[k] == ')' ? -1 : 0;
    from = k;
  }
}

std::string FormatReport(const EstimateResult& r, const std::optional<ReducedFriction>& truth,
                         bool verbose) {
  std::ostringstream out;
  out << "method: " << ToString(r.method) << " (" << ToString(r.status) << ")\n";
  if (r.status == TerminationStatus::kTooLittleExcitation) {
    out << r.message << "\n";
    return out.str();
  }
  out << Printf("%-14s %12s %12s %27s  %-16s%s\n", "parameter", "estimate", "std. error", "95% CI",
                "verdict", truth ? "  truth (log metadata)" : "");
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    out << Printf("%-14s %12s %12s %27s  %-16s", ParameterName(i), Number(p.value),
                  Number(p.stderr_value), Interval(p.ci95_lo, p.ci95_hi), ToString(p.verdict));
    if (truth) out << "  " << Number(TruthOf(*truth, i));
    out << "\n";
    ReportReasons(out, p.verdict, p.reason, p.note, verbose);
  }
  if (r.mu_pusher_examined) {
    const ParameterEstimate& p = r.mu_pusher;
    out << Printf("%-14s %12s %12s %27s  %-16s\n", "mu_pusher", Number(p.value),
                  Number(p.stderr_value), Interval(p.ci95_lo, p.ci95_hi), ToString(p.verdict));
    ReportReasons(out, p.verdict, p.reason, p.note, verbose);
  }
  out << "(e_t_mu = e_t mu; e_o_over_e_t = e_o/e_t; e_r_over_e_t = e_r/e_t [m]"
      << (r.mu_pusher_examined ? "; mu_pusher = the tip-edge friction coefficient" : "") << ")\n";
  if (!r.nuisance.empty()) {
    out << "sensor nuisances:\n";
    for (const NuisanceEstimate& n : r.nuisance) {
      out << Printf("  %-18s %-24s %12s %12s %27s  %s\n", n.name,
                    n.log.empty() ? "(all logs)" : n.log.c_str(), Number(n.value),
                    Number(n.stderr_value), Interval(n.ci95_lo, n.ci95_hi), ToString(n.verdict));
      ReportReasons(out, n.verdict, n.reason, "", verbose);
    }
  }
  if (!r.logs.empty()) ReportLogs(out, r);
  if (std::isfinite(r.log_noise) && std::isfinite(r.residual_rms)) out << ResidualLine(r);
  out << "steps: " << r.steps_used << " used of " << r.steps_total;
  for (const auto& [reason, count] : r.steps_excluded) {
    out << "; " << count << " excluded (" << reason << ")";
  }
  out << "\n" << SolverLines(r, verbose);
  return out.str();
}

void WriteResidualsCsv(const EstimateResult& r, const std::string& path) {
  WriteFileAtomically(path, "residuals", [&](std::ostream& out) {
    out << "# per-step residuals of the " << ToString(r.method) << " fit\n";
    out << "row,t," << r.residual_names[0] << "," << r.residual_names[1] << ","
        << r.residual_names[2] << ",used\n";
    for (const StepResidual& s : r.residuals) {
      out << s.row << "," << ExactCell(s.t_s) << "," << ExactCell(s.value[0]) << ","
          << ExactCell(s.value[1]) << "," << ExactCell(s.value[2]) << "," << (s.used ? 1 : 0)
          << "\n";
    }
  });
}

}  // namespace slideid
