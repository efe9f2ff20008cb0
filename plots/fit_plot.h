#pragma once
// A picture of an identification (what `identify --json` writes, read back with
// io/result_json.h): a forest plot with one panel per parameter, each log's own estimate
// with its 95% interval on a row of its own, the pooled estimate as a diamond with its
// interval shaded across the panel, and the verdict on whether the logs agree (Cochran's Q,
// I2, tau) above it. Logs whose interval misses the pooled value are drawn in red. Drawn by
// gnuplot (plots/gnuplot.h); `plot-fit` is the tool.

#include <string>

#include "estimator/estimate.h"
#include "plots/gnuplot.h"

namespace slideid {

/// plot-fit's picture: 1500 px wide, its height from the number of logs by default
/// (height_px 0: kFitPlotRowPx per row, at least kFitPlotMinHeightPx).
struct FitPlotOptions : PictureOptions {
  FitPlotOptions() {
    width_px = 1500;
    height_px = 0;
  }
  /// PictureOptions::IsValid, with a height of 0 (automatic) allowed.
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
