// Run time of each estimator on a 10,000-step noisy log (issue 3's targets: closed form
// under 10 ms, trajectory fit under 1 s, single thread). Prints each method's relative
// errors against the truth beside its time.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>

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

BENCHMARK(BM_ClosedForm)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_EquationError)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_Trajectory)->Unit(benchmark::kMillisecond)->Repetitions(3)->ReportAggregatesOnly(true);

}  // namespace
}  // namespace slideid

BENCHMARK_MAIN();
