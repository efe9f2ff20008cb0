#include "estimator/equation_error.h"

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "estimator/closed_form.h"
#include "estimator/identifiability.h"
#include "estimator/robust_statistics.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();


/// Raw (un-robustified) residuals and their Jacobian w.r.t. all three log-parameters.
struct Linearisation {
  std::vector<double> residuals;  ///< 3 per used step
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  ///< J^T J
  double sum_squares = 0;
  bool ok = true;
};

Linearisation Linearise(const std::vector<std::unique_ptr<ceres::CostFunction>>& costs,
                        const double* theta) {
  Linearisation out;
  const double* params[3] = {&theta[0], &theta[1], &theta[2]};
  for (const auto& cost : costs) {
    double r[3], ja[3], jb[3], jc[3];
    double* jacobians[3] = {ja, jb, jc};
    if (!cost->Evaluate(params, r, jacobians)) {
      out.ok = false;
      return out;
    }
    Eigen::Matrix3d j;
    for (int k = 0; k < 3; ++k) j.row(k) << ja[k], jb[k], jc[k];
    out.information += j.transpose() * j;
    for (int k = 0; k < 3; ++k) {
      out.residuals.push_back(r[k]);
      out.sum_squares += r[k] * r[k];
    }
  }
  return out;
}

}  // namespace

EstimateResult EstimateEquationError(const Trajectory& log, const IdentifyOptions& identify,
                                     const EstimateResult* closed_form) {
  const auto start_time = std::chrono::steady_clock::now();
  std::string why;
  const EquationErrorOptions& options = identify.equation_error;
  if (!options.IsValid(&why)) throw std::invalid_argument("EstimateEquationError: " + why);
  // The seed.
  const EstimateResult seed_result =
      closed_form ? *closed_form : EstimateClosedForm(log, identify);
  if (seed_result.status == TerminationStatus::kTooLittleExcitation) {
    EstimateResult r = seed_result;
    r.method = EstimatorMethod::kEquationError;
    return r;
  }
  const std::vector<StepObservation> steps = ExtractStepObservations(log);
  const double radius = std::sqrt(log.slider.inertia_kgm2 / log.slider.mass_kg);  // L [m]

  EstimateResult result;
  result.method = EstimatorMethod::kEquationError;
  result.steps_total = static_cast<int>(steps.size());
  result.residual_names = {{"t", "o", "r"}};

  // Which steps enter the fit.
  std::vector<double> speed(steps.size(), 0.0);
  std::vector<double> candidate_speeds;
  std::vector<bool> candidate(steps.size(), false);
  for (size_t k = 0; k < steps.size(); ++k) {
    const StepObservation& o = steps[k];
    if (!InformativeStep(o, &result)) continue;
    const Eigen::Vector3d& v = o.ecp_velocity;
    speed[k] = std::sqrt(v(0) * v(0) + v(1) * v(1) + radius * radius * v(2) * v(2));
    candidate[k] = true;
    candidate_speeds.push_back(speed[k]);
  }
  const double floor =
      candidate_speeds.empty() ? 0.0 : kEcpSpeedFloorFraction * Median(candidate_speeds);
  std::vector<int> used;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  for (size_t k = 0; k < steps.size(); ++k) {
    if (!candidate[k]) continue;
    if (!(speed[k] > floor)) {
      result.Exclude("ECP speed near zero");
      continue;
    }
    used.push_back(static_cast<int>(k));
    costs.emplace_back(EquationErrorResidual::Create(steps[k], radius));
  }
  result.steps_used = static_cast<int>(used.size());
  if (result.steps_used < kMinStepsPerParameter) {
    result.status = TerminationStatus::kTooLittleExcitation;
    result.converged = false;
    result.message = "too little sliding to identify anything: " +
                     std::to_string(result.steps_used) + " of " +
                     std::to_string(steps.size()) + " steps usable";
    return result;
  }

  // Seed from the closed form; b = 1 (isotropic) and c = L (uniform disc-like pressure)
  // where it has none.
  const std::array<double, 3> fallback{{kNaN, 1.0, radius}};
  std::array<double, 3> seed;
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = seed_result.parameters[i];
    seed[i] = std::log(p.identifiable ? p.value : fallback[i]);
  }
  double theta[3] = {seed[0], seed[1], seed[2]};

  // Robust loss scale from the spread of the residuals at the seed.
  const Linearisation at_seed = Linearise(costs, theta);
  double sigma_hat = kMinLossSigma;
  if (at_seed.ok) {
    const double centre = Median(at_seed.residuals);
    std::vector<double> deviation;
    for (double r : at_seed.residuals) deviation.push_back(std::abs(r - centre));
    sigma_hat = std::max(kMadToSigma * Median(deviation), kMinLossSigma);
  }
  const double loss_scale = options.loss_scale_sigmas * sigma_hat;
  std::unique_ptr<ceres::LossFunction> loss;
  if (options.loss == RobustLoss::kHuber) loss = std::make_unique<ceres::HuberLoss>(loss_scale);
  if (options.loss == RobustLoss::kCauchy) loss = std::make_unique<ceres::CauchyLoss>(loss_scale);

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  auto build = [&](ceres::LossFunction* loss_function, const std::array<bool, 3>& active) {
    auto problem = std::make_unique<ceres::Problem>(problem_options);
    for (const auto& cost : costs) {
      problem->AddResidualBlock(cost.get(), loss_function, &theta[0], &theta[1], &theta[2]);
    }
    for (int i = 0; i < 3; ++i) {
      if (!active[i]) problem->SetParameterBlockConstant(&theta[i]);
    }
    return problem;
  };

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = identify.threads;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.logging_type = ceres::SILENT;
  // No gradient test: Ceres' gradient tolerance is absolute, and on a log that barely
  // feels a parameter (a 1000 kg slider whose spin is 2 mrad/s) it stopped the fit with c
  // 5.5e-5 off and its interval excluding the truth (docs/stability.md). The default
  // relative function and parameter tolerances end every fit.
  solver_options.gradient_tolerance = 0.0;

  // Fit, judge identifiability, hold what is not identifiable at its seed, refit.
  std::array<bool, 3> active{{true, true, true}};
  std::array<std::string, 3> held_note;
  std::array<ParameterIdentifiability, 3> verdict;
  Linearisation at_solution;
  double variance = kNaN;
  ceres::Solver::Summary summary;
  result.iterations = 0;
  for (int pass = 0; pass < 4; ++pass) {  // each pass but the last holds >= 1 more
    for (int i = 0; i < 3; ++i) {
      if (!active[i]) theta[i] = seed[i];
    }
    auto problem = build(loss.get(), active);
    ceres::Solve(solver_options, problem.get(), &summary);
    result.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    at_solution = Linearise(costs, theta);
    const int n_free = static_cast<int>(std::count(active.begin(), active.end(), true));
    const int dof = static_cast<int>(at_solution.residuals.size()) - n_free;
    if (!at_solution.ok || dof <= 0) break;
    variance = at_solution.sum_squares / dof;
    verdict = AssessIdentifiability(at_solution.information, variance, active);
    bool changed = false;
    for (int i = 0; i < 3; ++i) {
      if (active[i] && !verdict[i].identifiable) {
        active[i] = false;
        held_note[i] = verdict[i].note;
        changed = true;
      }
    }
    if (!changed || std::none_of(active.begin(), active.end(), [](bool x) { return x; })) break;
  }
  for (int i = 0; i < 3; ++i) {
    if (!active[i]) theta[i] = seed[i];
  }
  result.final_cost = summary.final_cost;
  const bool solve_converged =
      summary.termination_type == ceres::CONVERGENCE && at_solution.ok;
  result.message = summary.BriefReport();
  if (!at_solution.ok) result.message += "; the model could not be evaluated at the solution";

  // Standard errors of the free log-parameters: covariance of the un-robustified problem,
  // scaled by the residual variance.
  std::array<double, 3> log_stderr{{kNaN, kNaN, kNaN}};
  const bool any_active = std::any_of(active.begin(), active.end(), [](bool x) { return x; });
  if (any_active && std::isfinite(variance)) {
    auto plain = build(nullptr, active);
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::DENSE_SVD;
    covariance_options.num_threads = identify.threads;
    ceres::Covariance covariance(covariance_options);
    std::vector<std::pair<const double*, const double*>> blocks;
    for (int i = 0; i < 3; ++i) {
      if (active[i]) blocks.emplace_back(&theta[i], &theta[i]);
    }
    if (covariance.Compute(blocks, plain.get())) {
      for (int i = 0; i < 3; ++i) {
        double v = kNaN;
        if (active[i] && covariance.GetCovarianceBlock(&theta[i], &theta[i], &v)) {
          log_stderr[i] = std::sqrt(variance * std::max(v, 0.0));
        }
      }
    } else {
      result.message += "; covariance could not be computed";
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (active[i]) {
      result.parameters[i] = EstimateFromLog(theta[i], log_stderr[i]);
    } else {
      result.parameters[i] = NotIdentifiable(std::exp(seed[i]), held_note[i]);
    }
  }

  // Per-step residuals at the solution (raw).
  result.residuals.reserve(steps.size());
  size_t next_used = 0;
  for (size_t k = 0; k < steps.size(); ++k) {
    StepResidual r;
    r.row = steps[k].row;
    r.t_s = log.samples[steps[k].row].t_s;
    r.used = next_used < used.size() && used[next_used] == static_cast<int>(k);
    if (r.used && at_solution.ok) {
      for (int c = 0; c < 3; ++c) r.value[c] = at_solution.residuals[3 * next_used + c];
    } else {
      r.value = {{kNaN, kNaN, kNaN}};
    }
    if (r.used) ++next_used;
    result.residuals.push_back(r);
  }
  for (ParameterEstimate& p : result.parameters) {
    p.verdict = p.identifiable ? Verdict::kOk : Verdict::kNotIdentifiable;
  }
  // Usable is not converged: a solve cut off by the iteration limit is usable to Ceres.
  result.Conclude(solve_converged);
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace slideid
