// identify: estimate the friction parameters (a = e_t mu, b = e_o/e_t, c = e_r/e_t) of a
// sliding object from a push log (docs: shared log-format.md; exit codes and what counts
// as bad input: docs/robustness.md).

#include <glog/logging.h>

#include <cmath>
#include <iostream>
#include <stdexcept>

#include "estimator/identify.h"
#include "estimator/quasi_static_fit.h"
#include "forward_model/push_log.h"
#include "io/wrench_twist_csv.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

namespace {

// Beyond these the fit only gets slower, never better: more Ceres threads than any machine
// here has cores, and forward-model steps far below any time scale of the motion.
constexpr int kMaxThreads = 256;
constexpr int kMaxSubsteps = 1000;

template <typename Enum>
Enum Choose(const po::variables_map& vm, const char* option,
            std::initializer_list<std::pair<const char*, Enum>> choices) {
  const std::string given = vm[option].as<std::string>();
  std::string names;
  for (const auto& [name, value] : choices) {
    if (given == name) return value;
    names += (names.empty() ? "" : ", ") + std::string(name);
  }
  throw po::error(std::string("--") + option + ": unknown value '" + given + "' (one of " +
                  names + ")");
}

/// Whether the user gave `option` (not just its default).
bool Given(const po::variables_map& vm, const char* option) {
  return vm.count(option) && !vm[option].defaulted();
}

/// An option that changes the estimate but that `method` does not use is an error: the user
/// believes it did something (docs/robustness.md). --threads only changes speed: accepted.
void RejectOptionsTheMethodIgnores(const po::variables_map& vm, EstimatorMethod method) {
  std::vector<const char*> unused;
  if (method != EstimatorMethod::kTrajectory) unused = {"segment", "substeps"};
  if (method == EstimatorMethod::kClosedForm) {
    unused.insert(unused.end(), {"loss", "max-iterations"});
  }
  if (method == EstimatorMethod::kQuasiStatic) {
    unused.insert(unused.end(), {"max-gap-ratio", "com-height"});
  }
  for (const char* option : unused) {
    if (Given(vm, option)) {
      throw po::error(std::string("--") + option + " does not apply to --method " +
                      ToString(method));
    }
  }
}

EstimatorOptions ParseEstimatorOptions(const po::variables_map& vm) {
  EstimatorOptions o;
  o.method = Choose<EstimatorMethod>(vm, "method",
                                     {{"closed-form", EstimatorMethod::kClosedForm},
                                      {"equation-error", EstimatorMethod::kEquationError},
                                      {"trajectory", EstimatorMethod::kTrajectory},
                                      {"quasi-static", EstimatorMethod::kQuasiStatic}});
  o.loss = Choose<RobustLoss>(vm, "loss", {{"huber", RobustLoss::kHuber},
                                           {"cauchy", RobustLoss::kCauchy},
                                           {"none", RobustLoss::kNone}});
  RejectOptionsTheMethodIgnores(vm, o.method);
  o.segment_steps = vm["segment"].as<int>();
  o.substeps = vm["substeps"].as<int>();
  o.threads = vm["threads"].as<int>();
  o.max_iterations = vm["max-iterations"].as<int>();
  std::string why;
  if (!o.IsValid(&why)) throw po::error(why);
  if (o.threads > kMaxThreads) {
    throw po::error("--threads must be <= " + std::to_string(kMaxThreads));
  }
  if (o.substeps > kMaxSubsteps) {
    throw po::error("--substeps must be <= " + std::to_string(kMaxSubsteps));
  }
  return o;
}

/// The value of a physical option, checked like the log's metadata would be.
std::optional<double> PhysicalOption(const po::variables_map& vm, const char* option,
                                     bool zero_allowed) {
  if (!vm.count(option)) return std::nullopt;
  const double value = vm[option].as<double>();
  if (!std::isfinite(value) || value < 0.0 || (!zero_allowed && value == 0.0)) {
    throw po::error(std::string("--") + option + " = " + std::to_string(value) +
                    (zero_allowed ? ": must be a finite number >= 0"
                                  : ": must be a finite number > 0"));
  }
  return value;
}

LogReadOptions ParseLogOptions(const po::variables_map& vm) {
  LogReadOptions o;
  o.overrides.mass_kg = PhysicalOption(vm, "mass", false);
  o.overrides.inertia_kgm2 = PhysicalOption(vm, "inertia", false);
  o.overrides.com_height_m = PhysicalOption(vm, "com-height", true);
  o.overrides.gravity_mps2 = PhysicalOption(vm, "gravity", false);
  o.max_gap_ratio = vm["max-gap-ratio"].as<double>();
  if (std::isnan(o.max_gap_ratio)) throw po::error("--max-gap-ratio must be a number");
  return o;
}

/// The first identifiable parameter whose estimate or error is not finite, or -1.
int NonFiniteEstimate(const EstimateResult& result) {
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = result.parameters[i];
    if (p.identifiable && !(std::isfinite(p.value) && std::isfinite(p.stderr_value) &&
                            std::isfinite(p.ci95_lo) && std::isfinite(p.ci95_hi))) {
      return i;
    }
  }
  return -1;
}

/// The other methods: the --log file is a push log.
EstimateResult IdentifyPushLog(const std::string& path, const LogReadOptions& log_options,
                               const EstimatorOptions& options, bool verbose,
                               std::optional<ReducedFriction>* truth) {
  LogReadReport read_report;
  const Trajectory log = ReadPushLog(path, log_options, &read_report);
  for (const std::string& warning : read_report.warnings) {
    std::cerr << "identify: warning: " << warning << "\n";
  }
  if (verbose) {
    for (const std::string& note : read_report.notes) {
      std::cerr << "identify: note: " << path << ": " << note << "\n";
    }
  }
  if (log.true_friction) *truth = ReducedFriction::From(*log.true_friction);
  try {
    return Identify(log, options);
  } catch (const std::invalid_argument& e) {  // the log cannot identify anything
    throw tools::BadInput(path + ": " + e.what());
  }
}

/// --method quasi-static: the --log file holds wrench-twist pairs (io/wrench_twist_csv.h).
EstimateResult IdentifyQuasiStatic(const std::string& path, const LogReadOptions& log_options,
                                   const EstimatorOptions& options, bool verbose,
                                   std::optional<ReducedFriction>* truth) {
  WrenchTwistReadReport report;
  const WrenchTwistData data = ReadWrenchTwistCsv(path, log_options.overrides, &report);
  if (verbose) {
    for (const std::string& note : report.notes) {
      std::cerr << "identify: note: " << path << ": " << note << "\n";
    }
  }
  if (data.true_friction) *truth = ReducedFriction::From(*data.true_friction);
  try {
    return EstimateQuasiStatic(data.Pairs(), QuasiStaticOptionsFor(data, options));
  } catch (const std::invalid_argument& e) {  // too few pairs
    throw tools::BadInput(path + ": " + e.what());
  }
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
        ("log", po::value<std::string>()->value_name("FILE"),
         "push log (CSV, log format); with --method quasi-static, wrench-twist pairs (CSV)")
        ("mass", po::value<double>()->value_name("KG"), "slider mass; overrides the log's")
        ("inertia", po::value<double>()->value_name("KG_M2"),
         "moment of inertia about the vertical axis through the CM; overrides the log's")
        ("com-height", po::value<double>()->value_name("M"), "CM height; overrides the log's")
        ("gravity", po::value<double>()->value_name("M_S2"), "gravity; overrides the log's (9.81)")
        ("method", po::value<std::string>()->default_value("trajectory"),
         "closed-form (Appendix A per step, median), equation-error (Ceres fit of the "
         "friction impulses), trajectory (Ceres fit of the simulated trajectory) or "
         "quasi-static (Ceres fit of the limit surface to wrench-twist pairs)")
        ("loss", po::value<std::string>()->default_value("huber"),
         "robust loss: huber, cauchy, none (not closed-form)")
        ("segment", po::value<int>()->default_value(50)->value_name("N"),
         "trajectory only: log intervals per shooting segment (>= 2)")
        ("substeps", po::value<int>()->default_value(1)->value_name("N"),
         "trajectory only: forward-model steps per log interval (1 to 1000)")
        ("threads", po::value<int>()->default_value(1)->value_name("N"), "Ceres threads (1 to 256)")
        ("json", "print one JSON object instead of the table")
        ("residuals", po::value<std::string>()->value_name("OUT.csv"),
         "write per-step residuals (only when the fit succeeds)")
        ("verbose,v", "also print what the reader noticed about the log (notes)");
    po::options_description advanced("Advanced options");
    advanced.add_options()
        ("max-gap-ratio", po::value<double>()->default_value(10.0)->value_name("R"),
         "an interval between rows longer than R times the median one is an error (the force "
         "is held across it); 0 accepts any gap")
        ("max-iterations", po::value<int>()->default_value(100)->value_name("N"),
         "Ceres iterations per solve; a fit that needs more fails with exit code 3");
    opts.add(advanced);
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, opts), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts << "\nExit codes: 0 ok; 1 bad input (a malformed or physically invalid\n"
                           "log, or one that cannot identify anything); 2 usage (unknown, missing,\n"
                           "invalid or conflicting options); 3 numerical (the fit did not\n"
                           "converge); 4 a file could not be written. Warnings (absurd magnitudes,\n"
                           "gaps in t) always go to stderr; --verbose adds the reader's notes.\n";
      return tools::FlushStdout("identify");
    }
    if (vm.count("version")) {
      std::cout << "identify (slideid) " << SLIDEID_VERSION << "\n";
      return tools::FlushStdout("identify");
    }
    if (!vm.count("log")) throw po::error("the option '--log' is required");
    // Ceres logs a page per residual block that evaluates to NaN at a trial point of a
    // fit; the result says how the fit ended, so keep those pages for --verbose.
    if (!vm.count("verbose")) FLAGS_minloglevel = google::GLOG_ERROR;
    const EstimatorOptions options = ParseEstimatorOptions(vm);
    const LogReadOptions log_options = ParseLogOptions(vm);

    const std::string path = vm["log"].as<std::string>();
    std::optional<ReducedFriction> truth;
    const EstimateResult result =
        options.method == EstimatorMethod::kQuasiStatic
            ? IdentifyQuasiStatic(path, log_options, options, vm.count("verbose"), &truth)
            : IdentifyPushLog(path, log_options, options, vm.count("verbose"), &truth);
    std::cout << (vm.count("json") ? FormatJson(result) + "\n" : FormatReport(result, truth));
    if (!result.converged) {
      std::cerr << "identify: error: " << path << ": the " << ToString(options.method)
                << " fit did not converge (" << result.message
                << "); no residuals written\n";
      return tools::kExitNumerical;
    }
    if (const int i = NonFiniteEstimate(result); i >= 0) {
      std::cerr << "identify: error: " << path << ": the " << ToString(options.method)
                << " fit gave a non-finite " << ParameterName(i)
                << " (a numerical failure); no residuals written\n";
      return tools::kExitNumerical;
    }
    if (vm.count("residuals")) {
      try {
        WriteResidualsCsv(result, vm["residuals"].as<std::string>());
      } catch (const std::exception& e) {
        std::cerr << "identify: error: " << e.what() << "\n";
        return tools::kExitIo;
      }
    }
    return tools::FlushStdout("identify");
  });
}
