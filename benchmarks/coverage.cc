// Calibration of the 95% intervals (issue 11): a Monte Carlo coverage suite over the
// conditions users' logs meet, identified with every method that reads push logs.
//
// A condition is a way of making logs with the datasets library (DrawDatasetLog: sliders,
// friction and push programs drawn from the dataset defaults, simulated and logged by
// MakeLog): how fine the simulation is against the log rate, how many rows, which motion
// columns, and which noise. Every condition makes --logs logs from fixed seeds (the same
// sliders, friction and programs for conditions of the same length), and each log is
// identified by the closed form, the equation error and the trajectory fit at their
// defaults. Per condition, method and parameter the suite reports how often the 95%
// interval holds the truth (coverage), the median signed relative error (bias), the median
// absolute relative error, the median relative standard error, how often the parameter was
// identifiable and how often suspect, and the median run time.
//
// A plain program, not Google Benchmark: each run is one Identify call on a different log.
// Logs are made and identified on --threads worker threads, each fit on one thread.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "benchmarks/bench_args.h"
#include "benchmarks/table_tool.h"
#include "datasets/coverage_conditions.h"
#include "estimator/identify.h"

namespace slideid {
namespace {

// The coverage band a method's 95% interval must fall in (issue 11).
constexpr double kBandLo = 0.90, kBandHi = 0.98;

struct Method {
  std::string name;
  IdentifyOptions options;
};

/// Every method at its defaults, except what `trajectory` (segment steps and substeps of
/// the trajectory fit, for experiments) overrides.
std::vector<Method> AllMethods(const TrajectoryOptions& trajectory) {
  std::vector<Method> m;
  for (EstimatorMethod e : {EstimatorMethod::kClosedForm, EstimatorMethod::kEquationError,
                            EstimatorMethod::kTrajectory}) {
    IdentifyOptions o;
    o.method = e;
    o.threads = 1;
    o.trajectory = trajectory;
    m.push_back({ToString(e), o});
  }
  return m;
}

/// One Identify call.
struct Run {
  int condition = 0, index = 0, method = 0;
  bool failed = false;  ///< threw, or too little excitation
  std::string status;
  ParameterEstimate p[3];
  double truth[3] = {0, 0, 0};
  double wall_s = 0;
};

Run IdentifyTimed(const CoverageLog& made, const Method& method) {
  Run run;
  for (int i = 0; i < 3; ++i) run.truth[i] = made.truth[i];
  const auto t0 = std::chrono::steady_clock::now();
  try {
    const EstimateResult r = Identify(made.log, method.options);
    run.failed = r.status == TerminationStatus::kTooLittleExcitation;
    run.status = ToString(r.status);
    if (run.failed) run.status += ": " + r.message;
    for (int i = 0; i < 3; ++i) run.p[i] = r.parameters[i];
  } catch (const std::exception& e) {
    run.failed = true;
    run.status = std::string("threw: ") + e.what();
  }
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool HasInterval(const ParameterEstimate& p) {
  return p.identifiable && std::isfinite(p.ci95_lo) && std::isfinite(p.ci95_hi) &&
         std::isfinite(p.value);
}

/// Per condition x method x parameter.
struct Cell {
  int logs = 0, failed = 0, identifiable = 0, suspect = 0, intervals = 0, covered = 0;
  std::vector<double> signed_error, abs_error, rel_stderr, wall_s;

  void Add(const Run& run, int i) {
    ++logs;
    wall_s.push_back(run.wall_s);
    if (run.failed) {
      ++failed;
      return;
    }
    const ParameterEstimate& p = run.p[i];
    if (!p.identifiable) return;
    ++identifiable;
    suspect += p.verdict == Verdict::kSuspect;
    const double e = p.value / run.truth[i] - 1.0;
    signed_error.push_back(e);
    abs_error.push_back(std::abs(e));
    if (std::isfinite(p.stderr_value)) rel_stderr.push_back(p.stderr_value / p.value);
    if (HasInterval(p)) {
      ++intervals;
      covered += p.ci95_lo <= run.truth[i] && run.truth[i] <= p.ci95_hi;
    }
  }
  double Coverage() const { return intervals ? double(covered) / intervals : NAN; }
  /// The Wilson 95% interval of the coverage itself: what this many logs can tell. At 200
  /// logs a 95% interval's measured coverage spreads over about 92-98%, so one cell of 33 at
  /// the band's edge says little; the page is drawn from enough logs to tell.
  std::pair<double, double> CoverageInterval() const {
    if (!intervals) return {NAN, NAN};
    constexpr double z = 1.959963984540054;
    const double n = intervals, p = Coverage();
    const double centre = (p + z * z / (2 * n)) / (1 + z * z / n);
    const double half = z / (1 + z * z / n) * std::sqrt(p * (1 - p) / n + z * z / (4 * n * n));
    return {centre - half, centre + half};
  }
  bool InBand() const {
    const double c = Coverage();
    return c >= kBandLo && c <= kBandHi;
  }
};

using bench::Fmt;

std::string Percent(double fraction) {
  if (!std::isfinite(fraction)) return "-";
  const double p = 100 * fraction;
  const double a = std::abs(p);
  return Fmt(a >= 10 || a == 0 ? "%.0f%%" : a >= 1 ? "%.1f%%" : a >= 0.1 ? "%.2f%%" : "%.3f%%", p);
}

/// Coverage with one decimal: 98.5% is outside the band and must not print as 98%.
std::string CoveragePercent(double fraction) {
  return std::isfinite(fraction) ? Fmt("%.1f%%", 100 * fraction) : "-";
}

/// Half the width of the Wilson 95% interval of a measured coverage of 95% over `logs`.
double SamplingHalfWidth(int logs) {
  Cell cell;
  cell.intervals = logs;
  cell.covered = int(std::lround(0.95 * logs));
  const auto [lo, hi] = cell.CoverageInterval();
  return (hi - lo) / 2;
}

std::string Seconds(double s) {
  if (!std::isfinite(s)) return "-";
  return s >= 1 ? Fmt("%.2f s", s) : s >= 1e-3 ? Fmt("%.1f ms", s * 1e3) : Fmt("%.0f us", s * 1e6);
}

struct Config {
  int logs = 200;
  int threads = 1;
  bool quick = false;
  std::vector<std::string> only_conditions;
  std::vector<std::string> only_methods;
  std::string csv_path;  ///< none unless asked: a benchmark does not litter its directory
  std::string markdown_path;
  std::string runs_path;
  TrajectoryOptions trajectory;
};

template <typename T>
std::vector<T> Select(const std::vector<T>& all, const std::vector<std::string>& names,
                      const char* what) {
  if (names.empty()) return all;
  std::vector<T> out;
  for (const std::string& n : names) {
    auto it = std::find_if(all.begin(), all.end(), [&](const T& x) { return x.name == n; });
    if (it == all.end()) throw std::invalid_argument(std::string("unknown ") + what + " " + n);
    out.push_back(*it);
  }
  return out;
}

using CellKey = std::tuple<int, int, int>;  // condition, method, parameter

void WriteCsv(const std::string& path, const std::map<CellKey, Cell>& cells,
              const std::vector<CoverageCondition>& conditions,
              const std::vector<Method>& methods) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "condition,method,parameter,logs,failed,identifiable,suspect,intervals,covered,"
         "coverage,coverage_ci95_lo,coverage_ci95_hi,in_band,bias_median_rel,median_abs_rel_error,"
         "median_rel_stderr,"
         "median_wall_s\n";
  for (const auto& [key, cell] : cells) {
    const auto [c, m, i] = key;
    out << conditions[c].name << ',' << methods[m].name << ',' << ParameterName(i) << ','
        << cell.logs << ',' << cell.failed << ',' << cell.identifiable << ',' << cell.suspect << ','
        << cell.intervals << ',' << cell.covered << ',' << Fmt("%.4f", cell.Coverage()) << ','
        << Fmt("%.4f", cell.CoverageInterval().first) << ','
        << Fmt("%.4f", cell.CoverageInterval().second) << ','
        << (cell.intervals ? (cell.InBand() ? "yes" : "no") : "-") << ','
        << Fmt("%.6g", Median(cell.signed_error)) << ',' << Fmt("%.6g", Median(cell.abs_error))
        << ',' << Fmt("%.6g", Median(cell.rel_stderr)) << ',' << Fmt("%.6g", Median(cell.wall_s))
        << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

void WriteMarkdown(const std::string& path, const std::map<CellKey, Cell>& cells,
                   const std::vector<CoverageCondition>& conditions,
                   const std::vector<Method>& methods, const Config& config) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "### Conditions\n\n"
      << "Every log: a slider, friction and push program drawn by `DrawDatasetLog` (dataset "
         "defaults, seed "
      << kCoverageSeed << "), logged at 100 Hz with push points; " << config.logs
      << " logs per condition.\n\n| condition | logs |\n|---|---|\n";
  for (const CoverageCondition& c : conditions) out << "| " << c.name << " | " << c.what << " |\n";
  for (size_t m = 0; m < methods.size(); ++m) {
    out << "\n### " << methods[m].name << "\n\n"
        << "Per parameter a / b / c. Coverage: share of the reported 95% intervals that hold "
           "the truth (in bold when outside 90-98%; a cell of "
        << config.logs << " logs measures a true 95% to within "
        << Fmt("%.1f", 100 * SamplingHalfWidth(config.logs))
        << " points, Wilson 95%); bias: median of estimate / truth - 1; "
           "error: median |estimate / truth - 1|; rel. s.e.: median standard error / "
           "estimate; identifiable and suspect: share of the logs; time: median per log, one "
           "thread.\n\n"
        << "| condition | coverage | bias | error | rel. s.e. | identifiable | suspect | "
           "failed | time |\n|---|---|---|---|---|---|---|---:|---:|\n";
    for (size_t c = 0; c < conditions.size(); ++c) {
      auto cell = [&](int i) -> const Cell& { return cells.at({int(c), int(m), i}); };
      auto three = [&](auto f) {
        std::string s;
        for (int i = 0; i < 3; ++i) s += (i ? " / " : "") + f(cell(i));
        return s;
      };
      out << "| " << conditions[c].name << " | " << three([](const Cell& x) {
        const std::string s = CoveragePercent(x.Coverage());
        return x.intervals && !x.InBand() ? "**" + s + "**" : s;
      }) << " | "
          << three([](const Cell& x) { return Percent(Median(x.signed_error)); }) << " | "
          << three([](const Cell& x) { return Percent(Median(x.abs_error)); }) << " | "
          << three([](const Cell& x) { return Percent(Median(x.rel_stderr)); }) << " | "
          << three([](const Cell& x) { return Percent(double(x.identifiable) / x.logs); }) << " | "
          << three([](const Cell& x) { return Percent(double(x.suspect) / x.logs); }) << " | "
          << cell(0).failed << " | " << Seconds(Median(cell(0).wall_s)) << " |\n";
    }
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

void Usage(const char* argv0) {
  std::printf(
      "usage: %s [--quick] [--logs N] [--threads N] [--conditions A,B] [--methods A,B]\n"
      "          [--csv FILE] [--markdown FILE] [--runs FILE] [--segment N] [--substeps N]\n"
      "          [--fit-delay] [--no-mismatch] [--mean-wrench] [--log-every K]\n"
      "Coverage of the 95%% intervals of every method over synthetic logs of known friction.\n"
      "  --logs N          logs per condition (default 200; quick 30)\n"
      "  --quick           30 logs per condition\n"
      "  --threads N       worker threads, each fitting one log on one thread (default 1)\n"
      "  --conditions A,B  only these conditions (default all; --list shows them)\n"
      "  --methods A,B     only these methods (closed-form, equation-error, trajectory)\n"
      "  --csv FILE        one row per condition, method and parameter (default: none)\n"
      "  --markdown FILE   the tables in Markdown\n"
      "  --runs FILE       one row per log, method and parameter\n"
      "  --segment N       the trajectory fit's segment steps (default: adaptive)\n"
      "  --substeps N      the trajectory fit's substeps (default 1)\n"
      "  --fit-delay       the trajectory fit fits a delay of the force stream\n"
      "  --no-mismatch     the trajectory fit does not correct for model mismatch\n"
      "  --mean-wrench     every condition logs the mean wrench over each interval\n"
      "  --log-every K     every condition simulates K steps per log interval\n"
      "  --list            print the conditions and stop\n",
      argv0);
}

int Main(int argc, char** argv) {
  Config config;
  bool logs_given = false, list = false, mean_wrench = false;
  int log_every = 0;
  bench::Args args(argc, argv);
  while (args.Next()) {
    if (args.Is("--quick"))
      config.quick = true;
    else if (args.Is("--logs"))
      config.logs = args.Integer(), logs_given = true;
    else if (args.Is("--threads"))
      config.threads = args.Integer();
    else if (args.Is("--conditions"))
      config.only_conditions = args.List();
    else if (args.Is("--methods"))
      config.only_methods = args.List();
    else if (args.Is("--csv"))
      config.csv_path = args.Value();
    else if (args.Is("--markdown"))
      config.markdown_path = args.Value();
    else if (args.Is("--runs"))
      config.runs_path = args.Value();
    else if (args.Is("--list"))
      list = true;
    else if (args.Is("--segment"))
      config.trajectory.segment_steps = args.Integer();
    else if (args.Is("--substeps"))
      config.trajectory.substeps = args.Integer();
    else if (args.Is("--mean-wrench"))
      mean_wrench = true;
    else if (args.Is("--no-mismatch"))
      config.trajectory.correct_mismatch = false;
    else if (args.Is("--log-every"))
      log_every = args.Integer();
    else if (args.Is("--fit-delay"))
      config.trajectory.fit_delay = DelayFit::kPerLog;
    else if (args.Is("--help") || args.Is("-h")) {
      Usage(argv[0]);
      return 0;
    } else {
      std::fprintf(stderr, "coverage: unknown option %s\n", args.option().c_str());
      Usage(argv[0]);
      return 2;
    }
  }
  if (config.quick && !logs_given) config.logs = 30;
  if (config.logs < 1 || config.threads < 1) {
    std::fprintf(stderr, "coverage: --logs and --threads must be >= 1\n");
    return 2;
  }
  std::vector<CoverageCondition> conditions =
      Select(CoverageConditions(), config.only_conditions, "condition");
  for (CoverageCondition& c : conditions) {
    c.mean_wrench = c.mean_wrench || mean_wrench;
    if (log_every > 0) c.log_every = log_every;
  }
  std::string why;
  if (!config.trajectory.IsValid(&why)) {
    std::fprintf(stderr, "coverage: %s\n", why.c_str());
    return 2;
  }
  const std::vector<Method> methods =
      Select(AllMethods(config.trajectory), config.only_methods, "method");
  if (list) {
    for (const CoverageCondition& c : conditions)
      std::printf("%-18s %s\n", c.name.c_str(), c.what.c_str());
    return 0;
  }

  const auto t_start = std::chrono::steady_clock::now();
  const int jobs = static_cast<int>(conditions.size()) * config.logs;
  std::vector<std::vector<Run>> runs(jobs);
  std::atomic<int> next{0};
  std::mutex error_mutex;
  std::string error;
  auto worker = [&] {
    for (int j = next++; j < jobs; j = next++) {
      const int c = j / config.logs, index = j % config.logs;
      try {
        const CoverageLog made = MakeCoverageLog(conditions[c], index);
        for (size_t m = 0; m < methods.size(); ++m) {
          Run run = IdentifyTimed(made, methods[m]);
          run.condition = c;
          run.index = index;
          run.method = static_cast<int>(m);
          runs[j].push_back(run);
        }
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (error.empty()) error = e.what();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < config.threads; ++t) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  if (!error.empty()) throw std::runtime_error(error);

  std::map<CellKey, Cell> cells;
  for (const std::vector<Run>& job : runs) {
    for (const Run& run : job) {
      for (int i = 0; i < 3; ++i) cells[{run.condition, run.method, i}].Add(run, i);
    }
  }
  if (!config.csv_path.empty()) WriteCsv(config.csv_path, cells, conditions, methods);
  if (!config.markdown_path.empty())
    WriteMarkdown(config.markdown_path, cells, conditions, methods, config);
  if (!config.runs_path.empty()) {
    std::ofstream out(config.runs_path);
    if (!out) throw std::runtime_error("cannot write " + config.runs_path);
    out << "condition,index,method,parameter,truth,identifiable,verdict,value,stderr,ci95_lo,"
           "ci95_hi,covered,wall_s,status,reason,note\n";
    for (const std::vector<Run>& job : runs) {
      for (const Run& run : job) {
        for (int i = 0; i < 3; ++i) {
          const ParameterEstimate& p = run.p[i];
          std::string status = run.status.substr(0, 120), note = p.note, reason = p.reason;
          for (std::string* s : {&status, &note, &reason}) {
            std::replace(s->begin(), s->end(), ',', ';');
            std::replace(s->begin(), s->end(), '\n', ' ');
          }
          out << conditions[run.condition].name << ',' << run.index << ','
              << methods[run.method].name << ',' << ParameterName(i) << ','
              << Fmt("%.9g", run.truth[i]) << ',' << p.identifiable << ',' << ToString(p.verdict)
              << ',' << Fmt("%.9g", p.value) << ',' << Fmt("%.6g", p.stderr_value) << ','
              << Fmt("%.9g", p.ci95_lo) << ',' << Fmt("%.9g", p.ci95_hi) << ','
              << (HasInterval(p) && p.ci95_lo <= run.truth[i] && run.truth[i] <= p.ci95_hi) << ','
              << Fmt("%.6g", run.wall_s) << ',' << status << ',' << reason << ',' << note << '\n';
        }
      }
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  // The summary: how many cells of each method lie in the band.
  std::printf("coverage: %zu conditions x %d logs, %zu methods, %d threads; %.0f s%s%s\n",
              conditions.size(), config.logs, methods.size(), config.threads, seconds,
              config.csv_path.empty() ? "" : "; wrote ", config.csv_path.c_str());
  for (size_t m = 0; m < methods.size(); ++m) {
    int in = 0, with = 0;
    double lowest = 1, highest = 0;
    std::string outside;
    for (size_t c = 0; c < conditions.size(); ++c) {
      for (int i = 0; i < 3; ++i) {
        const Cell& cell = cells.at({int(c), int(m), i});
        if (!cell.intervals) continue;
        ++with;
        in += cell.InBand();
        lowest = std::min(lowest, cell.Coverage());
        highest = std::max(highest, cell.Coverage());
        if (!cell.InBand()) {
          outside += " " + conditions[c].name + ":" + ParameterName(i) + "=" +
                     CoveragePercent(cell.Coverage());
        }
      }
    }
    const std::string range =
        with ? " (" + CoveragePercent(lowest) + " to " + CoveragePercent(highest) + ")" : "";
    std::printf("coverage: %-15s %d of %d cells in 90-98%%%s%s%s\n", methods[m].name.c_str(), in,
                with, range.c_str(), outside.empty() ? "" : "; outside:", outside.c_str());
  }
  return 0;
}

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) {
  return slideid::bench::RunTableTool("coverage", slideid::Main, argc, argv);
}
