#pragma once
// The cost of one shooting segment of the trajectory fit (estimator/trajectory_fit.h): the
// forward model simulated from the segment's initial state with the logged wrench, against
// the logged poses (or velocities), with exact derivatives through every step
// (estimator/step_sensitivity.h).
//
// Parameter blocks, in order: the segment's initial state (x, y, theta, v_x, v_y, w_z);
// log a; log b; log c (read by FromLogBlocks, log_friction.h); then, when fitted, the log's force
// offset (o_x, o_y) [N] and its delay [s]. Residuals: 3 per row (x, y, L theta, or v_x, v_y, L
// w_z), L the radius of gyration, each row's triple robustified on its own (SetRowLoss).

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Which sensor nuisances the cost takes as parameter blocks.
struct SegmentNuisances {
  /// (o_x, o_y) [N]: what the force channel reads with no force on the object. The force
  /// on the object is the logged one minus o, applied where the logged force is (its
  /// moment about the CM follows from the push point; at the CM for a log without one).
  bool force_bias = false;
  /// d [s]: the force stream lags the poses by d; the wrench acting over a row's interval
  /// is the logged one over the interval shifted by d (piecewise-constant rows, integrated).
  bool delay = false;
};

/// The wrench acting over the interval starting at `row` when the force stream lags by
/// `delay_s`, and its derivative with respect to the delay [per s].
void DelayedWrench(const Trajectory& log, int row, double delay_s, AppliedWrench* wrench,
                   AppliedWrench* d_wrench_d_delay);

/// The derivative of a row's wrench with respect to the force offset (o_x, o_y): minus the
/// force, and minus its moment about the CM at the row's push point.
void OffsetWrenchJacobian(const Trajectory& log, int row, AppliedWrench* d_wrench_d_ox,
                          AppliedWrench* d_wrench_d_oy);

/// The same when the stream lags by `delay_s`: the offset is read with the stream, so its
/// moment arm is that of the rows the delayed interval reads (OffsetWrenchJacobian averaged
/// as DelayedWrench averages the wrench); also the derivatives of those with respect to
/// the delay [per s].
void DelayedOffsetWrenchJacobian(const Trajectory& log, int row, double delay_s,
                                 AppliedWrench* d_wrench_d_ox, AppliedWrench* d_wrench_d_oy,
                                 AppliedWrench* d2_wrench_d_ox_d_delay,
                                 AppliedWrench* d2_wrench_d_oy_d_delay);

/// A robust loss rho(s) applied to each row's squared residual norm s, inside the cost: the
/// row's residuals are scaled to sqrt(rho(s) / s) r, so that their squared norm is rho(s)
/// (Ceres' own loss would act on the whole segment's norm at once). The Jacobian is that
/// of the scaled residuals, exactly.
struct RowLoss {
  RobustLoss kind = RobustLoss::kNone;
  double scale = 0;  ///< a of Huber or Cauchy, in the residuals' units
  /// Whether it changes any row: a robust kind with a positive scale.
  bool active() const { return kind != RobustLoss::kNone && scale > 0; }
};

/// How the row loss scales a row of squared norm s: r~ = g r, with g' = dg/ds, so that a
/// change dr of the row changes r~ by g dr + 2 g' r (r . dr). SegmentCost's Jacobian and
/// the mismatch directions (mismatch_nuisances.h) are both linearised this way.
struct RowLossScaling {
  double g = 1.0, g_prime = 0.0;
};
/// For a row loss of kind Huber or Cauchy (scale > 0).
RowLossScaling RowLossScalingAt(const RowLoss& loss, double s);

class SegmentCost final : public ceres::CostFunction {
 public:
  /// Rows first_row..last_row of `log` (which must outlive the cost); substeps forward-model
  /// steps per log interval; use_pose: compare poses (else velocities).
  SegmentCost(const Trajectory& log, int first_row, int last_row, int substeps, bool use_pose,
              SegmentNuisances nuisances);

  void SetRowLoss(const RowLoss& loss) { loss_ = loss; }
  /// Replaces the logged wrench of every row u with held_rows[u] != 0 (indexed by the log's
  /// rows; u + 1 must be a row) by the mean of it and row u + 1's: the mismatch directions'
  /// held-force variants (mismatch_nuisances.h), without a copy of the log. Null: the
  /// logged wrenches. `held_rows` must outlive the cost.
  void SetHeldRows(const std::vector<char>* held_rows) { held_rows_ = held_rows; }
  /// Whether SetHeldRows(&held_rows) would change a wrench this segment simulates: a held
  /// row among those whose intervals it steps over, or any held row where a fitted delay
  /// reads rows beyond them.
  bool Holds(const std::vector<char>& held_rows) const;
  /// The raw residuals and every block's Jacobian (row-major, n x the block's size) in the
  /// cost's own storage, which it keeps: a later request for derivatives at the same
  /// parameter values (bit for bit), the information at a solve's final point or a next
  /// solve's iteration zero, then costs no simulation. Valid until the next evaluation;
  /// empty where a step fails. Raw: for a cost without a row loss. The storage is a
  /// Jacobian (8 bytes per residual and parameter) per segment, held until the cost goes.
  std::vector<const double*> EvaluateKept(double const* const* params, double* residuals) const;
  const RowLoss& row_loss() const { return loss_; }
  /// The residuals alone, with or without the row loss (diagnostics, the seed scan).
  bool Residuals(double const* const* params, double* residuals, bool with_row_loss) const;
  /// The simulated state at every row first_row..last_row (in order) at `params`, as the
  /// residuals see it; false where a step fails. Seeds other segmentations of the same log
  /// (TrajectoryProblem::StatesFrom).
  bool SimulatedStates(double const* const* params, std::vector<PlanarState>* states) const;
  int first_row() const { return first_; }
  int last_row() const { return last_; }
  double length_m() const { return length_m_; }

  /// Never throws: an infeasible point (a failed step) returns false.
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override;

 private:
  /// Writes the state at every row into `states` when not null.
  bool Simulate(double const* const* params, double* residuals, double** jacobians,
                std::vector<PlanarState>* states = nullptr) const;
  /// Simulate, or the residuals of the last simulation when asked for no derivatives at
  /// the same parameter values (bit for bit), or for derivatives where EvaluateKept last
  /// evaluated there.
  bool RawResiduals(double const* const* params, double* residuals, double** jacobians) const;
  /// The kept storage's blocks (sized on first use).
  std::vector<double*> KeptBlocks() const;
  /// Copies the kept Jacobian into every block `jacobians` asks for.
  void CopyKeptJacobian(double** jacobians) const;
  void ApplyRowLoss(double* residuals, double** jacobians) const;
  /// The wrench held over row `row`'s interval before any nuisance: the logged one, or its
  /// mean with the next row's (SetHeldRows).
  AppliedWrench RowWrench(int row) const;

  const Trajectory& log_;
  int first_, last_, substeps_;
  bool use_pose_;
  SegmentNuisances nuisances_;
  int offset_block_ = -1, delay_block_ = -1;  // parameter block indices, -1 when absent
  double length_m_;
  RowLoss loss_;
  const std::vector<char>* held_rows_ = nullptr;
  // Per (step, substep) cache of the last solution; a residual block is evaluated by one
  // thread at a time, so the cache needs no lock.
  mutable std::vector<Eigen::Vector4d> warm_start_;
  // The parameter values and raw residuals of the last successful simulation. On a problem
  // with bounds, Ceres' trust-region minimizer evaluates every accepted step twice at the
  // same point (its projected line search, then the candidate point): the second costs
  // nothing. Same threading as warm_start_.
  mutable std::vector<double> last_params_, last_residuals_;
  // EvaluateKept's Jacobian, every block, block after block; whether it is that at
  // last_params_.
  mutable std::vector<double> kept_jacobian_;
  mutable bool jacobian_kept_ = false;
};

/// The cost of one shooting segment (rows first_row..last_row of `log`, which must outlive
/// it), parameter blocks as SegmentCost says. Exposed for derivative checks.
ceres::CostFunction* NewSegmentCost(const Trajectory& log, int first_row, int last_row,
                                    int substeps, bool use_pose, SegmentNuisances nuisances = {});

}  // namespace slideid
