// How often the pre-fit check (identify --check, estimator/log_check.h) agrees with the full
// fit on which parameters a log identifies, over synthetic logs that identify everything and
// logs that do not (fixtures/check_cases.h), and which verdicts differ. The figure in
// docs/identify.md, "Check before fitting"; tests/log_check_test.cc runs a CI-sized part.
// A plain program, not Google Benchmark.
//
// With --scene-suite N, also the first N logs of the randomized scene suite
// (datasets/scene_suite.h: boxes, disks, rings, tall boxes; free slides and pushes; force and
// push-point noise, outliers), at most --max-rows rows each.
//
// Usage: check_agreement [--logs N] [--first K] [--seed S] [--scene-suite N]
//                        [--max-rows R] [--verbose]

#include "fixtures/check_agreement.h"

#include <cstdio>
#include <stdexcept>
#include <string>

#include "benchmarks/bench_args.h"
#include "datasets/scene_suite.h"
#include "fixtures/check_cases.h"

int main(int argc, char** argv) {
  using namespace slideid;
  int logs = 400, first = 0, suite_logs = 0, max_rows = 1000;
  std::uint64_t seed = 20261125;
  bool verbose = false;
  try {
    bench::Args args(argc, argv);
    while (args.Next()) {
      if (args.Is("--logs")) {
        logs = args.Integer(1);
      } else if (args.Is("--first")) {
        first = args.Integer(0);
      } else if (args.Is("--seed")) {
        seed = static_cast<std::uint64_t>(args.Integer(0));
      } else if (args.Is("--scene-suite")) {
        suite_logs = args.Integer(0);
      } else if (args.Is("--max-rows")) {
        max_rows = args.Integer(100);
      } else if (args.Is("--verbose")) {
        verbose = true;
      } else {
        std::fprintf(stderr,
                     "usage: check_agreement [--logs N] [--first K] [--seed S] [--scene-suite N] "
                     "[--max-rows R] [--verbose]\n");
        return 2;
      }
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "check_agreement: %s\n", e.what());
    return 2;
  }
  testing::AgreementTally tally;
  for (int k = first; k < first + logs; ++k) {
    const testing::CheckCase c = testing::MakeCheckCase(k, seed);
    const testing::CheckComparison r = testing::CompareCheckWithFit(c.log, IdentifyOptions{});
    tally.Add(r, "case " + std::to_string(k) + " (" + c.description + ")");
    if (verbose) {
      std::printf("case %d: check %d%d%d fit %d%d%d  %s\n", k, r.check[0], r.check[1], r.check[2],
                  r.fit[0], r.fit[1], r.fit[2], c.description.c_str());
    }
  }
  std::printf(
      "%d logs (cases %d-%d, seed %llu): %d of %d verdicts agree (%.1f%%); %d of %d logs "
      "agree on all three\n",
      tally.logs, first, first + logs - 1, static_cast<unsigned long long>(seed), tally.agreed,
      tally.verdicts, 100 * tally.Share(), tally.logs_agreed, tally.logs);
  testing::AgreementTally suite;
  for (int k = 0; k < suite_logs; ++k) {
    const SuiteLog s = MakeSuiteLog(k, kSceneSuiteSeed, {100, max_rows});
    const testing::CheckComparison r = testing::CompareCheckWithFit(s.log, IdentifyOptions{});
    suite.Add(r, "suite log " + std::to_string(k) + " (" + s.Describe() + ")");
    tally.Add(r, "suite log " + std::to_string(k) + " (" + s.Describe() + ")");
  }
  if (suite_logs > 0) {
    std::printf(
        "scene suite, %d logs of at most %d rows: %d of %d verdicts agree (%.1f%%); all "
        "three on %d\n",
        suite.logs, max_rows, suite.agreed, suite.verdicts, 100 * suite.Share(), suite.logs_agreed);
    std::printf("together: %d of %d verdicts agree (%.1f%%)\n", tally.agreed, tally.verdicts,
                100 * tally.Share());
  }
  for (int i = 0; i < 3; ++i) {
    std::printf(
        "  %-13s fit identifies in %d logs (check says no in %d), not in %d (check says "
        "yes in %d)\n",
        ParameterName(i), tally.fit_yes[i], tally.check_no_fit_yes[i], tally.fit_no[i],
        tally.check_yes_fit_no[i]);
  }
  std::printf("disagreements:\n");
  for (const std::string& d : tally.disagreements) std::printf("  %s\n", d.c_str());
  return 0;
}
