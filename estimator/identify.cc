#include "estimator/identify.h"

#include <stdexcept>

#include "estimator/closed_form.h"
#include "estimator/equation_error.h"
#include "estimator/trajectory_fit.h"

namespace slideid {

EstimateResult Identify(const Trajectory& log, const EstimatorOptions& options) {
  switch (options.method) {
    case EstimatorMethod::kClosedForm: return EstimateClosedForm(log, options);
    case EstimatorMethod::kEquationError: return EstimateEquationError(log, options);
    case EstimatorMethod::kTrajectory: return EstimateTrajectory(log, options);
  }
  throw std::invalid_argument("unknown estimator method");
}

}  // namespace slideid
