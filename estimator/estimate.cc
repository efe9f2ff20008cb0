#include "estimator/estimate.h"

namespace slideid {

const char* ToString(EstimatorMethod method) {
  switch (method) {
    case EstimatorMethod::kClosedForm: return "closed-form";
    case EstimatorMethod::kEquationError: return "equation-error";
    case EstimatorMethod::kTrajectory: return "trajectory";
    case EstimatorMethod::kQuasiStatic: return "quasi-static";
  }
  return "?";
}

const char* ToString(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::kNone: return "none";
    case RobustLoss::kHuber: return "huber";
    case RobustLoss::kCauchy: return "cauchy";
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

bool EstimatorOptions::IsValid(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(loss_scale_sigmas > 0)) return fail("loss scale must be > 0");
  if (segment_steps < 2) return fail("--segment must be >= 2");
  if (substeps < 1) return fail("--substeps must be >= 1");
  if (threads < 1) return fail("--threads must be >= 1");
  if (max_iterations < 1) return fail("max iterations must be >= 1");
  return true;
}

}  // namespace slideid
