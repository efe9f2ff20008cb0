#pragma once
// The trajectory (output-error) estimator: Ceres robust least squares of the simulated
// trajectory against the measured one, over one log or over several logs pooled.
//
// Each log is cut into shooting segments (TrajectorySegmentSteps intervals each). Each
// segment's initial state (x, y, theta, v_x, v_y, w_z) is a parameter block of its own,
// (log a, log b, log c) are shared by every segment of every log, and each log may add
// sensor nuisances (a force offset, a delay: TrajectoryOptions). This is the
// structure of bundle adjustment, solved with Ceres' Schur complement (segments eliminated
// first). Within a segment the forward model is simulated from the segment's state with
// the logged wrench, substeps per log interval, sticking included; the residuals are the
// measured poses (or velocities, for a log without poses) minus the simulated ones, each
// row robustified on its own at a scale set by the noise the log itself shows
// (estimator/log_diagnostics.h). Derivatives through each step are exact.
//
// Intervals: the white-noise covariance (s^2 times the inverse of the marginal information)
// and the cluster-robust (sandwich) covariances with the segments, and for a pooled fit the
// logs, as clusters, with the small-sample factor G / (G - 1) and Student's t quantile on
// G - 1 degrees of freedom. The widest of these is reported and the table says which: the
// residuals of real and coarsely sampled logs are correlated within a segment (forces are
// noisy and held over each row), and pooled logs differ by more than their noise.

#include <memory>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Fits (a, b, c) to `log` (slider properties set; rows strictly increasing in time).
/// Seeds (b, c) from the closed form, a from a scan of the trajectory cost. A log that
/// determines nothing gives status kTooLittleExcitation, with the reason in the message.
/// Throws std::invalid_argument for invalid options.
EstimateResult EstimateTrajectory(const Trajectory& log, const IdentifyOptions& options);

/// Fits (a, b, c) shared by every log, each log with its own segments, slider properties
/// and nuisances; result.logs holds every log fitted on its own (which also seed the pooled
/// fit) and result.heterogeneity whether they agree. One log: as EstimateTrajectory(log).
EstimateResult EstimateTrajectory(const std::vector<Trajectory>& logs,
                                  const IdentifyOptions& options);

/// A pooled fit kept, to start fits of subsets of its logs from: cross-validation's folds.
/// A subset's fit starts at the pooled friction and at each log's pooled segment states and
/// skips the logs' own fits (which only seed a pooled fit and test its heterogeneity), so
/// it costs one pooled solve from nearby. Its result has no per-log fits (logs empty).
class PooledTrajectoryFit {
 public:
  /// The pooled fit of `logs` (at least 2), as EstimateTrajectory(logs, options).
  PooledTrajectoryFit(std::vector<Trajectory> logs, const IdentifyOptions& options);
  ~PooledTrajectoryFit();
  PooledTrajectoryFit(const PooledTrajectoryFit&) = delete;
  PooledTrajectoryFit& operator=(const PooledTrajectoryFit&) = delete;

  const EstimateResult& result() const;
  /// The pooled fit of the logs `subset` (indices into the logs given), started here; a fit
  /// of their own when the full fit did not converge. Thread-safe: it only reads this.
  EstimateResult FitSubset(const std::vector<int>& subset) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace slideid
