#pragma once
// A picture of an identification (what `identify --json` writes, read back with
// io/result_json.h): a forest plot with one panel per parameter, each log's own estimate
// with its 95% interval on a row of its own, the pooled estimate as a diamond with its
// interval shaded across the panel, and the verdict on whether the logs agree (Cochran's Q,
// I2, tau) above it. Logs whose interval misses the pooled value are drawn in red. Drawn by
// gnuplot (datasets/log_plot.h RunGnuplot); `plot-fit` is the tool.

#include <string>

#include "estimator/estimate.h"

namespace slideid {

struct FitPlotOptions {
  std::string out_png;  ///< where the picture goes (required)
  int width_px = 1500;
  /// 0: from the number of logs (kFitPlotRowPx per row, at least kFitPlotMinHeightPx).
  int height_px = 0;
  std::string title;                ///< above the panels (e.g. the JSON file's name)
  std::string gnuplot = "gnuplot";  ///< the program to run
  /// When not empty, the script and data files are written here and kept.
  std::string work_dir;

  /// False (and why) without an output file, a gnuplot program, or with sizes outside
  /// 200..20000 px (height 0 is automatic).
  bool IsValid(std::string* why) const;
};

/// Pixels per row of the forest (one row per log, and the pooled row), and the smallest
/// automatic height [px].
constexpr int kFitPlotRowPx = 16;
constexpr int kFitPlotMinHeightPx = 450;

/// The height the picture gets: options.height_px, or from the number of rows.
int FitPlotHeight(const EstimateResult& result, const FitPlotOptions& options);

/// Writes p0.dat, p1.dat, p2.dat (each log's estimate and interval per parameter) and
/// pooled.dat into `data_dir`.
void WriteFitPlotData(const EstimateResult& result, const std::string& data_dir);

/// The gnuplot script drawing `result` from the files WriteFitPlotData wrote in `data_dir`.
std::string FitPlotScript(const EstimateResult& result, const FitPlotOptions& options,
                          const std::string& data_dir);

/// Draws `result` to options.out_png. Throws std::invalid_argument for invalid options or
/// a result with nothing to draw (no parameter identified, by the pooled fit or any log);
/// std::runtime_error when gnuplot cannot be run or fails, or a file cannot be written.
void PlotFit(const EstimateResult& result, const FitPlotOptions& options);

}  // namespace slideid
