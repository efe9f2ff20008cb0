#include "report/html_report.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "forward_model/constants.h"
#include "forward_model/contact_patch.h"
#include "forward_model/logged_poses.h"
#include "forward_model/number_format.h"
#include "report/html_text.h"
#include "report/svg_plot.h"

namespace slideid {
namespace {

// Patch outlines drawn along a path: about this many, evenly over the rows.
constexpr int kPatchSnapshots = 6;
// Figure sizes [px]: wide enough to read, two side by side in a 1100 px window.
constexpr int kFigureWidth = 520, kFigureHeight = 360, kForestRowHeight = 22;

// Loads nothing: no default source; inline style only; images only from data: URIs (none
// are used, but a browser's own favicon request then fails silently instead of loading).
constexpr const char* kContentSecurityPolicy =
    "default-src 'none'; style-src 'unsafe-inline'; img-src data:";

constexpr const char* kStyle = R"(
body { font-family: sans-serif; margin: 1.5em auto; padding: 0 1em; max-width: 1200px; color: #222; }
h1 { font-size: 1.5em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: .2em; }
table { border-collapse: collapse; margin: .5em 0; }
th, td { border: 1px solid #ccc; padding: .25em .5em; text-align: left; vertical-align: top; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.ok { color: #06612b; } .suspect { color: #a15c00; } .not-identifiable { color: #888; }
.status { font-size: 1.1em; padding: .5em; background: #f4f4f4; border-left: 4px solid #0072B2; }
.note { color: #555; font-size: .9em; }
.figures { display: flex; flex-wrap: wrap; gap: 1em; }
figure { margin: 0; } figcaption { font-size: .85em; color: #555; max-width: 520px; }
svg.figure { max-width: 100%; height: auto; }
svg .grid { stroke: #eee; } svg .tick { font-size: 11px; fill: #444; }
svg .axis-label { font-size: 12px; fill: #222; } svg .fig-title { font-size: 13px; font-weight: bold; }
svg .legend { font-size: 11px; fill: #222; }
code, pre { background: #f4f4f4; padding: .1em .3em; white-space: pre-wrap; word-break: break-all; }
nav a { margin-right: 1em; }
article { border-top: 1px dashed #ccc; margin-top: 1em; }
)";

const char* VerdictClass(Verdict v) {
  switch (v) {
    case Verdict::kOk:
      return "ok";
    case Verdict::kSuspect:
      return "suspect";
    case Verdict::kNotIdentifiable:
      return "not-identifiable";
  }
  return "";
}

const char* ParameterLabel(int i) {
  static const char* const labels[] = {"a = e_t·mu", "b = e_o/e_t", "c = e_r/e_t [m]"};
  return labels[i];
}

std::string Td(const std::string& html, bool number = false) {
  return std::string(number ? "<td class=\"num\">" : "<td>") + html + "</td>";
}

std::string Interval(double lo, double hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return std::string(kMissingValue);
  return "[" + HtmlNumber(lo, 6) + ", " + HtmlNumber(hi, 6) + "]";
}

/// One row of the estimates table.
std::string EstimateRow(const std::string& name, const ParameterEstimate& p,
                        const std::string& truth) {
  std::ostringstream row;
  const bool known = p.verdict != Verdict::kNotIdentifiable;
  row << "<tr>" << Td(HtmlEscape(name))
      << Td(known ? HtmlNumber(p.value, 6) : "not identifiable", known)
      << Td(HtmlNumber(p.stderr_value, 3), true) << Td(Interval(p.ci95_lo, p.ci95_hi), true)
      << "<td class=\"" << VerdictClass(p.verdict) << "\">" << HtmlEscape(ToString(p.verdict))
      << "</td>" << Td(truth, true) << Td(HtmlEscape(p.reason.empty() ? p.note : p.reason))
      << "</tr>";
  return row.str();
}

// ---- geometry of the path figures ---------------------------------------------------------

void AddPath(const std::vector<PlanarState>& poses, const SvgStyle& style,
             const std::string& legend, SvgPlot* plot) {
  std::vector<double> x, y;
  for (const PlanarState& q : poses) {
    x.push_back(q.x * 1e3);
    y.push_back(q.y * 1e3);
  }
  plot->AddLine(x, y, style, legend);
}

/// The patch outline at the snapshot rows of `poses`.
void AddOutlines(const ContactPatch& patch, const std::vector<PlanarState>& poses,
                 const std::vector<size_t>& rows, const SvgStyle& style, SvgPlot* plot) {
  const std::vector<Eigen::Vector2d> outline = patch.Outline(48);
  for (const size_t u : rows) {
    if (u >= poses.size()) continue;
    const PlanarState& q = poses[u];
    const double c = std::cos(q.theta), s = std::sin(q.theta);
    std::vector<double> x, y;
    for (const Eigen::Vector2d& p : outline) {
      x.push_back(1e3 * (q.x + c * p.x() - s * p.y()));
      y.push_back(1e3 * (q.y + s * p.x() + c * p.y()));
    }
    if (!outline.empty()) {
      x.push_back(x.front());
      y.push_back(y.front());
    }
    plot->AddLine(x, y, style);
  }
}

std::vector<size_t> SnapshotRows(size_t rows) {
  std::vector<size_t> out;
  if (rows == 0) return out;
  for (int k = 0; k < kPatchSnapshots; ++k) {
    out.push_back(std::min(rows - 1, k * (rows - 1) / (kPatchSnapshots - 1)));
  }
  return out;
}

/// The CM path of the log (and of `other`, a replay or a prediction), the patch at a few
/// poses and the tip's path.
std::string PathFigure(const Trajectory& log, const Trajectory* other,
                       const std::string& other_name) {
  SvgPlot plot(kFigureWidth, kFigureHeight);
  plot.SetTitle("path of the CM, patch at " + std::to_string(kPatchSnapshots) + " poses");
  plot.SetXLabel("x [mm]");
  plot.SetYLabel("y [mm]");
  plot.SetEqualAspect(true);
  const std::vector<PlanarState> poses = LoggedOrIntegratedPoses(log);
  const std::vector<size_t> rows = SnapshotRows(poses.size());
  const std::vector<std::string>& colors = SeriesColors();
  if (const std::optional<ContactPatch>& patch = log.patch) {
    AddOutlines(*patch, poses, rows, {colors[0], 0.8, false, 0.6}, &plot);
    if (other)
      AddOutlines(*patch, other->samples.empty() ? poses : LoggedOrIntegratedPoses(*other), rows,
                  {colors[1], 0.8, true, 0.6}, &plot);
  }
  AddPath(poses, {colors[0], 2.0}, "logged", &plot);
  if (other) AddPath(LoggedOrIntegratedPoses(*other), {colors[1], 1.6, true}, other_name, &plot);
  if (log.measured.tip) {
    std::vector<double> x, y;
    for (const TrajectorySample& s : log.samples) {
      x.push_back(s.tip_world ? s.tip_world->x() * 1e3 : std::nan(""));
      y.push_back(s.tip_world ? s.tip_world->y() * 1e3 : std::nan(""));
    }
    plot.AddLine(x, y, {colors[2], 1.2}, "pusher tip");
  }
  return plot.Render("the logged path of " + (log.source.empty() ? "the log" : log.source) +
                     (other ? " and the " + other_name : ""));
}

/// Unit and scale of a residual channel from its name's suffix ("x_m", "vx_mps").
std::pair<double, std::string> ResidualUnit(const std::string& name) {
  auto ends = [&](const std::string& s) {
    return name.size() >= s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0;
  };
  if (ends("_mps")) return {1e3, "mm/s"};
  if (ends("_m")) return {1e3, "mm"};
  return {1.0, ""};
}

std::string ResidualFigure(const EstimateResult& result, int fit_index) {
  SvgPlot plot(kFigureWidth, kFigureHeight);
  plot.SetTitle("residuals against time");
  plot.SetXLabel("t [s]");
  const auto [scale, unit] = ResidualUnit(result.residual_names[0]);
  plot.SetYLabel(unit.empty() ? "residual" : "residual [" + unit + "]");
  for (int c = 0; c < 3; ++c) {
    std::vector<double> t, v;
    for (const StepResidual& r : result.residuals) {
      if (r.log != fit_index) continue;
      t.push_back(r.t_s);
      v.push_back(r.used ? r.value[c] * scale : std::nan(""));
    }
    plot.AddLine(t, v, {SeriesColors()[c], 1.0}, result.residual_names[c]);
  }
  return plot.Render("the residuals of the fit against time");
}

/// |predicted - logged| CM position [mm] against time, rows matched by index.
std::string PredictionErrorFigure(const Trajectory& log, const Trajectory& predicted) {
  SvgPlot plot(kFigureWidth, kFigureHeight);
  plot.SetTitle("prediction error against time");
  plot.SetXLabel("t [s]");
  plot.SetYLabel("error [mm] / [deg]");
  std::vector<double> t, position, rotation;
  const std::vector<PlanarState> a = LoggedOrIntegratedPoses(log),
                                 b = LoggedOrIntegratedPoses(predicted);
  for (size_t u = 0; u < std::min(a.size(), b.size()); ++u) {
    t.push_back(log.samples[u].t_s);
    position.push_back(1e3 * std::hypot(a[u].x - b[u].x, a[u].y - b[u].y));
    rotation.push_back(std::abs(a[u].theta - b[u].theta) * kRadToDeg);
  }
  plot.AddLine(t, position, {SeriesColors()[0], 1.5}, "CM position [mm]");
  plot.AddLine(t, rotation, {SeriesColors()[1], 1.5, true}, "heading [deg]");
  return plot.Render("the prediction's error against time");
}

std::string Figure(const std::string& svg, const std::string& caption) {
  return "<figure>" + svg + "<figcaption>" + HtmlEscape(caption) + "</figcaption></figure>";
}

// ---- sections -------------------------------------------------------------------------------

std::string StatusInWords(const ReportInputs& in) {
  if (in.result) {
    const EstimateResult& r = *in.result;
    int ok = 0, suspect = 0, unknown = 0;
    for (const ParameterEstimate& p : r.parameters) {
      ok += p.verdict == Verdict::kOk;
      suspect += p.verdict == Verdict::kSuspect;
      unknown += p.verdict == Verdict::kNotIdentifiable;
    }
    std::string words =
        std::string("The ") + ToString(r.method) + " fit " +
        (r.status == TerminationStatus::kConverged ? "converged, and every estimate is ok."
         : r.status == TerminationStatus::kConvergedWithCaveats
             ? "converged with caveats: " + std::to_string(ok) + " ok, " + std::to_string(suspect) +
                   " suspect, " + std::to_string(unknown) + " not identifiable."
         : r.status == TerminationStatus::kNoConvergence
             ? "did not converge: its estimates are not to be used."
             : "found too little excitation: the logs determine no parameter.");
    const int fitted = static_cast<int>(
        std::count_if(r.logs.begin(), r.logs.end(), [](const LogResult& l) { return !l.skipped; }));
    if (fitted > 1) words += " " + std::to_string(fitted) + " logs pooled.";
    return words;
  }
  if (in.validation) {
    const ValidationResult& v = *in.validation;
    return "Cross-validation of " + std::to_string(v.logs.size()) + " logs in " +
           std::to_string(v.folds) + " folds, driven by the " + ToString(v.drive) + ".";
  }
  return "Nothing was identified.";
}

std::string EstimatesSection(const ReportInputs& in) {
  std::ostringstream s;
  s << "<section id=\"estimates\"><h2>Estimates</h2>";
  if (in.result) {
    const EstimateResult& r = *in.result;
    s << "<table><tr><th>parameter</th><th>estimate</th><th>std. error</th><th>95% interval</th>"
         "<th>verdict</th><th>truth (log metadata)</th><th>why / how</th></tr>";
    const double truth[3] = {in.truth ? in.truth->a : NAN, in.truth ? in.truth->b : NAN,
                             in.truth ? in.truth->c : NAN};
    for (int i = 0; i < 3; ++i) {
      s << EstimateRow(std::string(ParameterName(i)) + " (" + ParameterLabel(i) + ")",
                       r.parameters[i], HtmlNumber(truth[i], 6));
    }
    if (r.mu_pusher_examined) {
      s << EstimateRow("mu_pusher (tip on edge)", r.mu_pusher, std::string(kMissingValue));
      if (std::isfinite(r.mu_pusher_lower_bound)) {
        s << "<tr><td colspan=\"7\" class=\"note\">mu_pusher is at least "
          << HtmlNumber(r.mu_pusher_lower_bound) << "</td></tr>";
      }
    }
    for (const NuisanceEstimate& n : r.nuisance) {
      ParameterEstimate p;
      p.verdict = n.verdict;
      p.value = n.value;
      p.stderr_value = n.stderr_value;
      p.ci95_lo = n.ci95_lo;
      p.ci95_hi = n.ci95_hi;
      p.reason = n.reason;
      s << EstimateRow(n.name + (n.log.empty() ? "" : " (" + n.log + ")"), p,
                       std::string(kMissingValue));
    }
    s << "</table><p>Residuals: " << HtmlNumber(r.residual_rms * 1e3, 3)
      << " mm RMS against the log's own noise of " << HtmlNumber(r.log_noise * 1e3, 3)
      << " mm; steps used " << r.steps_used << " of " << r.steps_total << "; " << r.iterations
      << " solver iterations, " << HtmlNumber(r.seconds, 3) << " s.</p>";
    s << "<p class=\"note\">The last solve's own account (of its iterations alone; the "
         "trace below has every solve's): "
      << HtmlEscape(r.message) << "</p>";
  } else if (in.validation) {
    s << "<p>Each fold's friction, fitted pooled on the other logs:</p><table><tr><th>fold</th>"
         "<th>held out</th><th>a</th><th>b</th><th>c [m]</th><th>mu_p</th><th>from</th></tr>";
    for (const FoldFit& f : in.validation->fold_fits) {
      std::string held;
      for (const std::string& h : f.held_out) held += (held.empty() ? "" : ", ") + h;
      s << "<tr>" << Td(std::to_string(f.fold), true) << Td(HtmlEscape(held));
      if (f.ok) {
        s << Td(HtmlNumber(f.friction.a, 5), true) << Td(HtmlNumber(f.friction.b, 5), true)
          << Td(HtmlNumber(f.friction.c, 5), true) << Td(HtmlNumber(f.mu_pusher, 4), true)
          << Td(HtmlEscape(f.mu_pusher_from));
      } else {
        s << "<td colspan=\"5\">failed: " << HtmlEscape(f.error) << "</td>";
      }
      s << "</tr>";
    }
    s << "</table>";
  }
  return s.str() + "</section>";
}

std::string ForestPlot(const EstimateResult& r, int i,
                       const std::optional<ReducedFriction>& truth) {
  std::vector<std::string> names;
  std::vector<const ParameterEstimate*> rows;
  for (const LogResult& l : r.logs) {
    if (l.skipped) continue;
    names.push_back(l.name + (l.parameters[i].identifiable ? "" : " (not identifiable)"));
    rows.push_back(&l.parameters[i]);
  }
  names.push_back("pooled");
  rows.push_back(&r.parameters[i]);
  const int height = 70 + kForestRowHeight * static_cast<int>(names.size());
  SvgPlot plot(kFigureWidth, height);
  plot.SetTitle(ParameterLabel(i));
  plot.SetXLabel(std::string(ParameterName(i)) + ": estimate and 95% interval");
  plot.SetYCategories(names);
  const std::vector<std::string>& colors = SeriesColors();
  std::vector<double> x, y, px, py;
  for (size_t k = 0; k < rows.size(); ++k) {
    const bool pooled = k + 1 == rows.size();
    const ParameterEstimate& p = *rows[k];
    if (p.verdict == Verdict::kNotIdentifiable) continue;
    plot.AddIntervalX(k, p.ci95_lo, p.ci95_hi,
                      {pooled ? colors[1] : colors[0], pooled ? 2.5 : 1.5});
    (pooled ? px : x).push_back(p.value);
    (pooled ? py : y).push_back(k);
  }
  plot.AddMarkers(x, y, {colors[0]}, "square", 7);
  plot.AddMarkers(px, py, {colors[1]}, "diamond", 12);
  if (truth) {
    const double t[3] = {truth->a, truth->b, truth->c};
    plot.AddVerticalLine(t[i], {colors[6], 1.0, true}, "truth");
  }
  return plot.Render(std::string("forest plot of ") + ParameterName(i));
}

std::string PooledSection(const ReportInputs& in) {
  std::ostringstream s;
  s << "<section id=\"pooled\"><h2>Pooled fit: each log and all together</h2>";
  const EstimateResult* r = in.result ? &*in.result : nullptr;
  if (!r || r->logs.empty()) {
    s << "<p>One log: nothing was pooled.</p></section>";
    return s.str();
  }
  s << "<div class=\"figures\">";
  for (int i = 0; i < 3; ++i) {
    s << Figure(ForestPlot(*r, i, in.truth),
                "Each log fitted on its own (squares, 95% intervals) and the pooled fit (diamond)" +
                    std::string(in.truth ? "; dashed: the truth the logs record" : "") + ".");
  }
  s << "</div><h3>Heterogeneity: do the logs agree?</h3><table><tr><th>parameter</th>"
       "<th>logs</th><th>Cochran's Q</th><th>p</th><th>I²</th><th>tau (log scale)</th>"
       "<th>consistent</th></tr>";
  for (int i = 0; i < 3; ++i) {
    const Heterogeneity& h = r->heterogeneity[i];
    s << "<tr>" << Td(ParameterName(i));
    if (!h.tested) {
      s << "<td colspan=\"6\">not tested (fewer than two logs identify it)</td></tr>";
      continue;
    }
    s << Td(std::to_string(h.logs), true) << Td(HtmlNumber(h.q, 4), true)
      << Td(HtmlNumber(h.p_value, 3), true) << Td(HtmlNumber(h.i2, 3), true)
      << Td(HtmlNumber(h.tau_log, 3), true) << Td(h.consistent ? "yes" : "no: the logs differ")
      << "</tr>";
  }
  s << "</table>";
  const bool skipped =
      std::any_of(r->logs.begin(), r->logs.end(), [](const LogResult& l) { return l.skipped; });
  if (skipped) {
    s << "<p>Skipped:</p><ul>";
    for (const LogResult& l : r->logs) {
      if (l.skipped)
        s << "<li>" << HtmlEscape(l.name) << ": " << HtmlEscape(l.skip_reason) << "</li>";
    }
    s << "</ul>";
  }
  return s.str() + "</section>";
}

std::string Yes(bool b) { return b ? "yes" : "no"; }

std::string CheckTable(const LogCheck& c) {
  std::ostringstream s;
  auto row = [&](const std::string& what, const std::string& html) {
    s << "<tr><th>" << HtmlEscape(what) << "</th>" << Td(html) << "</tr>";
  };
  s << "<table>";
  row("rows, duration, rate", std::to_string(c.rows) + " rows, " + HtmlNumber(c.duration_s, 4) +
                                  " s, " + HtmlNumber(c.rate_hz, 4) + " Hz");
  row("gaps", std::to_string(c.gaps) +
                  (c.gaps > 0 ? ", the longest " + HtmlNumber(c.longest_gap_s, 3) + " s" : ""));
  row("columns", "pose " + Yes(c.has_pose) + ", velocity " + Yes(c.has_velocity) + ", force " +
                     Yes(c.has_force) + ", push point " + Yes(c.has_push_point) + ", tip " +
                     Yes(c.has_tip));
  row("noise the log shows", HtmlNumber(c.pose_noise_m * 1e3, 3) + " mm, " +
                                 HtmlNumber(c.angle_noise_rad * 1e3, 3) + " mrad");
  row("force at rest", std::to_string(c.rest_rows) + " rows at rest, median (" +
                           HtmlNumber(c.rest_force_x_n, 3) + ", " +
                           HtmlNumber(c.rest_force_y_n, 3) + ") N; largest push " +
                           HtmlNumber(c.max_push_n, 3) + " N");
  std::string dead;
  for (const std::string& d : c.dead_channels) dead += (dead.empty() ? "" : "; ") + HtmlEscape(d);
  row("dead channels", dead.empty() ? "none" : dead);
  row("excitation",
      "turns " + HtmlNumber(c.rotation_range_rad * kRadToDeg, 3) + " deg; pushed over " +
          HtmlNumber(c.push_directions_rad * kRadToDeg, 3) + " deg of directions, slides over " +
          HtmlNumber(c.slide_directions_rad * kRadToDeg, 3) + " deg; pushes pass up to " +
          HtmlNumber(c.max_push_offset_m * 1e3, 3) + " mm from the CM; slides " +
          HtmlNumber(100 * c.sliding_share, 3) + "% of the time");
  if (!c.failure.empty()) row("the fit could not look", HtmlEscape(c.failure));
  for (int i = 0; i < 3; ++i) {
    const ParameterOutlook& o = c.parameters[i];
    row(std::string("could identify ") + ParameterName(i),
        o.identifiable ? "yes, to about " + HtmlNumber(100 * o.relative_stderr, 2) +
                             "% (one sigma, white noise), from a seed of " + HtmlNumber(o.seed, 4)
                       : "<span class=\"not-identifiable\">no</span>: " + HtmlEscape(o.reason));
  }
  if (c.mu_pusher_examined) {
    row("could identify mu_pusher",
        c.mu_pusher.identifiable ? "yes (" + std::to_string(c.tip_sliding_rows) + " of " +
                                       std::to_string(c.tip_contact_rows) + " contact rows slide)"
                                 : "no: " + HtmlEscape(c.mu_pusher.reason));
  }
  for (const auto& [name, o] : c.nuisances) {
    row("could identify " + name, o.identifiable ? "yes" : "no: " + HtmlEscape(o.reason));
  }
  row("condition number of J^T J",
      std::isinf(c.condition_number) ? "infinite (singular)" : HtmlNumber(c.condition_number, 3));
  std::string advice;
  for (const std::string& a : c.advice) advice += "<li>" + HtmlEscape(a) + "</li>";
  row("what would help", advice.empty() ? "nothing is amiss" : "<ul>" + advice + "</ul>");
  s << "</table>";
  return s.str();
}

std::string CheckSection(const ReportInputs& in) {
  std::ostringstream s;
  s << "<section id=\"check\"><h2>Check before fitting</h2><p class=\"note\">What each log "
       "shows about itself and what a fit could make of it, from J<sup>T</sup>J at the fit's "
       "seed (identify --check).</p>";
  for (const ReportLog& l : in.logs) {
    s << "<h3>" << HtmlEscape(l.name) << "</h3>";
    s << (l.check ? CheckTable(*l.check) : "<p>No check: " + HtmlEscape(l.check_note) + "</p>");
  }
  return s.str() + "</section>";
}

// A cell's background: blue for +1, red for -1, white for 0.
std::string CorrelationCell(double r) {
  if (!std::isfinite(r)) return "<td class=\"num\">" + std::string(kMissingValue) + "</td>";
  const int shade = static_cast<int>(std::lround(255 * (1 - std::min(1.0, std::abs(r)) * 0.6)));
  const std::string color =
      r >= 0 ? Printf("rgb(%d,%d,255)", shade, shade) : Printf("rgb(255,%d,%d)", shade, shade);
  return "<td class=\"num\" style=\"background:" + color + "\">" + Printf("%+.3f", r) + "</td>";
}

std::string CorrelationSection(const ReportInputs& in) {
  std::ostringstream s;
  s << "<section id=\"correlation\"><h2>Correlations of a, b, c</h2>";
  const bool any =
      in.result && std::any_of(in.result->correlation.begin(), in.result->correlation.end(),
                               [](const std::array<double, 3>& row) {
                                 return std::isfinite(row[0]) || std::isfinite(row[1]) ||
                                        std::isfinite(row[2]);
                               });
  if (!any) {
    s << "<p>Not available: "
      << (in.result ? "this method does not compute them, or no parameter is identifiable."
                    : "validate fits each fold; see identify --report.")
      << "</p></section>";
    return s.str();
  }
  s << "<p class=\"note\">Of the estimates of log a, log b and log c, from the covariance the "
       "intervals come from. Near ±1: the log cannot tell the two apart well. "
    << kMissingValue << ": not identifiable.</p><table><tr><th></th>";
  for (int j = 0; j < 3; ++j) s << "<th>" << ParameterName(j) << "</th>";
  s << "</tr>";
  for (int i = 0; i < 3; ++i) {
    s << "<tr><th>" << ParameterName(i) << "</th>";
    for (int j = 0; j < 3; ++j) s << CorrelationCell(in.result->correlation[i][j]);
    s << "</tr>";
  }
  return s.str() + "</table></section>";
}

std::string TraceSection(const ReportInputs& in) {
  std::ostringstream s;
  s << "<section id=\"trace\"><h2>Optimisation trace</h2>";
  if (!in.result || in.result->trace.empty()) {
    s << "<p>Not available: "
      << (in.result ? "only the trajectory fit records its solves' iterations."
                    : "validate fits each fold; see identify --report.")
      << "</p></section>";
    return s.str();
  }
  const std::vector<SolverIteration>& trace = in.result->trace;
  SvgPlot plot(kFigureWidth * 2 - 100, kFigureHeight);
  plot.SetTitle("Ceres cost per iteration, solve by solve");
  plot.SetXLabel("iteration, counted over the solves in order");
  plot.SetYLabel("cost");
  plot.SetLogY(true);
  std::vector<std::string> stages;
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> series;
  std::ostringstream table;
  table << "<table><tr><th>solve</th><th>iterations (with its start)</th><th>cost at start</th>"
           "<th>cost at end</th></tr>";
  int n = 0;
  for (size_t k = 0; k < trace.size(); ++k) {
    const SolverIteration& it = trace[k];
    if (std::find(stages.begin(), stages.end(), it.stage) == stages.end())
      stages.push_back(it.stage);
    auto& [x, y] = series[it.stage];
    if (it.iteration == 0 && !x.empty()) {  // a new solve of a stage already seen: break the line
      x.push_back(std::nan(""));
      y.push_back(std::nan(""));
    }
    x.push_back(n++);
    y.push_back(it.cost);
    const bool last = k + 1 == trace.size() || trace[k + 1].iteration == 0;
    if (last) {
      size_t first = k;
      while (first > 0 && trace[first].iteration != 0) --first;
      table << "<tr>" << Td(HtmlEscape(it.stage)) << Td(std::to_string(k - first + 1), true)
            << Td(HtmlNumber(trace[first].cost, 4), true) << Td(HtmlNumber(it.cost, 4), true)
            << "</tr>";
    }
  }
  for (size_t k = 0; k < stages.size(); ++k) {
    const auto& [x, y] = series[stages[k]];
    const SvgStyle style{SeriesColors()[k % SeriesColors().size()], 1.5};
    plot.AddLine(x, y, style, stages[k]);
    plot.AddMarkers(x, y, style, "circle", 5);
  }
  s << Figure(plot.Render("the optimisation trace"),
              "Each solve's cost is that of its own problem (the segments' heads, the plain or the "
              "robust loss): compare within a solve. Cost: half the sum of the squared "
              "(robustified) residuals.")
    << table.str() << "</table>";
  return s.str() + "</section>";
}

std::string ErrorCells(const ErrorSummary& e, double scale) {
  if (e.pushes == 0) return "<td colspan=\"1\">" + std::string(kMissingValue) + "</td>";
  return Td(HtmlNumber(e.median * scale, 3) + " [" + HtmlNumber(e.q25 * scale, 3) + ", " +
                HtmlNumber(e.q75 * scale, 3) + "] " + HtmlNumber(e.worst * scale, 3),
            true);
}

std::string PredictionsSection(const ReportInputs& in) {
  std::ostringstream s;
  s << "<section id=\"predictions\"><h2>Predictions against the logs</h2>";
  if (!in.validation) {
    s << "<p>Not run: validate --report predicts each push from the other logs' fit.</p></section>";
    return s.str();
  }
  s << "<p>Errors: median [quartiles] worst over the pushes "
       "predicted.</p><table><tr><th>method</th>"
       "<th>failed</th><th>final position [mm]</th><th>final rotation [deg]</th>"
       "<th>position per 100 mm [mm]</th><th>position / displacement [%]</th></tr>";
  for (const MethodValidation& m : in.validation->methods) {
    s << "<tr>" << Td(HtmlEscape(m.method)) << Td(std::to_string(m.failed), true)
      << ErrorCells(m.final_position_m, 1e3) << ErrorCells(m.final_rotation_rad, kRadToDeg)
      << ErrorCells(m.final_position_per_100mm_m, 1e3) << ErrorCells(m.final_position_fraction, 100)
      << "</tr>";
  }
  return s.str() + "</table></section>";
}

std::string LogArticle(const ReportInputs& in, const ReportLog& l) {
  std::ostringstream s;
  s << "<article class=\"log\"><h3>" << HtmlEscape(l.name) << "</h3>";
  if (!l.path.empty() && l.path != l.name)
    s << "<p class=\"note\">" << HtmlEscape(l.path) << "</p>";
  s << "<div class=\"figures\">";
  if (in.validation) {
    s << Figure(PathFigure(l.log, l.prediction ? &*l.prediction : nullptr, "predicted"),
                "Solid: the log; dashed: its fold's prediction from the first row" +
                    std::string(l.log.measured.tip ? "; green: the pusher tip" : "") + "." +
                    (l.prediction_note.empty() ? "" : " " + l.prediction_note));
    if (l.prediction)
      s << Figure(PredictionErrorFigure(l.log, *l.prediction),
                  "How far the prediction is from the log, row by row.");
  } else {
    s << Figure(PathFigure(l.log, l.replay ? &*l.replay : nullptr, "replayed"),
                "Solid: the log; dashed: replayed from its first row under the logged forces with "
                "the estimates (held values where not identifiable)" +
                    std::string(l.log.measured.tip ? "; green: the pusher tip" : "") + "." +
                    (l.replay_note.empty() ? "" : " " + l.replay_note));
    if (in.result && l.fit_index >= 0) {
      s << Figure(ResidualFigure(*in.result, l.fit_index),
                  "What the fit could not explain, per row (rows between shooting segments are "
                  "not fitted: gaps).");
    }
  }
  s << "</div>";
  if (in.validation) {
    s << "<table><tr><th>method</th><th>final position [mm]</th><th>final rotation [deg]</th>"
         "<th>mean position [mm]</th><th>parts at [s]</th><th></th></tr>";
    for (const MethodValidation& m : in.validation->methods) {
      for (const PushPrediction& p : m.pushes) {
        if (p.log != l.name && p.log != l.path) continue;
        const PredictionErrors& e = p.errors;
        s << "<tr>" << Td(HtmlEscape(m.method)) << Td(HtmlNumber(e.final_position_m * 1e3, 3), true)
          << Td(HtmlNumber(e.final_rotation_rad * kRadToDeg, 3), true)
          << Td(HtmlNumber(e.mean_position_m * 1e3, 3), true)
          << Td(e.parting_time_s ? HtmlNumber(*e.parting_time_s, 3) : "never", true)
          << Td(p.ok ? "" : "failed: " + HtmlEscape(p.error)) << "</tr>";
      }
    }
    s << "</table>";
  }
  if (!l.import_row.empty()) {
    s << "<details open><summary>Import report row (" << HtmlEscape(l.import_report_path)
      << ")</summary><table>";
    for (const auto& [column, cell] : l.import_row) {
      s << "<tr><th>" << HtmlEscape(column) << "</th>"
        << Td(cell.empty() ? std::string(kMissingValue) : HtmlEscape(cell)) << "</tr>";
    }
    s << "</table></details>";
  } else {
    s << "<p class=\"note\">No import report beside it (only logs written by import-log have "
         "one).</p>";
  }
  return s.str() + "</article>";
}

std::string LogsSection(const ReportInputs& in) {
  std::ostringstream s;
  s << "<section id=\"logs\"><h2>Per log</h2>";
  for (const ReportLog& l : in.logs) s << LogArticle(in, l);
  return s.str() + "</section>";
}

std::string RunSection(const ReportInputs& in) {
  std::ostringstream s;
  s << "<section id=\"run\"><h2>Run</h2><table><tr><th>command line</th><td><code>"
    << HtmlEscape(in.command_line) << "</code></td></tr><tr><th>version</th><td>slideid "
    << HtmlEscape(in.version) << "</td></tr>";
  for (const ReportTiming& t : in.timings) {
    s << "<tr><th>" << HtmlEscape(t.what) << "</th>" << Td(HtmlNumber(t.seconds, 3) + " s", true)
      << "</tr>";
  }
  s << "</table>";
  if (!in.warnings.empty()) {
    s << "<h3>Warnings</h3><ul>";
    for (const std::string& w : in.warnings) s << "<li>" << HtmlEscape(w) << "</li>";
    s << "</ul>";
  }
  return s.str() + "</section>";
}

}  // namespace

const std::vector<std::string>& ReportSectionIds() {
  static const std::vector<std::string> ids = {"summary",     "estimates", "pooled",
                                               "predictions", "logs",      "check",
                                               "correlation", "trace",     "run"};
  return ids;
}

std::string RenderHtmlReport(const ReportInputs& in) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
       << "<meta http-equiv=\"Content-Security-Policy\" content=\"" << kContentSecurityPolicy
       << "\"><meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
       << "<title>slideid " << HtmlEscape(in.tool) << " report</title><style>" << kStyle
       << "</style></head><body>\n";
  html << "<h1>slideid " << HtmlEscape(in.tool) << " report</h1>";
  html << "<nav>";
  for (const std::string& id : ReportSectionIds())
    html << "<a href=\"#" << id << "\">" << id << "</a>";
  html << "</nav>\n";
  html << "<section id=\"summary\"><p class=\"status\">" << HtmlEscape(StatusInWords(in)) << "</p>";
  std::string names;
  for (const ReportLog& l : in.logs) names += (names.empty() ? "" : ", ") + l.name;
  html << "<p>Logs: " << HtmlEscape(names.empty() ? std::string(kMissingValue) : names)
       << "</p></section>\n";
  for (const std::string& section :
       {EstimatesSection(in), PooledSection(in), PredictionsSection(in), LogsSection(in),
        CheckSection(in), CorrelationSection(in), TraceSection(in), RunSection(in)}) {
    html << section << "\n";
  }
  html << "</body></html>\n";
  return html.str();
}

}  // namespace slideid
