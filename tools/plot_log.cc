// plot-log: draw a push log as the paper draws its examples (CM path with patch snapshots,
// ECP, push; velocities and spin against time), optionally with the trajectory replayed
// from identified parameters (identify --json). Uses gnuplot.

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "forward_model/number_format.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"
#include "io/result_json.h"
#include "pipeline/log_read_cli_options.h"
#include "pipeline/picture_cli_options.h"
#include "plots/log_plot.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

int main(int argc, char** argv) {
  return tools::RunTool("plot-log", [&]() -> int {
    po::options_description opts(
        "plot-log: draw a push log to a PNG with gnuplot (Debian: gnuplot-nox).\n"
        "Left: the CM path, the contact patch (from the log's 'patch' metadata) every K rows,\n"
        "the ECP of every step (when the log has ax, ay) and the push as arrows. Right: vx, vy\n"
        "and wz against time. With --fit, also the trajectory replayed from the log's first\n"
        "state under the logged forces with the identified parameters.\n\n"
        "Usage: plot-log LOG.csv --out FIG.png [--fit RESULT.json | --prediction PRED.csv]\n"
        "       [options]\n\nOptions");
    PlotOptions defaults;
    opts.add_options()("help,h", "print this help and exit")("version",
                                                             "print the version and exit")(
        "log", po::value<std::string>()->value_name("LOG.csv"), "the push log (or first argument)")(
        "fit", po::value<std::string>()->value_name("RESULT.json"),
        "identify --json output: overlay the replay with its parameters (held values where "
        "not identifiable)")("prediction", po::value<std::string>()->value_name("PRED.csv"),
                             "what predict --out wrote: overlay the predicted path and patches")(
        "substeps", po::value<int>()->default_value(1)->value_name("N"),
        "forward-model steps per log interval for the replay (use identify's)")(
        "every", po::value<int>()->default_value(0)->value_name("K"),
        "rows between patch snapshots (0: about 16 over the log)");
    cli::AddPictureOptions(&opts, defaults, "picture height [px]",
                           "title above the figure (default: the log's file name)");
    cli::AddLogReadOptions(&opts, &opts);
    po::positional_options_description positional;
    positional.add("log", 1);
    po::variables_map vm;
    po::store(po::command_line_parser(argc, argv).options(opts).positional(positional).run(), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts
                << "\nExit codes: 0 ok, 1 bad log or result file, 2 usage, "
                   "3 the replay failed, 4 gnuplot missing or failing, or a file not "
                   "writable.\n";
      return tools::kExitOk;
    }
    if (vm.count("version")) {
      std::cout << "plot-log (slideid) " << SLIDEID_VERSION << "\n";
      return tools::kExitOk;
    }
    if (!vm.count("log")) throw po::error("the log (LOG.csv) is required");
    const std::string log_path = vm["log"].as<std::string>();
    PlotOptions options;
    cli::ReadPictureOptions(vm, log_path, &options);
    options.snapshot_every = vm["every"].as<int>();
    std::string why;
    if (!options.IsValid(&why)) throw po::error(why);
    if (vm["substeps"].as<int>() < 1 || vm["substeps"].as<int>() > kMaxSubstepsPerInterval) {
      throw po::error("--substeps must be 1 to " + std::to_string(kMaxSubstepsPerInterval));
    }
    if (vm.count("fit") && vm.count("prediction")) {
      throw po::error("--fit and --prediction exclude each other: draw one overlay");
    }

    LogReadOptions read = cli::ReadLogReadOptions(vm);
    read.require_slider_properties = vm.count("fit") > 0;  // the replay needs them
    const Trajectory log = ReadPushLog(log_path, read);
    std::optional<Trajectory> fit;
    std::string fit_label;
    if (vm.count("fit")) {
      const std::string path = vm["fit"].as<std::string>();
      std::ifstream in(path);
      if (!in) throw std::runtime_error(path + ": cannot read");
      std::stringstream json;
      json << in.rdbuf();
      ReducedFriction r;
      try {
        r = ParseIdentifyJson(json.str());
      } catch (const ResultJsonError& e) {
        throw std::runtime_error(path + ": " + e.what());  // as predict and plot-fit name it
      }
      const SimulationResult replay = ReplayLog(log, r, vm["substeps"].as<int>());
      if (!replay.summary.ok()) {
        std::cerr << "plot-log: replay: " << ToString(replay.summary.status) << ": "
                  << replay.summary.message << "\n";
        return tools::kExitNumerical;
      }
      fit = replay.trajectory;
      fit_label = Printf("fit: a = %.4g, b = %.4g, c = %.4g m", r.a, r.b, r.c);
    }
    if (vm.count("prediction")) {
      const std::string path = vm["prediction"].as<std::string>();
      fit = ReadPushLog(path);
      options.overlay_name = "prediction";
      options.overlay_patches = true;
      fit_label = "prediction: " + path;
    }
    try {
      PlotLog(log, fit ? &*fit : nullptr, options, fit_label);
    } catch (const std::runtime_error& e) {
      std::cerr << "plot-log: " << e.what() << "\n";
      return tools::kExitIo;
    }
    std::printf("wrote %s\n", options.out_png.c_str());
    return tools::kExitOk;
  });
}
