// identify: estimate the friction parameters (a = e_t mu, b = e_o/e_t, c = e_r/e_t) of a
// sliding object from a push log (docs: shared log-format.md).

#include <iostream>

#include "estimator/identify.h"
#include "forward_model/push_log.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

namespace {

template <typename Enum>
Enum Choose(const po::variables_map& vm, const char* option,
            std::initializer_list<std::pair<const char*, Enum>> choices) {
  const std::string given = vm[option].as<std::string>();
  for (const auto& [name, value] : choices) {
    if (given == name) return value;
  }
  throw po::error(std::string("--") + option + ": unknown value '" + given + "'");
}

EstimatorOptions ParseEstimatorOptions(const po::variables_map& vm) {
  EstimatorOptions o;
  o.method = Choose<EstimatorMethod>(vm, "method",
                                     {{"closed-form", EstimatorMethod::kClosedForm},
                                      {"equation-error", EstimatorMethod::kEquationError},
                                      {"trajectory", EstimatorMethod::kTrajectory}});
  o.loss = Choose<RobustLoss>(vm, "loss", {{"huber", RobustLoss::kHuber},
                                           {"cauchy", RobustLoss::kCauchy},
                                           {"none", RobustLoss::kNone}});
  o.segment_steps = vm["segment"].as<int>();
  o.substeps = vm["substeps"].as<int>();
  o.threads = vm["threads"].as<int>();
  std::string why;
  if (!o.IsValid(&why)) throw po::error(why);
  return o;
}

LogReadOptions ParseLogOptions(const po::variables_map& vm) {
  LogReadOptions o;
  if (vm.count("mass")) o.overrides.mass_kg = vm["mass"].as<double>();
  if (vm.count("inertia")) o.overrides.inertia_kgm2 = vm["inertia"].as<double>();
  if (vm.count("com-height")) o.overrides.com_height_m = vm["com-height"].as<double>();
  if (vm.count("gravity")) o.overrides.gravity_mps2 = vm["gravity"].as<double>();
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  return tools::RunTool("identify", [&]() -> int {
    po::options_description opts(
        "identify: estimate the friction of a sliding object from a push log.\n"
        "Recovers a = e_t*mu, b = e_o/e_t and c = e_r/e_t [m] (the combinations the motion\n"
        "depends on), says which the log cannot identify, and how sure each estimate is.\n\n"
        "Usage: identify --log FILE.csv [options]\n\nOptions");
    opts.add_options()
        ("help,h", "print this help and exit")
        ("version", "print the version and exit")
        ("log", po::value<std::string>()->value_name("FILE"), "push log (CSV, log format)")
        ("mass", po::value<double>()->value_name("KG"), "slider mass; overrides the log's")
        ("inertia", po::value<double>()->value_name("KG_M2"),
         "moment of inertia about the vertical axis through the CM; overrides the log's")
        ("com-height", po::value<double>()->value_name("M"), "CM height; overrides the log's")
        ("gravity", po::value<double>()->value_name("M_S2"), "gravity; overrides the log's (9.81)")
        ("method", po::value<std::string>()->default_value("trajectory"),
         "closed-form (Appendix A per step, median), equation-error (Ceres fit of the "
         "friction impulses) or trajectory (Ceres fit of the simulated trajectory)")
        ("loss", po::value<std::string>()->default_value("huber"), "robust loss: huber, cauchy, none")
        ("segment", po::value<int>()->default_value(50)->value_name("N"),
         "trajectory: log intervals per shooting segment (>= 2)")
        ("substeps", po::value<int>()->default_value(1)->value_name("N"),
         "trajectory: forward-model steps per log interval (>= 1)")
        ("threads", po::value<int>()->default_value(1)->value_name("N"), "Ceres threads")
        ("json", "print one JSON object instead of the table")
        ("residuals", po::value<std::string>()->value_name("OUT.csv"), "write per-step residuals")
        ("verbose,v", "also print what the reader noticed about the log");
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, opts), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts << "\nExit codes: 0 ok, 1 bad input (log or values), 2 usage, "
                           "3 the fit did not converge, 4 a file could not be written.\n";
      return tools::kExitOk;
    }
    if (vm.count("version")) {
      std::cout << "identify (slideid) " << SLIDEID_VERSION << "\n";
      return tools::kExitOk;
    }
    if (!vm.count("log")) throw po::error("the option '--log' is required");
    const EstimatorOptions options = ParseEstimatorOptions(vm);

    LogReadReport read_report;
    const Trajectory log = ReadPushLog(vm["log"].as<std::string>(), ParseLogOptions(vm), &read_report);
    if (vm.count("verbose")) {
      for (const std::string& note : read_report.notes) std::cerr << "identify: note: " << note << "\n";
    }
    const EstimateResult result = Identify(log, options);
    std::optional<ReducedFriction> truth;
    if (log.true_friction) truth = ReducedFriction::From(*log.true_friction);
    std::cout << (vm.count("json") ? FormatJson(result) + "\n" : FormatReport(result, truth));
    if (!result.converged) {
      std::cerr << "identify: the fit did not converge: " << result.message << "\n";
      return tools::kExitNumerical;
    }
    if (vm.count("residuals")) {
      try {
        WriteResidualsCsv(result, vm["residuals"].as<std::string>());
      } catch (const std::exception& e) {
        std::cerr << "identify: " << e.what() << "\n";
        return tools::kExitIo;
      }
    }
    return tools::kExitOk;
  });
}
