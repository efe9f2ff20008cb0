// Time per step of SolveStep on realistic sliding steps, by path, against a generic solver
// of the same four equations: MINPACK's hybrid dogleg (Eigen unsupported, hybrd1 with a
// finite-difference Jacobian, as MATLAB's fsolve 'trust-region-dogleg' used by the paper).
//
// Both solvers start from the same first guess (the decoupled solution) and are compared at
// equal residual: before timing, main() solves every case with both and prints the median
// and max of max|SlidingEquationResiduals| (model.md, "One step") at their solutions, and
// the number of cases each failed. The same figures are attached to the benchmarks as
// counters. Every benchmark cycles through a fixed, seeded set of sliding steps, one step
// per benchmark iteration, so the reported time is per step; with 10 repetitions the
// aggregates include the median. On the decoupled family the shared first guess is already
// the root, so BM_DoglegBaseline_Decoupled times the dogleg's fixed cost of confirming it.

#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/NonLinearOptimization>
#include <utility>
#include <vector>

#include "fixtures/random_step_cases.h"
#include "fixtures/tolerances.h"
#include "forward_model/step_equations.h"
#include "forward_model/step_solver.h"

namespace slideid {
namespace {

// Sliding steps per family: enough to average over the spread of scenes, small enough to
// stay in cache like the state of one simulation.
constexpr int kCases = 1024;
constexpr unsigned kSeed = 20240611;
// hybrd1's tolerance (relative change of the iterate at which it stops): the loosest power
// of ten at which the dogleg's median and max residual on the general set are no larger
// than SolveStep's (measured: 1e-12 leaves a median ~3x ours; 1e-14 costs ~10% more time
// for residuals below ours, and ends 20% of the cases with "tolerance too small").
constexpr double kDoglegXtol = 1e-13;
// A solution whose max|SlidingEquationResiduals| exceeds the tests' acceptance threshold
// (fixtures/tolerances.h) counts as a failure.
using testing::kIndependentTolerance;
// Repetitions for the median time; the minimum time per repetition keeps the whole run
// under about a minute.
constexpr int kRepetitions = 10;
constexpr double kMinTimePerRepetition_s = 0.25;

using testing::Case;

/// The scenes of a benchmark, named by the path SolveStep takes on them.
enum class Family { kGeneral, kDecoupled, kPureTranslation };

// The shared random cases (fixtures/random_step_cases.h), with what each family's path does
// not need switched off.
Case Make(testing::CaseGenerator& gen, Family family) {
  Case c = gen.General();
  if (family == Family::kDecoupled) {
    c.slider.com_height_m = 0;
    c.applied.tx = c.applied.ty = 0;
  } else if (family == Family::kPureTranslation) {
    c.friction.e_o = c.friction.e_t;
    c.state.wz = 0;
    c.applied.tx = c.applied.ty = c.applied.tz = 0;
  }
  return c;
}

const char* ToString(Family family) {
  switch (family) {
    case Family::kGeneral:
      return "general";
    case Family::kDecoupled:
      return "decoupled";
    case Family::kPureTranslation:
      return "closed-form";
  }
  return "?";
}

StepPath ExpectedPath(Family family) {
  switch (family) {
    case Family::kGeneral:
      return StepPath::kGeneral;
    case Family::kDecoupled:
      return StepPath::kDecoupled;
    case Family::kPureTranslation:
      return StepPath::kPureTranslation;
  }
  return StepPath::kGeneral;
}

StepResult Solve(const Case& c, const StepOptions& options = {}) {
  return SolveStep(c.slider, c.friction, c.state, c.applied, c.dt_s, options);
}

/// kCases sliding steps of `family` (sticking steps skipped). Throws std::logic_error if a
/// step fails or SolveStep takes another path than the family's.
std::vector<Case> MakeCases(Family family, unsigned seed) {
  testing::CaseGenerator gen(seed);
  std::vector<Case> cases;
  while (static_cast<int>(cases.size()) < kCases) {
    const Case c = Make(gen, family);
    const StepResult r = Solve(c);
    if (!r.ok()) throw std::logic_error(std::string("case set: SolveStep failed: ") + r.message);
    if (r.mode == StepMode::kStick) continue;
    if (r.path != ExpectedPath(family)) {
      throw std::logic_error(std::string("case set ") + ToString(family) + ": SolveStep took the " +
                             ToString(r.path) + " path");
    }
    cases.push_back(c);
  }
  return cases;
}

// The paper's four equations, as the residuals the tests verify (relative, unscaled
// unknowns (p_t, p_o, p_r, sigma)), in the functor form HybridNonLinearSolver takes.
struct PaperEquations {
  const Case* c;
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& fvec) const {
    fvec = SlidingEquationResiduals(c->slider, c->friction, c->state, c->applied, c->dt_s,
                                    Eigen::Vector4d(x(0), x(1), x(2), x(3)));
    return 0;
  }
};

/// What the dogleg baseline ends with.
struct DoglegOutcome {
  Eigen::Vector4d x;  ///< (p_t, p_o, p_r, sigma)
  Eigen::HybridNonLinearSolverSpace::Status status;
  int evaluations;  ///< function evaluations, the finite differences included
};

/// The baseline step: the same first guess as SolveStep (the decoupled solution, as
/// unknowns (p, e_t s)), then hybrd1 on the paper's equations.
DoglegOutcome SolveWithDogleg(const Case& c) {
  const StepEquations eq(c.slider, ReducedFriction::From(c.friction), c.state, c.applied, c.dt_s);
  const Eigen::Vector4d z = eq.DecoupledGuess();
  Eigen::VectorXd x(4);
  x << eq.Impulses(z), c.friction.e_t * z(3);
  PaperEquations functor{&c};
  Eigen::HybridNonLinearSolver<PaperEquations> dogleg(functor);
  const auto status = dogleg.hybrd1(x, kDoglegXtol);
  return {Eigen::Vector4d(x), status, static_cast<int>(dogleg.nfev)};
}

double MaxResidual(const Case& c, const Eigen::Vector4d& x) {
  return SlidingEquationResiduals(c.slider, c.friction, c.state, c.applied, c.dt_s, x)
      .cwiseAbs()
      .maxCoeff();
}

/// Accuracy of one solver over a case set: every case counts, failures included.
struct Accuracy {
  double median_residual = 0;  ///< of max|SlidingEquationResiduals| at the solutions
  double max_residual = 0;
  int failures = 0;              ///< not converged, or residual above kIndependentTolerance
  int not_status_converged = 0;  ///< dogleg only: ended other than "relative error too small"
  double mean_work = 0;          ///< Newton iterations (SolveStep) or evaluations (dogleg)
};

// Fills the residual figures from one residual per case (NaN counts as failed).
void Summarise(std::vector<double> residuals, Accuracy* a) {
  std::sort(residuals.begin(), residuals.end(), [](double x, double y) {
    return std::isnan(y) ? !std::isnan(x) : x < y;  // NaNs last, so they are the max
  });
  const size_t n = residuals.size();
  a->median_residual = n % 2 ? residuals[n / 2] : 0.5 * (residuals[n / 2 - 1] + residuals[n / 2]);
  a->max_residual = residuals.back();
}

Accuracy MeasureStepSolver(const std::vector<Case>& cases, const StepOptions& options) {
  Accuracy a;
  std::vector<double> residuals;
  double work = 0;
  for (const Case& c : cases) {
    const StepResult r = Solve(c, options);
    const double residual = MaxResidual(c, Eigen::Vector4d(r.pt, r.po, r.pr, r.sigma));
    a.failures += !r.ok() || !(residual <= kIndependentTolerance);
    work += r.iterations;
    residuals.push_back(residual);
  }
  a.mean_work = work / cases.size();
  Summarise(std::move(residuals), &a);
  return a;
}

Accuracy MeasureDogleg(const std::vector<Case>& cases) {
  Accuracy a;
  std::vector<double> residuals;
  double work = 0;
  for (const Case& c : cases) {
    const DoglegOutcome d = SolveWithDogleg(c);
    const double residual = MaxResidual(c, d.x);
    a.failures += !(residual <= kIndependentTolerance && d.x(3) > 0);
    a.not_status_converged += d.status != Eigen::HybridNonLinearSolverSpace::RelativeErrorTooSmall;
    work += d.evaluations;
    residuals.push_back(residual);
  }
  a.mean_work = work / cases.size();
  Summarise(std::move(residuals), &a);
  return a;
}

void AddCounters(const Accuracy& a, benchmark::State& state) {
  state.counters["median_residual"] = a.median_residual;
  state.counters["max_residual"] = a.max_residual;
  state.counters["failures"] = a.failures;
  state.counters["not_status_1"] = a.not_status_converged;
}

// One step per benchmark iteration, cycling through the case set.
template <typename StepFunction>
void TimeSteps(benchmark::State& state, const std::vector<Case>& cases, const Accuracy& accuracy,
               StepFunction step) {
  size_t i = 0;
  for (auto _ : state) {
    auto result = step(cases[i]);
    benchmark::DoNotOptimize(result);
    if (++i == cases.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
  AddCounters(accuracy, state);
}

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) {
  using namespace slideid;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  std::vector<Case> general, decoupled, closed_form;
  try {
    general = MakeCases(Family::kGeneral, kSeed);
    decoupled = MakeCases(Family::kDecoupled, kSeed + 1);
    closed_form = MakeCases(Family::kPureTranslation, kSeed + 2);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "step_benchmark: %s\n", e.what());
    return 1;
  }
  StepOptions forced;
  forced.use_special_cases = false;

  // Accuracy first: the speed ratio is honest only at equal (or baseline-better) residual.
  const Accuracy ours_general = MeasureStepSolver(general, {});
  const Accuracy ours_decoupled = MeasureStepSolver(decoupled, {});
  const Accuracy ours_closed_form = MeasureStepSolver(closed_form, {});
  const Accuracy ours_forced = MeasureStepSolver(decoupled, forced);
  const Accuracy dogleg_general = MeasureDogleg(general);
  const Accuracy dogleg_decoupled = MeasureDogleg(decoupled);
  std::printf(
      "%d sliding steps per family; residual = max|SlidingEquationResiduals| at the "
      "solution;\nfailure = not converged or residual > %.0e; dogleg: hybrd1, "
      "xtol %.0e, finite-difference Jacobian.\n",
      kCases, kIndependentTolerance, kDoglegXtol);
  std::printf("%-38s %12s %12s %9s %12s %10s\n", "solver / family", "median res", "max res",
              "failures", "non-status-1", "mean work");
  const std::pair<const char*, const Accuracy*> rows[] = {
      {"SolveStep / general", &ours_general},
      {"SolveStep / decoupled", &ours_decoupled},
      {"SolveStep / closed-form", &ours_closed_form},
      {"SolveStep forced general / decoupled", &ours_forced},
      {"dogleg / general", &dogleg_general},
      {"dogleg / decoupled", &dogleg_decoupled},
  };
  for (const auto& [name, a] : rows) {
    std::printf("%-38s %12.3e %12.3e %9d %12d %10.2f\n", name, a->median_residual, a->max_residual,
                a->failures, a->not_status_converged, a->mean_work);
  }
  std::printf(
      "(mean work: Newton or scalar-root iterations for SolveStep, function "
      "evaluations for the dogleg)\n\n");
  std::fflush(stdout);

  auto solve_step = [](const StepOptions& options) {
    return [options](const Case& c) { return Solve(c, options); };
  };
  auto dogleg = [](const Case& c) { return SolveWithDogleg(c).x; };
  struct Entry {
    const char* name;
    std::function<void(benchmark::State&)> run;
  };
  const Entry entries[] = {
      {"BM_GeneralStep",
       [&](benchmark::State& s) { TimeSteps(s, general, ours_general, solve_step({})); }},
      {"BM_DecoupledStep",
       [&](benchmark::State& s) { TimeSteps(s, decoupled, ours_decoupled, solve_step({})); }},
      {"BM_ClosedFormStep",
       [&](benchmark::State& s) { TimeSteps(s, closed_form, ours_closed_form, solve_step({})); }},
      {"BM_GeneralStepForcedGeneralPath",
       [&](benchmark::State& s) { TimeSteps(s, decoupled, ours_forced, solve_step(forced)); }},
      {"BM_DoglegBaseline_General",
       [&](benchmark::State& s) { TimeSteps(s, general, dogleg_general, dogleg); }},
      {"BM_DoglegBaseline_Decoupled",
       [&](benchmark::State& s) { TimeSteps(s, decoupled, dogleg_decoupled, dogleg); }},
  };
  for (const Entry& e : entries) {
    benchmark::RegisterBenchmark(e.name, e.run)
        ->Unit(benchmark::kNanosecond)
        ->MinTime(kMinTimePerRepetition_s)
        ->Repetitions(kRepetitions)
        ->ReportAggregatesOnly(true);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
