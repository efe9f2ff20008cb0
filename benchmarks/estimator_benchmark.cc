// Run time of each estimator on a 10,000-step noisy poses-only log (targets: closed form
// under 10 ms; trajectory fit at most 0.2 s on one thread, at most 30 passes with
// derivatives, and 1.6x faster on two threads). Prints each method's relative errors against
// the truth beside its time, and for the trajectory fit the time of one forward pass with
// derivatives (pass_ms), one without (residual_pass_ms) and the fit in units of the first
// (fit_in_passes), all measured in the same run.
// Also a pooled fit of 50 short logs against the sum of their single fits, measured in the
// same run (issue 10: within 2x).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/noise.h"
#include "estimator/identify.h"
#include "estimator/internal/segment_cost.h"
#include "estimator/internal/trajectory_problem.h"
#include "estimator/trajectory_fit.h"
#include "fixtures/synthetic_scenes.h"
#include "forward_model/simulator.h"

namespace slideid {
namespace {

constexpr int kSteps = 10000;

const Trajectory& NoisyLog() {
  static const Trajectory log = testing::NoisyLongPushLog(kSteps);
  return log;
}

// One pass over the log with derivatives, as a Gauss-Newton iteration makes it: every
// shooting segment the fit would cut, simulated with exact sensitivities [s] (median of 5,
// after a first pass that warm-starts every step's Newton, as the fit's own passes are).
double ForwardPassSeconds(const Trajectory& log, bool with_derivatives) {
  const int rows = static_cast<int>(log.samples.size());
  const int steps = TrajectorySegmentSteps(rows, MedianInterval(log), TrajectoryOptions{});
  const ReducedFriction abc = testing::LongPushScene(kSteps).friction.reduced();
  double log_abc[3] = {std::log(abc.a), std::log(abc.b), std::log(abc.c)};
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  std::vector<std::array<double, 6>> states;
  for (int first = 0; first + steps < rows; first += steps + 1) {
    costs.emplace_back(NewSegmentCost(log, first, first + steps, 1, log.measured.pose));
    const PlanarState& s = log.samples[first].state;
    states.push_back({s.x, s.y, s.theta, s.vx, s.vy, s.wz});
  }
  const int n = 3 * (steps + 1);
  std::vector<double> r(n), js(6 * n), ja(n), jb(n), jc(n);
  double* jac[4] = {js.data(), ja.data(), jb.data(), jc.data()};
  // Each pass at a new point, as in a fit (SegmentCost returns the residuals of a point it
  // has just simulated without simulating again).
  double nudge = 0;
  auto pass = [&] {
    log_abc[0] += (nudge += 1e-12);
    for (size_t k = 0; k < costs.size(); ++k) {
      const double* params[4] = {states[k].data(), &log_abc[0], &log_abc[1], &log_abc[2]};
      costs[k]->Evaluate(params, r.data(), with_derivatives ? jac : nullptr);
      benchmark::DoNotOptimize(r);
    }
  };
  pass();
  std::vector<double> times;
  for (int rep = 0; rep < 5; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    pass();
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::nth_element(times.begin(), times.begin() + 2, times.end());
  return times[2];
}

void Run(benchmark::State& state, EstimatorMethod method, int threads = 1) {
  const Trajectory& log = NoisyLog();
  IdentifyOptions options;
  options.method = method;
  options.threads = threads;
  EstimateResult result;
  for (auto _ : state) {
    result = Identify(log, options);
    benchmark::DoNotOptimize(result);
  }
  const ReducedFriction truth = testing::LongPushScene(kSteps).friction.reduced();
  const double t[3] = {truth.a, truth.b, truth.c};
  const char* names[3] = {"err_a", "err_b", "err_c"};
  for (int i = 0; i < 3; ++i) {
    state.counters[names[i]] =
        result.parameters[i].identifiable ? std::abs(result.parameters[i].value / t[i] - 1) : NAN;
  }
  state.counters["steps"] = static_cast<double>(log.samples.size() - 1);
  state.counters["iterations"] = result.iterations;
  if (method == EstimatorMethod::kTrajectory) {
    // The floor of a fit is a few Gauss-Newton passes: the fit's time in units of one pass
    // with derivatives, both measured here, in the same run.
    const double pass = ForwardPassSeconds(log, true);
    state.counters["pass_ms"] = 1e3 * pass;
    state.counters["residual_pass_ms"] = 1e3 * ForwardPassSeconds(log, false);
    state.counters["fit_in_passes"] = result.seconds / pass;
  }
}

void BM_ClosedForm(benchmark::State& s) { Run(s, EstimatorMethod::kClosedForm); }
void BM_EquationError(benchmark::State& s) { Run(s, EstimatorMethod::kEquationError); }
void BM_Trajectory(benchmark::State& s) {
  Run(s, EstimatorMethod::kTrajectory, static_cast<int>(s.range(0)));
}

// ---- pooled against single fits ----------------------------------------------------------

// Issue 10: a pooled fit of 50 logs of 60-300 rows must stay within 2x the sum of the single
// fits. Fifty logs of one slider on one surface, two random pushes each (80 to 300 rows at
// 100 Hz from a 1 ms simulation), with motion-capture noise on the poses.
constexpr int kPooledLogs = 50;

const std::vector<Trajectory>& PooledLogs() {
  static const std::vector<Trajectory> logs = [] {
    DatasetSpec spec;
    spec.count = kPooledLogs;
    spec.seed = 2026;
    spec.mass_kg = {0.8, 0.8};
    spec.com_height_m = {0.03, 0.03};
    spec.patch = PatchRange::Parse("rectangle 0.1 0.08");
    spec.mu = {0.35, 0.35};
    spec.e_t = {1.0, 1.0};
    spec.e_o = {1.3, 1.3};
    spec.e_r_m = {0.03, 0.03};
    spec.program.count = 2;
    spec.program.duration_s = {0.2, 1.0};
    spec.log.noise.pose_m = 3e-4;
    spec.log.noise.angle_rad = 3e-3;
    std::vector<Trajectory> out(kPooledLogs);
    for (int k = 0; k < kPooledLogs; ++k) {
      out[k].source = DrawDatasetLog(spec, k, &out[k]).file;
    }
    return out;
  }();
  return logs;
}

// Process CPU time [s]: the machine may be shared, and both fits run on one thread.
double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// Each iteration times the 50 single fits one after the other, then the pooled fit of the
// same logs (which runs those single fits again, for its per-log results and its seeds);
// the counters are the last iteration's CPU times and their ratio, the figure the issue
// bounds.
void BM_PooledAgainstSingleFits(benchmark::State& state) {
  const std::vector<Trajectory>& logs = PooledLogs();
  IdentifyOptions options;
  options.threads = 1;
  double singles_s = 0, pooled_s = 0;
  EstimateResult pooled;
  for (auto _ : state) {
    double t0 = CpuSeconds();
    for (const Trajectory& log : logs) benchmark::DoNotOptimize(Identify(log, options));
    singles_s = CpuSeconds() - t0;
    t0 = CpuSeconds();
    pooled = Identify(logs, options);
    pooled_s = CpuSeconds() - t0;
  }
  int rows_min = 1 << 30, rows_max = 0;
  for (const Trajectory& log : logs) {
    rows_min = std::min<int>(rows_min, log.samples.size());
    rows_max = std::max<int>(rows_max, log.samples.size());
  }
  state.counters["singles_s"] = singles_s;
  state.counters["pooled_s"] = pooled_s;
  state.counters["ratio"] = pooled_s / singles_s;
  state.counters["rows_min"] = rows_min;
  state.counters["rows_max"] = rows_max;
  state.counters["pooled_iterations"] = pooled.iterations;
  state.counters["err_a"] = std::abs(pooled.parameters[0].value / 0.35 - 1);
}

BENCHMARK(BM_PooledAgainstSingleFits)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3);

BENCHMARK(BM_ClosedForm)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_EquationError)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);
// Argument: Ceres threads (1, then 2 for the speed-up on the same log). Wall time, since
// the threads' work is what a user waits for.
BENCHMARK(BM_Trajectory)
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace slideid

BENCHMARK_MAIN();
