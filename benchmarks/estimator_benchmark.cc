// Run time of each estimator on a 10,000-step noisy log (issue 3's targets: closed form
// under 10 ms, trajectory fit under 1 s, single thread). Prints each method's relative
// errors against the truth beside its time. Also a pooled fit of 50 short logs against the
// sum of their single fits, measured in the same run (issue 10: within 2x).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <vector>

#include "datasets/dataset.h"
#include "datasets/noise.h"
#include "estimator/identify.h"
#include "forward_model/simulator.h"

namespace slideid {
namespace {

constexpr int kSteps = 10000;

Scene LongPushScene() {
  Scene s;
  s.source = "benchmark";
  s.slider = {1.0, 1.0 * (0.1 * 0.1 + 0.1 * 0.1) / 12, 0.03, 9.81};
  s.friction = {0.35, 1.0, 1.3, 0.035};
  s.patch = ContactPatch::Rectangle(0.1, 0.1);
  s.initial = {0, 0, 0, 0.2, 0.1, 0.0};
  PushSpec p;
  p.point_body = {-0.05, -0.02};
  p.direction_body = Eigen::Vector2d(1, 0.2).normalized();
  p.height_m = s.slider.com_height_m;
  p.force_N = 3.0;
  p.amplitude_N = 2.5;
  p.period_s = 0.37;
  s.pushes.push_back(p);
  s.dt_s = 0.01;
  s.duration_s = kSteps * s.dt_s;
  return s;
}

const Trajectory& NoisyLog() {
  static const Trajectory log = [] {
    const SimulationResult sim = Simulate(LongPushScene());
    if (!sim.summary.ok()) {
      std::fprintf(stderr, "benchmark scene failed: %s\n", sim.summary.message.c_str());
      std::abort();
    }
    NoiseSpec noise;
    noise.pose_m = 3e-4;
    noise.angle_rad = 3e-3;
    noise.seed = 7;
    Trajectory noisy = AddNoise(sim.trajectory, noise);
    noisy.columns.velocity = false;  // motion capture: poses only
    return noisy;
  }();
  return log;
}

void Run(benchmark::State& state, EstimatorMethod method) {
  const Trajectory& log = NoisyLog();
  IdentifyOptions options;
  options.method = method;
  options.threads = 1;
  EstimateResult result;
  for (auto _ : state) {
    result = Identify(log, options);
    benchmark::DoNotOptimize(result);
  }
  const ReducedFriction truth = ReducedFriction::From(LongPushScene().friction);
  const double t[3] = {truth.a, truth.b, truth.c};
  const char* names[3] = {"err_a", "err_b", "err_c"};
  for (int i = 0; i < 3; ++i) {
    state.counters[names[i]] = result.parameters[i].identifiable
                                   ? std::abs(result.parameters[i].value / t[i] - 1)
                                   : NAN;
  }
  state.counters["steps"] = static_cast<double>(log.samples.size() - 1);
  state.counters["iterations"] = result.iterations;
}

void BM_ClosedForm(benchmark::State& s) { Run(s, EstimatorMethod::kClosedForm); }
void BM_EquationError(benchmark::State& s) { Run(s, EstimatorMethod::kEquationError); }
void BM_Trajectory(benchmark::State& s) { Run(s, EstimatorMethod::kTrajectory); }

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
BENCHMARK(BM_EquationError)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_Trajectory)->Unit(benchmark::kMillisecond)->Repetitions(3)->ReportAggregatesOnly(true);

}  // namespace
}  // namespace slideid

BENCHMARK_MAIN();
