#include "pipeline/identify_options.h"

#include <sys/stat.h>

#include <cmath>
#include <initializer_list>
#include <map>
#include <utility>

#include "forward_model/simulator.h"
#include "pipeline/log_read_cli_options.h"

namespace slideid::cli {
namespace {

namespace po = boost::program_options;

// Beyond this the fit only gets slower, never better: more Ceres threads than any machine
// here has cores (substeps: kMaxSubstepsPerInterval, forward_model/simulator.h).
constexpr int kMaxThreads = 256;

template <typename Enum>
Enum Choose(const po::variables_map& vm, const char* option,
            std::initializer_list<std::pair<const char*, Enum>> choices) {
  const std::string given = vm[option].as<std::string>();
  std::string names;
  for (const auto& [name, value] : choices) {
    if (given == name) return value;
    names += (names.empty() ? "" : ", ") + std::string(name);
  }
  throw po::error(std::string("--") + option + ": unknown value '" + given + "' (one of " + names +
                  ")");
}

/// Whether the user gave `option` (not just its default).
bool Given(const po::variables_map& vm, const char* option) {
  return vm.count(option) && !vm[option].defaulted();
}

/// An option that changes the estimate but that `method` does not use is an error: the user
/// believes it did something (docs/robustness.md). --threads only changes speed: accepted.
void RejectOptionsTheMethodIgnores(const po::variables_map& vm, EstimatorMethod method) {
  std::vector<const char*> unused;
  if (method != EstimatorMethod::kTrajectory) {
    unused = {"segment", "substeps", "fit-force-bias", "fit-delay", "no-cross-check"};
  }
  if (method == EstimatorMethod::kClosedForm) {
    unused.insert(unused.end(), {"loss", "max-iterations"});
  }
  for (const char* option : unused) {
    if (Given(vm, option)) {
      throw po::error(std::string("--") + option + " does not apply to --method " +
                      ToString(method));
    }
  }
}

IdentifyOptions ReadEstimatorOptions(const po::variables_map& vm) {
  IdentifyOptions o;
  o.method = Choose<EstimatorMethod>(vm, "method",
                                     {{"closed-form", EstimatorMethod::kClosedForm},
                                      {"equation-error", EstimatorMethod::kEquationError},
                                      {"trajectory", EstimatorMethod::kTrajectory},
                                      {"quasi-static", EstimatorMethod::kQuasiStatic}});
  RejectOptionsTheMethodIgnores(vm, o.method);
  const RobustLoss loss = Choose<RobustLoss>(vm, "loss",
                                             {{"huber", RobustLoss::kHuber},
                                              {"cauchy", RobustLoss::kCauchy},
                                              {"none", RobustLoss::kNone}});
  const int iterations = vm["max-iterations"].as<int>();
  for (LossOptions* l :
       std::initializer_list<LossOptions*>{&o.equation_error, &o.trajectory, &o.quasi_static}) {
    l->loss = loss;
    l->max_iterations = iterations;
  }
  o.trajectory.segment_steps = vm["segment"].as<int>();
  o.trajectory.substeps = vm["substeps"].as<int>();
  o.trajectory.fit_force_bias = vm.count("fit-force-bias") > 0;
  o.trajectory.cross_check = vm.count("no-cross-check") == 0;
  if (vm.count("fit-delay")) {
    o.trajectory.fit_delay = Choose<DelayFit>(
        vm, "fit-delay", {{"shared", DelayFit::kShared}, {"per-log", DelayFit::kPerLog}});
  }
  o.trajectory.max_delay_s = vm["max-delay"].as<double>();
  o.threads = vm["threads"].as<int>();
  std::string why;
  if (!o.IsValid(&why)) throw po::error(why);
  if (o.threads > kMaxThreads)
    throw po::error("--threads must be <= " + std::to_string(kMaxThreads));
  if (o.trajectory.substeps > kMaxSubstepsPerInterval) {
    throw po::error("--substeps must be <= " + std::to_string(kMaxSubstepsPerInterval));
  }
  return o;
}

}  // namespace

FileIdentifyOptions ReadFileIdentifyOptions(const po::variables_map& vm) {
  FileIdentifyOptions o;
  o.identify = ReadEstimatorOptions(vm);
  o.read = ReadLogReadOptions(vm);
  o.skip_bad = vm.count("skip-bad") > 0;
  return o;
}

void AddIdentifyOptions(po::options_description* options, po::options_description* advanced) {
  options->add_options()(
      "log", po::value<std::vector<std::string>>()->value_name("FILE"),
      "push log (CSV, log format); repeat it to pool several logs of one slider on one "
      "surface. With --method quasi-static: wrench-twist pairs (CSV)")(
      "logs", po::value<std::vector<std::string>>()->value_name("DIR|GLOB"),
      "every *.csv file of a directory, or the files a quoted glob names (repeatable)");
  AddLogReadOptions(options, advanced);
  options->add_options()(
      "method", po::value<std::string>()->default_value("trajectory"),
      "closed-form (Appendix A per step, median), equation-error (Ceres fit of the friction "
      "impulses), trajectory (Ceres fit of the simulated trajectory) or quasi-static (Ceres "
      "fit of the limit surface to wrench-twist pairs)")(
      "loss", po::value<std::string>()->default_value("huber"),
      "robust loss: huber, cauchy, none (not closed-form)")(
      "fit-force-bias",
      "trajectory only: fit a constant offset (x, y) of each log's force "
      "channel, with its interval")(
      "no-cross-check",
      "trajectory only: on a log of at most 300 rows, do not fit it again over "
      "long segments to mark estimates that depend on how it is cut")(
      "fit-delay", po::value<std::string>()->implicit_value("shared")->value_name("MODE"),
      "trajectory only: fit the delay of the force stream against the poses, one for all "
      "logs (shared, the default) or one per log (per-log)")(
      "threads", po::value<int>()->default_value(1)->value_name("N"), "Ceres threads (1 to 256)")(
      "strict", "a suspect verdict is an error (exit code 3) instead of a warning")(
      "skip-bad",
      "list a log that cannot be read or used as skipped, with the reason, "
      "instead of failing the run")("json", "print one JSON object instead of the table")(
      "residuals", po::value<std::string>()->value_name("OUT.csv"),
      "write per-step residuals (only when the fit succeeds)")(
      "report", po::value<std::string>()->value_name("OUT.html"),
      "also write a self-contained HTML report: the estimates, the forest plot of pooled logs, "
      "each log's path, replay and residuals, the check before fitting, the correlations, "
      "the optimisation trace, the command line and the timings (docs/identify.md)")(
      "verbose,v",
      "also print what the readers noticed about the logs (notes), the solver's own report "
      "and how each interval was computed in full")(
      "check",
      "fit nothing: say per log its rates, gaps, noise and dead channels, how it excites the "
      "friction, which of a, b, c (and mu_p) the fit could identify and how precisely, and "
      "what would help (exit 1 when a log cannot be read or could identify nothing)")(
      "follow",
      "read one log from standard input as a logger writes it (metadata and header, then a "
      "row per line) and print the online estimate as a JSON line after each row "
      "(docs/online.md)")(
      "every", po::value<int>()->default_value(1)->value_name("N"),
      "with --follow: a line after every N rows (and at a change, and after the last row)")(
      "batch-check", po::value<int>()->default_value(128)->value_name("N"),
      "with --follow: check the online estimate against the trajectory fit of the rows so far "
      "after N, 2N, 4N ... rows, and take the fit's over where the filter ran off; an update "
      "that runs one takes the fit's time (0: no check; docs/online.md)")(
      "batch", po::value<std::string>()->value_name("DIR|GLOB"),
      "fit every log of a directory (or a quoted glob) on its own, writing one JSON line per "
      "log to --out as each finishes (a failed log gives a line with its error)")(
      "jobs", po::value<int>()->default_value(1)->value_name("N"),
      "with --batch: logs fitted at once (threads)")(
      "out", po::value<std::string>()->value_name("RESULTS.jsonl"),
      "with --batch: where the JSON lines go")(
      "resume",
      "with --batch: keep the lines already in --out and fit only the logs they lack (a log "
      "is known by its path and SHA-256: a changed one is fitted again; a torn last line is "
      "dropped with a warning)")(
      "shard", po::value<std::string>()->value_name("I/N"),
      "with --batch: take only the logs whose index in the sorted list is I modulo N "
      "(0 <= I < N), for job arrays");
  advanced->add_options()(
      "segment", po::value<int>()->default_value(0)->value_name("N"),
      "trajectory only: log intervals per shooting segment (>= 2; 0 adapts it to the log)")(
      "substeps", po::value<int>()->default_value(1)->value_name("N"),
      "trajectory only: forward-model steps per log interval (1 to 1000)")(
      "max-delay", po::value<double>()->default_value(0.1)->value_name("S"),
      "with --fit-delay: the largest delay searched [s]")(
      "max-iterations", po::value<int>()->default_value(100)->value_name("N"),
      "Ceres iterations per solve; a fit that needs more fails with exit code 3");
}

// One file named twice among the pooled logs (--log a.csv --logs DIR with a.csv in DIR,
// ./a.csv and a.csv, a symbolic or hard link) would be pooled twice: its rows counted twice,
// the intervals narrower by about sqrt(2) than its data allow, and the logs' agreement a
// foregone conclusion. Files are compared by device and inode; one that cannot be read is
// left to the reader's error.
void RejectRepeatedFiles(const std::vector<std::string>& files) {
  std::map<std::pair<dev_t, ino_t>, const std::string*> seen;
  for (const std::string& file : files) {
    struct stat s;
    if (::stat(file.c_str(), &s) != 0) continue;
    const auto [at, inserted] = seen.emplace(std::make_pair(s.st_dev, s.st_ino), &file);
    if (!inserted) {
      throw po::error("'" + file + "' is the same file as '" + *at->second +
                      "': pooled twice, its rows would count twice and narrow the intervals");
    }
  }
}

// --batch and its companions; the batch's files, sharded.
void ReadBatchOptions(const po::variables_map& vm, IdentifyRequest* r) {
  r->batch = true;
  for (const char* option : {"log", "logs", "json", "residuals", "skip-bad", "strict", "report"}) {
    if (vm.count(option)) throw po::error(std::string("--") + option + " does not go with --batch");
  }
  if (!vm.count("out")) throw po::error("--batch needs --out RESULTS.jsonl");
  r->batch_out = vm["out"].as<std::string>();
  r->resume = vm.count("resume") > 0;
  r->jobs = vm["jobs"].as<int>();
  if (r->jobs < 1 || r->jobs > kMaxThreads) {
    throw po::error("--jobs must be from 1 to " + std::to_string(kMaxThreads));
  }
  Shard shard;
  if (vm.count("shard")) {
    try {
      shard = Shard::Parse(vm["shard"].as<std::string>());
    } catch (const std::invalid_argument& e) {
      throw po::error(std::string("--shard: ") + e.what());
    }
  }
  try {
    r->files = shard.Select(ExpandFiles(vm["batch"].as<std::string>()));
  } catch (const FileError& e) {
    throw po::error(std::string("--batch: ") + e.what());
  }
}

// --follow and --every: rows from standard input, to the online identifier.
void ReadFollowOptions(const po::variables_map& vm, IdentifyRequest* r) {
  r->follow = true;
  for (const char* option :
       {"log", "logs", "batch", "residuals", "skip-bad", "strict", "json", "report"}) {
    if (vm.count(option))
      throw po::error(std::string("--") + option + " does not go with --follow");
  }
  if (!vm["method"].defaulted()) throw po::error("--method does not go with --follow");
  r->follow_every = vm["every"].as<int>();
  if (r->follow_every < 1) throw po::error("--every must be >= 1");
  r->follow_batch_check_rows = vm["batch-check"].as<int>();
  if (r->follow_batch_check_rows < 0) throw po::error("--batch-check must be >= 0");
  r->options.read = ReadLogReadOptions(vm);
  r->verbose = vm.count("verbose") > 0;
}

IdentifyRequest ReadIdentifyOptions(const po::variables_map& vm) {
  IdentifyRequest r;
  if (vm.count("check")) {
    r.check = true;
    for (const char* option : {"batch", "residuals", "strict", "follow", "report"}) {
      if (vm.count(option))
        throw po::error(std::string("--") + option + " does not go with --check");
    }
    if (vm["method"].as<std::string>() != "trajectory") {
      throw po::error("--check forecasts the trajectory fit: it does not go with --method " +
                      vm["method"].as<std::string>());
    }
  }
  if (vm.count("follow")) {
    ReadFollowOptions(vm, &r);
    return r;
  }
  if (!vm["every"].defaulted()) throw po::error("--every needs --follow");
  if (!vm["batch-check"].defaulted()) throw po::error("--batch-check needs --follow");
  if (vm.count("batch")) {
    ReadBatchOptions(vm, &r);
  } else {
    for (const char* option : {"out", "shard", "resume"}) {
      if (vm.count(option)) throw po::error(std::string("--") + option + " needs --batch");
    }
    if (!vm["jobs"].defaulted()) throw po::error("--jobs needs --batch");
  }
  if (vm.count("log")) r.files = vm["log"].as<std::vector<std::string>>();
  if (vm.count("logs")) {
    for (const std::string& pattern : vm["logs"].as<std::vector<std::string>>()) {
      try {
        for (std::string& f : ExpandFiles(pattern)) r.files.push_back(std::move(f));
      } catch (const FileError& e) {
        throw po::error(std::string("--logs: ") + e.what());
      }
    }
  }
  if (r.files.empty() && !r.batch) {
    throw po::error("the option '--log' (or '--logs') is required");
  }
  if (!r.batch && !r.check) RejectRepeatedFiles(r.files);
  r.options.identify = ReadEstimatorOptions(vm);
  r.options.read = ReadLogReadOptions(vm);
  r.options.skip_bad = vm.count("skip-bad") > 0;
  r.json = vm.count("json") > 0;
  r.verbose = vm.count("verbose") > 0;
  r.strict = vm.count("strict") > 0;
  if (vm.count("residuals")) r.residuals_path = vm["residuals"].as<std::string>();
  if (vm.count("report")) r.report_path = vm["report"].as<std::string>();
  // Per-row residuals only where something writes them (48 MB of a 1e6-row log).
  r.options.identify.keep_residuals = !r.residuals_path.empty() || !r.report_path.empty();
  r.options.keep_logs = !r.report_path.empty();  // the report draws the logs the fit read
  return r;
}

}  // namespace slideid::cli
