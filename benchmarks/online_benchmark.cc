// Cost of the online identifier (issue 21: at most 100 us per row amortised, on one thread)
// on the 100 Hz benchmark log of estimator_benchmark (10,000 rows of noisy motion-capture
// poses), against the batch trajectory fit of the same rows measured in the same run.
// Counters: us_per_row (amortised over the log, wall time; cpu_us_per_row the thread's
// CPU time), worst_update_us (the slowest single Update, wall; worst_update_cpu_us in CPU
// time, which a loaded machine's scheduler does not inflate), batch_s (the trajectory fit of all
// rows, one thread), ratio (the online identifier's whole run over the batch fit), and each one's
// relative error in a, b, c. The argument `check` is the batch check
// (OnlineOptions::batch_check_first_rows): 0 in each update that is due (the default), 1 on a
// thread of its own (batch_check_thread: the counters then are the updating thread's), 2 none.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>

#include "datasets/noise.h"
#include "estimator/identify.h"
#include "estimator/online_identifier.h"
#include "fixtures/synthetic_scenes.h"
#include "forward_model/simulator.h"

namespace slideid {
namespace {

constexpr int kSteps = 10000;

// The log of estimator_benchmark: the same scene, noise and seed.
const Trajectory& NoisyLog() {
  static const Trajectory log = testing::NoisyLongPushLog(kSteps);
  return log;
}

double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// This thread's CPU time [s]: a single update's cost without the time the scheduler gave
// other processes (wall time on a shared machine counts those).
double ThreadCpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

void BM_OnlineAgainstBatch(benchmark::State& state) {
  const Trajectory& log = NoisyLog();
  const ReducedFriction truth = testing::LongPushScene(kSteps).friction.reduced();
  const double truths[3] = {truth.a, truth.b, truth.c};
  double online_s = 0, worst_s = 0, worst_cpu_s = 0, online_cpu_s = 0, batch_s = 0;
  OnlineResult last;
  EstimateResult batch;
  OnlineOptions options;
  options.batch_check_thread = state.range(0) == 1;
  if (state.range(0) == 2) options.batch_check_first_rows = 0;
  for (auto _ : state) {
    OnlineIdentifier id(log, options);
    worst_s = worst_cpu_s = 0;
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = ThreadCpuSeconds();
    for (const TrajectorySample& row : log.samples) {
      const auto r0 = std::chrono::steady_clock::now();
      const double rc0 = ThreadCpuSeconds();
      id.Update(row);
      worst_cpu_s = std::max(worst_cpu_s, ThreadCpuSeconds() - rc0);
      worst_s = std::max(worst_s, Seconds(std::chrono::steady_clock::now() - r0));
    }
    online_s = Seconds(std::chrono::steady_clock::now() - t0);
    online_cpu_s = ThreadCpuSeconds() - c0;
    last = id.WaitForBatchCheck();
    const auto b0 = std::chrono::steady_clock::now();
    batch = Identify(log, IdentifyOptions{});
    batch_s = Seconds(std::chrono::steady_clock::now() - b0);
  }
  const double rows = static_cast<double>(log.samples.size());
  state.counters["rows"] = rows;
  state.counters["us_per_row"] = 1e6 * online_s / rows;
  state.counters["worst_update_us"] = 1e6 * worst_s;
  state.counters["cpu_us_per_row"] = 1e6 * online_cpu_s / rows;
  state.counters["worst_update_cpu_us"] = 1e6 * worst_cpu_s;
  state.counters["online_s"] = online_s;
  state.counters["batch_s"] = batch_s;
  state.counters["ratio"] = online_s / batch_s;
  state.counters["batch_checks"] = last.batch_checks;
  state.counters["batch_takeovers"] = last.batch_takeovers;
  const char* names[3] = {"err_a", "err_b", "err_c"};
  const char* batch_names[3] = {"batch_err_a", "batch_err_b", "batch_err_c"};
  for (int i = 0; i < 3; ++i) {
    state.counters[names[i]] = std::abs(last.parameters[i].value / truths[i] - 1);
    state.counters[batch_names[i]] = std::abs(batch.parameters[i].value / truths[i] - 1);
  }
}

BENCHMARK(BM_OnlineAgainstBatch)
    ->ArgName("check")
    ->DenseRange(0, 2)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->Repetitions(3);

}  // namespace
}  // namespace slideid

BENCHMARK_MAIN();
