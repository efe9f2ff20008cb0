#include "plots/log_plot.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>

#include "forward_model/constants.h"
#include "forward_model/contact_patch.h"
#include "forward_model/logged_poses.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {

/// Force arrows are drawn this long, for the largest force of the log, in patch sizes.
constexpr double kArrowPatchSizes = 1.0;
/// A snapshot is skipped when the slider moved less than this fraction of the patch size
/// (and turned less than kSameAngle_rad) since the last one drawn: while it rests, the
/// outlines would only pile up.
constexpr double kSamePlaceFraction = 0.05;
constexpr double kSameAngle_rad = 0.05;

int SnapshotEvery(const Trajectory& log, const PlotOptions& o) {
  if (o.snapshot_every > 0) return o.snapshot_every;
  return std::max<int>(1, static_cast<int>(log.samples.size()) / kDefaultSnapshots);
}

/// One closed outline at a pose, then a blank line (gnuplot: a separate polyline).
void WriteOutline(std::ostream& out, const std::vector<Eigen::Vector2d>& body,
                  const PlanarState& q) {
  const double c = std::cos(q.theta), s = std::sin(q.theta);
  for (const Eigen::Vector2d& p : body) {
    out << GnuplotNumber(q.x + c * p.x() - s * p.y()) << ' '
        << GnuplotNumber(q.y + s * p.x() + c * p.y()) << '\n';
  }
  out << '\n';
}

void WriteMotion(std::ostream& out, const Trajectory& t, const std::vector<PlanarState>& poses) {
  out << "# t x y theta vx vy wz\n";
  for (size_t u = 0; u < t.samples.size(); ++u) {
    const PlanarState& q = poses[u];
    const PlanarState& v = t.samples[u].state;
    out << GnuplotNumber(t.samples[u].t_s) << ' ' << GnuplotNumber(q.x) << ' ' << GnuplotNumber(q.y)
        << ' ' << GnuplotNumber(q.theta) << ' ' << GnuplotNumber(v.vx) << ' ' << GnuplotNumber(v.vy)
        << ' ' << GnuplotNumber(v.wz) << '\n';
  }
}

bool HasEcp(const Trajectory& log) {
  if (!log.measured.step_info) return false;
  for (size_t u = 1; u < log.steps.size(); ++u) {
    if (!log.steps[u].ecp_world.isZero(0.0)) return true;
  }
  return false;
}

/// A string of the form "key=value" of the log's truth, for the title.
std::string TruthText(const Trajectory& log) {
  if (!log.true_friction) return "";
  const ReducedFriction r = ReducedFriction::From(*log.true_friction);
  return Printf("truth: a = %.4g, b = %.4g, c = %.4g m", r.a, r.b, r.c);
}

}  // namespace

bool PlotOptions::IsValid(std::string* why) const {
  if (!PictureOptions::IsValid(why)) return false;
  if (snapshot_every < 0) {
    if (why) *why = "plot: snapshot_every must be >= 0";
    return false;
  }
  return true;
}

void WritePlotData(const Trajectory& log, const Trajectory* fit, const PlotOptions& options,
                   const std::string& dir) {
  const std::vector<PlanarState> poses = LoggedOrIntegratedPoses(log);
  std::ostringstream path, patch, ecp, push;
  WriteMotion(path, log, poses);

  const int every = SnapshotEvery(log, options);
  const std::optional<ContactPatch>& shape = log.patch;
  double max_force = 0.0;
  for (const TrajectorySample& s : log.samples) {
    max_force = std::max(max_force, std::hypot(s.applied.fx, s.applied.fy));
  }
  const double size = shape ? 2.0 * std::sqrt(shape->Area() / kPi) : 0.05;
  const double arrow_scale = max_force > 0 ? kArrowPatchSizes * size / max_force : 0.0;
  patch << "# x y: patch outlines at every " << every << "th row\n";
  push << "# x y dx dy: push point and force (scaled)\n";
  std::optional<PlanarState> last_drawn;
  std::ostringstream overlay_patch;
  overlay_patch << "# x y: the overlay's patch outlines at the same rows\n";
  for (size_t u = 0; u < log.samples.size(); u += every) {
    const bool moved = !last_drawn ||
                       std::hypot(poses[u].x - last_drawn->x, poses[u].y - last_drawn->y) >
                           kSamePlaceFraction * size ||
                       std::abs(poses[u].theta - last_drawn->theta) > kSameAngle_rad;
    if (!moved) continue;
    last_drawn = poses[u];
    if (shape && fit && options.overlay_patches && u < fit->samples.size()) {
      WriteOutline(overlay_patch, shape->Outline(), fit->samples[u].state);
    }
    if (shape) {
      WriteOutline(patch, shape->Outline(), poses[u]);
      const auto inner = shape->InnerOutline();
      if (!inner.empty()) WriteOutline(patch, inner, poses[u]);
      // The body x axis from the CM, so that the turning of round patches shows.
      WriteOutline(patch, {Eigen::Vector2d::Zero(), Eigen::Vector2d(size / 2, 0.0)}, poses[u]);
    }
    const TrajectorySample& s = log.samples[u];
    const double fx = s.applied.fx, fy = s.applied.fy;
    if (fx == 0.0 && fy == 0.0) continue;
    const Eigen::Vector2d at =
        s.push_point_world ? Eigen::Vector2d(s.push_point_world->x(), s.push_point_world->y())
                           : Eigen::Vector2d(poses[u].x, poses[u].y);
    push << GnuplotNumber(at.x() - arrow_scale * fx) << ' '
         << GnuplotNumber(at.y() - arrow_scale * fy) << ' ' << GnuplotNumber(arrow_scale * fx)
         << ' ' << GnuplotNumber(arrow_scale * fy) << '\n';
  }
  ecp << "# ax ay\n";
  for (size_t u = 1; u < log.samples.size(); ++u) {
    const Eigen::Vector2d& a = StepAt(log, u).ecp_world;
    ecp << GnuplotNumber(a.x()) << ' ' << GnuplotNumber(a.y()) << '\n';
  }
  WritePlotFile(dir + "/path.dat", path.str());
  WritePlotFile(dir + "/patch.dat", patch.str() + "\n");
  WritePlotFile(dir + "/push.dat", push.str() + "\n");
  WritePlotFile(dir + "/ecp.dat", ecp.str());
  if (fit) {
    std::ostringstream f;
    std::vector<PlanarState> fit_poses;
    for (const TrajectorySample& s : fit->samples) fit_poses.push_back(s.state);
    WriteMotion(f, *fit, fit_poses);
    WritePlotFile(dir + "/fit.dat", f.str());
    WritePlotFile(dir + "/fit_patch.dat", overlay_patch.str() + "\n");
  }
}

std::string PlotScript(const Trajectory& log, const Trajectory* fit, const PlotOptions& o,
                       const std::string& dir, const std::string& fit_label) {
  const auto file = [&](const char* name) { return GnuplotSingleQuoted(dir + "/" + name); };
  const bool has_patch = log.patch.has_value();
  const bool has_push = [&] {
    for (const TrajectorySample& s : log.samples) {
      if (s.applied.fx != 0.0 || s.applied.fy != 0.0) return true;
    }
    return false;
  }();
  const bool has_ecp = HasEcp(log);
  std::string title = o.title;
  const std::string truth = TruthText(log);
  if (!truth.empty()) title += (title.empty() ? "" : "    ") + truth;
  if (fit) title += (title.empty() ? "" : "    ") + fit_label;

  std::ostringstream s;
  s << "# Generated by slideid plot-log.\n"
    << "set terminal pngcairo size " << o.width_px << "," << o.height_px
    << " font 'sans,10' noenhanced\n"
    << "set output " << GnuplotSingleQuoted(o.out_png) << "\n"
    << "set multiplot title " << GnuplotSingleQuoted(title) << "\n"
    << "set grid lc rgb '#dddddd'\n"
    << "set key below horizontal\n";
  // Left: the path, equal axes.
  s << "set origin 0,0\nset size 0.56,0.95\nset size ratio -1\n"
    << "set xlabel 'x [m]'\nset ylabel 'y [m]'\n"
    << "set title 'CM path" << (log.measured.pose ? "" : " (integrated from the velocities)")
    << (has_patch ? ", patch every " + std::to_string(SnapshotEvery(log, o)) + " rows" : "")
    << "'\n";
  std::vector<std::string> plots;
  if (has_patch) {
    plots.push_back(file("patch.dat") +
                    " using 1:2 with lines lc rgb '#9a9a9a' lw 1 title 'patch'");
  }
  plots.push_back(file("path.dat") +
                  " using 2:3 with lines lc rgb '#1f4e9a' lw 1.5 title 'CM (log)'");
  if (has_ecp) {
    plots.push_back(file("ecp.dat") +
                    " using 1:2 with points pt 7 ps 0.25 lc rgb '#d62728' title 'ECP'");
  }
  if (has_push) {
    plots.push_back(file("push.dat") +
                    " using 1:2:3:4 with vectors head filled size screen 0.008,20 lc rgb "
                    "'#2ca02c' lw 1.5 title 'push'");
  }
  if (fit && has_patch && o.overlay_patches) {
    plots.push_back(file("fit_patch.dat") +
                    " using 1:2 with lines dt 2 lc rgb '#f5b971' lw 1 "
                    "title 'patch (" +
                    o.overlay_name + ")'");
  }
  if (fit) {
    plots.push_back(file("fit.dat") +
                    " using 2:3 with lines dt 2 lc rgb '#ff7f0e' lw 2 title "
                    "'CM (" +
                    o.overlay_name + ")'");
  }
  plots.push_back(file("path.dat") +
                  " every ::0::0 using 2:3 with points pt 7 ps 1.2 lc rgb 'black' title 'start'");
  s << "plot ";
  for (size_t i = 0; i < plots.size(); ++i) s << (i ? ", \\\n     " : "") << plots[i];
  s << "\n";
  // Right: velocities and spin against time.
  s << "set size noratio\nset key inside top right vertical box opaque\nunset title\n";
  const char* names[3] = {"vx [m/s]", "vy [m/s]", "wz [rad/s]"};
  for (int k = 0; k < 3; ++k) {
    s << "set origin 0.56," << GnuplotNumber(0.64 - 0.31 * k) << "\nset size 0.44,0.31\n"
      << "set xlabel " << (k == 2 ? "'t [s]'" : "''") << "\nset ylabel '" << names[k] << "'\n"
      << "plot " << file("path.dat") << " using 1:" << 5 + k
      << " with lines lc rgb '#1f4e9a' lw 1 title '"
      << (log.measured.velocity ? "log" : "log (from poses)") << "'";
    if (fit) {
      s << ", " << file("fit.dat") << " using 1:" << 5 + k
        << " with lines dt 2 lc rgb '#ff7f0e' lw 2 title '" << o.overlay_name << "'";
    }
    s << "\n";
  }
  s << "unset multiplot\nset output\n";
  return s.str();
}

void PlotLog(const Trajectory& log, const Trajectory* fit, const PlotOptions& options,
             const std::string& fit_label) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  if (log.samples.size() < 2) throw std::invalid_argument("plot: the log has fewer than 2 rows");
  RunGnuplot(options, [&](const std::string& dir, const std::string& staged_png) {
    PlotOptions staged = options;
    staged.out_png = staged_png;
    WritePlotData(log, fit, staged, dir);
    return PlotScript(log, fit, staged, dir, fit_label);
  });
}

}  // namespace slideid
