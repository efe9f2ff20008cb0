#pragma once
// The least-squares problem behind the trajectory fit (estimator/trajectory_fit.h), over
// one log or several pooled: shooting segments with their own initial states, and the
// global parameters they share. Internal to the estimator; tests use it to check the
// information it computes against ceres::Covariance.
//
// Global parameters, in order: log a, log b, log c (the first kFrictionGlobals); then for each log
// its force offset (o_x, o_y) [N] when fitted; then the delay [s] of each log's force stream, or
// one shared delay, when fitted.

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "estimator/internal/log_friction.h"
#include "estimator/internal/segment_cost.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Global parameters 0, 1, 2 are log a, log b, log c (log_friction.h); the sensor
/// nuisances, when fitted, follow from this index on.
constexpr int kFrictionGlobals = 3;

/// Intervals per shooting segment for a log of `rows` rows, `interval_s` apart (its median
/// interval): options.segment_steps when set, else rows / kTargetSegments within
/// [kMinAutoSegment_s, kMaxAutoSegment_s] of log time, shortened (to no less than
/// kMinShortSegmentSteps) where that leaves fewer than kMinRobustSegments segments, unless
/// the log is a free slide (`free_slide`: no row applies a wrench).
/// Long segments make accurate estimates: every segment spends 6 parameters on its state,
/// and a segment's friction information is the curvature of its path, which noisy poses
/// show only over a long enough time (on 300-row logs, 50-interval segments had 0.4 times
/// the error of a of 30-interval ones). The bounds are in seconds, not rows, for that
/// reason: the same 35 rows are 0.35 s at 100 Hz but 0.14 s at 250 Hz, and a 750-row,
/// 250 Hz push (datasets/scenes/holdout_pushed_250hz.ini, 12 noise seeds) spread a by 3.2%
/// in 37-interval segments and by 0.8% in 88-interval ones. Many segments make an honest
/// interval: they are the clusters of its cluster-robust covariance (trajectory_fit.cc),
/// and its t quantile sits on their degrees of freedom. Measured over the coverage suite
/// (benchmarks/coverage.cc, 100 Hz logs, 100 per condition): 10 segments of 100 intervals
/// on 1000-row logs put b's interval around the truth in 99-100% of logs (too wide), 20 of
/// 50 in 92-97%. On the scene suite (docs/scene-suite.md), keeping at least 10 segments
/// where the floor in time would leave fewer identified fewer logs (488 against 493 of
/// 500) and left more outside 3 standard errors (96.9% against 98.0%). At 100 Hz the
/// bounds are 35 and 100 intervals, as they were in rows.
/// A free slide is not shortened for a cluster-robust interval. The segments' own states
/// are there to absorb process noise (a mis-measured force, a held one), and a free slide
/// has none, so short segments would only throw away the information of its whole path.
/// The holdout disk (datasets/scenes/holdout_free_disk.ini: 100 rows, a 0.6 s slide), cut
/// into 5 segments of 19 intervals, had a standard error of a of 6% and came out -1.8% /
/// -2.6% / +0.3%; in 3 segments of 35 intervals the standard error is 0.5% and it comes
/// out -0.56% / +0.23% / +0.32% (the discretization allowance of trajectory_fit.cc covers
/// the step's own error, which long segments show). On the scene suite's 124 free
/// slides the median error went from 0.41 / 0.50 / 0.74% to 0.15 / 0.16 / 0.28%.
int TrajectorySegmentSteps(int rows, double interval_s, const TrajectoryOptions& options,
                           bool free_slide = false);

/// No row of the log applies a wrench: the object slides (or rests) on its own.
bool IsFreeSlide(const Trajectory& log);

/// How many intervals of `interval_s` make `seconds` of log time (rounded, at least 2); a
/// log without a usable interval (one row, or equal times) counts as a 100 Hz one.
int IntervalsIn(double seconds, double interval_s);
constexpr int kTargetSegments = 20;
constexpr double kMinAutoSegment_s = 0.35;
constexpr double kMaxAutoSegment_s = 1.0;
/// Fewer segments than this give no cluster-robust covariance (its t quantile would sit on
/// 1-3 degrees of freedom: 4.3-12.7, intervals too wide to say anything) and no mismatch
/// correction (two nuisances per log from a handful of segments fit their noise).
constexpr int kMinRobustSegments = 5;
/// A short log's segments are shortened to give it kMinRobustSegments, down to this.
constexpr int kMinShortSegmentSteps = 10;
/// Below this many segments the fit's intervals lean on the white-noise covariance (alone
/// below kMinRobustSegments, as a floor under the cluster-robust one up to here:
/// trajectory_fit.cc), so Information() also gives each residual channel's share of the
/// information (FitInformation::channel_fisher).
constexpr int kWhiteFloorClusters = 8;

/// Residuals below this [m or m/s] are rounding, not noise: a log whose noise is below it
/// needs no robust loss (and a zero scale would make the loss degenerate).
constexpr double kNoiseFloor = 1e-10;
/// The robust loss is scaled to the noise the log shows; residuals whose robust scale sits
/// above this many times that noise (model mismatch) are refitted at their own scale, so
/// that the loss does not treat most rows as outliers.
constexpr double kRescaleRatio = 2.0;
/// The noise a log's robust row loss is scaled to (the robust stage of trajectory_fit.cc):
/// its rows' noise `row_noise`, or its residuals' robust scale `residual_scale` where that
/// sits above kRescaleRatio times the noise or the noise is below kNoiseFloor.
inline double RowLossNoise(double row_noise, double residual_scale) {
  const bool rescale = residual_scale > kRescaleRatio * row_noise || !(row_noise > kNoiseFloor);
  return rescale ? residual_scale : row_noise;
}

/// One shooting segment: rows first_row..last_row of log `log`.
struct TrajectorySegment {
  int log = 0;
  int first_row = 0, last_row = 0;
  /// Its own 6x6 information has full rank (a segment that starts stuck leaves its start
  /// velocity undetermined).
  bool state_determined = true;
  Eigen::Matrix<double, 6, 1> state = Eigen::Matrix<double, 6, 1>::Zero();
  std::unique_ptr<SegmentCost> cost;
};

/// One segment's share of FitInformation: the clusters of the cluster-robust covariances.
struct SegmentInformation {
  int log = 0;
  Eigen::MatrixXd fisher;  ///< G x G, J~^T J~
  Eigen::VectorXd score;   ///< G, J~^T r
  /// With extra residual directions X (Information's argument), projected like J: X~^T J~
  /// (E x G), X~^T X~ (E x E) and X~^T r (E); empty without.
  Eigen::MatrixXd extra_cross, extra_fisher;
  Eigen::VectorXd extra_score;
  double sum_squares = 0;  ///< of its (row-loss) residuals
  int residuals = 0;
  int state_parameters = 6;  ///< 6, or 3 for a velocity log
};

/// What the residuals say about the global parameters, marginalised over the segment
/// states (Schur complement), and the scores the cluster-robust covariances need.
struct FitInformation {
  Eigen::MatrixXd fisher;                       ///< G x G
  Eigen::MatrixXd segment_score_outer;          ///< sum over segments of g g^T, g = J~^T r
  Eigen::MatrixXd log_score_outer;              ///< sum over logs of the sum of their segments' g
  std::vector<SegmentInformation> per_segment;  ///< every segment that contributed
  int segments = 0;                             ///< segments that contributed
  int logs = 0;                                 ///< logs with at least one such segment
  double sum_squares = 0;                       ///< of the (row-loss) residuals used
  int residuals = 0;
  /// Per residual channel (x, y, L theta; or v_x, v_y, L w_z), over problems of fewer than
  /// kWhiteFloorClusters segments (empty otherwise): the G x G information of that
  /// channel's rows, J~_c^T J~_c with J~ projected as for `fisher` (the three sum to it),
  /// and the sum of squares of its residuals. A log's channels need not be equally noisy
  /// (motion capture's heading times L is often several times finer than its position),
  /// and one variance for all then misstates the white-noise covariance.
  std::vector<Eigen::MatrixXd> channel_fisher;
  std::array<double, 3> channel_sum_squares{};
};

class TrajectoryProblem {
 public:
  /// The logs must outlive the problem and have their slider properties set. Throws
  /// std::invalid_argument when no log is long enough for one segment.
  TrajectoryProblem(const std::vector<const Trajectory*>& logs, const IdentifyOptions& options);

  /// The same logs, options and global values over the first `seconds` of log time, and
  /// at least `min_steps` intervals, of each of this problem's segments (IntervalsIn at its
  /// log's median interval; all of a shorter one), the segments in the same order with the
  /// same states: a cheaper problem, less nonlinear in the friction, whose fit seeds this
  /// one (set_point).
  std::unique_ptr<TrajectoryProblem> Heads(double seconds, int min_steps) const;
  /// The same logs, options and global values cut into segments of `steps` intervals (the
  /// whole log when it is shorter), each segment's state read off this problem's simulated
  /// trajectory (StatesFrom): a second start of the fit, on a segmentation whose states
  /// have fewer ways to absorb what the friction should explain.
  std::unique_ptr<TrajectoryProblem> Resegmented(int steps) const;
  /// Sets each segment's state to `other`'s simulated state at the segment's first row,
  /// where a segment of `other` (same logs) covers that row at other's current point;
  /// other segments keep theirs. Carries a fit from one segmentation to another.
  void StatesFrom(const TrajectoryProblem& other);
  /// Rows of the segments' heads (as Heads) over Rows().
  double HeadsFraction(double seconds, int min_steps) const;
  /// Where the fit is: the global values and every segment's state. A point of a problem
  /// is a point of its Heads() and back (same globals, segments in the same order).
  struct Point {
    std::vector<double> global;
    std::vector<Eigen::Matrix<double, 6, 1>> states;
  };
  Point point() const;
  void set_point(const Point& point);

  int num_logs() const { return static_cast<int>(logs_.size()); }
  int num_global() const { return static_cast<int>(global_.size()); }
  /// Name of global parameter i ("e_t_mu", "force_bias_x_n", "delay_s", ...) and the log
  /// it belongs to (-1: all).
  std::string GlobalName(int i) const;
  int GlobalLog(int i) const { return global_log_[i]; }
  bool IsFriction(int i) const { return i < kFrictionGlobals; }
  double global(int i) const { return global_[i]; }
  void set_global(int i, double value) { global_[i] = value; }
  /// Sets (a, b, c), clamped to the search range (global parameters 0-2 hold their logs).
  void SetFriction(const ReducedFriction& friction);
  ReducedFriction Friction() const;

  std::vector<TrajectorySegment>& segments() { return segments_; }
  const std::vector<TrajectorySegment>& segments() const { return segments_; }
  const Trajectory& log(int k) const { return *logs_[k]; }
  bool use_pose(int k) const { return logs_[k]->measured.pose; }
  int substeps() const { return options_.trajectory.substeps; }
  int threads() const { return options_.threads; }
  int Rows() const;  ///< rows inside segments, over all logs

  void SetRowLoss(const RowLoss& loss);
  /// Residuals of every segment in order, robustified (raw = false) or not; a segment
  /// whose simulation fails gives zeros. Runs on options.threads threads.
  std::vector<double> Residuals(bool raw) const;
  /// Calls f(k, r) for every segment k in order with its residuals r, as Residuals(raw)
  /// gives them, evaluating a chunk of segments at a time on options.threads threads: the
  /// whole log's residual vector (24 MB for 1e6 rows) is never held.
  void ForEachSegmentResiduals(bool raw,
                               const std::function<void(int, const std::vector<double>&)>& f) const;
  /// Sum of squares of the raw residuals; infinity if a segment fails.
  double RawCost() const;
  /// RawCost, evaluated with derivatives where the problem keeps them
  /// (SegmentCost::EvaluateKept): a solve starting at this point then evaluates nothing
  /// at its iteration zero. Elsewhere RawCost itself.
  double RawCostKeepingJacobians() const;

  /// Levenberg-Marquardt over the segment states and the free global parameters
  /// (free.size() == num_global()), stopping once the free ones settle (the callback in
  /// trajectory_problem.cc).
  /// `stage`: an intermediate solve, settled more loosely (trajectory_problem.cc).
  /// `settle_on`, for a stage: asked when the stage has settled; true makes the solve go on
  /// and settle as a last solve would (the iterations a next solve would spend, without its
  /// iteration zero).
  ceres::Solver::Summary Solve(const std::vector<bool>& free, bool stage = false,
                               const std::function<bool()>& settle_on = nullptr);

  /// The information of every global parameter, marginalised over the states; also marks
  /// segments whose state is undetermined. `extra`, when given, gives for segment k (called
  /// for each, concurrently on options.threads threads) E further residual directions
  /// (rows x E, in the units of the row-loss residuals): linearised nuisances whose shares
  /// FitInformation::per_segment then holds.
  FitInformation Information(const std::function<Eigen::MatrixXd(int)>* extra = nullptr);

  /// The raw residuals (no row loss) of segment `segment` with `substeps` steps per interval
  /// and, where `held_rows` is given (indexed by its log's rows), each row u with
  /// held_rows[u] != 0 holding the mean of its and the next row's wrench
  /// (SegmentCost::SetHeldRows), at the current state and parameters; empty where a step
  /// fails. Safe to call for different segments concurrently.
  Eigen::VectorXd SegmentResidualsWith(int segment, const std::vector<char>* held_rows,
                                       int substeps) const;
  /// The raw residuals of segment `segment` by its own cost, at the current state and
  /// parameters (empty where a step fails): no simulation where the cost last evaluated this
  /// very point, as Information() just did (its cache). Safe to call for different segments
  /// concurrently.
  Eigen::VectorXd SegmentResiduals(int segment) const;

  /// One-sigma errors of the free global parameters from Information() and the residual
  /// variance (0 where undetermined).
  std::vector<double> StandardErrors(const std::vector<bool>& free);
  /// The same from the information `fisher` (G x G) of `residuals` residuals whose sum of
  /// squares is `sum_squares`.
  std::vector<double> StandardErrorsFrom(const Eigen::MatrixXd& fisher, double sum_squares,
                                         int residuals, const std::vector<bool>& free) const;

  /// Degrees of freedom the segment states take: 6 per segment (3 for velocity logs).
  int StateParameters() const;

 private:
  /// Whether the segments' costs keep their last Jacobian (kKeptJacobianBytes).
  bool KeepsJacobians() const;
  TrajectoryProblem() = default;
  /// Per log, the intervals of a segment's head (Heads).
  std::vector<int> HeadSteps(double seconds, int min_steps) const;
  /// Segment of rows first_row..last_row of log `log`, starting at `state`, with its cost.
  TrajectorySegment NewSegment(int log, int first_row, int last_row,
                               const Eigen::Matrix<double, 6, 1>& state) const;
  /// The sensor nuisances the options fit (parameter blocks of every segment's cost).
  SegmentNuisances FittedNuisances() const;
  std::vector<double*> BlocksOf(TrajectorySegment& seg);
  /// BlocksOf(segments_[segment]), read only.
  std::vector<const double*> ParametersOf(int segment) const;
  /// Evaluates a segment's cost at its parameters into the residuals; false where it fails.
  using SegmentEvaluation = std::function<bool(const SegmentCost&, double const* const*, double*)>;
  /// ForEachSegmentResiduals with `evaluate` for the residuals.
  void ForEachSegmentEvaluation(
      const SegmentEvaluation& evaluate,
      const std::function<void(int, const std::vector<double>&)>& f) const;
  /// The sum of squares over every segment's `evaluate`, in the segments' order; infinity
  /// if one fails.
  double SumOfSquares(const SegmentEvaluation& evaluate) const;
  /// The indices in global_ of the global parameters `seg`'s cost takes, in block order
  /// (the columns of its Jacobian after the state's 6).
  std::vector<int> GlobalColumnsOf(TrajectorySegment& seg);

  std::vector<const Trajectory*> logs_;
  IdentifyOptions options_;
  std::vector<TrajectorySegment> segments_;
  std::vector<double> global_;
  std::vector<int> global_log_;    // log of each global parameter (-1: shared)
  std::vector<int> offset_index_;  // per log, index of o_x in global_ (-1: none)
  std::vector<int> delay_index_;   // per log, index of its delay in global_ (-1: none)
};

}  // namespace slideid
