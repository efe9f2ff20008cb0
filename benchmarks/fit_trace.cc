// One default trajectory fit of estimator_benchmark's noisy poses-only log (10,000 steps, or
// the argument's; or the log file named, e.g. scripts/large_logs.sh's 1,000,000 rows), on one
// thread: every solver iteration (stage, iteration, cost, step), the estimates with their
// intervals, and the fit's CPU time. A fit to count instructions in (docs/performance.md:
// valgrind --tool=callgrind --toggle-collect='slideid::Identify*' build/bin/fit_trace) and to
// compare traces and estimates before and after a change.

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "estimator/identify.h"
#include "fixtures/synthetic_scenes.h"
#include "io/push_log.h"

int main(int argc, char** argv) {
  using namespace slideid;
  const std::string arg = argc > 1 ? argv[1] : "10000";
  const bool is_file = arg.find_first_not_of("0123456789") != std::string::npos;
  const Trajectory log =
      is_file ? ReadPushLog(arg) : testing::NoisyLongPushLog(std::atoi(arg.c_str()));
  IdentifyOptions options;
  options.method = EstimatorMethod::kTrajectory;
  options.threads = 1;
  const std::clock_t start = std::clock();
  const EstimateResult r = Identify(log, options);
  const double cpu_s = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
  for (const SolverIteration& it : r.trace) {
    std::printf("%-30s %3d  cost %.10g  step %.3g\n", it.stage.c_str(), it.iteration, it.cost,
                it.step_norm);
  }
  const char* names[3] = {"a", "b", "c"};
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = r.parameters[i];
    std::printf("%s %.10g (minimum %.10g)  s.e. %.6g  95%% [%.10g, %.10g]\n", names[i], p.value,
                p.minimum_value, p.stderr_value, p.ci95_lo, p.ci95_hi);
  }
  std::printf("iterations %d  final cost %.10g  cpu %.4f s  wall %.4f s\n", r.iterations,
              r.final_cost, cpu_s, r.seconds);
  return 0;
}
