#include "plots/validate_plot.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "forward_model/constants.h"
#include "plots/gnuplot.h"

namespace slideid {

std::string ValidationPlotScript(const ValidationResult& r, const std::string& dir,
                                 const ValidationPlotOptions& options) {
  const std::string& out_png = options.out_png;
  const std::string& title = options.title;
  std::ostringstream points, summary, tics;
  points << "# method position_mm rotation_deg\n";
  summary << "# method p25 p50 p75 r25 r50 r75 (mm, deg)\n";
  for (size_t m = 0; m < r.methods.size(); ++m) {
    const MethodValidation& method = r.methods[m];
    for (const PushPrediction& p : method.pushes) {
      if (!p.ok) continue;
      points << m << ' ' << p.errors.final_position_m * 1e3 << ' '
             << p.errors.final_rotation_rad * kRadToDeg << '\n';
    }
    const ErrorSummary &sp = method.final_position_m, &sr = method.final_rotation_rad;
    summary << m << ' ' << sp.q25 * 1e3 << ' ' << sp.median * 1e3 << ' ' << sp.q75 * 1e3 << ' '
            << sr.q25 * kRadToDeg << ' ' << sr.median * kRadToDeg << ' ' << sr.q75 * kRadToDeg
            << '\n';
    tics << (m ? ", " : "") << '"' << method.method << "\" " << m;
  }
  WritePlotFile(dir + "/errors.dat", points.str());
  WritePlotFile(dir + "/summary.dat", summary.str());
  const std::string errors = "'" + dir + "/errors.dat'", sum = "'" + dir + "/summary.dat'";
  std::ostringstream s;
  s << "set terminal pngcairo size " << options.width_px << "," << options.height_px
    << " font 'sans,10' noenhanced\n"
    << "set output '" << out_png << "'\n"
    << "set multiplot layout 1,2 title '" << title << "'\n"
    << "set grid ytics lc rgb '#dddddd'\nset xtics (" << tics.str() << ")\n"
    << "set xrange [-0.5:" << r.methods.size() - 0.5 << "]\nset key top left\n";
  const char* names[2] = {"final position error [mm]", "final rotation error [deg]"};
  for (int panel = 0; panel < 2; ++panel) {
    const int column = 2 + panel, q = 2 + 3 * panel;
    s << "set ylabel '" << names[panel] << "'\nset title '" << names[panel]
      << ": each push, median and quartiles'\n"
      << "plot " << errors << " using ($1 + 0.25 * (rand(0) - 0.5)):" << column
      << " with points pt 7 ps 0.5 lc rgb '#1f4e9a' title 'push', \\\n     " << sum
      << " using 1:" << q + 1 << ":" << q << ":" << q + 2
      << " with yerrorbars pt 5 ps 1.2 lw 2 lc rgb '#d62728' title 'median, IQR'\n";
  }
  s << "unset multiplot\nset output\n";
  return s.str();
}

void PlotValidation(const ValidationResult& result, const ValidationPlotOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  const std::string& out_png = options.out_png;
  const std::string& title = options.title;
  bool any = false;
  for (const MethodValidation& m : result.methods) any = any || m.final_position_m.pushes > 0;
  if (!any) throw std::invalid_argument("plot: nothing to draw: no push was predicted");
  if (out_png.find('\'') != std::string::npos || title.find('\'') != std::string::npos) {
    throw std::invalid_argument(
        "plot: quote characters in the file name or title are not "
        "supported");
  }
  RunGnuplot(options, [&](const std::string& dir, const std::string& staged_png) {
    ValidationPlotOptions staged = options;
    staged.out_png = staged_png;
    return ValidationPlotScript(result, dir, staged);
  });
}

}  // namespace slideid
