// predict: what a friction predicts for a logged push. Replays the push from its first
// state, driven by the pusher's path (the log's tip_x, tip_y) or by the logged force, and
// prints how far the prediction lands from the log (prediction/predict.h).

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "io/push_log.h"
#include "pipeline/log_read_cli_options.h"
#include "pipeline/predict_options.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

namespace {

using tools::Fixed;

void PrintErrors(const Prediction& p) {
  const PredictionErrors& e = p.errors;
  std::cout << "final position error  " << Fixed(e.final_position_m * 1e3, 2) << " mm";
  if (e.travel_m > 0) {
    std::cout << "  (" << Fixed(e.final_position_per_100mm_m * 1e3, 2) << " mm per 100 mm of "
              << e.travel_of << " travel";
  }
  if (e.logged_displacement_m > 0) {
    std::cout << "; " << Fixed(100 * e.final_position_fraction, 1) << "% of the "
              << Fixed(e.logged_displacement_m * 1e3, 1) << " mm displacement";
  }
  std::cout << (e.travel_m > 0 ? ")" : "") << "\n";
  std::cout << "final rotation error  " << Fixed(e.final_rotation_rad * kRadToDeg, 2) << " deg";
  if (e.travel_m > 0) {
    std::cout << "  (" << Fixed(e.final_rotation_per_100mm_rad * kRadToDeg, 2)
              << " deg per 100 mm of " << e.travel_of << " travel)";
  }
  std::cout << "\nmean errors           " << Fixed(e.mean_position_m * 1e3, 2) << " mm, "
            << Fixed(e.mean_rotation_rad * kRadToDeg, 2) << " deg over the rows\n";
  std::cout << "parts from the log    "
            << (e.parting_time_s ? "at t = " + Fixed(*e.parting_time_s, 3) + " s"
                                 : std::string("never"))
            << " (first error past 5 mm or 5 deg)\n";
}

}  // namespace

int main(int argc, char** argv) {
  return tools::RunTool("predict", [&]() -> int {
    po::options_description opts(
        "predict: what a friction predicts for a logged push. The push is replayed from the\n"
        "log's first pose and velocity, driven by the pusher's path (the log's tip_x, tip_y,\n"
        "with '# tip_radius' and '# patch') or by the logged force, and compared with the\n"
        "log row by row.\n\n"
        "Usage: predict --log PUSH.csv --friction RESULT.json [--drive pusher|force]\n"
        "       predict --log PUSH.csv --mu A --b B --c C --mu-pusher MU_P\n\nOptions");
    opts.add_options()("help,h", "print this help and exit")("version",
                                                             "print the version and exit")(
        "log", po::value<std::string>()->value_name("PUSH.csv"), "the push to predict (required)")(
        "out", po::value<std::string>()->value_name("PRED.csv"),
        "write the predicted trajectory as a push log")(
        "json", "print the errors as one JSON object instead of the table");
    cli::AddPredictOptions(&opts);
    cli::AddLogReadOptions(&opts, &opts);
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, opts), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts
                << "\nExit codes: 0 ok, 1 bad input (the log, the result, a drive the "
                   "log cannot give), 2 usage, 3 the prediction failed to converge "
                   "part way (errors over the rows predicted), 4 a file not writable.\n";
      return tools::FlushStdout("predict");
    }
    if (vm.count("version")) {
      std::cout << "predict (slideid) " << SLIDEID_VERSION << "\n";
      return tools::FlushStdout("predict");
    }
    if (!vm.count("log")) throw po::error("the option '--log' is required");
    const cli::PredictRequest request = cli::ReadPredictOptions(vm);
    const std::string log_path = vm["log"].as<std::string>();
    PushLogFile file = ReadPushLogFile(log_path, cli::ReadLogReadOptions(vm));
    // Named in the prediction's errors ("LOG: the force drive needs logged forces").
    file.log.source = log_path;
    const Trajectory& log = file.log;
    PredictionOptions options = request.options;
    options.drive = cli::DriveFor(request, log);
    const Prediction p = PredictPush(log, request.friction, request.mu_pusher, options);
    if (vm.count("out")) {
      try {
        // The log's patch text goes with it: a patch written as it was read.
        WritePushLog(PushLogFile{p.predicted, file.patch_spec, {}}, vm["out"].as<std::string>());
      } catch (const std::exception& e) {
        std::cerr << "predict: error: " << e.what() << "\n";
        return tools::kExitIo;
      }
    }
    if (vm.count("json")) {
      std::cout << cli::PredictionJson(p, request.friction) << "\n";
    } else {
      std::cout << "predict " << log_path << ", driven by the " << ToString(p.drive)
                << ": a = " << request.friction.a << ", b = " << request.friction.b
                << ", c = " << request.friction.c * 1e3 << " mm";
      if (p.drive == PredictionDrive::kPusher) {
        std::cout << ", mu_p = " << p.mu_pusher << ", tip radius " << Fixed(p.tip_radius_m * 1e3, 2)
                  << " mm";
        if (log.tip_radius_m && p.tip_radius_m != *log.tip_radius_m) {
          std::cout << " (registered: the log's " << Fixed(*log.tip_radius_m * 1e3, 2)
                    << " mm plus the median contact gap while pushing)";
        }
      }
      std::cout << "\n";
      if (!p.summary.ok()) {
        std::cout << "DOUBTFUL: the prediction stopped part way (" << p.summary.message
                  << "); the errors cover the rows predicted\n";
      }
      PrintErrors(p);
      if (p.drive == PredictionDrive::kPusher) {
        std::cout << "tip                   " << p.summary.tip_stick_steps << " steps sticking, "
                  << p.summary.tip_slide_steps << " sliding along the edge, "
                  << p.summary.steps - p.summary.tip_stick_steps - p.summary.tip_slide_steps
                  << " apart\n";
      }
      if (vm.count("out")) std::cout << "wrote " << vm["out"].as<std::string>() << "\n";
    }
    const int flushed = tools::FlushStdout("predict");
    if (flushed != tools::kExitOk) return flushed;
    return p.summary.ok() ? tools::kExitOk : tools::kExitNumerical;
  });
}
