// The online identifier (issue 21) against the truth and the batch fit, over the coverage
// suite's conditions (datasets/coverage_conditions.h): per condition, how often its 95%
// intervals hold the truth at 25%, 50%, 75% and 100% of the rows, and how often its final
// estimate lies within the batch trajectory fit's 95% interval of the whole log.
//
//   online_coverage [--logs N] [--conditions base,force-1%,...] [--threads N] [--no-batch]
//   online_coverage --scene-suite FIRST [--logs N] [--threads N] [--no-batch]
//
// With --scene-suite, logs FIRST to FIRST + N - 1 of the randomized scene suite
// (datasets/scene_suite.h: 100 to 1000 Hz, free slides and pushes, 100 to 10,000 rows)
// instead, tallied over all of them and by rate, motion and length.
//
// A plain program (each run is one log); logs are made and run on --threads threads.
// Experiment hooks (environment): SLIDEID_ONLINE_VERBOSE=1 prints each log's end on stderr,
// SLIDEID_ONLINE_TRACE=K every 5th row of log K; SLIDEID_ONLINE_NO_CHANGES=1 turns change
// detection off, SLIDEID_ONLINE_NO_CONFIRM=1 the confirmation of changes; SLIDEID_ONLINE_FORCE and
// SLIDEID_ONLINE_ACC set the process noise (OnlineOptions::force_noise_fraction,
// model_acceleration_mps2); SLIDEID_ONLINE_BATCH_CHECK=N sets OnlineOptions::batch_check_first_rows
// (0: off); SLIDEID_ONLINE_Z=1 prints each log's standardized errors (log(value / truth) over the
// interval's standard error) at the four points, and the rows of the last batch takeover.

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "benchmarks/bench_args.h"
#include "benchmarks/table_tool.h"
#include "datasets/coverage_conditions.h"
#include "datasets/scene_suite.h"
#include "estimator/identify.h"
#include "estimator/online_identifier.h"

namespace slideid {
namespace {

constexpr double kFractions[4] = {0.25, 0.5, 0.75, 1.0};

struct Tally {
  int logs = 0, failed = 0;
  int intervals[4][3] = {}, covered[4][3] = {};
  int batch_intervals[3] = {}, within_batch[3] = {};
  double rel_error_sum[3] = {}, batch_rel_error_sum[3] = {};
  // At the end of the log: estimates marked suspect, and misses (the interval does not hold
  // the truth) that are marked ok: the silently wrong answers.
  int suspect[3] = {}, missed_ok[3] = {};
};

/// A log to run and what it is tallied under.
struct MadeLog {
  Trajectory log;
  std::array<double, 3> truth{};
  std::string name;                 ///< the condition's, or "scene suite"
  std::vector<std::string> groups;  ///< the tallies it counts in
};

MadeLog FromCondition(const CoverageCondition& condition, int index) {
  CoverageLog made = MakeCoverageLog(condition, index);
  return {std::move(made.log), made.truth, condition.name, {condition.name}};
}

/// The groups of the --scene-suite table, in their order.
const std::vector<std::string>& SuiteGroups() {
  static const std::vector<std::string> groups = {
      "all",        "100 Hz",       "200 Hz", "250 Hz",       "500 Hz",       "1000 Hz",
      "free slide", "pushes+rests", "pushes", "100-299 rows", "300-999 rows", "1000+ rows"};
  return groups;
}

MadeLog FromSuite(int index) {
  SuiteLog made = MakeSuiteLog(index);
  const std::size_t rows = made.log.samples.size();
  std::vector<std::string> groups = {"all", std::to_string(static_cast<int>(made.rate_hz)) + " Hz",
                                     ToString(made.motion),
                                     rows < 300    ? "100-299 rows"
                                     : rows < 1000 ? "300-999 rows"
                                                   : "1000+ rows"};
  return {std::move(made.log), made.truth, "scene suite", std::move(groups)};
}

void Count(const MadeLog& made, const std::vector<OnlineResult>& results, const EstimateResult* fit,
           Tally* tally) {
  for (int f = 0; f < 4; ++f) {
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = results[f].parameters[i];
      if (!p.identifiable) continue;
      const bool covered = p.ci95_lo <= made.truth[i] && made.truth[i] <= p.ci95_hi;
      ++tally->intervals[f][i];
      tally->covered[f][i] += covered;
      if (f < 3) continue;
      tally->rel_error_sum[i] += std::abs(p.value / made.truth[i] - 1);
      tally->suspect[i] += p.verdict == Verdict::kSuspect;
      tally->missed_ok[i] += !covered && p.verdict == Verdict::kOk;
    }
  }
  if (!fit) return;
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& b = fit->parameters[i];
    const ParameterEstimate& p = results[3].parameters[i];
    if (!b.identifiable || !p.identifiable) continue;
    ++tally->batch_intervals[i];
    tally->within_batch[i] += b.ci95_lo <= p.value && p.value <= b.ci95_hi;
    tally->batch_rel_error_sum[i] += std::abs(b.value / made.truth[i] - 1);
  }
}

// The experiment hooks' lines (the file's comment), on stderr.
void Trace(const MadeLog& made, int index, int rows, const std::vector<OnlineResult>& results,
           const EstimateResult* fit) {
  if (std::getenv("SLIDEID_ONLINE_Z")) {
    for (int f = 0; f < 4; ++f) {
      std::fprintf(stderr, "Z %s %d %d takeover %d", made.name.c_str(), index, f,
                   results[f].batch_takeover_rows);
      for (int i = 0; i < 3; ++i) {
        const ParameterEstimate& p = results[f].parameters[i];
        const double sd = std::log(p.ci95_hi / p.ci95_lo) / (2 * kZ95);
        std::fprintf(stderr, " %.4f",
                     p.identifiable ? std::log(p.value / made.truth[i]) / sd : NAN);
      }
      std::fprintf(stderr, "\n");
    }
  }
  if (std::getenv("SLIDEID_ONLINE_VERBOSE")) {
    const OnlineResult& r = results[3];
    std::fprintf(stderr, "%s %d rows %d: ", made.name.c_str(), index, rows);
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      std::fprintf(stderr, " %.5g [%.5g %.5g] (truth %.5g; batch %.5g)", p.value, p.ci95_lo,
                   p.ci95_hi, made.truth[i], fit ? fit->parameters[i].value : 0.0);
    }
    std::fprintf(stderr,
                 " failed %d changes %zu withdrawn %d noise %.3g %.3g force %.3g kappa %.3g",
                 r.failed_steps, r.changes.size(), r.withdrawn_changes, r.pose_noise_m,
                 r.angle_noise_rad, r.force_noise_fraction, r.variance_factor);
    for (const FrictionChange& c : r.changes)
      std::fprintf(stderr, " [row %d at %d stat %.1f ratio %.3f %.3f %.3f]", c.row, c.detected_row,
                   c.statistic, c.ratio[0], c.ratio[1], c.ratio[2]);
    std::fprintf(stderr, "\n");
  }
}

// OnlineOptions as the experiment hooks set them (the file's comment).
OnlineOptions HookedOptions() {
  OnlineOptions options;
  options.detect_changes = !std::getenv("SLIDEID_ONLINE_NO_CHANGES");
  options.confirm_changes = !std::getenv("SLIDEID_ONLINE_NO_CONFIRM");
  if (const char* v = std::getenv("SLIDEID_ONLINE_FORCE"))
    options.force_noise_fraction = std::atof(v);
  if (const char* v = std::getenv("SLIDEID_ONLINE_ACC"))
    options.model_acceleration_mps2 = std::atof(v);
  if (const char* v = std::getenv("SLIDEID_ONLINE_BATCH_CHECK"))
    options.batch_check_first_rows = std::atoi(v);
  return options;
}

// SLIDEID_ONLINE_TRACE=K: every 5th row of log K, run again row by row, on stderr.
void TraceRows(const MadeLog& made, int index, const OnlineOptions& options) {
  const char* trace = std::getenv("SLIDEID_ONLINE_TRACE");
  if (!trace || std::atoi(trace) != index) return;
  const std::vector<OnlineResult> all = RunOnline(made.log, options);
  for (size_t u = 0; u < all.size(); u += 5) {
    const OnlineResult& r = all[u];
    const TrajectorySample& row = made.log.samples[u];
    std::fprintf(stderr,
                 "%zu t %.2f f %.3f %.3f | %.4g %.4g %.4g held %.4g %.4g %.4g nis %.3g v %.4f "
                 "%.4f %.4f\n",
                 u, r.t_s, row.applied.fx, row.applied.fy, r.parameters[0].value,
                 r.parameters[1].value, r.parameters[2].value, r.parameters[0].held_at,
                 r.parameters[1].held_at, r.parameters[2].held_at, r.nis, r.state.vx, r.state.vy,
                 r.state.wz);
  }
}

void RunLog(const MadeLog& made, int index, bool batch, std::map<std::string, Tally>* tallies,
            std::mutex* mutex) {
  const std::string& name = made.name;
  const int rows = static_cast<int>(made.log.samples.size());
  std::vector<int> keep;
  for (double f : kFractions) keep.push_back(std::max(0, static_cast<int>(f * rows) - 1));
  std::vector<OnlineResult> results;
  bool failed = false;
  try {
    const OnlineOptions options = HookedOptions();
    results = RunOnline(made.log, options, keep);
    TraceRows(made, index, options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s log %d: %s\n", name.c_str(), index, e.what());
    failed = true;
  }
  EstimateResult fit;
  if (batch && !failed) fit = Identify(made.log, IdentifyOptions{});
  std::lock_guard<std::mutex> lock(*mutex);
  for (const std::string& group : made.groups) {
    Tally* tally = &(*tallies)[group];
    ++tally->logs;
    if (failed) {
      ++tally->failed;
      continue;
    }
    Count(made, results, batch ? &fit : nullptr, tally);
  }
  if (failed) return;
  Trace(made, index, rows, results, batch ? &fit : nullptr);
}

std::string Percent(int k, int n) {
  if (n == 0) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.1f%%", 100.0 * k / n);
  return text;
}

void PrintHeader(const char* first_column) {
  std::printf(
      "| %s | logs | a: 25/50/75/100%% rows | b: 25/50/75/100%% | c: 25/50/75/100%% "
      "| in batch CI a/b/c | mean rel. error online a/b/c | batch a/b/c "
      "| at the end: suspect a/b/c; missed and ok a/b/c |\n",
      first_column);
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
}

void PrintRow(const std::string& name, const Tally& tally) {
  std::printf("| %s | %d%s |", name.c_str(), tally.logs,
              tally.failed ? (" (" + std::to_string(tally.failed) + " failed)").c_str() : "");
  for (int i = 0; i < 3; ++i) {
    for (int f = 0; f < 4; ++f) {
      std::printf("%s%s", f ? " / " : " ",
                  Percent(tally.covered[f][i], tally.intervals[f][i]).c_str());
    }
    std::printf(" |");
  }
  for (int i = 0; i < 3; ++i)
    std::printf("%s%s", i ? " / " : " ",
                Percent(tally.within_batch[i], tally.batch_intervals[i]).c_str());
  std::printf(" |");
  for (int i = 0; i < 3; ++i)
    std::printf("%s%.3f%%", i ? " / " : " ",
                100 * tally.rel_error_sum[i] / std::max(1, tally.intervals[3][i]));
  std::printf(" |");
  for (int i = 0; i < 3; ++i)
    std::printf("%s%.3f%%", i ? " / " : " ",
                100 * tally.batch_rel_error_sum[i] / std::max(1, tally.batch_intervals[i]));
  std::printf(" | %d / %d / %d; %d / %d / %d |\n", tally.suspect[0], tally.suspect[1],
              tally.suspect[2], tally.missed_ok[0], tally.missed_ok[1], tally.missed_ok[2]);
  std::fflush(stdout);
}

// Runs logs 0 to count - 1 of `make` on `threads` threads into `tallies`.
template <typename Make>
void RunAll(int count, int threads, bool batch, const Make& make,
            std::map<std::string, Tally>* tallies) {
  std::mutex mutex;
  std::atomic<int> next{0};
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      for (int k; (k = next++) < count;) RunLog(make(k), k, batch, tallies, &mutex);
    });
  }
  for (std::thread& t : pool) t.join();
}

int Main(int argc, char** argv) {
  int logs = 100, threads = 1, suite_first = -1;
  bool batch = true;
  std::vector<std::string> names;
  bench::Args args(argc, argv);
  while (args.Next()) {
    if (args.Is("--logs")) {
      logs = args.Integer(1);
    } else if (args.Is("--threads")) {
      threads = args.Integer(1);
    } else if (args.Is("--no-batch")) {
      batch = false;
    } else if (args.Is("--scene-suite")) {
      suite_first = args.Integer(0);
    } else if (args.Is("--conditions")) {
      std::stringstream list(args.Value());
      std::string name;
      while (std::getline(list, name, ',')) names.push_back(name);
    } else {
      std::fprintf(stderr,
                   "usage: online_coverage [--logs N] [--conditions A,B | --scene-suite FIRST] "
                   "[--threads N] [--no-batch]\n");
      return 2;
    }
  }
  PrintHeader(suite_first >= 0 ? "scene suite logs" : "condition");
  if (suite_first >= 0) {
    std::map<std::string, Tally> tallies;
    RunAll(
        logs, threads, batch, [&](int k) { return FromSuite(suite_first + k); }, &tallies);
    for (const std::string& group : SuiteGroups()) {
      if (tallies.count(group)) PrintRow(group, tallies[group]);
    }
    for (const auto& [group, tally] : tallies) {  // a rate the list does not name
      const auto& listed = SuiteGroups();
      if (std::find(listed.begin(), listed.end(), group) == listed.end()) PrintRow(group, tally);
    }
    return 0;
  }
  std::vector<CoverageCondition> conditions;
  if (names.empty()) {
    conditions = CoverageConditions();
  } else {
    for (const std::string& n : names) conditions.push_back(FindCoverageCondition(n));
  }
  for (const CoverageCondition& c : conditions) {
    std::map<std::string, Tally> tallies;
    RunAll(
        logs, threads, batch, [&](int k) { return FromCondition(c, k); }, &tallies);
    PrintRow(c.name, tallies[c.name]);
  }
  return 0;
}

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) {
  return slideid::bench::RunTableTool("online_coverage", slideid::Main, argc, argv);
}
