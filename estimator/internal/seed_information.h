#pragma once
// What the trajectory fit's information says before the fit: J at the point the fit starts
// from (its seeds), through the fit's own problem and Ceres cost functions, judged by the
// fit's own identifiability rules (estimator/identifiability.h). Internal: the pre-fit
// check (estimator/log_check.h) is its user.

#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "estimator/identifiability.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// The information of (log a, log b, log c) at the trajectory fit's seed.
struct SeedInformation {
  /// Empty when the information was computed; else why not (too short for one shooting
  /// segment, a dead force channel: what the fit would answer "too little excitation" with).
  std::string failure;
  ReducedFriction seed{0, 0, 0};  ///< the friction the fit starts from
  /// J^T J of (log a, log b, log c), the segment states and any sensor nuisances
  /// marginalised out (Schur complement), in units of the residuals [m^2 or (m/s)^2].
  Eigen::Matrix3d fisher = Eigen::Matrix3d::Zero();
  /// The residual variance the verdicts assume [m^2 or (m/s)^2]: the lesser of the log's own
  /// noise and the residuals at the seed, per residual (each a guess at what the fit's
  /// residuals will be: the seed's exceed them where the seed is off, the noise where the
  /// model misses the log).
  double residual_variance = std::numeric_limits<double>::quiet_NaN();
  /// The fit's rules applied to every global parameter (a, b, c first, then any sensor
  /// nuisances the options fit), with the thresholds the fit uses.
  std::vector<ParameterIdentifiability> verdicts;
  std::vector<std::string> names;  ///< of the global parameters, as the fit names them
  int segments = 0;                ///< shooting segments with information
  int rows = 0;                    ///< rows inside segments
};

/// The information of `log` (slider properties set) at the seed the trajectory fit of
/// `options` starts from: the closed-form and equation-error candidates, the scan of a and
/// the first fit on the segments' heads (trajectory_fit.cc, "seeds"). Costs the seeding
/// alone, a fraction of the fit. Throws std::invalid_argument for invalid options.
SeedInformation TrajectoryInformationAtSeed(const Trajectory& log, const IdentifyOptions& options);

}  // namespace slideid
