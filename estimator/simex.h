#pragma once
// Errors in variables, corrected by simulation and extrapolation (SIMEX; Cook & Stefanski,
// JASA 1994), for the equation error (estimator/equation_error.h).
//
// The equation error reads the friction off each step's measured velocities: the same noisy
// sample is both in the impulse m (v' - v) and in the direction of sliding v', and a
// direction of noisy quantities is biased, not just noisy (a by -0.3% at 2 mm/s on the
// datasets' logs, one to two of its standard errors on a 450-row log, more on longer ones).
// To first order that bias grows with the noise variance. SIMEX measures it: it adds as much
// noise again (lambda = 1, from the noise the log itself shows) to kSimexReplicates copies,
// re-estimates on the same steps, and takes the mean change as the bias of the estimate at
// the log's own noise; the corrected estimate is the estimate less that bias (linear
// extrapolation to no noise). (The closed form's robust mean over per-step ratios is not
// smooth enough for it: its corrections were noisier than its bias.)

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "estimator/cheap_methods.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Noisier copies per SIMEX estimate. The bias is estimated with a standard error of about
/// the estimate's own over sqrt(kSimexReplicates) (the added noise moves each copy by about
/// one standard error): 16 copies keep it at a quarter, which widens the corrected
/// interval by 3%.
constexpr int kSimexReplicates = 16;

/// Fewest replicates that must give an estimate for the bias to be taken.
constexpr int kMinSimexReplicates = 8;

/// A bias larger than this in log(parameter) (about 15%) is outside what a linear
/// extrapolation in the noise variance describes: the parameter is then not identifiable
/// by the cheap methods (its noise dominates).
constexpr double kMaxSimexBiasLog = 0.15;

/// What SIMEX found for each parameter, in log(parameter); NaN where not estimated.
struct SimexBias {
  std::array<double, 3> bias_log;    ///< mean change of the estimate with the noise doubled
  std::array<double, 3> stderr_log;  ///< standard error of that mean
  std::array<int, 3> replicates{};   ///< copies that gave an estimate
};

/// The logs' estimate (log a, log b, log c; NaN where none) as a function of the logs.
using LogEstimator =
    std::function<std::array<double, 3>(const std::vector<const Trajectory*>& logs)>;

/// SIMEX with lambda = 1 around `at_log_noise` (the estimate on `logs` themselves): adds to
/// each log Gaussian noise of the standard deviation it shows (DiagnoseLog: on vx, vy, wz
/// when the log has velocities, on x, y, theta otherwise), kSimexReplicates times with fixed
/// seeds, and re-estimates with `estimate`. A log that shows no noise is left as it is.
SimexBias EstimateSimexBias(const std::vector<const Trajectory*>& logs,
                            const std::array<double, 3>& at_log_noise,
                            const LogEstimator& estimate);

/// Subtracts parameter i's SIMEX bias from `e` and adds its standard error to e's in
/// quadrature, with a note saying by how much. Returns false, with the reason, when the
/// bias is beyond kMaxSimexBiasLog; leaves `e` as it is when no bias was estimated.
bool CorrectNoiseBias(const SimexBias& bias, int i, LogEstimate* e, std::string* reason);

}  // namespace slideid
