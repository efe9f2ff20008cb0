#include "estimator/estimate.h"

#include <cmath>

namespace slideid {
namespace {

bool Fail(std::string* why, const char* text) {
  if (why) *why = text;
  return false;
}

}  // namespace

const char* ToString(EstimatorMethod method) {
  switch (method) {
    case EstimatorMethod::kClosedForm:
      return "closed-form";
    case EstimatorMethod::kEquationError:
      return "equation-error";
    case EstimatorMethod::kTrajectory:
      return "trajectory";
    case EstimatorMethod::kQuasiStatic:
      return "quasi-static";
  }
  return "?";
}

const char* ToString(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::kNone:
      return "none";
    case RobustLoss::kHuber:
      return "huber";
    case RobustLoss::kCauchy:
      return "cauchy";
  }
  return "?";
}

const char* ToString(Verdict verdict) {
  switch (verdict) {
    case Verdict::kOk:
      return "ok";
    case Verdict::kSuspect:
      return "suspect";
    case Verdict::kNotIdentifiable:
      return "not identifiable";
  }
  return "?";
}

const char* ToString(TerminationStatus status) {
  switch (status) {
    case TerminationStatus::kConverged:
      return "converged";
    case TerminationStatus::kConvergedWithCaveats:
      return "converged with caveats";
    case TerminationStatus::kNoConvergence:
      return "no convergence";
    case TerminationStatus::kTooLittleExcitation:
      return "too little excitation";
  }
  return "?";
}

const char* ParameterName(int index) {
  static const char* const kNames[] = {"e_t_mu", "e_o_over_e_t", "e_r_over_e_t"};
  return index >= 0 && index < 3 ? kNames[index] : "?";
}

void EstimateResult::Exclude(const std::string& reason, int count) {
  for (auto& entry : steps_excluded) {
    if (entry.first == reason) {
      entry.second += count;
      return;
    }
  }
  steps_excluded.emplace_back(reason, count);
}

void EstimateResult::Conclude(bool solve_converged) {
  if (status == TerminationStatus::kTooLittleExcitation) {
    converged = false;
    return;
  }
  if (!solve_converged) {
    status = TerminationStatus::kNoConvergence;
    converged = false;
    return;
  }
  bool all_ok = true;
  for (const ParameterEstimate& p : parameters) all_ok = all_ok && p.verdict == Verdict::kOk;
  for (const NuisanceEstimate& n : nuisance) all_ok = all_ok && n.verdict == Verdict::kOk;
  status = all_ok ? TerminationStatus::kConverged : TerminationStatus::kConvergedWithCaveats;
  converged = true;
}

bool ClosedFormOptions::IsValid(std::string* why) const {
  if (!(divisor_fraction > 0 && divisor_fraction < 1)) {
    return Fail(why, "closed form: divisor fraction must be in (0, 1)");
  }
  return true;
}

bool LossOptions::IsValid(std::string* why) const {
  if (!(loss_scale_sigmas > 0) || !std::isfinite(loss_scale_sigmas)) {
    return Fail(why, "loss scale must be a finite number > 0");
  }
  if (max_iterations < 1) return Fail(why, "max iterations must be >= 1");
  return true;
}

bool TrajectoryOptions::IsValid(std::string* why) const {
  if (!LossOptions::IsValid(why)) return false;
  if (segment_steps != 0 && segment_steps < 2) {
    return Fail(why, "--segment must be >= 2 (or 0: adapt to the log)");
  }
  if (substeps < 1) return Fail(why, "--substeps must be >= 1");
  if (!(max_delay_s > 0) || !std::isfinite(max_delay_s)) {
    return Fail(why, "the largest delay must be a finite number > 0");
  }
  return true;
}

bool IdentifyOptions::IsValid(std::string* why) const {
  if (threads < 1) return Fail(why, "--threads must be >= 1");
  switch (method) {
    case EstimatorMethod::kClosedForm:
      return closed_form.IsValid(why);
    case EstimatorMethod::kEquationError:
      return closed_form.IsValid(why) && equation_error.IsValid(why);
    case EstimatorMethod::kTrajectory:  // seeded by both cheap methods
      return closed_form.IsValid(why) && equation_error.IsValid(why) && trajectory.IsValid(why);
    case EstimatorMethod::kQuasiStatic:
      return quasi_static.IsValid(why);
  }
  return Fail(why, "unknown method");
}

}  // namespace slideid
