// make-dataset: draw N sliders and friction parameters from ranges, push each with a random
// push program, and write the logs with a truth manifest (io/dataset_files.h).

#include <cstdio>
#include <iostream>

#include "io/dataset_files.h"
#include "pipeline/log_cli_options.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

int main(int argc, char** argv) {
  return tools::RunTool("make-dataset", [&]() -> int {
    po::options_description opts(
        "make-dataset: make a synthetic dataset of push logs with known friction.\n"
        "For each log: draws a slider and friction parameters from the ranges, simulates a\n"
        "random push program (pushes from the patch boundary, rests between them), redraws\n"
        "if the slider would tip, and writes DIR/log_NNNN.csv with the sampling, columns and\n"
        "noise asked for. DIR/truth.csv lists every log's slider, friction (and a = e_t mu,\n"
        "b = e_o/e_t, c = e_r/e_t), noise, patch, rows and redraws. Deterministic by --seed.\n\n"
        "Usage: make-dataset --count N --seed S --out DIR [ranges...] [log options...]\n\n"
        "Options");
    opts.add_options()("help,h", "print this help and exit")(
        "version", "print the version and exit")("quiet,q", "print nothing but errors");
    cli::AddDatasetOptions(&opts, DatasetSpec{});
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, opts), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts
                << "\nExit codes: 0 ok, 2 usage (bad or missing option), 3 a log "
                   "could not be drawn without tipping in --max-redraws, 4 the "
                   "directory or a file could not be written.\n";
      return tools::kExitOk;
    }
    if (vm.count("version")) {
      std::cout << "make-dataset (slideid) " << SLIDEID_VERSION << "\n";
      return tools::kExitOk;
    }
    if (!vm.count("out")) throw po::error("the option '--out' is required");
    const DatasetSpec spec = cli::DatasetSpecFromOptions(vm);
    const std::string dir = vm["out"].as<std::string>();
    DatasetSummary summary;
    try {
      summary = MakeDataset(spec, dir);
    } catch (const NoValidDraw& e) {
      std::cerr << "make-dataset: " << e.what() << "\n";
      return tools::kExitNumerical;
    } catch (const std::runtime_error& e) {
      std::cerr << "make-dataset: " << e.what() << "\n";
      return tools::kExitIo;
    }
    if (vm.count("quiet")) return tools::kExitOk;
    for (const DatasetEntry& e : summary.entries) {
      const ReducedFriction& r = e.scene.friction.reduced();
      std::printf("%s  %4d rows  m = %.3f kg  a = %.4f  b = %.4f  c = %.4f m  redraws %zu\n",
                  e.file.c_str(), e.rows, e.scene.slider.mass_kg, r.a, r.b, r.c,
                  e.redraw_reasons.size());
      for (const std::string& why : e.redraw_reasons) std::printf("    redrawn: %s\n", why.c_str());
    }
    std::printf("wrote %zu logs and %s/truth.csv (%d redraws)\n", summary.entries.size(),
                dir.c_str(), summary.redraws);
    return tools::kExitOk;
  });
}
