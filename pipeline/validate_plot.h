#pragma once
// A picture of a cross-validation (prediction/validate.h): for each friction (the folds, the
// quasi-static model, the own fits, the textbook), every push's final position error and
// final rotation error as points, with the median and the quartiles as bars; two panels,
// one per error. Drawn by gnuplot (datasets/log_plot.h RunGnuplot); `validate --plot`.

#include <string>

#include "prediction/validate.h"

namespace slideid {

/// Writes errors.dat (method index, position [mm], rotation [deg] per push) and
/// summary.dat (method index, quartiles and median of each) into `data_dir`; returns the
/// gnuplot script that draws them to `out_png` (width x height px, `title` above).
std::string ValidationPlotScript(const ValidationResult& result, const std::string& data_dir,
                                 const std::string& out_png, const std::string& title,
                                 int width_px = 1200, int height_px = 600);

/// Draws the picture. Throws std::runtime_error when gnuplot cannot be run or fails (naming
/// the program and how to install it), std::invalid_argument when no push was predicted.
void PlotValidation(const ValidationResult& result, const std::string& out_png,
                    const std::string& title, const std::string& gnuplot = "gnuplot");

}  // namespace slideid
