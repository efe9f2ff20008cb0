#pragma once
// A picture of a cross-validation (prediction/validate.h): for each friction (the folds, the
// quasi-static model, the own fits, the textbook), every push's final position error and
// final rotation error as points, with the median and the quartiles as bars; two panels,
// one per error. Drawn by gnuplot (plots/gnuplot.h); `validate --plot`.

#include <string>

#include "plots/gnuplot.h"
#include "prediction/validate.h"

namespace slideid {

/// validate --plot's picture: 1200 x 600 px by default (PictureOptions).
struct ValidationPlotOptions : PictureOptions {
  ValidationPlotOptions() {
    width_px = 1200;
    height_px = 600;
  }
};

/// Writes errors.dat (method index, position [mm], rotation [deg] per push) and
/// summary.dat (method index, quartiles and median of each) into `data_dir`; returns the
/// gnuplot script that draws them to options.out_png.
std::string ValidationPlotScript(const ValidationResult& result, const std::string& data_dir,
                                 const ValidationPlotOptions& options);

/// Draws the picture. Throws std::runtime_error when gnuplot cannot be run or fails (naming
/// the program and how to install it), std::invalid_argument for invalid options, quotes
/// in the file name or title, or when no push was predicted.
void PlotValidation(const ValidationResult& result, const ValidationPlotOptions& options);

}  // namespace slideid
