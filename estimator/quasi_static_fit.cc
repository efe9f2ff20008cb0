#include "estimator/quasi_static_fit.h"

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "estimator/identifiability.h"
#include "estimator/internal/log_friction.h"
#include "estimator/internal/quasi_static_residuals.h"
#include "estimator/plausibility.h"
#include "estimator/pooling.h"
#include "estimator/robust_statistics.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Median of the norm of a 2-D standard Gaussian, sqrt(2 ln 2): the per-axis sigma of the
/// direction residuals is their median length over this.
constexpr double kRayleighMedian = 1.1774100225154747;
/// Seed of c when the pairs give neither a spin nor a moment arm [m]: a hand-sized object.
/// It only starts the fit, or is the value c is held at when nothing determines it.
constexpr double kFallbackSeedC_m = 0.02;

std::string Short(double x) { return Printf("%.3g", x); }

void CheckPairs(const std::vector<WrenchTwistPair>& pairs, double weight_n) {
  if (static_cast<int>(pairs.size()) < kMinQuasiStaticPairs) {
    throw std::invalid_argument(
        "too few wrench-twist pairs to identify anything: " + std::to_string(pairs.size()) +
        " (need at least " + std::to_string(kMinQuasiStaticPairs) + ")");
  }
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const WrenchTwistPair& p = pairs[i];
    const std::string which = "pair " + std::to_string(i + 1) + ": ";
    const double all[] = {p.fx, p.fy, p.fz, p.mz, p.vx, p.vy, p.wz};
    for (double x : all) {
      if (!std::isfinite(x)) throw std::invalid_argument(which + "not finite");
    }
    if (p.fx == 0.0 && p.fy == 0.0 && p.mz == 0.0) {
      throw std::invalid_argument(which + "the applied wrench (fx, fy, mz) is zero");
    }
    if (p.vx == 0.0 && p.vy == 0.0 && p.wz == 0.0) {
      throw std::invalid_argument(which + "the twist (vx, vy, wz) is zero");
    }
    if (!(weight_n - p.fz > 0.0)) {
      throw std::invalid_argument(which + "the normal force m g - fz is not positive");
    }
  }
}

/// The seed: b = 1, c from the spins, a from the wrench norms (see the header).
ReducedFriction Seed(const std::vector<WrenchTwistPair>& pairs, double weight_n,
                     double length_scale_m) {
  std::vector<double> c_candidates, arms;
  for (const WrenchTwistPair& p : pairs) {
    const double f = std::hypot(p.fx, p.fy), v = std::hypot(p.vx, p.vy);
    if (f > 0.0 && p.mz != 0.0) arms.push_back(std::abs(p.mz) / f);
    if (f > 0.0 && v > 0.0 && p.mz * p.wz > 0.0) {
      const double c2 = p.mz * v / (f * p.wz);
      if (std::isfinite(c2) && c2 > 0.0) c_candidates.push_back(std::sqrt(c2));
    }
  }
  double c = kFallbackSeedC_m;
  if (!c_candidates.empty()) {
    c = Median(c_candidates);
  } else if (length_scale_m > 0.0) {
    c = length_scale_m;
  } else if (!arms.empty() && Median(arms) > 0.0) {
    c = Median(arms);
  }
  std::vector<double> a;
  for (const WrenchTwistPair& p : pairs) {
    a.push_back(std::hypot(p.fx, p.fy, p.mz / c) / (weight_n - p.fz));
  }
  return {Median(a), 1.0, c};
}

/// Weighted residuals of every pair, their Jacobian's J^T J in theta, and raw parts.
struct Linearisation {
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  double sum_squares = 0;              ///< weighted
  std::vector<double> magnitude;       ///< unweighted log ratios
  std::vector<Eigen::Vector3d> chord;  ///< unweighted direction chords
  bool ok = true;
};

struct Costs {
  std::vector<std::unique_ptr<ceres::CostFunction>> magnitude, direction;
  double w_magnitude = 1.0, w_direction = 1.0;
};

Linearisation Linearise(const Costs& costs, const double* theta) {
  Linearisation out;
  const double* params[3] = {&theta[0], &theta[1], &theta[2]};
  for (std::size_t i = 0; i < costs.magnitude.size(); ++i) {
    double rm[1], jm[3][1], rd[3], jd[3][3];
    double* jac_m[3] = {jm[0], jm[1], jm[2]};
    double* jac_d[3] = {jd[0], jd[1], jd[2]};
    if (!costs.magnitude[i]->Evaluate(params, rm, jac_m) ||
        !costs.direction[i]->Evaluate(params, rd, jac_d)) {
      out.ok = false;
      return out;
    }
    Eigen::Matrix<double, 4, 3> j;
    j.row(0) << jm[0][0], jm[1][0], jm[2][0];
    for (int k = 0; k < 3; ++k) j.row(k + 1) << jd[0][k], jd[1][k], jd[2][k];
    out.information += j.transpose() * j;
    out.sum_squares += rm[0] * rm[0] + rd[0] * rd[0] + rd[1] * rd[1] + rd[2] * rd[2];
    out.magnitude.push_back(rm[0] / costs.w_magnitude);
    out.chord.push_back(Eigen::Vector3d(rd[0], rd[1], rd[2]) / costs.w_direction);
  }
  return out;
}

/// Robust scales of the two residual kinds (unweighted), floored.
std::pair<double, double> ResidualScales(const Linearisation& l) {
  const double centre = Median(l.magnitude);
  std::vector<double> deviation, length;
  for (double r : l.magnitude) deviation.push_back(std::abs(r - centre));
  for (const Eigen::Vector3d& c : l.chord) length.push_back(c.norm());
  return {std::max(kMadToSigma * Median(deviation), kMinQuasiStaticSigma),
          std::max(Median(length) / kRayleighMedian, kMinQuasiStaticSigma)};
}

}  // namespace

bool QuasiStaticFitOptions::IsValid(std::string* why) const {
  if (!method.IsValid(why)) return false;
  if (threads < 1) {
    if (why) *why = "--threads must be >= 1";
    return false;
  }
  if (!(std::isfinite(weight_n) && weight_n > 0.0)) {
    if (why) *why = "the weight m g must be finite and > 0";
    return false;
  }
  if (!(std::isfinite(length_scale_m) && length_scale_m >= 0.0)) {
    if (why) *why = "the length scale must be finite and >= 0";
    return false;
  }
  return true;
}

QuasiStaticFitOptions QuasiStaticOptionsFor(const WrenchTwistData& data,
                                            const IdentifyOptions& options) {
  QuasiStaticFitOptions o;
  o.method = options.quasi_static;
  o.threads = options.threads;
  o.weight_n = data.WeightN();
  if (data.inertia_kgm2 && data.mass_kg > 0.0) {
    o.length_scale_m = std::sqrt(*data.inertia_kgm2 / data.mass_kg);
  }
  return o;
}

EstimateResult EstimateQuasiStatic(const std::vector<WrenchTwistPair>& pairs,
                                   const QuasiStaticFitOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("EstimateQuasiStatic: " + why);
  CheckPairs(pairs, options.weight_n);
  const ReducedFriction seed_value = Seed(pairs, options.weight_n, options.length_scale_m);
  const double length = options.length_scale_m > 0.0 ? options.length_scale_m : seed_value.c;
  std::array<double, 3> start;  // the seed's log a, log b, log c, where a held block stays
  ToLogParameters(seed_value, start.data());
  // The seed as the blocks hold it (log_friction.h): a held parameter's value.
  const ReducedFriction seed = FromLogParameters(start.data());
  std::array<double, 3> theta = start;  // the fit's parameter blocks

  EstimateResult result;
  result.method = EstimatorMethod::kQuasiStatic;
  result.steps_total = result.steps_used = static_cast<int>(pairs.size());
  result.residual_names = {{"log_wrench_ratio", "twist_angle_rad", "spin_share_misfit"}};

  Costs costs;
  for (const WrenchTwistPair& p : pairs) {
    costs.magnitude.emplace_back(
        LimitSurfaceMagnitudeResidual::Create(p, options.weight_n - p.fz, &costs.w_magnitude));
    costs.direction.emplace_back(TwistDirectionResidual::Create(p, length, &costs.w_direction));
  }
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  // Residuals are in units of their scales after weighting: the loss scale is in sigmas.
  const double loss_scale = options.method.loss_scale_sigmas;
  std::unique_ptr<ceres::LossFunction> loss;
  if (options.method.loss == RobustLoss::kHuber) {
    loss = std::make_unique<ceres::HuberLoss>(loss_scale);
  }
  if (options.method.loss == RobustLoss::kCauchy) {
    loss = std::make_unique<ceres::CauchyLoss>(loss_scale);
  }
  auto build = [&](ceres::LossFunction* loss_function, const std::array<bool, 3>& active) {
    auto problem = std::make_unique<ceres::Problem>(problem_options);
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      problem->AddResidualBlock(costs.magnitude[i].get(), loss_function, &theta[0], &theta[1],
                                &theta[2]);
      problem->AddResidualBlock(costs.direction[i].get(), loss_function, &theta[0], &theta[1],
                                &theta[2]);
    }
    for (int i = 0; i < 3; ++i) {
      if (!active[i]) problem->SetParameterBlockConstant(&theta[i]);
    }
    return problem;
  };
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.method.max_iterations;
  solver_options.num_threads = options.threads;
  solver_options.logging_type = ceres::SILENT;
  // As in equation_error.cc: Ceres' gradient tolerance is absolute; the function and
  // parameter tolerances end every fit.
  solver_options.gradient_tolerance = 0.0;
  ceres::Solver::Summary summary;
  result.iterations = 0;
  auto solve = [&](const std::array<bool, 3>& active) {
    auto problem = build(loss.get(), active);
    ceres::Solve(solver_options, problem.get(), &summary);
    result.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
  };
  auto reweight = [&]() {
    const Linearisation l = Linearise(costs, theta.data());
    if (!l.ok) return;
    const auto [sigma_m, sigma_d] = ResidualScales(l);
    costs.w_magnitude = 1.0 / sigma_m;
    costs.w_direction = 1.0 / sigma_d;
  };

  // Weights from the residuals at the seed, a first robust fit, weights again at its
  // solution: the seed's misfit is not noise, the first fit's nearly is.
  const std::array<bool, 3> all{{true, true, true}};
  reweight();
  solve(all);
  reweight();

  // Fit, judge identifiability, hold what is not identifiable at its seed, refit.
  std::array<bool, 3> active = all;
  std::array<std::string, 3> held_note;
  Linearisation at_solution;
  double variance = kNaN;
  for (int pass = 0; pass < 4; ++pass) {  // each pass but the last holds >= 1 more
    for (int i = 0; i < 3; ++i) {
      if (!active[i]) theta[i] = start[i];
    }
    solve(active);
    at_solution = Linearise(costs, theta.data());
    const int n_free = static_cast<int>(std::count(active.begin(), active.end(), true));
    const int dof = 3 * static_cast<int>(pairs.size()) - n_free;
    if (!at_solution.ok || dof <= 0) break;
    variance = at_solution.sum_squares / dof;
    const auto verdict = AssessIdentifiability(at_solution.information, variance, active);
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
    if (!active[i]) theta[i] = start[i];
  }
  result.final_cost = summary.final_cost;
  const bool solve_converged = summary.termination_type == ceres::CONVERGENCE && at_solution.ok;
  result.message = summary.BriefReport() + "; residual scales: magnitude " +
                   Short(1.0 / costs.w_magnitude) + " (log ratio), direction " +
                   Short(1.0 / costs.w_direction) +
                   " (per axis); twist length scale L = " + Short(length) + " m";
  if (!at_solution.ok) result.message += "; the model could not be evaluated at the solution";

  std::array<double, 3> log_stderr{{kNaN, kNaN, kNaN}};
  const bool any_active = std::any_of(active.begin(), active.end(), [](bool x) { return x; });
  if (any_active && std::isfinite(variance)) {
    auto plain = build(nullptr, active);
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::DENSE_SVD;
    covariance_options.num_threads = options.threads;
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
    result.parameters[i] = active[i] ? EstimateFromLog(theta[i], log_stderr[i])
                                     : NotIdentifiable(seed[i], held_note[i]);
  }
  PlausibilityContext context;
  context.seed = seed;
  JudgeEstimates(context, &result.parameters);
  result.Conclude(solve_converged);

  for (std::size_t i = 0; i < pairs.size(); ++i) {
    StepResidual r;
    r.row = static_cast<int>(i);
    r.t_s = kNaN;
    if (at_solution.ok) {
      const Eigen::Vector3d& chord = at_solution.chord[i];
      // The chord is xi_hat - n_hat; its length is 2 sin(angle / 2).
      r.value = {{at_solution.magnitude[i], 2.0 * std::asin(std::min(1.0, 0.5 * chord.norm())),
                  -chord.z()}};
    } else {
      r.value = {{kNaN, kNaN, kNaN}};
    }
    result.residuals.push_back(r);
  }
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

namespace {

class QuasiStaticMethod : public PoolableFit {
 public:
  QuasiStaticMethod(const std::vector<WrenchTwistData>& sets, const IdentifyOptions& options)
      : sets_(sets), options_(options) {}

  LogResult FitAlone(int k) override {
    const EstimateResult own = Fit(sets_[k]);
    LogResult r;
    r.name = sets_[k].source;
    r.rows = static_cast<int>(sets_[k].rows.size());
    r.steps_used = own.steps_used;
    r.status = own.status;
    r.message = own.message;
    r.parameters = own.parameters;
    return r;
  }

  EstimateResult FitTogether(std::vector<LogResult>* alone) override {
    if (!alone) return Fit(sets_[0]);
    WrenchTwistData all = sets_[0];
    for (size_t k = 1; k < sets_.size(); ++k) {
      all.rows.insert(all.rows.end(), sets_[k].rows.begin(), sets_[k].rows.end());
    }
    return Fit(all);
  }

 private:
  EstimateResult Fit(const WrenchTwistData& set) const {
    try {
      return EstimateQuasiStatic(set.Pairs(), QuasiStaticOptionsFor(set, options_));
    } catch (const std::invalid_argument& e) {  // too few pairs, a zero twist, ...
      throw std::invalid_argument(set.source + ": " + e.what());
    }
  }

  const std::vector<WrenchTwistData>& sets_;
  const IdentifyOptions& options_;
};

}  // namespace

EstimateResult EstimateQuasiStatic(const std::vector<WrenchTwistData>& sets,
                                   const IdentifyOptions& options) {
  for (const WrenchTwistData& set : sets) {
    if (std::abs(set.WeightN() / sets[0].WeightN() - 1) > kSameWeightRelative) {
      throw std::invalid_argument(set.source + ": its slider weighs " +
                                  std::to_string(set.WeightN()) + " N, " + sets[0].source + "'s " +
                                  std::to_string(sets[0].WeightN()) +
                                  " N: pooled pairs must come from one slider");
    }
  }
  QuasiStaticMethod method(sets, options);
  return FitOneOrMany(static_cast<int>(sets.size()), &method);
}

}  // namespace slideid
