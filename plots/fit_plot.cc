#include "plots/fit_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "forward_model/number_format.h"
#include "plots/gnuplot.h"

namespace slideid {
namespace {

// Panels get a log axis when their intervals span more than this factor: a log with a
// weak estimate (c of a log that barely turns) would otherwise squeeze every other row
// into a corner. The agreement test works on the logarithms too (estimator/pooling.h).
constexpr double kLogAxisSpan = 4.0;
// Each panel's x range: its intervals' span and this fraction of it either side.
constexpr double kRangeMargin = 0.06;
// ... and at least this fraction of the values: gnuplot cannot draw a range near rounding.
constexpr double kMinRangeFraction = 1e-4;
// Most tick labels a panel's x axis gets.
constexpr int kMaxTicks = 5;
// The left panel's room for the log names [fraction of the width]; the room above the
// panels for the title (two lines) and the panels' titles, below them for their axes and
// labels, and at the bottom for the legend [px].
constexpr double kNamesFraction = 0.12;
constexpr int kTopPx = 95;
constexpr int kAxesPx = 50;
constexpr int kLegendPx = 22;
constexpr int kChromePx = kTopPx + kAxesPx + kLegendPx;
// Log names longer than this are shortened from the left (the file name's end says most).
constexpr size_t kMaxNameChars = 28;

const char* const kAgreeColour = "#1f4e9a";
const char* const kDisagreeColour = "#d62728";
const char* const kPooledColour = "#222222";
const char* const kBandColour = "#dde7f3";

const char* const kLongNames[3] = {"a = e_t mu", "b = e_o / e_t", "c = e_r / e_t [m]"};

/// A round tick step (1, 2 or 5 times a power of ten) giving at most kMaxTicks ticks over
/// `span`: gnuplot's own choice ignores the panel's width and crowds narrow panels.
double NiceStep(double span) {
  const double raw = span / kMaxTicks;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0}) {
    if (m * decade >= raw) return m * decade;
  }
  return 10.0 * decade;
}

/// Tick marks 1, 2 and 5 times the powers of ten within [x0, x1] (a log axis), as a gnuplot
/// tic list: gnuplot's own give one label a decade, often none in a panel.
std::string LogTicks(double x0, double x1) {
  std::string out;
  for (double decade = std::pow(10.0, std::floor(std::log10(x0))); decade <= x1; decade *= 10) {
    for (double m : {1.0, 2.0, 5.0}) {
      const double x = m * decade;
      if (x < x0 || x > x1) continue;
      out += (out.empty() ? "" : ", ") + std::string("\"") + GnuplotNumber(x) + "\" " +
             GnuplotNumber(x);
    }
  }
  return "(" + out + ")";
}

std::string ShortName(const std::string& name) {
  return name.size() <= kMaxNameChars ? name : "..." + name.substr(name.size() - kMaxNameChars + 3);
}

/// The logs drawn (not skipped), in input order.
std::vector<const LogResult*> DrawnLogs(const EstimateResult& r) {
  std::vector<const LogResult*> out;
  for (const LogResult& log : r.logs) {
    if (!log.skipped) out.push_back(&log);
  }
  return out;
}

bool Holds(const ParameterEstimate& p, double value) {
  return std::isfinite(value) && p.ci95_lo <= value && value <= p.ci95_hi;
}

bool HasInterval(const ParameterEstimate& p) {
  return p.identifiable && std::isfinite(p.value) && std::isfinite(p.ci95_lo) &&
         std::isfinite(p.ci95_hi);
}

/// The estimates drawn in panel i: each drawn log's and the pooled one.
std::vector<const ParameterEstimate*> PanelEstimates(const EstimateResult& r, int i) {
  std::vector<const ParameterEstimate*> out;
  for (const LogResult* log : DrawnLogs(r)) out.push_back(&log->parameters[i]);
  out.push_back(&r.parameters[i]);
  return out;
}

bool PanelHasData(const EstimateResult& r, int i) {
  for (const ParameterEstimate* p : PanelEstimates(r, i)) {
    if (HasInterval(*p)) return true;
  }
  return false;
}

std::string AgreementText(const EstimateResult& r, int i) {
  if (r.logs.empty()) return "one log";
  const Heterogeneity& h = r.heterogeneity[i];
  if (!h.tested) return "agreement not tested\n(fewer than two logs identify it)";
  return Printf("%s (p = %.2g)\nQ = %.3g on %d logs, I2 = %.0f%%, tau = %.2g%%",
                h.consistent ? "the logs agree" : "the logs DISAGREE", h.p_value, h.q, h.logs,
                100 * h.i2, 100 * h.tau_log);
}

int Rows(const EstimateResult& r) { return static_cast<int>(DrawnLogs(r).size()); }

}  // namespace

bool FitPlotOptions::IsValid(std::string* why) const {
  return PictureOptions::IsValid(why, /*automatic_height=*/true);
}

int FitPlotHeight(const EstimateResult& result, const FitPlotOptions& options) {
  if (options.height_px > 0) return options.height_px;
  return std::min(20000,
                  std::max(kFitPlotMinHeightPx, kChromePx + kFitPlotRowPx * (Rows(result) + 2)));
}

void WriteFitPlotData(const EstimateResult& r, const std::string& dir) {
  const std::vector<const LogResult*> logs = DrawnLogs(r);
  const int n = static_cast<int>(logs.size());
  for (int i = 0; i < 3; ++i) {
    const double pooled = r.parameters[i].identifiable ? r.parameters[i].value : NAN;
    std::ostringstream out;
    out << "# row value ci95_lo ci95_hi colour suspect: " << ParameterName(i)
        << " of each log (row " << n << " is the first)\n";
    for (int k = 0; k < n; ++k) {
      const ParameterEstimate& p = logs[k]->parameters[i];
      if (!HasInterval(p)) continue;
      const bool agrees = r.logs.empty() || !std::isfinite(pooled) || Holds(p, pooled);
      out << n - k << ' ' << GnuplotNumber(p.value) << ' ' << GnuplotNumber(p.ci95_lo) << ' '
          << GnuplotNumber(p.ci95_hi) << ' ' << (agrees ? "0x1f4e9a" : "0xd62728") << ' '
          << (p.verdict == Verdict::kSuspect ? 1 : 0) << '\n';
    }
    WritePlotFile(dir + "/p" + std::to_string(i) + ".dat", out.str() + "\n");
  }
}

std::string FitPlotScript(const EstimateResult& r, const FitPlotOptions& o,
                          const std::string& dir) {
  const std::vector<const LogResult*> logs = DrawnLogs(r);
  const int n = static_cast<int>(logs.size());
  std::vector<int> panels;
  for (int i = 0; i < 3; ++i) {
    if (PanelHasData(r, i)) panels.push_back(i);
  }
  std::string title = o.title;
  title += std::string(title.empty() ? "" : "    ") + ToString(r.method) + " (" +
           ToString(r.status) + ")";
  if (n > 0) title += ", " + std::to_string(n) + " logs pooled";
  std::string skipped;
  for (const LogResult& log : r.logs) {
    if (log.skipped) skipped += (skipped.empty() ? "" : ", ") + log.name;
  }
  if (!skipped.empty()) title += "\nskipped (unreadable): " + skipped;

  const int height = FitPlotHeight(r, o);
  const double legend = static_cast<double>(kLegendPx) / height;
  std::ostringstream s;
  s << "# Generated by slideid plot-fit.\n"
    << "set terminal pngcairo size " << o.width_px << "," << height
    << " font 'sans,10' noenhanced\n"
    << "set output '" << o.out_png << "'\n"
    << "set multiplot title " << GnuplotDoubleQuoted(title) << "\n"
    << "set grid xtics lc rgb '#e4e4e4'\n"
    << "unset key\n"
    << "set yrange [-1:" << n + 1 << "]\n"
    << "set xtics font ',9'\n"
    << "set bmargin at screen " << GnuplotNumber(static_cast<double>(kAxesPx + kLegendPx) / height)
    << "\nset tmargin at screen " << GnuplotNumber(1.0 - static_cast<double>(kTopPx) / height)
    << "\n";
  // Row labels: the logs from the top, the pooled estimate at the bottom.
  std::string ytics = "set ytics (" + GnuplotDoubleQuoted(n > 0 ? "pooled" : "estimate") + " 0";
  for (int k = 0; k < n; ++k) {
    ytics += ", " + GnuplotDoubleQuoted(ShortName(logs[k]->name)) + " " + std::to_string(n - k);
  }
  ytics += ") nomirror font ',8'\n";
  const double panel_width = (1.0 - kNamesFraction) / std::max<size_t>(1, panels.size());
  for (size_t j = 0; j < panels.size(); ++j) {
    const int i = panels[j];
    const ParameterEstimate& pooled = r.parameters[i];
    double lo = INFINITY, hi = -INFINITY;
    for (const ParameterEstimate* p : PanelEstimates(r, i)) {
      if (!HasInterval(*p)) continue;
      lo = std::min(lo, p->ci95_lo);
      hi = std::max(hi, p->ci95_hi);
    }
    const bool log_axis = lo > 0 && hi / lo > kLogAxisSpan;
    // The intervals' own range with a margin (no tick label on a panel's edge); at least
    // kMinRangeFraction of the values either side (a noiseless fit's intervals are nil).
    double x0, x1;
    if (log_axis) {
      const double pad = std::pow(hi / lo, kRangeMargin);
      x0 = lo / pad;
      x1 = hi * pad;
    } else {
      const double pad = std::max(kRangeMargin * (hi - lo),
                                  kMinRangeFraction * std::max(std::abs(hi), std::abs(lo)));
      x0 = lo - pad;
      x1 = hi + pad;
    }
    s << "\n# ---- " << ParameterName(i) << "\n"
      << "set lmargin at screen " << GnuplotNumber(kNamesFraction + j * panel_width + 0.01) << "\n"
      << "set rmargin at screen " << GnuplotNumber(kNamesFraction + (j + 1) * panel_width - 0.01)
      << "\n"
      << (j == 0 ? ytics : "unset ytics\nset ytics 1 format '' scale 0.5\n")
      << (log_axis ? "set logscale x\n" : "unset logscale x\n") << "set xrange ["
      << GnuplotNumber(x0) << ":" << GnuplotNumber(x1) << "]\n"
      << "set xtics " << (log_axis ? LogTicks(x0, x1) : GnuplotNumber(NiceStep(x1 - x0))) << "\n"
      << "set xlabel "
      << GnuplotDoubleQuoted(std::string(ParameterName(i)) + "   (" + kLongNames[i] + ")")
      << "\nset title " << GnuplotDoubleQuoted(AgreementText(r, i)) << " textcolor rgb '"
      << (r.heterogeneity[i].tested && !r.heterogeneity[i].consistent ? kDisagreeColour : "#000000")
      << "'\nunset object\nunset arrow\n";
    if (HasInterval(pooled)) {
      // The pooled interval shaded across the rows, its value dashed, and a diamond.
      s << "set object 1 rect from " << GnuplotNumber(pooled.ci95_lo) << ", graph 0 to "
        << GnuplotNumber(pooled.ci95_hi) << ", graph 1 fc rgb '" << kBandColour
        << "' fs solid 1.0 noborder behind\n"
        << "set arrow 1 from " << GnuplotNumber(pooled.value) << ", graph 0 to "
        << GnuplotNumber(pooled.value) << ", graph 1 nohead dt 2 lc rgb '" << kPooledColour << "'\n"
        << "set object 2 polygon from " << GnuplotNumber(pooled.ci95_lo) << ",0 to "
        << GnuplotNumber(pooled.value) << ",0.4 to " << GnuplotNumber(pooled.ci95_hi) << ",0 to "
        << GnuplotNumber(pooled.value) << ",-0.4 to " << GnuplotNumber(pooled.ci95_lo)
        << ",0 fc rgb '" << kPooledColour << "' fs solid 1.0 front\n";
    } else if (!r.logs.empty()) {
      s << "set label 1 'pooled: not identifiable' at graph 0.02, first 0 front\n";
    }
    const std::string file = "'" + dir + "/p" + std::to_string(i) + ".dat'";
    s << "plot " << file
      << " using 2:($6 == 0 ? $1 : 1/0):3:4:5 with xerrorbars lc rgb variable pt 7 ps 0.7, \\\n"
      << "     " << file
      << " using 2:($6 == 1 ? $1 : 1/0):3:4:5 with xerrorbars lc rgb variable pt 6 ps 0.9\n"
      << "unset label\n";
  }
  // Legend along the bottom.
  s << "\nset origin 0,0\nset size 1," << GnuplotNumber(legend) << "\n"
    << "unset title\nunset xlabel\nunset ylabel\nunset tics\nunset border\nunset grid\n"
    << "unset object\nunset arrow\nunset logscale x\n"
    << "set lmargin 0\nset rmargin 0\nset tmargin 0\nset bmargin 0\n"
    << "set xrange [0:1]\nset yrange [0:1]\n"
    << "set label 10 "
    << GnuplotDoubleQuoted(
           n > 0 ? "rows: each log's own estimate and 95% interval (red: misses the pooled "
                   "value; open: suspect)    diamond and band: the pooled estimate and its "
                   "95% interval"
                 : "diamond and band: the estimate and its 95% interval")
    << " at 0.5,0.5 center font ',9'\n"
    << "plot 2 with lines lc rgb 'white'\n"
    << "unset multiplot\nset output\n";
  return s.str();
}

void PlotFit(const EstimateResult& result, const FitPlotOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  bool any = false;
  for (int i = 0; i < 3; ++i) any = any || PanelHasData(result, i);
  if (!any) {
    throw std::invalid_argument(
        "plot: nothing to draw: no parameter was identified, by the "
        "pooled fit or by any log");
  }
  if (options.out_png.find('\'') != std::string::npos) {
    throw std::invalid_argument("plot: quote characters in '" + options.out_png +
                                "' are not supported");
  }
  RunGnuplot(options, [&](const std::string& dir, const std::string& staged_png) {
    FitPlotOptions staged = options;
    staged.out_png = staged_png;
    WriteFitPlotData(result, dir);
    return FitPlotScript(result, staged, dir);
  });
}

}  // namespace slideid
