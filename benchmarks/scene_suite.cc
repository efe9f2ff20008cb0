// The randomized scene suite (issue 17): --logs logs drawn widely (datasets/scene_suite.h),
// each identified by the default trajectory fit and judged against the fits a user could
// have run instead (fixtures/suite_check.h). Reports, over the logs:
//   - how often the default fit ends in the best basin (goal: 99.5%);
//   - how often no identified parameter is more than 3 standard errors from the truth (99%);
//   - how often a parameter whose interval's half-width is under 1% is within 1.5% (99%);
//   - the intervals' coverage, overall and by kind of log;
//   - the worst logs, with what they are.
// A plain program, not Google Benchmark. `scripts/scene_suite.sh` writes docs/scene-suite.md.
//
// Usage: scene_suite [--logs N] [--first K] [--threads N] [--max-rows N] [--markdown FILE]
//                    [--csv FILE] [--dump DIR]
//                    [--second-start] [--no-cross-check]

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "benchmarks/bench_args.h"
#include "benchmarks/table_tool.h"
#include "fixtures/suite_check.h"
#include "io/push_log.h"
#include "io/simulated_log.h"

namespace slideid {
namespace {

using bench::Fmt;

struct Config {
  int logs = 500;
  int first = 0;
  int threads = 1;
  int max_rows = 10000;
  double noise_scale = 1.0;  ///< SceneSuiteLimits::noise_scale
  std::string markdown_path, csv_path;
  suite::FitChoices choices;  ///< of the default fit
  std::string dump_dir;       ///< writes each log there as suite_NNNN.csv (to look at one)
};

Config Parse(int argc, char** argv) {
  Config c;
  bench::Args args(argc, argv);
  while (args.Next()) {
    if (args.Is("--logs"))
      c.logs = args.Integer(1);
    else if (args.Is("--first"))
      c.first = args.Integer(0);
    else if (args.Is("--threads"))
      c.threads = args.Integer(1);
    else if (args.Is("--max-rows"))
      c.max_rows = args.Integer(100);
    else if (args.Is("--noise-scale"))
      c.noise_scale = std::stod(args.Value());
    else if (args.Is("--markdown"))
      c.markdown_path = args.Value();
    else if (args.Is("--csv"))
      c.csv_path = args.Value();
    else if (args.Is("--dump"))
      c.dump_dir = args.Value();
    else if (args.Is("--second-start"))
      c.choices.second_start = true;
    else if (args.Is("--no-cross-check"))
      c.choices.cross_check = false;
    else
      throw std::invalid_argument("unknown option " + args.option());
  }
  return c;
}

struct Row {
  int index = 0;
  std::string what;
  suite::Outcome o;
  std::string failure;  ///< the log could not be made
};

std::string Percent(int n, int of) {
  return of ? Fmt("%.1f%%", 100.0 * n / of) + " (" + std::to_string(n) + "/" + std::to_string(of) +
                  ")"
            : "-";
}

using suite::Tally;

std::string TallyLine(const std::string& name, const Tally& t) {
  std::ostringstream s;
  s << "| " << name << " | " << t.logs << " | " << t.determined << " | "
    << Percent(t.basin, t.determined) << " | " << Percent(t.within3, t.determined) << " | "
    << Percent(t.suspect, t.determined) << " | " << Percent(t.ok_within3, t.determined) << " | "
    << Percent(t.within3_interval, t.determined) << " | " << Percent(t.narrow_ok, t.narrow);
  for (int i = 0; i < 3; ++i) s << " | " << Percent(t.covered[i], t.intervals[i]);
  s << " |\n";
  return s.str();
}

std::string RowsBucket(const std::string& what) {
  const size_t at = what.find(" rows");
  const int rows = std::atoi(what.substr(what.rfind(';', at) + 2).c_str());
  return rows < 300    ? "100-299 rows"
         : rows < 1000 ? "300-999 rows"
         : rows < 3000 ? "1000-2999 rows"
                       : "3000-10000 rows";
}

/// The i-th ';'-separated field of a description, trimmed.
std::string Field(const std::string& what, int i) {
  size_t start = 0;
  for (int k = 0; k < i; ++k) start = what.find(';', start) + 1;
  std::string f = what.substr(start, what.find(';', start) - start);
  return f.substr(f.find_first_not_of(' '));
}

std::string Report(const Config& c, const std::vector<Row>& rows) {
  std::ostringstream s;
  Tally all;
  std::vector<std::map<std::string, Tally>> groups(4);  // slider, motion, rows, columns
  int failures = 0;
  for (const Row& r : rows) {
    if (!r.failure.empty()) {
      ++failures;
      continue;
    }
    all.Add(r.o);
    groups[0][Field(r.what, 0)].Add(r.o);
    groups[1][Field(r.what, 1)].Add(r.o);
    groups[2][RowsBucket(r.what)].Add(r.o);
    groups[3][Field(r.what, 3)].Add(r.o);
  }
  s << "Logs " << c.first << " to " << c.first + c.logs - 1 << " of the suite (seed "
    << kSceneSuiteSeed << "), up to " << c.max_rows << " rows; " << failures
    << " could not be made. Default fit" << (c.choices.second_start ? " with the second start" : "")
    << (c.choices.cross_check ? "" : " without the cross-check") << ".\n\n";
  s << "| logs | count | identified | best basin | all within 3 SE | some suspect | "
       "ok ones within 3 SE | within 3 interval SE | narrow within 1.5% | a covered | b covered | "
       "c covered |\n"
       "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  s << TallyLine("**all**", all);
  for (const auto& group : groups) {
    for (const auto& [name, tally] : group) s << TallyLine(name, tally);
  }
  // The worst logs: largest error in standard errors.
  std::vector<const Row*> order;
  for (const Row& r : rows) {
    if (r.failure.empty() && r.o.determined) order.push_back(&r);
  }
  std::sort(order.begin(), order.end(),
            [](const Row* x, const Row* y) { return x->o.max_abs_z > y->o.max_abs_z; });
  s << "\nThe worst logs (largest error in standard errors of an identified parameter; "
       "errors relative, '-' not identified; verdicts: o ok, s suspect):\n\n"
       "| log | what | a error | b error | c error | max z | best basin from | in it |\n"
       "|---|---|---|---|---|---|---|---|\n";
  for (size_t k = 0; k < std::min<size_t>(15, order.size()); ++k) {
    const Row& r = *order[k];
    s << "| " << r.index << " | " << r.what;
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.o.fit.parameters[i];
      s << " | "
        << (r.o.identifiable[i]
                ? Fmt("%+.2f%%", 100 * r.o.rel_error[i]) + (p.verdict == Verdict::kOk ? " o" : " s")
                : "-");
    }
    s << " | " << Fmt("%.1f", r.o.max_abs_z) << " | " << r.o.best_from << " | "
      << (r.o.in_best_basin ? "yes" : "no") << " |\n";
  }
  return s.str();
}

int Main(int argc, char** argv) {
  const Config c = Parse(argc, argv);
  std::vector<Row> rows(c.logs);
  std::atomic<int> next{0};
  std::mutex print;
  SceneSuiteLimits limits;
  limits.max_rows = c.max_rows;
  limits.noise_scale = c.noise_scale;
  auto work = [&] {
    for (int k; (k = next++) < c.logs;) {
      Row& row = rows[k];
      row.index = c.first + k;
      try {
        const SuiteLog made = MakeSuiteLog(row.index, kSceneSuiteSeed, limits);
        row.what = made.Describe();
        if (!c.dump_dir.empty()) {
          WritePushLog(SimulatedLogFile(made.scene, made.log),
                       c.dump_dir + "/suite_" + std::to_string(row.index) + ".csv");
        }
        row.o = suite::Judge(made, c.choices);
      } catch (const std::exception& e) {
        row.failure = e.what();
      }
      std::lock_guard<std::mutex> lock(print);
      std::fprintf(
          stderr, "%4d %-60s %s\n", row.index, row.what.c_str(),
          row.failure.empty() ? Fmt("%.2f", row.o.max_abs_z).c_str() : row.failure.c_str());
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < c.threads; ++t) pool.emplace_back(work);
  for (std::thread& t : pool) t.join();
  const std::string report = Report(c, rows);
  std::fputs(report.c_str(), stdout);
  if (!c.markdown_path.empty()) {
    std::ofstream out(c.markdown_path);
    if (!(out << report)) throw std::runtime_error("cannot write " + c.markdown_path);
  }
  if (!c.csv_path.empty()) {
    std::ofstream out(c.csv_path);
    out << "index,what,determined,in_best_basin,best_from,default_cost,best_cost,max_abs_z,"
           "narrow_but_off,err_a,err_b,err_c,z_a,z_b,z_c,cov_a,cov_b,cov_c,seconds,status,"
           "max_abs_z_interval\n";
    for (const Row& r : rows) {
      const suite::Outcome& o = r.o;
      out << r.index << ',' << r.what << ',' << o.determined << ',' << o.in_best_basin << ','
          << o.best_from << ',' << Fmt("%.8g", o.default_cost) << ',' << Fmt("%.8g", o.best_cost)
          << ',' << Fmt("%.3f", o.max_abs_z) << ',' << o.narrow_but_off;
      for (int i = 0; i < 3; ++i)
        out << ',' << (o.identifiable[i] ? Fmt("%.5f", o.rel_error[i]) : "-");
      for (int i = 0; i < 3; ++i) out << ',' << (o.identifiable[i] ? Fmt("%.3f", o.z[i]) : "-");
      for (int i = 0; i < 3; ++i)
        out << ',' << (o.identifiable[i] ? (o.covered[i] ? "1" : "0") : "-");
      out << ',' << Fmt("%.4f", o.seconds) << ','
          << (r.failure.empty() ? ToString(o.fit.status) : "failed") << ','
          << Fmt("%.3f", o.max_abs_z_interval) << '\n';
    }
    if (!out) throw std::runtime_error("cannot write " + c.csv_path);
  }
  return 0;
}

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) {
  return slideid::bench::RunTableTool("scene_suite", slideid::Main, argc, argv);
}
