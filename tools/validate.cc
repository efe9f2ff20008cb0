// validate: cross-validation of the identified friction over logs (prediction/validate.h).
// Each fold is fitted pooled on the other logs and predicts its own pushes; the pushes'
// own fits (an oracle) and the textbook friction are predicted beside it.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "io/atomic_file.h"
#include "io/push_log.h"
#include "pipeline/identify_files.h"
#include "pipeline/log_read_cli_options.h"
#include "pipeline/predict_options.h"
#include "pipeline/report_files.h"
#include "plots/validate_plot.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

namespace {

using tools::Fixed;

std::string Summary(const ErrorSummary& s, double scale, int digits) {
  if (s.pushes == 0) return "-";
  return Fixed(s.median * scale, digits) + " [" + Fixed(s.q25 * scale, digits) + ", " +
         Fixed(s.q75 * scale, digits) + "] " + Fixed(s.worst * scale, digits);
}

void WriteCsv(const ValidationResult& r, const std::string& path) {
  WriteFileAtomically(path, "the validation table", [&](std::ostream& out) {
    out << "method,log,fold,ok,final_position_mm,final_rotation_deg,final_position_per_100mm_mm,"
           "final_position_percent,mean_position_mm,mean_rotation_deg,parting_time_s,error\n";
    for (const MethodValidation& m : r.methods) {
      for (const PushPrediction& p : m.pushes) {
        const PredictionErrors& e = p.errors;
        std::string error = p.error;
        std::replace(error.begin(), error.end(), '"', '\'');
        out << m.method << ",\"" << p.log << "\"," << p.fold << "," << (p.ok ? "yes" : "no") << ","
            << e.final_position_m * 1e3 << "," << e.final_rotation_rad * kRadToDeg << ","
            << e.final_position_per_100mm_m * 1e3 << "," << 100 * e.final_position_fraction << ","
            << e.mean_position_m * 1e3 << "," << e.mean_rotation_rad * kRadToDeg << ","
            << (e.parting_time_s ? Fixed(*e.parting_time_s, 3) : "") << ",\"" << error << "\"\n";
      }
    }
  });
}

}  // namespace

int main(int argc, char** argv) {
  return tools::RunTool("validate", [&]() -> int {
    po::options_description opts(
        "validate: cross-validation over push logs. Each fold fits a, b, c and mu_p pooled on\n"
        "the other logs and predicts its own pushes from their first state (predict); each\n"
        "push's own fit (an oracle: how well the model fits it at all) and the textbook\n"
        "friction (a = 0.25, b = 1, c from a uniform pressure, mu_p = 0.25) are predicted\n"
        "beside it. The summary gives the median [IQR] worst of each error.\n\n"
        "Usage: validate --logs DIR|GLOB [--folds K | --leave-one-out] [--drive pusher|force]\n\n"
        "Options");
    opts.add_options()("help,h", "print this help and exit")("version",
                                                             "print the version and exit")(
        "logs", po::value<std::string>()->value_name("DIR|GLOB"), "the push logs (required)")(
        "skip-bad", "leave out logs that cannot be read, with a warning")(
        "json", po::value<std::string>()->value_name("OUT.json"), "write everything as JSON")(
        "csv", po::value<std::string>()->value_name("OUT.csv"), "write the per-push table")(
        "plot", po::value<std::string>()->value_name("FIG.png"),
        "draw each friction's errors, push by push, with medians and quartiles (gnuplot)")(
        "report", po::value<std::string>()->value_name("OUT.html"),
        "write a self-contained HTML report: each fold's friction, each method's errors, per "
        "log the logged and predicted path and the error against time, the check before "
        "fitting, the command line and the timings (docs/identify.md)");
    cli::AddValidateOptions(&opts);
    cli::AddLogReadOptions(&opts, &opts);
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, opts), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts << "\nExit codes: 0 ok, 1 bad input, 2 usage, 4 a file not writable.\n";
      return tools::FlushStdout("validate");
    }
    if (vm.count("version")) {
      std::cout << "validate (slideid) " << SLIDEID_VERSION << "\n";
      return tools::FlushStdout("validate");
    }
    if (!vm.count("logs")) throw po::error("the option '--logs' is required");
    const LogReadOptions read = cli::ReadLogReadOptions(vm);
    std::vector<Trajectory> logs;
    for (const std::string& path : ExpandFiles(vm["logs"].as<std::string>())) {
      try {
        logs.push_back(ReadPushLog(path, read));
        if (logs.back().source.empty()) logs.back().source = path;
      } catch (const std::exception& e) {
        if (!vm.count("skip-bad")) throw;
        std::cerr << "validate: warning: skipped " << e.what() << "\n";
      }
    }
    const bool all_tip =
        std::all_of(logs.begin(), logs.end(), [](const Trajectory& l) { return l.measured.tip; });
    const ValidationOptions options = cli::ReadValidateOptions(vm, all_tip);
    const ValidationResult r = Validate(logs, options);

    std::cout << "validate: " << r.logs.size() << " logs, " << r.folds << " folds ("
              << (options.folds == 0 ? "leave-one-out" : "round-robin") << "), driven by the "
              << ToString(r.drive) << ", " << Fixed(r.seconds, 2) << " s\n";
    std::cout << "errors: median [IQR] worst over the pushes predicted\n";
    std::printf("%-10s %7s  %-28s  %-28s  %-28s  %-26s\n", "method", "failed",
                "final position [mm]", "final rotation [deg]", "position per 100 mm [mm]",
                "position / displacement [%]");
    for (const MethodValidation& m : r.methods) {
      std::printf("%-10s %7d  %-28s  %-28s  %-28s  %-26s\n", m.method.c_str(), m.failed,
                  Summary(m.final_position_m, 1e3, 1).c_str(),
                  Summary(m.final_rotation_rad, kRadToDeg, 1).c_str(),
                  Summary(m.final_position_per_100mm_m, 1e3, 1).c_str(),
                  Summary(m.final_position_fraction, 100, 1).c_str());
    }
    for (const MethodValidation& m : r.methods) {
      for (const PushPrediction& p : m.pushes) {
        if (!p.ok) std::cout << "  " << m.method << ": " << p.log << ": " << p.error << "\n";
      }
    }
    try {
      if (vm.count("csv")) WriteCsv(r, vm["csv"].as<std::string>());
      if (vm.count("json")) {
        WriteFileAtomically(vm["json"].as<std::string>(), "the validation JSON",
                            cli::ValidationJson(r) + "\n");
      }
      if (vm.count("report")) {
        const auto t0 = std::chrono::steady_clock::now();
        ReportInputs inputs = GatherValidateReport(logs, options, r);
        inputs.command_line = QuotedCommandLine(argc, argv);
        inputs.timings = {
            {"cross-validation", r.seconds},
            {"the report's predictions and checks",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
        WriteHtmlReport(inputs, vm["report"].as<std::string>());
      }
      if (vm.count("plot")) {
        ValidationPlotOptions picture;
        picture.out_png = vm["plot"].as<std::string>();
        picture.title = "validate " + vm["logs"].as<std::string>();
        PlotValidation(r, picture);
      }
    } catch (const std::runtime_error& e) {
      std::cerr << "validate: error: " << e.what() << "\n";
      return tools::kExitIo;
    }
    return tools::FlushStdout("validate");
  });
}
