#include "estimator/equation_error.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "estimator/cheap_methods.h"
#include "estimator/closed_form.h"
#include "estimator/identifiability.h"
#include "estimator/internal/equation_error_residual.h"
#include "estimator/internal/log_friction.h"
#include "estimator/internal/method_cores.h"
#include "estimator/plausibility.h"
#include "estimator/pooling.h"
#include "estimator/robust_statistics.h"
#include "estimator/simex.h"
#include "estimator/step_covariance.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One step in the fit.
struct FitStep {
  int log = 0;
  int row = 0;
  std::unique_ptr<ceres::CostFunction> cost;
  /// The change of the step's residuals if its force were the mean of its row's and the
  /// next row's (varying within the interval) instead of its row's held over it; zero at a
  /// force switch (kForceSwitchFraction), where holding is right.
  Eigen::Vector3d force_hold_shift = Eigen::Vector3d::Zero();
  /// The same step with the direction of sliding taken at the middle of the interval (the
  /// mean of its start and end velocities) instead of its end: what a motion that changes
  /// within the interval, rather than the model's backward-Euler step, would make of it.
  std::unique_ptr<ceres::CostFunction> mid_interval_cost;
};

Eigen::Vector3d ForceHoldShift(const LogSteps& s, const StepObservation& o) {
  const Eigen::Vector3d dp = ForceHoldImpulseShift(s, o);
  return Eigen::Vector3d(dp(0) / o.pn, dp(1) / o.pn, dp(2) / (o.pn * s.radius_m));
}
/// Residuals and Jacobians of every step at theta (3 residuals x 3 log-parameters each).
struct Linearisation {
  std::vector<Eigen::Vector3d> residual;
  std::vector<Eigen::Matrix3d> jacobian;
  bool ok = true;
};

Linearisation Linearise(const std::vector<FitStep>& steps, const double* theta) {
  Linearisation out;
  const double* params[3] = {&theta[0], &theta[1], &theta[2]};
  for (const FitStep& step : steps) {
    double r[3], ja[3], jb[3], jc[3];
    double* jacobians[3] = {ja, jb, jc};
    if (!step.cost->Evaluate(params, r, jacobians)) {
      out.ok = false;
      return out;
    }
    Eigen::Matrix3d j;
    for (int k = 0; k < 3; ++k) j.row(k) << ja[k], jb[k], jc[k];
    out.residual.emplace_back(r[0], r[1], r[2]);
    out.jacobian.push_back(j);
  }
  return out;
}

/// 1.4826 MAD of every residual component about their median: the residuals' scale,
/// which a few outliers (rows no log can flag) do not inflate as a sum of squares would.
double RobustScale(const Linearisation& l) {
  std::vector<double> all;
  for (const Eigen::Vector3d& r : l.residual) all.insert(all.end(), r.data(), r.data() + 3);
  if (all.empty()) return kNaN;
  const double centre = Median(all);
  for (double& r : all) r = std::abs(r - centre);
  return kMadToSigma * Median(all);
}

/// The free parameters' sandwich covariances of the robust fit (equation_error.h).
struct Sandwich {
  Eigen::MatrixXd blocks;  ///< blocks of steps (step_covariance.h)
  Eigen::MatrixXd logs;    ///< logs as clusters
  Eigen::MatrixXd white;   ///< independent steps
  /// How far the free log-parameters move under the other readings of the log (FitStep):
  /// forces varying within rows, and the direction of sliding at mid-interval.
  Eigen::VectorXd force_hold_shift;
  Eigen::VectorXd mid_interval_shift;
  int block_count = 0;
  int log_clusters = 0;
  bool ok = false;
};

Sandwich RobustSandwich(const std::vector<FitStep>& steps, const Linearisation& l,
                        const ceres::LossFunction* loss, const std::vector<int>& free,
                        const std::vector<int>& lag_of_log, const double* theta) {
  Sandwich out;
  const double* params[3] = {&theta[0], &theta[1], &theta[2]};
  const int p = static_cast<int>(free.size());
  const int n = static_cast<int>(steps.size());
  Eigen::MatrixXd bread = Eigen::MatrixXd::Zero(p, p);
  Eigen::MatrixXd scores(n, p);
  Eigen::VectorXd shift_score = Eigen::VectorXd::Zero(p);
  Eigen::VectorXd mid_score = Eigen::VectorXd::Zero(p);
  std::vector<int> log(n), row(n);
  for (int i = 0; i < n; ++i) {
    Eigen::MatrixXd j(3, p);
    for (int a = 0; a < p; ++a) j.col(a) = l.jacobian[i].col(free[a]);
    double rho[3] = {l.residual[i].squaredNorm(), 1.0, 0.0};
    if (loss) loss->Evaluate(l.residual[i].squaredNorm(), rho);
    bread += rho[1] * j.transpose() * j;
    scores.row(i) = (rho[1] * j.transpose() * l.residual[i]).transpose();
    shift_score += rho[1] * j.transpose() * steps[i].force_hold_shift;
    if (steps[i].mid_interval_cost) {
      double r_mid[3];
      if (steps[i].mid_interval_cost->Evaluate(params, r_mid, nullptr)) {
        const Eigen::Vector3d change =
            Eigen::Vector3d(r_mid[0], r_mid[1], r_mid[2]) - l.residual[i];
        mid_score += rho[1] * j.transpose() * change;
      }
    }
    log[i] = steps[i].log;
    row[i] = steps[i].row;
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(bread);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return out;
  const Eigen::MatrixXd inverse = ldlt.solve(Eigen::MatrixXd::Identity(p, p));
  auto sandwich = [&](const Eigen::MatrixXd& meat) {
    return Eigen::MatrixXd(inverse * meat * inverse);
  };
  out.white = sandwich(scores.transpose() * scores);
  out.force_hold_shift = -(inverse * shift_score);
  out.mid_interval_shift = -(inverse * mid_score);
  const StepBlocks blocks = BlocksOfSteps(log, row, lag_of_log);
  out.block_count = blocks.count;
  out.blocks = sandwich(BlockScoreCovariance(scores, blocks));
  out.logs = sandwich(ClusterScoreCovariance(scores, log, &out.log_clusters));
  out.ok = true;
  return out;
}

/// The interval of free parameter `a` (equation_error.h): blocks, else independent steps;
/// logs where wider.
LogEstimate ChooseInterval(const Sandwich& s, int a, bool spin) {
  LogEstimate iv;
  if (!s.ok) return iv;
  // The mid-interval reading only for c: a slider's spin changes by a large fraction within
  // an interval (it decays fast), its direction of sliding little. Applied to a and b it
  // over-covered (99-100% over the Monte Carlo); c without it covered 40-75%.
  iv.force_hold_shift_log =
      std::abs(s.force_hold_shift(a)) + (spin ? std::abs(s.mid_interval_shift(a)) : 0.0);
  if (s.block_count >= kMinBlocks && s.blocks(a, a) > 0) {
    iv.stderr_log = std::sqrt(s.blocks(a, a));
    iv.quantile = StudentT95(s.block_count - 1);
  } else {
    iv.stderr_log = std::sqrt(std::max(0.0, s.white(a, a)));
    iv.note = Printf("only %d blocks of %d steps: interval from independent steps (wider)",
                     s.block_count, kBlockSteps);
  }
  if (s.log_clusters >= kMinLogClusters) {
    const double between = std::sqrt(std::max(0.0, s.logs(a, a)));
    const double t = StudentT95(s.log_clusters - 1);
    if (t * between > iv.quantile * iv.stderr_log) {
      iv.note = Printf(
          "interval widened %.2fx: the logs differ by more than their noise "
          "(cluster-robust over %d logs, t quantile %.2f)",
          t * between / (iv.quantile * iv.stderr_log), s.log_clusters, t);
      iv.stderr_log = between;
      iv.quantile = t;
    }
  }
  return iv;
}

/// Seed of the fit: the closed form's where it identifies a parameter, else b = 1
/// (isotropic), c = L (uniform disc-like pressure), a = typical table-top friction.
constexpr double kDefaultA = 0.3;

ReducedFriction SeedOf(const EstimateResult& closed_form, double radius_m) {
  ReducedFriction seed{kDefaultA, 1.0, radius_m};
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = closed_form.parameters[i];
    if (p.identifiable) seed[i] = p.value;
  }
  return ClampToSearchRange(seed);
}

/// Residuals at least this fraction of the scale the logs' noise implies
/// (NoiseResidualScale) show that noise; noisy logs give about 1 (and more with force
/// noise), exact logs orders of magnitude less.
constexpr double kMinNoiseShown = 0.5;

/// The steps that enter the fit: sliding steps of logs whose impulses stand out of their
/// noise (exclusions counted in `result`).
struct StepSet {
  std::vector<LogSteps> log_steps;
  std::vector<FitStep> fit;
  std::vector<std::vector<int>> used_of_log;  ///< per log, indices into its steps
  std::string snr_reason;                     ///< set when a log was left out for its noise
  double rotation_snr = std::numeric_limits<double>::infinity();  ///< lowest of the logs
  std::string rotation_reason;
};

StepSet SelectSteps(const std::vector<const Trajectory*>& logs, EstimateResult* result) {
  StepSet set;
  set.used_of_log.resize(logs.size());
  for (size_t k = 0; k < logs.size(); ++k) {
    set.log_steps.push_back(ReadLogSteps(*logs[k]));
    const LogSteps& s = set.log_steps.back();
    result->steps_total += static_cast<int>(s.steps.size());
    std::vector<int> used;
    for (size_t j = 0; j < s.steps.size(); ++j) {
      if (!SlidingStep(s.steps[j], s.noise, s.radius_m, result)) continue;
      if (!(s.steps[j].ecp_velocity.squaredNorm() > 0)) {  // the direction is undefined
        result->Exclude("ECP speed zero");
        continue;
      }
      used.push_back(static_cast<int>(j));
    }
    const double snr = ImpulseSnr(s, used, false);
    if (snr < kMinImpulseSnr) {
      result->Exclude("impulse noise swamps the friction", static_cast<int>(used.size()));
      set.snr_reason = LowSnrReason(snr, s.noise.differentiated, false);
      continue;
    }
    const double rotation_snr = ImpulseSnr(s, used, true);
    if (rotation_snr < set.rotation_snr) {
      set.rotation_snr = rotation_snr;
      set.rotation_reason = LowSnrReason(rotation_snr, s.noise.differentiated, true);
    }
    for (int j : used) {
      set.fit.push_back({static_cast<int>(k), s.steps[j].row,
                         std::unique_ptr<ceres::CostFunction>(
                             EquationErrorResidual::Create(s.steps[j], s.radius_m)),
                         ForceHoldShift(s, s.steps[j]),
                         std::unique_ptr<ceres::CostFunction>(
                             EquationErrorResidual::Create(MidInterval(s.steps[j]), s.radius_m))});
    }
    set.used_of_log[k] = std::move(used);
  }
  return set;
}

/// options.loss at options.loss_scale_sigmas times the residuals' robust scale at theta.
std::unique_ptr<ceres::LossFunction> MakeLoss(const EquationErrorOptions& options,
                                              const std::vector<FitStep>& fit,
                                              const double* theta) {
  const Linearisation at = Linearise(fit, theta);
  const double sigma = at.ok ? RobustScale(at) : kNaN;
  const double scale =
      options.loss_scale_sigmas * std::max(std::isfinite(sigma) ? sigma : 0.0, kMinLossSigma);
  if (options.loss == RobustLoss::kHuber) return std::make_unique<ceres::HuberLoss>(scale);
  if (options.loss == RobustLoss::kCauchy) return std::make_unique<ceres::CauchyLoss>(scale);
  return nullptr;
}

/// Fits the active log-parameters in `theta` (the others held), within the search range.
ceres::Solver::Summary SolveFit(const std::vector<FitStep>& fit, ceres::LossFunction* loss,
                                const std::array<bool, 3>& active, const IdentifyOptions& identify,
                                double* theta) {
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (const FitStep& step : fit) {
    problem.AddResidualBlock(step.cost.get(), loss, &theta[0], &theta[1], &theta[2]);
  }
  for (int i = 0; i < 3; ++i) {
    if (!active[i]) {
      problem.SetParameterBlockConstant(&theta[i]);
    } else {
      problem.SetParameterLowerBound(&theta[i], 0, std::log(kFrictionLowerBound[i]));
      problem.SetParameterUpperBound(&theta[i], 0, std::log(kFrictionUpperBound[i]));
    }
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = identify.equation_error.max_iterations;
  solver_options.num_threads = identify.threads;
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.logging_type = ceres::SILENT;
  // No gradient test: Ceres' gradient tolerance is absolute, and on a log that barely
  // feels a parameter (a 1000 kg slider whose spin is 2 mrad/s) it stopped the fit with c
  // 5.5e-5 off and its interval excluding the truth (docs/stability.md). The default
  // relative function and parameter tolerances end every fit.
  solver_options.gradient_tolerance = 0.0;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  return summary;
}

/// The fit of (a, b, c) from `seed`, holding what AssessIdentifiability rejects (with the
/// residuals' robust scale) at its seed and refitting the rest.
struct FitOutcome {
  std::array<double, 3> theta;  ///< log a, log b, log c: the fit's parameter blocks
  /// The seed as the blocks hold it (log_friction.h), where a held parameter stays.
  ReducedFriction seed;
  std::array<bool, 3> active{{true, true, true}};
  std::array<std::string, 3> held_note;
  std::unique_ptr<ceres::LossFunction> loss;
  Linearisation at_solution;
  ceres::Solver::Summary summary;
  int iterations = 0;
};

FitOutcome FitWithIdentifiability(const std::vector<FitStep>& fit, const ReducedFriction& seed,
                                  const IdentifyOptions& identify) {
  FitOutcome out;
  std::array<double, 3> start;
  ToLogParameters(seed, start.data());
  out.seed = FromLogParameters(start.data());
  out.theta = start;
  out.loss = MakeLoss(identify.equation_error, fit, out.theta.data());
  for (int pass = 0; pass < 4; ++pass) {  // each pass but the last holds >= 1 more
    for (int i = 0; i < 3; ++i) {
      if (!out.active[i]) out.theta[i] = start[i];
    }
    out.summary = SolveFit(fit, out.loss.get(), out.active, identify, out.theta.data());
    out.iterations += out.summary.num_successful_steps + out.summary.num_unsuccessful_steps;
    out.at_solution = Linearise(fit, out.theta.data());
    if (!out.at_solution.ok) break;
    Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
    for (const Eigen::Matrix3d& j : out.at_solution.jacobian) information += j.transpose() * j;
    const double scale = RobustScale(out.at_solution);
    const auto verdict = AssessIdentifiability(information, scale * scale, out.active);
    bool changed = false;
    for (int i = 0; i < 3; ++i) {
      if (out.active[i] && !verdict[i].identifiable) {
        out.active[i] = false;
        out.held_note[i] = verdict[i].note;
        changed = true;
      }
    }
    if (!changed || std::none_of(out.active.begin(), out.active.end(), [](bool x) { return x; })) {
      break;
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (!out.active[i]) out.theta[i] = start[i];
  }
  return out;
}

/// The fit on noisier copies of the logs for SIMEX: the same steps (so that the change
/// measures how noise biases the fit, not which steps pass the noise thresholds), the same
/// loss and active set, as one Gauss-Newton step from the original solution (the change is
/// small: one step leaves an error of its square, and costs a tenth of a solve); NaN for
/// held parameters and a singular step.
std::array<double, 3> RefitCopies(const std::vector<const Trajectory*>& copies,
                                  const StepSet& original, const FitOutcome& fit) {
  std::vector<FitStep> steps;
  for (size_t k = 0; k < copies.size(); ++k) {
    const std::vector<StepObservation> observed = ExtractStepObservations(*copies[k]);
    const double radius = original.log_steps[k].radius_m;
    for (int j : original.used_of_log[k]) {
      steps.push_back(
          {static_cast<int>(k), observed[j].row,
           std::unique_ptr<ceres::CostFunction>(EquationErrorResidual::Create(observed[j], radius)),
           Eigen::Vector3d::Zero(), nullptr});
    }
  }
  std::array<double, 3> out{{kNaN, kNaN, kNaN}};
  const Linearisation l = Linearise(steps, fit.theta.data());
  if (!l.ok) return out;
  std::vector<int> free;
  for (int i = 0; i < 3; ++i) {
    if (fit.active[i]) free.push_back(i);
  }
  const int p = static_cast<int>(free.size());
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(p);
  for (size_t i = 0; i < steps.size(); ++i) {
    Eigen::MatrixXd j(3, p);
    for (int a = 0; a < p; ++a) j.col(a) = l.jacobian[i].col(free[a]);
    double rho[3] = {l.residual[i].squaredNorm(), 1.0, 0.0};
    if (fit.loss) fit.loss->Evaluate(l.residual[i].squaredNorm(), rho);
    normal += rho[1] * j.transpose() * j;
    gradient += rho[1] * j.transpose() * l.residual[i];
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return out;
  const Eigen::VectorXd step = -ldlt.solve(gradient);
  for (int a = 0; a < p; ++a) out[free[a]] = fit.theta[free[a]] + step(a);
  return out;
}

void FillResiduals(const std::vector<const Trajectory*>& logs, const StepSet& set,
                   const Linearisation& at_solution, EstimateResult* result) {
  size_t next = 0;
  for (size_t k = 0; k < logs.size(); ++k) {
    const LogSteps& s = set.log_steps[k];
    const std::vector<int>& used = set.used_of_log[k];
    size_t next_used = 0;
    for (size_t j = 0; j < s.steps.size(); ++j) {
      StepResidual r;
      r.log = static_cast<int>(k);
      r.row = s.steps[j].row;
      r.t_s = logs[k]->samples[s.steps[j].row].t_s;
      r.used = next_used < used.size() && used[next_used] == static_cast<int>(j);
      r.value = {{kNaN, kNaN, kNaN}};
      if (r.used) {
        if (at_solution.ok) {
          for (int c = 0; c < 3; ++c) r.value[c] = at_solution.residual[next](c);
        }
        ++next_used;
        ++next;
      }
      result->residuals.push_back(r);
    }
  }
}

/// The scale the logs' velocity noise alone would give the residuals: m s_dv / p_n on t
/// and o, I_z s_dw / (p_n L) on r, as an RMS over the three and the used steps
/// (dimensionless, as the residuals); 0 for exact logs.
double NoiseResidualScale(const StepSet& set) {
  double expected2 = 0;
  int steps = 0;
  for (size_t k = 0; k < set.log_steps.size(); ++k) {
    const LogSteps& s = set.log_steps[k];
    const SliderProperties& slider = s.log->slider;
    const double t = slider.mass_kg * s.noise.delta_velocity_mps;
    const double r = slider.inertia_kgm2 * s.noise.delta_spin_radps / s.radius_m;
    for (int j : set.used_of_log[k]) {
      const double pn = s.steps[j].pn;
      expected2 += (2 * t * t + r * r) / (3 * pn * pn);
      ++steps;
    }
  }
  return steps > 0 ? std::sqrt(expected2 / steps) : 0.0;
}

}  // namespace

EstimateResult EquationErrorCore(const std::vector<const Trajectory*>& logs,
                                 const IdentifyOptions& identify,
                                 const EstimateResult& seed_result) {
  if (seed_result.status == TerminationStatus::kTooLittleExcitation) {
    EstimateResult r = seed_result;
    r.method = EstimatorMethod::kEquationError;
    return r;
  }
  const auto start_time = std::chrono::steady_clock::now();
  EstimateResult result;
  result.method = EstimatorMethod::kEquationError;
  result.residual_names = {{"t", "o", "r"}};
  const StepSet set = SelectSteps(logs, &result);
  result.steps_used = static_cast<int>(set.fit.size());
  if (result.steps_used < kMinStepsPerParameter) {
    if (!set.snr_reason.empty()) {
      // Sliding enough, but too noisy: say so per parameter rather than "too little sliding".
      for (int i = 0; i < 3; ++i) result.parameters[i] = NotIdentifiable(kNaN, set.snr_reason);
      result.message = "no log's friction impulses stand out of its noise";
      result.Conclude(true);
      return result;
    }
    result.status = TerminationStatus::kTooLittleExcitation;
    result.converged = false;
    result.message =
        "too little sliding to identify anything: " + std::to_string(result.steps_used) + " of " +
        std::to_string(result.steps_total) + " steps usable" + RateTooHighNote(set.log_steps);
    return result;
  }

  const FitOutcome fit =
      FitWithIdentifiability(set.fit, SeedOf(seed_result, set.log_steps[0].radius_m), identify);
  result.iterations = fit.iterations;
  result.final_cost = fit.summary.final_cost;
  const bool solve_converged =
      fit.summary.termination_type == ceres::CONVERGENCE && fit.at_solution.ok;
  result.message = fit.summary.BriefReport();
  if (!fit.at_solution.ok) result.message += "; the model could not be evaluated at the solution";

  // Intervals: the robust sandwich, over blocks of steps, and over logs where wider.
  std::vector<int> free;
  for (int i = 0; i < 3; ++i) {
    if (fit.active[i]) free.push_back(i);
  }
  std::vector<int> lag_of_log;
  for (const LogSteps& s : set.log_steps) lag_of_log.push_back(s.lag);
  Sandwich sandwich;
  if (!free.empty() && fit.at_solution.ok) {
    sandwich = RobustSandwich(set.fit, fit.at_solution, fit.loss.get(), free, lag_of_log,
                              fit.theta.data());
    if (!sandwich.ok) result.message += "; covariance could not be computed";
  }
  // Errors in variables (estimator/simex.h), when the residuals show the noise the logs'
  // velocities carry: the noise read off an exact log is its motion's own curvature
  // (DiagnoseLog), which leaves no residual, and SIMEX would add noise the log never had.
  const double noise_scale = NoiseResidualScale(set);
  const double residual_scale = fit.at_solution.ok ? RobustScale(fit.at_solution) : kNaN;
  SimexBias bias;
  bias.bias_log = {{kNaN, kNaN, kNaN}};
  const bool noisy = residual_scale >= kMinNoiseShown * noise_scale && noise_scale > 0;
  if (identify.equation_error.correct_noise_bias && !free.empty() && solve_converged && noisy) {
    bias = EstimateSimexBias(logs, fit.theta, [&](const std::vector<const Trajectory*>& c) {
      return RefitCopies(c, set, fit);
    });
  }
  for (int i = 0; i < 3; ++i) {
    if (!fit.active[i]) result.parameters[i] = NotIdentifiable(fit.seed[i], fit.held_note[i]);
  }
  for (size_t a = 0; a < free.size(); ++a) {
    const int i = free[a];
    LogEstimate e = ChooseInterval(sandwich, static_cast<int>(a), i == kC);
    // Without noise the residuals themselves tell the readings apart: a fit to rounding
    // level rules the others out.
    if (!noisy) e.force_hold_shift_log = 0;
    e.log_value = fit.theta[i];
    std::string reason;
    if (!CorrectNoiseBias(bias, i, &e, &reason)) {
      result.parameters[i] = NotIdentifiable(kNaN, reason);
      continue;
    }
    result.parameters[i] = FromLogEstimate(e);
  }
  PlausibilityContext context = CheapContext(set.log_steps);
  // Model mismatch: residuals far above what the velocity noise leaves.
  if (noise_scale > 0) {
    context.residual_rms = result.residual_rms = residual_scale;
    context.log_noise = result.log_noise = noise_scale;
  }
  for (int i = 0; i < 3; ++i) {
    context.seed[i] = seed_result.parameters[i].identifiable ? fit.seed[i] : kNaN;
  }
  context.lower = kFrictionLowerBound;
  context.upper = kFrictionUpperBound;
  JudgeEstimates(context, &result.parameters);
  if (result.parameters[kC].identifiable && set.rotation_snr < kMinImpulseSnr) {
    result.parameters[kC] = NotIdentifiable(result.parameters[kC].value, set.rotation_reason);
  }
  FillResiduals(logs, set, fit.at_solution, &result);
  // Usable is not converged: a solve cut off by the iteration limit is usable to Ceres.
  result.Conclude(solve_converged);
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

EstimateResult EstimateEquationError(const Trajectory& log, const IdentifyOptions& identify) {
  return EstimateAs(EstimatorMethod::kEquationError, {&log}, identify);
}

EstimateResult EstimateEquationError(const std::vector<Trajectory>& logs,
                                     const IdentifyOptions& identify) {
  return EstimateAs(EstimatorMethod::kEquationError, Pointers(logs), identify);
}

}  // namespace slideid
