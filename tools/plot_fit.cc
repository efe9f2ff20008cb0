// plot-fit: draw what `identify --json` found as a forest plot: one panel per parameter,
// each log's own estimate with its 95% interval, the pooled estimate and its interval, and
// whether the logs agree (plots/fit_plot.h). Uses gnuplot.

#include <fstream>
#include <iostream>
#include <sstream>

#include "io/result_json.h"
#include "pipeline/picture_cli_options.h"
#include "plots/fit_plot.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

int main(int argc, char** argv) {
  return tools::RunTool("plot-fit", [&]() -> int {
    po::options_description opts(
        "plot-fit: draw an identification (identify --json) to a PNG with gnuplot (Debian:\n"
        "gnuplot-nox). One panel per parameter: each pooled log's own estimate and 95%\n"
        "interval on a row of its own (red when it misses the pooled value), the pooled\n"
        "estimate as a diamond with its interval shaded, and above each panel whether the\n"
        "logs agree (Cochran's Q, I2, tau). A single log's result draws its one estimate.\n\n"
        "Usage: identify --log A.csv --log B.csv ... --json > fit.json\n"
        "       plot-fit fit.json --out FIG.png [options]\n\nOptions");
    FitPlotOptions defaults;
    opts.add_options()("help,h", "print this help and exit")("version",
                                                             "print the version and exit")(
        "result", po::value<std::string>()->value_name("RESULT.json"),
        "what identify --json printed (or first argument)");
    cli::AddPictureOptions(&opts, defaults, "picture height [px] (0: from the number of logs)",
                           "title above the panels (default: the file name)");
    po::positional_options_description positional;
    positional.add("result", 1);
    po::variables_map vm;
    po::store(po::command_line_parser(argc, argv).options(opts).positional(positional).run(), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts
                << "\nExit codes: 0 ok, 1 bad or unreadable result file (or nothing "
                   "identified to draw), 2 usage, 4 gnuplot missing or failing, or a "
                   "file not writable.\n";
      return tools::FlushStdout("plot-fit");
    }
    if (vm.count("version")) {
      std::cout << "plot-fit (slideid) " << SLIDEID_VERSION << "\n";
      return tools::FlushStdout("plot-fit");
    }
    if (!vm.count("result")) throw po::error("the result (RESULT.json) is required");
    const std::string path = vm["result"].as<std::string>();
    FitPlotOptions options;
    cli::ReadPictureOptions(vm, path, &options);
    std::string why;
    if (!options.IsValid(&why)) throw po::error(why);

    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot open the result file");
    std::stringstream json;
    json << in.rdbuf();
    EstimateResult result;
    try {
      result = ParseResultJson(json.str());
    } catch (const ResultJsonError& e) {
      throw std::runtime_error(path + ": " + e.what());
    }
    try {
      PlotFit(result, options);
    } catch (const std::runtime_error& e) {
      std::cerr << "plot-fit: " << e.what() << "\n";
      return tools::kExitIo;
    }
    std::cout << "wrote " << options.out_png << "\n";
    return tools::FlushStdout("plot-fit");
  });
}
