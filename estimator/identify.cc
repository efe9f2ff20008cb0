#include "estimator/identify.h"

#include <stdexcept>

#include "estimator/closed_form.h"
#include "estimator/equation_error.h"
#include "estimator/log_diagnostics.h"
#include "estimator/pusher_friction.h"
#include "estimator/trajectory_fit.h"

namespace slideid {

EstimateResult Identify(const Trajectory& log, const IdentifyOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  // A force channel that never changes while the object moves is a dead sensor, whatever
  // the method (it would read as too little sliding, or fit nonsense).
  if (const auto dead = DiagnoseLog(log).dead_force_channel) {
    EstimateResult r;
    r.method = options.method;
    r.status = TerminationStatus::kTooLittleExcitation;
    r.converged = false;
    r.message = *dead;
    return r;
  }
  EstimateResult r;
  switch (options.method) {
    case EstimatorMethod::kClosedForm:
      r = EstimateClosedForm(log, options);
      break;
    case EstimatorMethod::kEquationError:
      r = EstimateEquationError(log, options);
      break;
    case EstimatorMethod::kTrajectory:
      r = EstimateTrajectory(log, options);
      break;
    case EstimatorMethod::kQuasiStatic:
      throw std::invalid_argument(
          "the quasi-static method fits wrench-twist pairs "
          "(EstimateQuasiStatic), not a push log");
  }
  AddPusherFriction({&log}, &r);  // mu_p, from the tip's path where the log has it
  return r;
}

EstimateResult Identify(const std::vector<Trajectory>& logs, const IdentifyOptions& options) {
  if (logs.size() == 1) return Identify(logs[0], options);
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  if (options.method != EstimatorMethod::kTrajectory) {  // the trajectory fit checks its own
    for (size_t k = 0; k < logs.size(); ++k) {
      if (const auto dead = DiagnoseLog(logs[k]).dead_force_channel) {
        EstimateResult r;
        r.method = options.method;
        r.status = TerminationStatus::kTooLittleExcitation;
        r.converged = false;
        r.message =
            (logs[k].source.empty() ? "log " + std::to_string(k) : logs[k].source) + ": " + *dead;
        return r;
      }
    }
  }
  EstimateResult r;
  switch (options.method) {
    case EstimatorMethod::kClosedForm:
      r = EstimateClosedForm(logs, options);
      break;
    case EstimatorMethod::kEquationError:
      r = EstimateEquationError(logs, options);
      break;
    case EstimatorMethod::kTrajectory:
      r = EstimateTrajectory(logs, options);
      break;
    case EstimatorMethod::kQuasiStatic:
      throw std::invalid_argument(std::string("method ") + ToString(options.method) +
                                  " does not take push logs");
  }
  std::vector<const Trajectory*> pointers;
  for (const Trajectory& log : logs) pointers.push_back(&log);
  AddPusherFriction(pointers, &r);
  return r;
}

}  // namespace slideid
