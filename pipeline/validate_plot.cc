#include "pipeline/validate_plot.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "datasets/log_plot.h"
#include "forward_model/constants.h"

namespace slideid {
namespace {


void Write(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error(path + ": cannot write the plot data");
}

}  // namespace

std::string ValidationPlotScript(const ValidationResult& r, const std::string& dir,
                                 const std::string& out_png, const std::string& title,
                                 int width_px, int height_px) {
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
  Write(dir + "/errors.dat", points.str());
  Write(dir + "/summary.dat", summary.str());
  const std::string errors = "'" + dir + "/errors.dat'", sum = "'" + dir + "/summary.dat'";
  std::ostringstream s;
  s << "set terminal pngcairo size " << width_px << "," << height_px
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

void PlotValidation(const ValidationResult& result, const std::string& out_png,
                    const std::string& title, const std::string& gnuplot) {
  bool any = false;
  for (const MethodValidation& m : result.methods) any = any || m.final_position_m.pushes > 0;
  if (!any) throw std::invalid_argument("plot: nothing to draw: no push was predicted");
  if (out_png.find('\'') != std::string::npos || title.find('\'') != std::string::npos) {
    throw std::invalid_argument("plot: quote characters in the file name or title are not "
                                "supported");
  }
  RunGnuplot(gnuplot, "", out_png, [&](const std::string& dir) {
    return ValidationPlotScript(result, dir, out_png, title);
  });
}

}  // namespace slideid
