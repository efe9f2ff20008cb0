#include "pipeline/identify_outcome.h"

#include <cmath>

namespace slideid {

std::string NumericalFailure(const EstimateResult& result) {
  const std::string fit = std::string("the ") + ToString(result.method) + " fit";
  if (!result.converged) return fit + " did not converge (" + result.message + ")";
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = result.parameters[i];
    if (p.identifiable && !(std::isfinite(p.value) && std::isfinite(p.stderr_value) &&
                            std::isfinite(p.ci95_lo) && std::isfinite(p.ci95_hi))) {
      return fit + " gave a non-finite " + ParameterName(i);
    }
  }
  return "";
}

std::string SuspectEstimates(const EstimateResult& result) {
  std::string names;
  for (int i = 0; i < 3; ++i) {
    if (result.parameters[i].verdict == Verdict::kSuspect) {
      names += (names.empty() ? "" : ", ") + std::string(ParameterName(i));
    }
  }
  for (const NuisanceEstimate& n : result.nuisance) {
    if (n.verdict == Verdict::kSuspect) names += (names.empty() ? "" : ", ") + n.name;
  }
  return names;
}

}  // namespace slideid
