#include "estimator/identify.h"

#include <stdexcept>

#include "estimator/internal/method_cores.h"
#include "estimator/pooling.h"
#include "estimator/pusher_friction.h"

namespace slideid {
namespace {

EstimateResult IdentifyLogs(const std::vector<const Trajectory*>& logs,
                            const IdentifyOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  if (options.method == EstimatorMethod::kQuasiStatic) {
    throw std::invalid_argument(
        "the quasi-static method fits wrench-twist pairs "
        "(EstimateQuasiStatic), not push logs");
  }
  EstimateResult r = EstimateOneOrMany(logs, options);
  AddPusherFriction(logs, &r);  // mu_p, from the tip's path where the logs have it
  return r;
}

}  // namespace

EstimateResult EstimateOneOrMany(const std::vector<const Trajectory*>& logs,
                                 const IdentifyOptions& options) {
  if (logs.empty()) throw std::invalid_argument("no logs to fit");
  if (std::optional<EstimateResult> dead = DeadSensorResult(logs, options.method)) return *dead;
  switch (options.method) {
    case EstimatorMethod::kClosedForm:
      return FitOneOrMany(logs, [&](const std::vector<const Trajectory*>& some) {
        return ClosedFormCore(some, options);
      });
    case EstimatorMethod::kEquationError:
      return FitOneOrMany(logs, [&](const std::vector<const Trajectory*>& some) {
        return EquationErrorCore(some, options, ClosedFormCore(some, options));
      });
    case EstimatorMethod::kTrajectory:
      return TrajectoryOneOrMany(logs, options);
    case EstimatorMethod::kQuasiStatic:
      break;
  }
  throw std::invalid_argument(std::string("method ") + ToString(options.method) +
                              " does not take push logs");
}

EstimateResult EstimateAs(EstimatorMethod method, const std::vector<const Trajectory*>& logs,
                          IdentifyOptions options) {
  options.method = method;
  std::string why;
  if (!options.IsValid(&why)) {
    throw std::invalid_argument(std::string(ToString(method)) + ": " + why);
  }
  return EstimateOneOrMany(logs, options);
}

EstimateResult Identify(const Trajectory& log, const IdentifyOptions& options) {
  return IdentifyLogs({&log}, options);
}

EstimateResult Identify(const std::vector<Trajectory>& logs, const IdentifyOptions& options) {
  return IdentifyLogs(Pointers(logs), options);
}

}  // namespace slideid
