// What prediction costs, as ratios against a baseline measured in the same run:
//  - one pusher-driven step (SolvePusherStep: the tip's contact solved around the support's
//    step) against one force-driven step (SolveStep) from the same states;
//  - leave-one-out cross-validation (validate, folds only) over N synthetic pushes against
//    one pooled fit of the same pushes.
// Each benchmark is Google Benchmark's; main() prints the ratios of their median times at
// the end. Usage: prediction_benchmark [--pushes N | --logs DIR] [google benchmark flags]
// (--logs: the logs of a directory, e.g. the imported rect1 pushes, instead of N synthetic).

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "benchmarks/bench_args.h"
#include "estimator/identify.h"
#include "fixtures/pushed_square.h"
#include "forward_model/pusher_step.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"
#include "pipeline/identify_files.h"
#include "prediction/validate.h"

namespace slideid {
namespace {

int pushes = 8;              // --pushes
std::string logs_directory;  // --logs: real logs instead of the synthetic pushes

Scene PushScene(int k) { return testing::PushedSquareScene(testing::PushOfSet(k)); }

std::vector<Trajectory> Logs(int n) {
  std::vector<Trajectory> logs;
  if (!logs_directory.empty()) {
    for (const std::string& path : ExpandFiles(logs_directory)) logs.push_back(ReadPushLog(path));
    return logs;
  }
  for (int k = 0; k < n; ++k) {
    logs.push_back(testing::NoisyPushLog(PushScene(k), 100 + k));
    logs.back().source = "push" + std::to_string(k);
  }
  return logs;
}

/// The states and tip moves of a simulated push, one per 1 ms step while the tip touches.
struct StepCase {
  PlanarState state;
  Eigen::Vector2d tip_start, tip_end;
  AppliedWrench applied;  ///< the tip's force over the step, for the force-driven step
};

std::vector<StepCase> StepCases() {
  std::vector<StepCase> cases;
  for (int k = 0; k < 6; ++k) {
    const Scene scene = PushScene(k);
    const SimulationResult r = Simulate(scene);
    for (size_t u = 0; u + 1 < r.trajectory.samples.size(); ++u) {
      const TrajectorySample& s = r.trajectory.samples[u];
      if (s.applied.IsZero()) continue;
      cases.push_back({s.state, *s.tip_world, *r.trajectory.samples[u + 1].tip_world, s.applied});
    }
  }
  return cases;
}

void BM_ForceDrivenStep(benchmark::State& state) {
  static const std::vector<StepCase> cases = StepCases();
  const Scene scene = PushScene(0);
  const ReducedFriction f = scene.friction.reduced();
  size_t i = 0;
  for (auto _ : state) {
    const StepCase& c = cases[i++ % cases.size()];
    benchmark::DoNotOptimize(SolveStep(scene.slider, f, c.state, c.applied, scene.dt_s));
  }
}
BENCHMARK(BM_ForceDrivenStep);

void BM_PusherDrivenStep(benchmark::State& state) {
  static const std::vector<StepCase> cases = StepCases();
  const Scene scene = PushScene(0);
  const ReducedFriction f = scene.friction.reduced();
  size_t i = 0;
  for (auto _ : state) {
    const StepCase& c = cases[i++ % cases.size()];
    benchmark::DoNotOptimize(SolvePusherStep(scene.slider, f, scene.patch, *scene.pusher, c.state,
                                             c.tip_start, c.tip_end, AppliedWrench{}, scene.dt_s));
  }
}
BENCHMARK(BM_PusherDrivenStep);

void BM_PooledFit(benchmark::State& state) {
  static const std::vector<Trajectory> logs = Logs(pushes);
  for (auto _ : state) benchmark::DoNotOptimize(Identify(logs, IdentifyOptions{}));
}
BENCHMARK(BM_PooledFit)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_ValidateLeaveOneOut(benchmark::State& state) {
  static const std::vector<Trajectory> logs = Logs(pushes);
  ValidationOptions options;
  options.own_fit = options.textbook = false;
  for (auto _ : state) benchmark::DoNotOptimize(Validate(logs, options));
}
BENCHMARK(BM_ValidateLeaveOneOut)->Unit(benchmark::kMillisecond)->Iterations(1);

/// Keeps each benchmark's real time per iteration, to print the ratios at the end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  std::map<std::string, double> seconds;
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      seconds[run.benchmark_name()] =
          run.GetAdjustedRealTime() / benchmark::GetTimeUnitMultiplier(run.time_unit);
    }
    ConsoleReporter::ReportRuns(runs);
  }
};

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) {
  // Our options out; the program name and everything else are Google Benchmark's.
  std::vector<char*> benchmark_args = {argv[0]};
  try {
    slideid::bench::Args args(argc, argv);
    while (args.Next()) {
      if (args.Is("--pushes"))
        slideid::pushes = std::max(2, args.Integer());
      else if (args.Is("--logs"))
        slideid::logs_directory = args.Value();
      else
        benchmark_args.push_back(args.arg());
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "prediction_benchmark: %s\n", e.what());
    return 2;
  }
  int n = static_cast<int>(benchmark_args.size());
  benchmark::Initialize(&n, benchmark_args.data());
  slideid::RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const auto& s = reporter.seconds;
  auto ratio = [&](const char* a, const char* b) {
    const auto x = s.find(a), y = s.find(b);
    if (x == s.end() || y == s.end() || !(y->second > 0)) return;
    std::printf("ratio %s / %s = %.2f\n", a, b, x->second / y->second);
  };
  ratio("BM_PusherDrivenStep", "BM_ForceDrivenStep");
  std::printf("(leave-one-out over %s, folds only, one thread)\n",
              slideid::logs_directory.empty()
                  ? (std::to_string(slideid::pushes) + " synthetic pushes").c_str()
                  : slideid::logs_directory.c_str());
  ratio("BM_ValidateLeaveOneOut/iterations:1", "BM_PooledFit/iterations:3");
  benchmark::Shutdown();
  return 0;
}
