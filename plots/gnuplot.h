#pragma once
// What every picture the tools draw shares: its options (where it goes, how large, titled
// what, which gnuplot draws it, where its script is kept) and the runner that writes the
// data and script and runs gnuplot (Debian: gnuplot-nox) on them. plot-log
// (plots/log_plot.h), plot-fit (plots/fit_plot.h) and validate --plot
// (plots/validate_plot.h) are drawn through it.

#include <functional>
#include <string>

namespace slideid {

/// Picture sizes outside this range are refused [px].
constexpr int kMinPicturePx = 200;
constexpr int kMaxPicturePx = 20000;

/// The options every picture takes. A picture's own options derive from it (PlotOptions,
/// FitPlotOptions) and set their own default size.
struct PictureOptions {
  std::string out_png;  ///< where the picture goes (required)
  int width_px = 1400;
  int height_px = 900;              ///< 0: chosen by the picture, where it can (FitPlotOptions)
  std::string title;                ///< above the figure (e.g. the input file's name)
  std::string gnuplot = "gnuplot";  ///< the program to run
  /// When not empty, the script and data files are written here and kept (for debugging or
  /// editing the figure); otherwise a temporary directory is used and removed.
  std::string work_dir;

  /// False (and why) without an output file or a gnuplot program, or with a size outside
  /// kMinPicturePx..kMaxPicturePx (a height of 0 passes when `automatic_height`).
  bool IsValid(std::string* why, bool automatic_height = false) const;
};

/// Runs options.gnuplot on the script `write_data(dir, staged_png)` returns, after it has
/// written its data files into `dir`: options.work_dir (created if missing, and kept), or a
/// temporary directory removed afterwards. The script writes the picture to `staged_png`, a
/// temporary beside options.out_png renamed to it once gnuplot succeeded (io/atomic_file.h). Throws
/// std::runtime_error when gnuplot cannot be run (naming the program and how to install it), fails
/// (with its message) or writes no options.out_png; std::invalid_argument for a program or
/// directory name with a quote.
void RunGnuplot(const PictureOptions& options,
                const std::function<std::string(const std::string& dir,
                                                const std::string& staged_png)>& write_data);

/// A number in a gnuplot data file or script: 9 significant digits, far below what a
/// picture resolves and far shorter than a round-trip 17.
std::string GnuplotNumber(double value);
/// Text in gnuplot's single quotes ('' escapes a quote; no escapes otherwise).
std::string GnuplotSingleQuoted(const std::string& text);
/// Text in gnuplot's double quotes, where "\n" is a line break.
std::string GnuplotDoubleQuoted(const std::string& text);
/// Writes a data file or script; throws std::runtime_error naming `path` when it cannot.
void WritePlotFile(const std::string& path, const std::string& text);

}  // namespace slideid
