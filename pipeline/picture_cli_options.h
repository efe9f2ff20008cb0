#pragma once
// The command-line options every picture tool takes (plot-log, plot-fit): where the picture
// goes, its size and title, the gnuplot program and where to keep its script
// (plots/gnuplot.h PictureOptions), declared and read once. Never prints; bad values throw
// boost::program_options::error naming the option (the tools map that to the usage exit
// code).

#include <boost/program_options.hpp>
#include <string>

#include "plots/gnuplot.h"

namespace slideid::cli {

/// Adds --out, --width, --height, --title, --gnuplot and --keep, with the defaults of
/// `defaults` quoted in the help; `height_help` describes --height (a picture may choose its
/// own height at 0), `title_help` --title.
void AddPictureOptions(boost::program_options::options_description* options,
                       const PictureOptions& defaults, const std::string& height_help,
                       const std::string& title_help);

/// Sets the fields of `picture` from those options: the title from --title, else
/// `default_title`. Throws boost::program_options::error when --out is missing; the
/// picture's own IsValid is the caller's to ask (its options add fields).
void ReadPictureOptions(const boost::program_options::variables_map& vm,
                        const std::string& default_title, PictureOptions* picture);

}  // namespace slideid::cli
