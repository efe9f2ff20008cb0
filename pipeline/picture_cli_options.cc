#include "pipeline/picture_cli_options.h"

namespace slideid::cli {

namespace po = boost::program_options;

void AddPictureOptions(po::options_description* options, const PictureOptions& defaults,
                       const std::string& height_help, const std::string& title_help) {
  options->add_options()("out", po::value<std::string>()->value_name("FIG.png"),
                         "the picture to write (required)")(
      "width", po::value<int>()->default_value(defaults.width_px), "picture width [px]")(
      "height", po::value<int>()->default_value(defaults.height_px), height_help.c_str())(
      "title", po::value<std::string>(), title_help.c_str())(
      "gnuplot", po::value<std::string>()->default_value(defaults.gnuplot), "gnuplot program")(
      "keep", po::value<std::string>()->value_name("DIR"),
      "write the gnuplot script and data into DIR and keep them");
}

void ReadPictureOptions(const po::variables_map& vm, const std::string& default_title,
                        PictureOptions* picture) {
  if (!vm.count("out")) throw po::error("the option '--out' is required");
  picture->out_png = vm["out"].as<std::string>();
  picture->width_px = vm["width"].as<int>();
  picture->height_px = vm["height"].as<int>();
  picture->gnuplot = vm["gnuplot"].as<std::string>();
  picture->title = vm.count("title") ? vm["title"].as<std::string>() : default_title;
  if (vm.count("keep")) picture->work_dir = vm["keep"].as<std::string>();
}

}  // namespace slideid::cli
