// predict: what a friction predicts for a logged push. Replays the push from its first
// state, driven by the pusher's path (the log's tip_x, tip_y) or by the logged force, and
// prints how far the prediction lands from the log (prediction/predict.h).

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/push_log.h"
#include "io/result_json.h"
#include "prediction/predict.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

std::string Fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

/// a, b, c and mu_p from --friction RESULT.json, then the options over them.
struct Friction {
  ReducedFriction reduced;
  std::optional<double> mu_pusher;
};

Friction FrictionFrom(const po::variables_map& vm) {
  Friction f;
  bool a = false, b = false, c = false;
  if (vm.count("friction")) {
    const std::string path = vm["friction"].as<std::string>();
    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot open the friction (identify --json)");
    std::stringstream text;
    text << in.rdbuf();
    EstimateResult r;
    try {
      r = ParseResultJson(text.str());
    } catch (const ResultJsonError& e) {
      throw std::runtime_error(path + ": " + e.what());
    }
    const ParameterEstimate* p = r.parameters.data();
    if (p[kA].identifiable) f.reduced.a = p[kA].value, a = true;
    if (p[kB].identifiable) f.reduced.b = p[kB].value, b = true;
    if (p[kC].identifiable) f.reduced.c = p[kC].value, c = true;
    if (r.mu_pusher.identifiable) f.mu_pusher = r.mu_pusher.value;
  }
  if (vm.count("mu")) f.reduced.a = vm["mu"].as<double>(), a = true;
  if (vm.count("b")) f.reduced.b = vm["b"].as<double>(), b = true;
  if (vm.count("c")) f.reduced.c = vm["c"].as<double>(), c = true;
  if (vm.count("mu-pusher")) f.mu_pusher = vm["mu-pusher"].as<double>();
  const char* missing = !a ? "a (--mu)" : !b ? "b (--b)" : !c ? "c (--c)" : nullptr;
  if (missing) {
    throw po::error(std::string("no value for ") + missing + ": give --friction RESULT.json "
                    "where it is identified, or the option");
  }
  if (!(f.reduced.a > 0 && f.reduced.b > 0 && f.reduced.c > 0)) {
    throw po::error("--mu, --b and --c must be > 0");
  }
  if (f.mu_pusher && !(*f.mu_pusher >= 0)) throw po::error("--mu-pusher must be >= 0");
  return f;
}

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

nlohmann::json ErrorsJson(const Prediction& p, const Friction& f) {
  const PredictionErrors& e = p.errors;
  nlohmann::json j;
  j["drive"] = ToString(p.drive);
  j["e_t_mu"] = f.reduced.a;
  j["e_o_over_e_t"] = f.reduced.b;
  j["e_r_over_e_t"] = f.reduced.c;
  j["mu_pusher"] = p.drive == PredictionDrive::kPusher ? nlohmann::json(p.mu_pusher) : nlohmann::json();
  j["tip_radius_m"] = p.drive == PredictionDrive::kPusher ? nlohmann::json(p.tip_radius_m) : nlohmann::json();
  j["ok"] = p.summary.ok();
  j["message"] = p.summary.message;
  j["rows_predicted"] = p.predicted.samples.size();
  j["final_position_m"] = e.final_position_m;
  j["final_rotation_rad"] = e.final_rotation_rad;
  j["mean_position_m"] = e.mean_position_m;
  j["mean_rotation_rad"] = e.mean_rotation_rad;
  j["travel_m"] = e.travel_m;
  j["travel_of"] = e.travel_of;
  j["final_position_per_100mm_m"] = e.final_position_per_100mm_m;
  j["final_rotation_per_100mm_rad"] = e.final_rotation_per_100mm_rad;
  j["logged_displacement_m"] = e.logged_displacement_m;
  j["final_position_fraction"] = e.final_position_fraction;
  j["parting_time_s"] = e.parting_time_s ? nlohmann::json(*e.parting_time_s) : nlohmann::json();
  return j;
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
    opts.add_options()
        ("help,h", "print this help and exit")
        ("version", "print the version and exit")
        ("log", po::value<std::string>()->value_name("PUSH.csv"), "the push to predict (required)")
        ("friction", po::value<std::string>()->value_name("RESULT.json"),
         "the friction: what identify --json printed (a, b, c, and mu_pusher when found)")
        ("mu", po::value<double>()->value_name("A"), "a = e_t mu (overrides the result's)")
        ("b", po::value<double>()->value_name("B"), "b = e_o / e_t")
        ("c", po::value<double>()->value_name("C"), "c = e_r / e_t [m]")
        ("mu-pusher", po::value<double>()->value_name("MU_P"),
         "tip-edge friction coefficient (the pusher drive needs it)")
        ("drive", po::value<std::string>(),
         "pusher or force (default: pusher when the log has tip_x, tip_y, else force)")
        ("substeps", po::value<int>()->default_value(1), "simulation steps per log interval")
        ("no-register-tip",
         "use the log's tip radius as it is (by default it is set so that the tip touches the "
         "outline, on the median, where the log pushes)")
        ("out", po::value<std::string>()->value_name("PRED.csv"),
         "write the predicted trajectory as a push log")
        ("json", "print the errors as one JSON object instead of the table");
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, opts), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts << "\nExit codes: 0 ok, 1 bad input (the log, the result, a drive the "
                           "log cannot give), 2 usage, 3 the prediction failed to converge "
                           "part way (errors over the rows predicted), 4 a file not writable.\n";
      return tools::FlushStdout("predict");
    }
    if (vm.count("version")) {
      std::cout << "predict (slideid) " << SLIDEID_VERSION << "\n";
      return tools::FlushStdout("predict");
    }
    if (!vm.count("log")) throw po::error("the option '--log' is required");
    const Friction friction = FrictionFrom(vm);
    const std::string log_path = vm["log"].as<std::string>();
    const Trajectory log = ReadPushLog(log_path);
    PredictionOptions options;
    options.drive = log.columns.tip ? PredictionDrive::kPusher : PredictionDrive::kForce;
    if (vm.count("drive") && !ParsePredictionDrive(vm["drive"].as<std::string>(), &options.drive)) {
      throw po::error("--drive must be pusher or force");
    }
    options.substeps = vm["substeps"].as<int>();
    options.register_tip = !vm.count("no-register-tip");
    std::string why;
    if (!options.IsValid(&why)) throw po::error(why);
    const Prediction p = PredictPush(log, friction.reduced, friction.mu_pusher, options);
    if (vm.count("out")) {
      try {
        WritePushLog(p.predicted, vm["out"].as<std::string>());
      } catch (const std::exception& e) {
        std::cerr << "predict: error: " << e.what() << "\n";
        return tools::kExitIo;
      }
    }
    if (vm.count("json")) {
      std::cout << ErrorsJson(p, friction).dump() << "\n";
    } else {
      std::cout << "predict " << log_path << ", driven by the " << ToString(p.drive)
                << ": a = " << friction.reduced.a << ", b = " << friction.reduced.b
                << ", c = " << friction.reduced.c * 1e3 << " mm";
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
