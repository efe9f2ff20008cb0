// The online identifier's estimate and 95% interval against time, beside the batch fit's
// interval of the whole log (and the truth, when the log has it), as SVG files for
// docs/online.md: one figure per parameter, drawn with report/svg_plot.h.
//
//   online_plot --log FILE.csv --out PREFIX [--title TEXT] [--from T]
//
// writes PREFIX_a.svg, PREFIX_b.svg, PREFIX_c.svg (and PREFIX_mu_p.svg when the log has
// the tip, from where its verdict is ok), from time T on (default: the log's start; the first rows'
// estimates, far off, would set the scale). A plain program; it reads the log, runs it through the
// identifier row by row (estimator/online_identifier.h) and the batch fit (Identify, defaults).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "benchmarks/bench_args.h"
#include "estimator/identify.h"
#include "estimator/online_identifier.h"
#include "io/push_log.h"
#include "report/svg_plot.h"

namespace slideid {
namespace {

// The report's figure styles (report/html_report.cc), inline: the file stands alone.
constexpr const char* kStyle =
    "<style>.grid { stroke: #eee; } .tick { font-size: 11px; fill: #444; font-family: sans-serif; "
    "} .axis-label { font-size: 12px; fill: #222; font-family: sans-serif; } .fig-title { "
    "font-size: 13px; font-weight: bold; font-family: sans-serif; } .legend { font-size: 11px; "
    "fill: #222; font-family: sans-serif; }</style>";

std::string Standalone(const std::string& svg) {
  std::string out = svg;
  const std::string open = "<svg ";
  out.replace(out.find(open), open.size(), "<svg xmlns=\"http://www.w3.org/2000/svg\" ");
  out.insert(out.find('>') + 1, kStyle);
  return out + "\n";
}

struct Series {
  std::vector<double> t, value, lo, hi;
};

void Write(const std::string& path, const std::string& title, const std::string& y_label,
           const Series& s, double t0, double t1, const ParameterEstimate* batch, double truth) {
  SvgPlot plot(640, 300);
  plot.SetTitle(title);
  plot.SetXLabel("t [s]");
  plot.SetYLabel(y_label);
  const std::vector<std::string>& colors = SeriesColors();
  SvgStyle band{colors[0], 1.0, true, 0.9};
  plot.AddLine(s.t, s.lo, band, "online 95% interval");
  plot.AddLine(s.t, s.hi, band);
  plot.AddLine(s.t, s.value, SvgStyle{colors[0], 2.0, false, 1.0}, "online estimate");
  if (batch && batch->identifiable) {
    const SvgStyle b{colors[1], 1.5, false, 0.9};
    plot.AddLine({t0, t1}, {batch->ci95_lo, batch->ci95_lo}, b, "batch fit's 95% interval");
    plot.AddLine({t0, t1}, {batch->ci95_hi, batch->ci95_hi}, b);
  }
  if (std::isfinite(truth)) {
    plot.AddLine({t0, t1}, {truth, truth}, SvgStyle{"#000", 1.0, true, 1.0}, "truth");
  }
  // Room above the lines for the legend (top right, over the frame): an invisible point.
  double y_lo = HUGE_VAL, y_hi = -HUGE_VAL;
  for (const std::vector<double>* v : {&s.lo, &s.hi})
    for (double y : *v) y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
  for (double y : {batch && batch->identifiable ? batch->ci95_hi : NAN, truth})
    if (std::isfinite(y)) y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
  plot.AddMarkers({t0}, {y_hi + 0.55 * (y_hi - y_lo)}, SvgStyle{"#fff", 0.0, false, 0.0});
  std::ofstream out(path);
  out << Standalone(plot.Render(title));
  if (!out) throw std::runtime_error("cannot write " + path);
  std::printf("wrote %s\n", path.c_str());
}

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) {
  using namespace slideid;
  std::string log_path, prefix, title;
  double from_s = -HUGE_VAL;
  try {
    bench::Args args(argc, argv);
    while (args.Next()) {
      if (args.Is("--log")) {
        log_path = args.Value();
      } else if (args.Is("--out")) {
        prefix = args.Value();
      } else if (args.Is("--title")) {
        title = args.Value();
      } else if (args.Is("--from")) {
        from_s = std::stod(args.Value());
      } else {
        std::fprintf(stderr,
                     "usage: online_plot --log FILE.csv --out PREFIX [--title TEXT] [--from T]\n");
        return 2;
      }
    }
    if (log_path.empty() || prefix.empty()) {
      std::fprintf(stderr,
                   "usage: online_plot --log FILE.csv --out PREFIX [--title TEXT] [--from T]\n");
      return 2;
    }
    const Trajectory log = ReadPushLog(log_path);
    if (title.empty()) title = log_path;
    const std::vector<OnlineResult> online = RunOnline(log, OnlineOptions{});
    const EstimateResult batch = Identify(log, IdentifyOptions{});
    Series series[4];
    for (const OnlineResult& r : online) {
      for (int i = 0; i < 4; ++i) {
        const ParameterEstimate& p = i < 3 ? r.parameters[i] : r.mu_pusher;
        if (!p.identifiable || r.t_s < from_s) continue;
        // mu_p while suspect rests on 2-3 batch medians (t on 1-2 df): intervals of +-5.
        if (i == 3 && p.verdict != Verdict::kOk) continue;
        series[i].t.push_back(r.t_s);
        series[i].value.push_back(p.value);
        series[i].lo.push_back(p.ci95_lo);
        series[i].hi.push_back(p.ci95_hi);
      }
    }
    const double t0 = std::max(from_s, log.samples.front().t_s), t1 = log.samples.back().t_s;
    const char* names[4] = {"a", "b", "c", "mu_p"};
    const char* labels[4] = {"a = e_t mu", "b = e_o / e_t", "c = e_r / e_t [m]", "mu_p"};
    double truth[4] = {NAN, NAN, NAN, NAN};
    if (log.true_friction) {
      const FrictionParameters& f = *log.true_friction;
      truth[0] = f.e_t * f.mu;
      truth[1] = f.e_o / f.e_t;
      truth[2] = f.e_r / f.e_t;
    }
    for (int i = 0; i < 4; ++i) {
      if (series[i].t.empty()) continue;
      const ParameterEstimate* b =
          i < 3 ? &batch.parameters[i] : (batch.mu_pusher_examined ? &batch.mu_pusher : nullptr);
      Write(prefix + "_" + names[i] + ".svg", title + ": " + labels[i], labels[i], series[i], t0,
            t1, b, truth[i]);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "online_plot: %s\n", e.what());
    return 1;
  }
  return 0;
}
