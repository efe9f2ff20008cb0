#pragma once
// What an identification's outcome means for its caller: whether it may be used at all (a
// numerical failure), and which estimates are doubtful. `identify` maps these to its exit
// code and messages, the Python module to its exceptions and warnings.

#include <string>

#include "estimator/estimate.h"

namespace slideid {

/// Why `result` must not be used (the fit did not converge, or gave a non-finite estimate
/// of an identifiable parameter), or "" when it may.
std::string NumericalFailure(const EstimateResult& result);

/// The suspect estimates, comma-separated ("e_t_mu, force_bias_x_N"), or "" when none is.
std::string SuspectEstimates(const EstimateResult& result);

}  // namespace slideid
