#pragma once
// Pictures of a push log the way the paper draws its examples: the CM path with snapshots of
// the contact patch, the ECP of every step and the push, beside the velocities and the spin
// against time; optionally overlaid with the trajectory replayed from identified parameters.
// Drawn by gnuplot (Debian: gnuplot-nox), run on a generated script.

#include <functional>
#include <optional>
#include <string>

#include "forward_model/slider.h"
#include "forward_model/trajectory.h"
#include "plots/gnuplot.h"

namespace slideid {

/// plot-log's picture: 1400 x 900 px by default (PictureOptions).
struct PlotOptions : PictureOptions {
  /// Rows between patch snapshots; 0: about kDefaultSnapshots over the log.
  int snapshot_every = 0;
  /// What the overlaid trajectory is called in the legends ("fit": a replay with identified
  /// parameters; "prediction": what predict wrote), and whether its patch is drawn at the
  /// log's snapshot rows too (dashed), so that its turning shows beside the log's.
  std::string overlay_name = "fit";
  bool overlay_patches = false;

  bool IsValid(std::string* why) const;
};

/// Snapshots of the patch drawn along the path when PlotOptions::snapshot_every is 0.
constexpr int kDefaultSnapshots = 16;

/// The gnuplot script for `log` (and `fit`, a replay at the log's times, when not null)
/// reading its data from files in `data_dir`; WritePlotData writes them.
std::string PlotScript(const Trajectory& log, const Trajectory* fit, const PlotOptions& options,
                       const std::string& data_dir, const std::string& fit_label = "");
/// Writes path.dat, patch.dat, ecp.dat, push.dat (and fit.dat) into `data_dir`.
void WritePlotData(const Trajectory& log, const Trajectory* fit, const PlotOptions& options,
                   const std::string& data_dir);

/// Draws `log` (and `fit`) to options.out_png. Throws std::runtime_error when gnuplot cannot
/// be run (naming the program and how to install it) or fails (with its message), or when a
/// file cannot be written; std::invalid_argument for invalid options or an empty log.
void PlotLog(const Trajectory& log, const Trajectory* fit, const PlotOptions& options,
             const std::string& fit_label = "");

}  // namespace slideid
