// identify: estimate the friction parameters (a = e_t mu, b = e_o/e_t, c = e_r/e_t) of a
// sliding object from one push log or several (docs/log-format.md; exit codes and
// what counts as bad input: docs/robustness.md).

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <functional>
#include <iostream>

#include "io/log_check_report.h"
#include "io/result_json.h"
#include "io/result_report.h"
#include "pipeline/check_files.h"
#include "pipeline/follow.h"
#include "pipeline/identify_options.h"
#include "pipeline/report_files.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

namespace {

constexpr const char* kExitCodes =
    "\nExit codes: 0 ok (a suspect verdict is a warning); 1 bad input (a malformed or\n"
    "physically invalid log, or one that cannot identify anything); 2 usage (unknown,\n"
    "missing, invalid or conflicting options); 3 numerical (the fit did not converge, or\n"
    "with --strict a suspect verdict); 4 a file could not be written; 130 / 143 --batch\n"
    "stopped by SIGINT / SIGTERM after its last whole line (--resume finishes it). Warnings\n"
    "(absurd magnitudes, gaps in t) always go to stderr; --verbose adds the readers' notes.\n"
    "With --check: 0 when every log is expected to identify something; 1 when a log cannot\n"
    "be read, or is expected to identify nothing; 2 usage.\n";

// Set by SIGINT and SIGTERM during a batch: no further log starts (lock-free, so safe to
// set in a handler).
std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_signal = 0;

extern "C" void OnStopSignal(int signal) {
  g_signal = signal;
  g_stop = true;
}

/// SIGINT and SIGTERM stop the batch cleanly; a second one ends the process at once (the
/// default action: SA_RESETHAND), which still leaves whole lines only.
void CatchStopSignals() {
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

/// --batch: every file on its own, JSON lines to the output (whole lines, resumable);
/// progress on a terminal.
int RunBatchCommand(const cli::IdentifyRequest& request) {
  const bool terminal = isatty(STDERR_FILENO);
  auto progress = [&](const BatchProgress& p) {
    const double rate = p.done / std::max(p.seconds, 1e-9);
    std::fprintf(stderr, "\ridentify: %d/%d logs, %d failed, %.1f logs/s, %.0f s left   ", p.done,
                 p.total, p.failed, rate, (p.total - p.done) / std::max(rate, 1e-9));
  };
  CatchStopSignals();
  BatchSummary summary;
  std::vector<std::string> warnings;
  BatchFileOptions file_options;
  file_options.resume = request.resume;
  try {
    summary = RunBatchToFile(
        request.files, {request.options, request.jobs, &g_stop}, request.batch_out, file_options,
        &warnings, terminal ? std::function<void(const BatchProgress&)>(progress) : nullptr);
  } catch (const std::runtime_error& e) {
    for (const std::string& w : warnings) std::cerr << "identify: warning: " << w << "\n";
    std::cerr << (terminal ? "\n" : "") << "identify: error: " << e.what() << "\n";
    return tools::kExitIo;
  }
  if (terminal) std::cerr << "\n";
  for (const std::string& w : warnings) std::cerr << "identify: warning: " << w << "\n";
  if (summary.skipped > 0) {
    std::cerr << "identify: resumed: " << summary.skipped << " of " << summary.total
              << " logs were already in " << request.batch_out << "\n";
  }
  if (summary.interrupted) {
    std::cerr << "identify: stopped by " << (g_signal == SIGINT ? "SIGINT" : "SIGTERM") << ": "
              << summary.ok + summary.failed << " of " << summary.total << " logs in "
              << request.batch_out << ", every line whole; run again with --resume to finish\n";
    return tools::kExitInterruptedBase + g_signal;
  }
  // One line at the end, on a terminal or not: a job array's log shows how each shard went.
  std::cerr << "identify: " << summary.total << " logs, " << summary.ok << " identified, "
            << summary.failed << " failed, " << Printf("%.1f", summary.seconds) << " s; results in "
            << request.batch_out
            << (summary.failed > 0 ? " (the failed logs' lines there say why)" : "") << "\n";
  return summary.failed > 0 ? tools::kExitBadInput : tools::kExitOk;
}

/// --check: every file checked on its own, nothing fitted.
int RunCheckCommand(const cli::IdentifyRequest& request) {
  int unusable = 0;
  for (const FileCheck& f : CheckFiles(request.files, request.options)) {
    for (const std::string& w : f.warnings) std::cerr << "identify: warning: " << w << "\n";
    unusable += !f.Usable();
    if (!f.check) {
      std::cerr << "identify: error: " << f.error << "\n";
      if (request.json) std::cout << FormatCheckErrorJson(f.path, f.error) << "\n";
      continue;
    }
    std::cout << (request.json ? FormatCheckJson(*f.check) + "\n" : FormatCheckText(*f.check));
  }
  if (unusable > 0) {
    std::cerr << "identify: " << unusable << " of " << request.files.size()
              << " logs cannot be read or are expected to identify nothing\n";
  }
  const int flushed = tools::FlushStdout("identify");
  return unusable > 0 ? tools::kExitBadInput : flushed;
}

/// --follow: rows from standard input; a JSON line per update, flushed at once. A reader
/// that goes away (a closed pipe) ends the run quietly, as `head` expects of `yes`.
int RunFollowCommand(const cli::IdentifyRequest& request) {
  std::signal(SIGPIPE, SIG_IGN);  // a closed pipe is a failed write, not a death
  FollowOptions options;
  options.every = request.follow_every;
  options.online.batch_check_first_rows = request.follow_batch_check_rows;
  options.overrides = request.options.read.overrides;
  options.missing_as_gaps = request.options.read.missing_as_gaps;
  options.warn = [](const std::string& w) { std::cerr << "identify: warning: " << w << "\n"; };
  const FollowSummary summary =
      FollowLog(std::cin, "<stdin>", options, [](const std::string& line) {
        std::cout << line << '\n' << std::flush;
        return static_cast<bool>(std::cout);
      });
  if (request.verbose) {
    std::cerr << "identify: note: " << summary.rows << " rows, " << summary.lines << " lines"
              << (summary.dropped_rows > 0
                      ? ", " + std::to_string(summary.dropped_rows) + " dropped (a missing cell)"
                      : std::string())
              << (summary.reader_gone ? ", the reader went away" : "") << "\n";
  }
  return tools::kExitOk;
}

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// --report: the HTML report of this run; false (with a message) when it cannot be written.
bool WriteReport(const cli::IdentifyRequest& request, const FileIdentifyResult& run,
                 const std::string& command_line, double identify_s) {
  const auto t0 = std::chrono::steady_clock::now();
  ReportInputs inputs = GatherIdentifyReport(request.files, request.options, run);
  inputs.command_line = command_line;
  inputs.timings = {{"reading the logs and identifying", identify_s},
                    {"the fit itself", run.result.seconds},
                    {"the report's replays and checks", SecondsSince(t0)}};
  try {
    WriteHtmlReport(inputs, request.report_path);
  } catch (const std::exception& e) {
    std::cerr << "identify: error: " << e.what() << "\n";
    return false;
  }
  return true;
}

std::string Describe(const std::vector<std::string>& files) {
  return files.size() == 1 ? files[0] : std::to_string(files.size()) + " logs";
}

}  // namespace

int main(int argc, char** argv) {
  return tools::RunTool("identify", [&]() -> int {
    po::options_description opts(
        "identify: estimate the friction of a sliding object from push logs.\n"
        "Recovers a = e_t*mu, b = e_o/e_t and c = e_r/e_t [m] (the combinations the motion\n"
        "depends on), says which the logs cannot identify, how sure each estimate is, and\n"
        "whether it is believable. Several logs are pooled: one estimate for all, each log's\n"
        "own, and whether they agree.\n\n"
        "Usage: identify --log FILE.csv [--log FILE2.csv ...] [options]\n"
        "       identify --batch DIR|GLOB --out RESULTS.jsonl [--jobs N] [--shard I/N]\n"
        "                [--resume] [options]\n"
        "       identify --check --log FILE.csv [--log ...] [--json] (fits nothing: what a fit\n"
        "                could identify, and what would help)\n"
        "       logger | identify --follow [--every N] [--mass M ...]"
        "\n\nOptions");
    opts.add_options()("help,h", "print this help and exit")("version",
                                                             "print the version and exit");
    po::options_description advanced("Advanced options");
    cli::AddIdentifyOptions(&opts, &advanced);
    opts.add(advanced);
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, opts), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts << kExitCodes;
      return tools::FlushStdout("identify");
    }
    if (vm.count("version")) {
      std::cout << "identify (slideid) " << SLIDEID_VERSION << "\n";
      return tools::FlushStdout("identify");
    }
    const cli::IdentifyRequest request = cli::ReadIdentifyOptions(vm);
    // Ceres' own lines (estimator/ceres_logging.h) are for --verbose only.
    if (request.verbose) SetCeresLogging(false);
    if (request.batch) return RunBatchCommand(request);
    if (request.check) return RunCheckCommand(request);
    if (request.follow) return RunFollowCommand(request);

    const auto t0 = std::chrono::steady_clock::now();
    const FileIdentifyResult run = IdentifyFiles(request.files, request.options);
    const double identify_s = SecondsSince(t0);
    for (const std::string& w : run.warnings) std::cerr << "identify: warning: " << w << "\n";
    // Written whatever the fit's outcome: the report says it in words.
    if (!request.report_path.empty() &&
        !WriteReport(request, run, QuotedCommandLine(argc, argv), identify_s)) {
      return tools::kExitIo;
    }
    if (request.verbose) {
      for (const std::string& n : run.notes) std::cerr << "identify: note: " << n << "\n";
    }
    const EstimateResult& result = run.result;
    const std::string what = Describe(request.files);
    // Printed whatever the outcome, as the report is: a fit that identifies nothing says why
    // per parameter (and --json keeps its documented keys) before the exit code says so.
    std::cout << (request.json ? FormatJson(result) + "\n"
                               : FormatReport(result, run.truth, request.verbose));
    if (const std::string nothing = NothingIdentified(result); !nothing.empty()) {
      std::cout.flush();
      throw tools::BadInput(what + ": " + nothing);
    }
    if (const std::string failure = NumericalFailure(result); !failure.empty()) {
      std::cerr << "identify: error: " << what << ": " << failure << "; no residuals written\n";
      return tools::kExitNumerical;
    }
    if (const std::string suspects = SuspectSummary(result); !suspects.empty()) {
      std::cerr << "identify: " << (request.strict ? "error" : "warning") << ": " << what << ": "
                << suspects << "\n";
      if (request.strict) return tools::kExitNumerical;
    }
    if (!request.residuals_path.empty()) {
      try {
        WriteResidualsCsv(result, request.residuals_path);
      } catch (const std::exception& e) {
        std::cerr << "identify: error: " << e.what() << "\n";
        return tools::kExitIo;
      }
    }
    return tools::FlushStdout("identify");
  });
}
