#include "estimator/internal/trajectory_problem.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "estimator/internal/gauss_newton_step.h"
#include "estimator/parallel_for.h"

namespace slideid {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix66 = Eigen::Matrix<double, 6, 6>;

// Rows of poses a segment's start velocity is seeded from (least-squares line): one
// difference of noisy poses would make the seed ~ sqrt(2) sigma / h off.
constexpr int kVelocitySeedRows = 5;
// Fewest rows a segment may have: 3 rows = 9 residuals against 6 state parameters.
constexpr int kMinSegmentRows = 3;
// Stop when an iteration lowers the cost by less than kStatisticalTolerance / N relative,
// N the number of residuals: with cost ~ N s^2 / 2, a parameter off by d standard errors
// raises the cost by ~ d^2 s^2 / 2, so this stops within 0.01 standard errors of the
// optimum. Noiseless fits (the cost falls to rounding quadratically) still reach the 1e-6
// relative accuracy the tests demand.
constexpr double kStatisticalTolerance = 1e-4;
constexpr double kMinFunctionTolerance = 1e-12;
constexpr double kParameterTolerance = 1e-10;
// No gradient test (issue 5, docs/stability.md): Ceres' gradient tolerance is absolute,
// and on a log whose poses barely feel a parameter the gradient fell below 1e-14 with the
// parameter still off by more than its interval. The tolerances above end every fit.
constexpr double kGradientTolerance = 0.0;
// kSettledFraction, kSettledDecrease: estimator/internal/gauss_newton_step.h.
// A stage that only has to bring the fit into the right basin for the next one (least
// squares before the robust loss) settles at this fraction of a standard error: the next
// stage starts within a fraction of an interval of its optimum either way.
constexpr double kStageSettledFraction = 0.3;
// The standard errors are recomputed once the cost is below this fraction of what it was
// when they were (the errors then shrank by half).
constexpr double kStdErrRefresh = 0.25;
// ... and the standard errors are first computed once every log-friction step is below
// this (0.1%), and nuisances' steps below this fraction of their own size plus ...
constexpr double kSettleCheck = 1e-3;
// ... this floor in their units (N or s): an offset of 1 mN or a delay of 1 ms.
constexpr double kNuisanceSettleFloor = 1e-3;
// A problem whose Jacobian (over every segment) fits in this many bytes keeps each
// segment's last one (SegmentCost::EvaluateKept): 2 MB on estimator_benchmark's 10,000
// rows; not on logs of more than about 150,000 rows, whose memory matters more.
constexpr double kKeptJacobianBytes = 32.0 * (1 << 20);
// A segment whose own information has a relative eigenvalue below this leaves part of its
// state undetermined (typically the start velocity of a segment that begins stuck).
constexpr double kRankDeficientSegment = 1e-12;

std::vector<std::pair<int, int>> CutSegments(int rows, int segment_steps) {
  std::vector<std::pair<int, int>> segments;
  for (int first = 0; first < rows; first += segment_steps + 1) {
    const int last = std::min(first + segment_steps, rows - 1);
    if (last - first + 1 < std::max(kMinSegmentRows, segment_steps / 2) && !segments.empty()) {
      segments.back().second = last;  // fold a short tail into the last segment
      break;
    }
    if (last - first + 1 < kMinSegmentRows) break;
    segments.emplace_back(first, last);
  }
  return segments;
}

Vector6 SeedState(const Trajectory& log, int row, int last_row) {
  const TrajectorySample& a = log.samples[row];
  Vector6 s;
  s << a.state.x, a.state.y, a.state.theta, a.state.vx, a.state.vy, a.state.wz;
  if (log.measured.velocity) return s;
  // Slope of a least-squares line through the first rows' poses.
  const int n = std::min(kVelocitySeedRows, last_row - row + 1);
  double t_mean = 0;
  for (int i = 0; i < n; ++i) t_mean += log.samples[row + i].t_s / n;
  double stt = 0;
  Eigen::Vector3d stq = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const TrajectorySample& b = log.samples[row + i];
    const double dt = b.t_s - t_mean;
    stt += dt * dt;
    stq += dt * Eigen::Vector3d(b.state.x, b.state.y, b.state.theta);
  }
  s.tail<3>() = stq / stt;  // n >= 3 distinct times: stt > 0
  return s;
}

// One segment's share of FitInformation, in its own global columns (`columns`).
struct SegmentShare {
  bool ok = false;
  bool state_determined = true;
  std::vector<int> columns;
  Eigen::MatrixXd h;
  Eigen::VectorXd score;
  Eigen::MatrixXd extra_cross, extra_h;
  Eigen::VectorXd extra_score;
  double sum_squares = 0;
  int residuals = 0;
  std::array<Eigen::MatrixXd, 3> channel_h;  ///< m x m, when asked for
  std::array<double, 3> channel_sum_squares{};
};

/// Each residual channel's share of a segment's information, J_m^T J_m over the channel's
/// rows (every third, from `channel`), with J_m = J_g - J_s P (J_s^T J_g) the globals'
/// columns projected as MarginaliseState does (P the pseudo-inverse of J_s^T J_s): A holds
/// [J_s, J_g, ...] and `gram` its Gram matrix.
void ChannelShares(const Eigen::MatrixXd& A, const Eigen::MatrixXd& gram, int m,
                   SegmentShare* share) {
  const Matrix66 Hss = gram.topLeftCorner<6, 6>();
  const Eigen::MatrixXd state_part =
      Hss.completeOrthogonalDecomposition().pseudoInverse() * gram.block(0, 6, 6, m);
  const Eigen::MatrixXd projected = A.middleCols(6, m) - A.leftCols<6>() * state_part;
  const Eigen::Index n = A.rows();
  for (int c = 0; c < 3; ++c) {
    share->channel_h[c] = Eigen::MatrixXd::Zero(m, m);
    double ss = 0;
    for (Eigen::Index i = c; i < n; i += 3) {
      share->channel_h[c].noalias() += projected.row(i).transpose() * projected.row(i);
      ss += A(i, A.cols() - 1) * A(i, A.cols() - 1);
    }
    share->channel_sum_squares[c] = ss;
  }
}

}  // namespace

bool IsFreeSlide(const Trajectory& log) {
  return std::all_of(log.samples.begin(), log.samples.end(),
                     [](const TrajectorySample& s) { return s.applied.IsZero(); });
}

int IntervalsIn(double seconds, double interval_s) {
  const double interval = interval_s > 0 && std::isfinite(interval_s) ? interval_s : 0.01;
  return static_cast<int>(std::clamp(std::round(seconds / interval), 2.0, 1e6));
}

int TrajectorySegmentSteps(int rows, double interval_s, const TrajectoryOptions& options,
                           bool free_slide) {
  if (options.segment_steps > 0) return options.segment_steps;
  const int steps = std::clamp(rows / kTargetSegments, IntervalsIn(kMinAutoSegment_s, interval_s),
                               IntervalsIn(kMaxAutoSegment_s, interval_s));
  if (free_slide) return steps;
  // A segment of s intervals holds s + 1 rows (CutSegments).
  const int for_robust = rows / kMinRobustSegments - 1;
  return steps <= for_robust ? steps : std::max(kMinShortSegmentSteps, for_robust);
}

TrajectoryProblem::TrajectoryProblem(const std::vector<const Trajectory*>& logs,
                                     const IdentifyOptions& options)
    : logs_(logs), options_(options) {
  const TrajectoryOptions& t = options.trajectory;
  const int n = static_cast<int>(logs.size());
  global_.assign(kFrictionGlobals, 0.0);
  global_log_.assign(kFrictionGlobals, -1);
  offset_index_.assign(n, -1);
  delay_index_.assign(n, -1);
  if (t.fit_force_bias) {
    for (int k = 0; k < n; ++k) {
      offset_index_[k] = num_global();
      global_.insert(global_.end(), {0.0, 0.0});
      global_log_.insert(global_log_.end(), {k, k});
    }
  }
  if (t.fit_delay == DelayFit::kShared) {
    delay_index_.assign(n, num_global());
    global_.push_back(0.0);
    global_log_.push_back(-1);
  } else if (t.fit_delay == DelayFit::kPerLog) {
    for (int k = 0; k < n; ++k) {
      delay_index_[k] = num_global();
      global_.push_back(0.0);
      global_log_.push_back(k);
    }
  }
  for (int k = 0; k < n; ++k) {
    const Trajectory& log = *logs[k];
    const int steps = TrajectorySegmentSteps(static_cast<int>(log.samples.size()),
                                             MedianInterval(log), t, IsFreeSlide(log));
    // No segment spans a gap: each run (forward_model/trajectory.h) is cut on its own.
    for (const auto& [run_first, run_last] : Runs(log)) {
      for (auto [first, last] : CutSegments(run_last - run_first + 1, steps)) {
        first += run_first;
        last += run_first;
        segments_.push_back(NewSegment(k, first, last, SeedState(log, first, last)));
      }
    }
  }
  if (segments_.empty()) {
    int rows = 0;
    for (const Trajectory* log : logs) rows = std::max(rows, int(log->samples.size()));
    throw std::invalid_argument("log too short for the trajectory method: " + std::to_string(rows) +
                                " rows");
  }
}

std::vector<int> TrajectoryProblem::HeadSteps(double seconds, int min_steps) const {
  std::vector<int> steps;
  for (const Trajectory* log : logs_) {
    steps.push_back(std::max(min_steps, IntervalsIn(seconds, MedianInterval(*log))));
  }
  return steps;
}

std::unique_ptr<TrajectoryProblem> TrajectoryProblem::Heads(double seconds, int min_steps) const {
  const std::vector<int> steps = HeadSteps(seconds, min_steps);
  std::unique_ptr<TrajectoryProblem> heads(new TrajectoryProblem);
  heads->logs_ = logs_;
  heads->options_ = options_;
  heads->global_ = global_;
  heads->global_log_ = global_log_;
  heads->offset_index_ = offset_index_;
  heads->delay_index_ = delay_index_;
  for (const TrajectorySegment& seg : segments_) {
    heads->segments_.push_back(heads->NewSegment(
        seg.log, seg.first_row, std::min(seg.last_row, seg.first_row + steps[seg.log]), seg.state));
  }
  return heads;
}

std::unique_ptr<TrajectoryProblem> TrajectoryProblem::Resegmented(int steps) const {
  IdentifyOptions options = options_;
  options.trajectory.segment_steps = steps;
  auto other = std::make_unique<TrajectoryProblem>(logs_, options);
  other->global_ = global_;
  other->StatesFrom(*this);
  return other;
}

void TrajectoryProblem::StatesFrom(const TrajectoryProblem& other) {
  // Per log, this problem's segments by their first row: the only rows whose simulated
  // state is kept (a state per row of the log took 56 bytes a row, and every one of other's
  // segments' simulated rows 48 more at once).
  std::vector<std::vector<std::pair<int, int>>> starts(logs_.size());  // (first row, segment)
  for (size_t i = 0; i < segments_.size(); ++i) {
    starts[segments_[i].log].emplace_back(segments_[i].first_row, static_cast<int>(i));
  }
  for (auto& log_starts : starts) std::sort(log_starts.begin(), log_starts.end());
  std::vector<std::optional<Vector6>> found(segments_.size());
  ParallelFor(static_cast<int>(other.segments_.size()), options_.threads, [&](int j) {
    const TrajectorySegment& seg = other.segments_[j];
    const std::vector<const double*> params = other.ParametersOf(j);
    std::vector<PlanarState> simulated;
    if (!seg.cost->SimulatedStates(params.data(), &simulated)) return;
    // other's segments cover disjoint rows: each of this problem's starts is written once.
    const std::vector<std::pair<int, int>>& log_starts = starts[seg.log];
    const int end = seg.first_row + static_cast<int>(simulated.size());
    for (auto it = std::lower_bound(log_starts.begin(), log_starts.end(),
                                    std::make_pair(seg.first_row, -1));
         it != log_starts.end() && it->first < end; ++it) {
      const PlanarState& p = simulated[it->first - seg.first_row];
      Vector6 state;
      state << p.x, p.y, p.theta, p.vx, p.vy, p.wz;
      found[it->second] = state;
    }
  });
  for (size_t i = 0; i < segments_.size(); ++i) {
    if (found[i]) segments_[i].state = *found[i];
  }
}

TrajectorySegment TrajectoryProblem::NewSegment(int log, int first_row, int last_row,
                                                const Eigen::Matrix<double, 6, 1>& state) const {
  TrajectorySegment seg;
  seg.log = log;
  seg.first_row = first_row;
  seg.last_row = last_row;
  seg.state = state;
  seg.cost =
      std::make_unique<SegmentCost>(*logs_[log], first_row, last_row, options_.trajectory.substeps,
                                    use_pose(log), FittedNuisances());
  return seg;
}

SegmentNuisances TrajectoryProblem::FittedNuisances() const {
  const TrajectoryOptions& t = options_.trajectory;
  return {t.fit_force_bias, t.fit_delay != DelayFit::kNone};
}

double TrajectoryProblem::HeadsFraction(double seconds, int min_steps) const {
  const std::vector<int> steps = HeadSteps(seconds, min_steps);
  int rows = 0;
  for (const TrajectorySegment& seg : segments_) {
    rows += std::min(seg.last_row - seg.first_row, steps[seg.log]) + 1;
  }
  return static_cast<double>(rows) / Rows();
}

TrajectoryProblem::Point TrajectoryProblem::point() const {
  Point p{global_, {}};
  for (const TrajectorySegment& seg : segments_) p.states.push_back(seg.state);
  return p;
}

void TrajectoryProblem::set_point(const Point& point) {
  global_ = point.global;
  for (size_t k = 0; k < segments_.size(); ++k) segments_[k].state = point.states[k];
}

std::string TrajectoryProblem::GlobalName(int i) const {
  if (IsFriction(i)) return ParameterName(i);
  const int k = global_log_[i];
  if (k >= 0 && offset_index_[k] == i) return "force_bias_x_n";
  if (k >= 0 && offset_index_[k] + 1 == i) return "force_bias_y_n";
  return "delay_s";
}

void TrajectoryProblem::SetFriction(const ReducedFriction& friction) {
  ToLogParameters(ClampToSearchRange(friction), &global_[0]);
}

ReducedFriction TrajectoryProblem::Friction() const { return FromLogParameters(&global_[0]); }

int TrajectoryProblem::Rows() const {
  int n = 0;
  for (const TrajectorySegment& seg : segments_) n += seg.last_row - seg.first_row + 1;
  return n;
}

bool TrajectoryProblem::KeepsJacobians() const {
  double bytes = 0;
  for (const TrajectorySegment& seg : segments_) {
    const std::vector<int32_t>& sizes = seg.cost->parameter_block_sizes();
    bytes += 8.0 * seg.cost->num_residuals() * std::accumulate(sizes.begin(), sizes.end(), 0);
  }
  return bytes <= kKeptJacobianBytes;
}

int TrajectoryProblem::StateParameters() const {
  int n = 0;
  for (const TrajectorySegment& seg : segments_) n += use_pose(seg.log) ? 6 : 3;
  return n;
}

std::vector<double*> TrajectoryProblem::BlocksOf(TrajectorySegment& seg) {
  std::vector<double*> blocks{seg.state.data(), &global_[0], &global_[1], &global_[2]};
  if (offset_index_[seg.log] >= 0) blocks.push_back(&global_[offset_index_[seg.log]]);
  if (delay_index_[seg.log] >= 0) blocks.push_back(&global_[delay_index_[seg.log]]);
  return blocks;
}

std::vector<const double*> TrajectoryProblem::ParametersOf(int segment) const {
  auto* self = const_cast<TrajectoryProblem*>(this);  // BlocksOf hands out pointers only
  const std::vector<double*> blocks = self->BlocksOf(self->segments_[segment]);
  return {blocks.begin(), blocks.end()};
}

std::vector<int> TrajectoryProblem::GlobalColumnsOf(TrajectorySegment& seg) {
  const std::vector<double*> blocks = BlocksOf(seg);
  const std::vector<int32_t>& sizes = seg.cost->parameter_block_sizes();
  std::vector<int> columns;
  for (size_t b = 1; b < blocks.size(); ++b) {
    const int first = static_cast<int>(blocks[b] - global_.data());
    for (int c = 0; c < sizes[b]; ++c) columns.push_back(first + c);
  }
  return columns;
}

void TrajectoryProblem::SetRowLoss(const RowLoss& loss) {
  for (TrajectorySegment& seg : segments_) seg.cost->SetRowLoss(loss);
}

std::vector<double> TrajectoryProblem::Residuals(bool raw) const {
  std::vector<int> offsets(segments_.size() + 1, 0);
  for (size_t k = 0; k < segments_.size(); ++k) {
    offsets[k + 1] = offsets[k] + segments_[k].cost->num_residuals();
  }
  std::vector<double> all(offsets.back(), 0.0);
  ParallelFor(static_cast<int>(segments_.size()), options_.threads, [&](int k) {
    const std::vector<const double*> params = ParametersOf(k);
    double* out = all.data() + offsets[k];
    if (!segments_[k].cost->Residuals(params.data(), out, !raw)) {
      std::fill(out, out + segments_[k].cost->num_residuals(),
                std::numeric_limits<double>::infinity());
    }
  });
  return all;
}

void TrajectoryProblem::ForEachSegmentResiduals(
    bool raw, const std::function<void(int, const std::vector<double>&)>& f) const {
  ForEachSegmentEvaluation([raw](const SegmentCost& cost, double const* const* params,
                                 double* r) { return cost.Residuals(params, r, !raw); },
                           f);
}

void TrajectoryProblem::ForEachSegmentEvaluation(
    const SegmentEvaluation& evaluate,
    const std::function<void(int, const std::vector<double>&)>& f) const {
  constexpr int kChunkSegments = 256;
  const int n = static_cast<int>(segments_.size());
  std::vector<std::vector<double>> chunk(std::min(n, kChunkSegments));
  for (int first = 0; first < n; first += kChunkSegments) {
    const int m = std::min(kChunkSegments, n - first);
    ParallelFor(m, options_.threads, [&](int j) {
      const SegmentCost& cost = *segments_[first + j].cost;
      const std::vector<const double*> params = ParametersOf(first + j);
      std::vector<double>& r = chunk[j];
      r.assign(cost.num_residuals(), 0.0);
      if (!evaluate(cost, params.data(), r.data())) {
        std::fill(r.begin(), r.end(), std::numeric_limits<double>::infinity());
      }
    });
    for (int j = 0; j < m; ++j) f(first + j, chunk[j]);
  }
}

double TrajectoryProblem::SumOfSquares(const SegmentEvaluation& evaluate) const {
  // In the segments' order, without a residual vector of the whole log (the seed scan takes
  // many costs).
  double cost = 0;
  ForEachSegmentEvaluation(evaluate, [&](int, const std::vector<double>& r) {
    for (double v : r) cost += v * v;
  });
  return std::isfinite(cost) ? cost : std::numeric_limits<double>::infinity();
}

double TrajectoryProblem::RawCost() const {
  return SumOfSquares([](const SegmentCost& cost, double const* const* params, double* r) {
    return cost.Residuals(params, r, false);
  });
}

double TrajectoryProblem::RawCostKeepingJacobians() const {
  const bool lossless = std::none_of(segments_.begin(), segments_.end(),
                                     [](const auto& seg) { return seg.cost->row_loss().active(); });
  if (!KeepsJacobians() || !lossless) return RawCost();
  return SumOfSquares([](const SegmentCost& cost, double const* const* params, double* r) {
    return !cost.EvaluateKept(params, r).empty();
  });
}

namespace {

// A segment's Gauss-Newton matrix at the solver's last evaluation with derivatives: a factor
// F (the compressed Jacobian's R, or the Jacobian itself) with F^T F = J^T J over every
// block (state, then the globals as BlocksOf orders them), the sum of squares of the
// (row-loss) residuals and their number. What Information() would compute at that point,
// without its pass: the solver evaluates the Jacobian at every point it accepts, before
// the iteration's callbacks run.
// Where the state's own block of R is well conditioned (every diagonal element above
// kStateConditioned times the largest), only R's block of the globals is kept: R_gg^T R_gg
// is the information marginalised over the state (the Schur complement of J^T J), and a
// few hundred bytes a segment during a solve instead of the whole factor's kilobyte.
struct SegmentGaussNewton {
  Eigen::MatrixXd factor;
  Eigen::VectorXd rhs;    ///< z with factor^T z = J^T r over the factor's columns
  bool marginal = false;  ///< factor is R_gg (the globals' columns only)
  /// Where marginal: |z_s|^2, by how much the state's own Gauss-Newton step (the globals
  /// held) would lower the sum of squares.
  double state_decrease = 0;
  double sum_squares = 0;
  int residuals = 0;
  bool ok = false;
};
constexpr double kStateConditioned = 1e-6;

// into(columns[a], columns[b]) += h(a, b): a segment's share of the globals' information,
// h over the globals it takes, added into the G x G matrix of all of them.
void AddAtColumns(const std::vector<int>& columns, const Eigen::MatrixXd& h,
                  Eigen::MatrixXd* into) {
  for (size_t a = 0; a < columns.size(); ++a) {
    for (size_t b = 0; b < columns.size(); ++b) (*into)(columns[a], columns[b]) += h(a, b);
  }
}

}  // namespace

// h in the order Information() has always computed it, H_sr^T (P H_sr); the gradient and
// the state's decrease in the order Solve's settle test did, H_rs (P g_s): each caller's
// digits bit for bit. (That test's h was (H_rs P) H_sr, the same but for the last bits:
// at most 8.5e-16 of h's largest element in fit_trace, whose output it leaves unchanged.)
StateMarginal MarginaliseState(const Eigen::MatrixXd& H, const Eigen::VectorXd& gradient) {
  const Matrix66 Hss = H.topLeftCorner<6, 6>();
  const Eigen::MatrixXd Hss_pinv = Hss.completeOrthogonalDecomposition().pseudoInverse();
  const int m = static_cast<int>(H.cols()) - 6;
  const Eigen::MatrixXd cross = H.topRightCorner(6, m);  // H_sr
  StateMarginal out;
  out.h = H.bottomRightCorner(m, m) - cross.transpose() * (Hss_pinv * cross);
  if (gradient.size() == 0) return out;
  const Eigen::VectorXd state_step = Hss_pinv * gradient.head<6>();
  out.gradient = gradient.tail(m) - H.bottomLeftCorner(m, 6) * state_step;
  out.state_decrease = gradient.head<6>().dot(state_step);
  return out;
}

GaussNewtonStep GaussNewtonMoves(const LastGaussNewton& at, const std::vector<bool>& free) {
  std::vector<int> idx;
  for (size_t i = 0; i < free.size(); ++i) {
    if (free[i]) idx.push_back(static_cast<int>(i));
  }
  const int n = static_cast<int>(idx.size());
  Eigen::MatrixXd H(n, n);
  Eigen::VectorXd g(n);
  for (int a = 0; a < n; ++a) {
    g(a) = at.gradient(idx[a]);
    for (int b = 0; b < n; ++b) H(a, b) = at.fisher(idx[a], idx[b]);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return {};
  const Eigen::VectorXd step = ldlt.solve(g);
  if (!step.allFinite()) return {};
  GaussNewtonStep out{std::vector<double>(free.size(), 0.0), at.state_decrease + g.dot(step)};
  for (int a = 0; a < n; ++a) out.moves[idx[a]] = std::abs(step(a));
  return out;
}

bool MovesWithin(const std::vector<double>& moves, const std::vector<bool>& free,
                 const std::vector<double>& standard_errors, double fraction) {
  if (moves.empty()) return false;
  for (size_t i = 0; i < free.size(); ++i) {
    if (free[i] && !(moves[i] <= fraction * standard_errors[i])) return false;
  }
  return true;
}

bool PredictedStepSettled(const LastGaussNewton& at, const std::vector<bool>& free,
                          const std::vector<double>& standard_errors, double fraction) {
  const GaussNewtonStep next = GaussNewtonMoves(at, free);
  const double mean_square = at.sum_squares / std::max(1, at.residuals);
  return MovesWithin(next.moves, free, standard_errors, fraction) &&
         next.decrease <= kSettledDecrease * mean_square;
}

namespace {

// Stops a solve once the free global parameters have settled: two successive successful
// iterations each moved every one by less than kSettledFraction of its standard error, or,
// for a solve that settles at kSettledFraction (the fit's last), one such iteration after
// which the Gauss-Newton step (GaussNewtonMoves) would move every one by less than that
// too and lower the sum of squares by at most kSettledDecrease mean squares: the second
// look is the step the solver would take next, not taken. On the benchmark log that step
// is within a few percent of the one then taken where the model held (0.0115 predicted,
// 0.0115 taken, in standard errors of b; a decrease of 0.63 mean squares predicted, 0.61
// made); it saves the last iteration, a pass with derivatives and a cost. Without the
// decrease test the rule also ended fits whose states still crept (the 1,000,000-row
// log's last iteration lowered the cost by about 4,600 mean squares), and the mismatch
// correction, which reads the residuals there, moved a by 0.035 standard errors on it and
// one scene-suite log by 0.098. Stages (kStageSettledFraction) keep the two taken steps:
// where they end decides the next solve's basin (the segments' states as well as the
// globals), and ending the heads' solve one iteration earlier moved two of the scene
// suite's stick-slip logs to other minima.
// The segment states may still creep along the kinks that stick-slip switching puts in the
// cost (on the 10k-row benchmark log, 50 more iterations that moved a, b, c by less than
// 0.01 of a standard error); nothing the estimate reports depends on them but the mismatch
// correction, weakly. The standard errors are computed once, when the steps first fall
// below kSettleCheck, from the Gauss-Newton matrix of the solver's own last evaluation
// (SegmentGaussNewton): no pass.
class SettledCallback final : public ceres::IterationCallback {
 public:
  /// `gauss_newton` gives the globals' Gauss-Newton matrix and gradient at the current
  /// point, `standard_errors` the free globals' standard errors from them.
  /// `settle_on`, when given and the solve is a stage: see TrajectoryProblem::Solve.
  SettledCallback(TrajectoryProblem* problem, const std::vector<bool>& free, double fraction,
                  std::function<LastGaussNewton()> gauss_newton,
                  std::function<std::vector<double>(const LastGaussNewton&)> standard_errors,
                  const std::function<bool()>& settle_on)
      : problem_(problem),
        free_(free),
        last_(free.size()),
        fraction_(fraction),
        gauss_newton_(std::move(gauss_newton)),
        standard_errors_(std::move(standard_errors)),
        settle_on_(settle_on) {
    for (size_t i = 0; i < free.size(); ++i) last_[i] = problem->global(int(i));
  }

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& it) override {
    if (!it.step_is_successful || it.iteration == 0) return ceres::SOLVER_CONTINUE;
    // With every global held (a profile over the states) Ceres' own tolerances end it.
    if (std::find(free_.begin(), free_.end(), true) == free_.end()) return ceres::SOLVER_CONTINUE;
    std::vector<double> moved(free_.size(), 0.0);
    bool small = true;
    for (size_t i = 0; i < free_.size(); ++i) {
      const double now = problem_->global(int(i));
      moved[i] = std::abs(now - last_[i]);
      last_[i] = now;
      if (!free_[i]) continue;
      const double check = problem_->IsFriction(int(i))
                               ? kSettleCheck
                               : kSettleCheck * std::abs(now) + kNuisanceSettleFloor;
      small = small && moved[i] <= check;
    }
    if (!small) {
      settled_ = 0;
      return ceres::SOLVER_CONTINUE;
    }
    // The errors scale with the residuals: computed again once the cost has fallen by
    // kStdErrRefresh since (on a noiseless log it falls by orders of magnitude, and errors
    // from early on would let the fit stop far from its last digits).
    std::optional<LastGaussNewton> at;
    if (stderr_.empty() || it.cost < kStdErrRefresh * cost_at_stderr_) {
      at = gauss_newton_();
      stderr_ = standard_errors_(*at);
      cost_at_stderr_ = it.cost;
    }
    const bool settled = MovesWithin(moved, free_, stderr_, fraction_);
    settled_ = settled ? settled_ + 1 : 0;
    bool done = settled_ >= 2;
    if (!done && settled && fraction_ <= kSettledFraction) {
      if (!at) at = gauss_newton_();
      done = PredictedStepSettled(*at, free_, stderr_, fraction_);
    }
    if (!done) return ceres::SOLVER_CONTINUE;
    if (settle_on_ && fraction_ > kSettledFraction && settle_on_()) {
      fraction_ = kSettledFraction;  // as a next solve would start: nothing settled yet
      settled_ = 0;
      return ceres::SOLVER_CONTINUE;
    }
    return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }

 private:
  TrajectoryProblem* problem_;
  std::vector<bool> free_;
  std::vector<double> last_;
  std::vector<double> stderr_;
  double fraction_;
  std::function<LastGaussNewton()> gauss_newton_;
  std::function<std::vector<double>(const LastGaussNewton&)> standard_errors_;
  std::function<bool()> settle_on_;
  double cost_at_stderr_ = 0;
  int settled_ = 0;
};

// Every block's Jacobian of `cost` at `params` (row-major, n x the block's size), with the
// residuals into r: in the cost's own storage where `keep` and the cost has no row loss
// (SegmentCost::EvaluateKept, whose Jacobian is the raw one), else evaluated into `local`.
// Empty where a step fails.
std::vector<const double*> EveryBlockJacobian(const SegmentCost& cost, bool keep,
                                              double const* const* params, double* r,
                                              std::vector<std::vector<double>>* local) {
  if (keep && !cost.row_loss().active()) return cost.EvaluateKept(params, r);
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  local->resize(sizes.size());
  std::vector<double*> all(sizes.size());
  for (size_t b = 0; b < sizes.size(); ++b) {
    (*local)[b].resize(static_cast<size_t>(cost.num_residuals()) * sizes[b]);
    all[b] = (*local)[b].data();
  }
  if (!cost.Evaluate(params, r, all.data())) return {};
  return {all.begin(), all.end()};
}

// What Ceres sees of a segment: its n residuals r and n x m Jacobian J (m the parameters of
// all its blocks) compressed by the thin QR J = Q R to m + 1 residuals [Q^T r; |r - Q Q^T r|]
// with Jacobian [R; 0]. The cost (|r|^2), the gradient J^T r = R^T Q^T r, the Gauss-Newton
// matrix J^T J = R^T R and so the model |r + J d|^2 of every step are those of the
// segment's own residuals, for any subset of its blocks held constant: the same solve in
// exact arithmetic (rounding aside), without the n x m Jacobian Ceres would keep for every
// segment (3 residuals a row x 9 parameters: 216 bytes a row, 216 MB for a 1e6-row log) nor
// its n-long residual vectors. An evaluation without derivatives returns the cost alone, as
// (0, ..., 0, |r|): Ceres takes residuals and Jacobian from the same evaluation (a step's
// model) and only the cost from the others. Segments with n <= m + 1 are not compressed.
class CompressedSegmentCost final : public ceres::CostFunction {
 public:
  /// `last`, when given, receives every evaluation with derivatives (SegmentGaussNewton).
  /// `keep`: the segment's cost keeps each Jacobian (SegmentCost::EvaluateKept) where it
  /// has no row loss, so that one at the same point later costs no simulation.
  CompressedSegmentCost(const SegmentCost* cost, SegmentGaussNewton* last, bool keep)
      : cost_(cost), last_(last), keep_(keep) {
    *mutable_parameter_block_sizes() = cost->parameter_block_sizes();
    for (const int32_t size : cost->parameter_block_sizes()) columns_ += size;
    set_num_residuals(std::min(cost->num_residuals(), columns_ + 1));
  }

  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    const int n = cost_->num_residuals();
    if (jacobians && last_) last_->ok = false;
    if (n == num_residuals() && !(jacobians && last_)) {
      return cost_->Evaluate(params, residuals, jacobians);
    }
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    Eigen::VectorXd r(n);
    if (!jacobians) {
      if (!cost_->Evaluate(params, r.data(), nullptr)) return false;
      std::fill(residuals, residuals + num_residuals(), 0.0);
      residuals[columns_] = r.norm();
      return true;
    }
    // Every block's Jacobian, held ones too: Q must not depend on which blocks Ceres asks for.
    std::vector<std::vector<double>> local;
    const std::vector<const double*> block =
        EveryBlockJacobian(*cost_, keep_, params, r.data(), &local);
    if (block.empty()) return false;
    Eigen::MatrixXd J(n, columns_);
    for (size_t b = 0, col = 0; b < sizes.size(); col += sizes[b], ++b) {
      J.middleCols(static_cast<Eigen::Index>(col), sizes[b]) =
          Eigen::Map<const RowMajorMatrix>(block[b], n, sizes[b]);
    }
    if (n == num_residuals()) {  // not compressed: J itself is the factor
      std::copy(r.data(), r.data() + n, residuals);
      for (size_t b = 0; b < sizes.size(); ++b) {
        if (jacobians[b]) std::copy(block[b], block[b] + n * sizes[b], jacobians[b]);
      }
      const double sum_squares = r.squaredNorm();
      *last_ = {std::move(J), std::move(r), false, 0.0, sum_squares, n, true};
      return true;
    }
    const Eigen::HouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(J);  // in place, in J
    r.applyOnTheLeft(qr.householderQ().adjoint());                  // Q^T r (n, full Q)
    for (int i = 0; i < columns_; ++i) residuals[i] = r(i);
    residuals[columns_] = r.tail(n - columns_).norm();
    const Eigen::MatrixXd R = J.topRows(columns_).triangularView<Eigen::Upper>();
    if (last_) {
      const Eigen::ArrayXd diagonal = R.diagonal().head<6>().cwiseAbs();
      const bool conditioned = diagonal.minCoeff() > kStateConditioned * diagonal.maxCoeff();
      if (conditioned) {
        *last_ = {R.bottomRightCorner(columns_ - 6, columns_ - 6),
                  r.segment(6, columns_ - 6),
                  true,
                  r.head<6>().squaredNorm(),
                  r.squaredNorm(),
                  n,
                  true};
      } else {
        *last_ = {R, r.head(columns_), false, 0.0, r.squaredNorm(), n, true};
      }
    }
    for (size_t b = 0, col = 0; b < sizes.size(); col += sizes[b], ++b) {
      if (!jacobians[b]) continue;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> out(
          jacobians[b], num_residuals(), sizes[b]);
      out.topRows(columns_) = R.middleCols(static_cast<Eigen::Index>(col), sizes[b]);
      out.bottomRows<1>().setZero();
    }
    return true;
  }

 private:
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  const SegmentCost* cost_;
  SegmentGaussNewton* last_;
  bool keep_;
  int columns_ = 0;
};

}  // namespace

ceres::Solver::Summary TrajectoryProblem::Solve(const std::vector<bool>& free, bool stage,
                                                const std::function<bool()>& settle_on) {
  ceres::Problem problem;  // owns the CompressedSegmentCosts, not the segments' costs
  auto* ordering = new ceres::ParameterBlockOrdering;
  std::vector<SegmentGaussNewton> last(segments_.size());
  const bool keep = KeepsJacobians();
  for (size_t k = 0; k < segments_.size(); ++k) {
    TrajectorySegment& seg = segments_[k];
    problem.AddResidualBlock(new CompressedSegmentCost(seg.cost.get(), &last[k], keep), nullptr,
                             BlocksOf(seg));
    ordering->AddElementToGroup(seg.state.data(), 0);
    if (!use_pose(seg.log)) {
      // Velocity residuals do not see the pose: only the velocity part is a parameter.
      problem.SetManifold(seg.state.data(), new ceres::SubsetManifold(6, {0, 1, 2}));
    }
  }
  for (int i = 0; i < num_global(); ++i) {
    double* block = &global_[i];
    if (!problem.HasParameterBlock(block)) continue;  // o_y, or a log without segments
    ordering->AddElementToGroup(block, 1);
    const bool is_offset_x = !IsFriction(i) && GlobalName(i) == "force_bias_x_n";
    if (IsFriction(i)) {
      problem.SetParameterLowerBound(block, 0, std::log(kFrictionLowerBound[i]));
      problem.SetParameterUpperBound(block, 0, std::log(kFrictionUpperBound[i]));
      if (!free[i]) problem.SetParameterBlockConstant(block);
    } else if (is_offset_x) {
      if (!free[i] && !free[i + 1]) {
        problem.SetParameterBlockConstant(block);
      } else if (!free[i] || !free[i + 1]) {
        problem.SetManifold(block, new ceres::SubsetManifold(2, {free[i] ? 1 : 0}));
      }
    } else {  // a delay
      problem.SetParameterLowerBound(block, 0, -options_.trajectory.max_delay_s);
      problem.SetParameterUpperBound(block, 0, options_.trajectory.max_delay_s);
      if (!free[i]) problem.SetParameterBlockConstant(block);
    }
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_SCHUR;
  solver.linear_solver_ordering.reset(ordering);
  solver.max_num_iterations = options_.trajectory.max_iterations;
  solver.num_threads = options_.threads;
  solver.function_tolerance =
      std::max(kMinFunctionTolerance, kStatisticalTolerance / (3.0 * Rows()));
  solver.parameter_tolerance = kParameterTolerance;
  solver.gradient_tolerance = kGradientTolerance;
  // With bounds, Ceres projects each step and searches along it (a line search that helps
  // on the kinks stick-slip puts in the cost: without bounds the benchmark fit took 31
  // iterations instead of 10). Its default cubic interpolation evaluates the gradient, a
  // whole pass with derivatives, at every trial point; quadratic interpolation needs the
  // cost alone.
  solver.line_search_interpolation_type = ceres::QUADRATIC;
  solver.logging_type = ceres::SILENT;
  // The settled test's standard errors from the solver's last evaluation with derivatives
  // (at the point the callback judges), as StandardErrors would compute them there.
  auto gauss_newton = [&]() {
    const int G = num_global();
    LastGaussNewton out{Eigen::MatrixXd::Zero(G, G), Eigen::VectorXd::Zero(G), 0, 0, 0};
    for (size_t k = 0; k < segments_.size(); ++k) {
      if (!last[k].ok) continue;
      TrajectorySegment& seg = segments_[k];
      Eigen::MatrixXd h;
      Eigen::VectorXd g;
      if (last[k].marginal && use_pose(seg.log)) {
        h = last[k].factor.transpose() * last[k].factor;
        g = last[k].factor.transpose() * last[k].rhs;
        out.state_decrease += last[k].state_decrease;
      } else {  // as Information() marginalises
        Eigen::MatrixXd F = last[k].factor;
        if (!use_pose(seg.log)) F.leftCols<3>().setZero();  // poses are not parameters then
        StateMarginal marginal = MarginaliseState(F.transpose() * F, F.transpose() * last[k].rhs);
        h = std::move(marginal.h);
        g = std::move(marginal.gradient);
        out.state_decrease += marginal.state_decrease;
      }
      const std::vector<int> columns = GlobalColumnsOf(seg);
      AddAtColumns(columns, h, &out.fisher);
      for (size_t a = 0; a < columns.size(); ++a) out.gradient(columns[a]) += g(a);
      out.sum_squares += last[k].sum_squares;
      out.residuals += last[k].residuals;
    }
    out.fisher = 0.5 * (out.fisher + out.fisher.transpose());
    return out;
  };
  auto standard_errors = [&](const LastGaussNewton& at) {
    return StandardErrorsFrom(at.fisher, at.sum_squares, at.residuals, free);
  };
  SettledCallback settled(this, free, stage ? kStageSettledFraction : kSettledFraction,
                          gauss_newton, standard_errors, settle_on);
  solver.update_state_every_iteration = true;
  solver.callbacks.push_back(&settled);
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  return summary;
}

FitInformation TrajectoryProblem::Information(const std::function<Eigen::MatrixXd(int)>* extra) {
  const int G = num_global();
  const bool keep = KeepsJacobians();
  const bool per_channel = static_cast<int>(segments_.size()) < kWhiteFloorClusters;
  std::vector<SegmentShare> shares(segments_.size());
  ParallelFor(static_cast<int>(segments_.size()), options_.threads, [&](int k) {
    TrajectorySegment& seg = segments_[k];
    SegmentShare& share = shares[k];
    const SegmentCost& cost = *seg.cost;
    const int n = cost.num_residuals();
    const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
    const std::vector<const double*> params = ParametersOf(k);
    std::vector<double> r(n);
    // Where the segment keeps its Jacobian, read in place: at the fit's end point it is the
    // solver's last, no copy.
    std::vector<std::vector<double>> jac_storage;
    const std::vector<const double*> jac =
        EveryBlockJacobian(cost, keep, params.data(), r.data(), &jac_storage);
    if (jac.empty()) return;
    share.columns = GlobalColumnsOf(seg);
    const int m = static_cast<int>(share.columns.size());
    const Eigen::MatrixXd X = extra ? (*extra)(k) : Eigen::MatrixXd();
    const int x = extra && X.rows() == n ? static_cast<int>(X.cols()) : 0;
    // The columns [J_s, J_g, X, r] side by side and their Gram matrix, from which every
    // product below is read: one pass over the segment's rows instead of J_g and X
    // projected row by row, n x (m + x) x 6 products and their copies (this function's own
    // instructions on the benchmark log: 29M -> 18M).
    Eigen::MatrixXd A(n, 6 + m + x + 1);
    A.leftCols<6>() =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>>(jac[0], n, 6);
    const bool pose = use_pose(seg.log);
    if (!pose) A.leftCols<3>().setZero();  // poses are not parameters then
    int col = 6;
    for (size_t b = 1; b < sizes.size(); ++b) {
      for (int c = 0; c < sizes[b]; ++c, ++col) {
        for (int i = 0; i < n; ++i) A(i, col) = jac[b][i * sizes[b] + c];
      }
    }
    if (x > 0) A.middleCols(6 + m, x) = X;
    A.rightCols<1>() = Eigen::Map<const Eigen::VectorXd>(r.data(), n);
    Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(A.cols(), A.cols());
    gram.selfadjointView<Eigen::Lower>().rankUpdate(A.transpose());
    gram = gram.selfadjointView<Eigen::Lower>();
    const Matrix66 Hss = gram.topLeftCorner<6, 6>();
    const int first_free = pose ? 0 : 3;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(
        Hss.bottomRightCorner(6 - first_free, 6 - first_free));
    share.state_determined =
        eig.eigenvalues()(0) > kRankDeficientSegment * eig.eigenvalues().maxCoeff();
    // Project the segment's state out of J_g: what the globals explain beyond it. A segment
    // whose state is not determined (at rest) gives them nothing; the pseudo-inverse keeps
    // that from poisoning the sum. With P the pseudo-inverse and J_m = J_g - J_s P J_s^T J_g,
    // J_m^T J_m = J_g^T J_g - (J_s^T J_g)^T P (J_s^T J_g) (P H_ss P = P), and the same for
    // X and r: the Schur complement of the Gram matrix of [J_s, J_g, X, r].
    const Eigen::MatrixXd projected = MarginaliseState(gram).h;  // over [J_g, X, r]
    share.h = projected.topLeftCorner(m, m);
    share.score = projected.block(0, m + x, m, 1);
    if (x > 0) {
      share.extra_cross = projected.block(m, 0, x, m);
      share.extra_h = projected.block(m, m, x, x);
      share.extra_score = projected.block(m, m + x, x, 1);
    }
    if (per_channel) ChannelShares(A, gram, m, &share);
    const Eigen::Map<const Eigen::VectorXd> rv(r.data(), n);
    share.sum_squares = rv.squaredNorm();
    share.residuals = n;
    share.ok = true;
  });

  FitInformation info;
  info.fisher = Eigen::MatrixXd::Zero(G, G);
  if (per_channel) info.channel_fisher.assign(3, Eigen::MatrixXd::Zero(G, G));
  info.segment_score_outer = Eigen::MatrixXd::Zero(G, G);
  info.log_score_outer = Eigen::MatrixXd::Zero(G, G);
  std::vector<Eigen::VectorXd> log_score(logs_.size(), Eigen::VectorXd::Zero(G));
  std::vector<bool> log_used(logs_.size(), false);
  for (size_t k = 0; k < shares.size(); ++k) {
    const SegmentShare& s = shares[k];
    segments_[k].state_determined = s.ok && s.state_determined;
    if (!s.ok) continue;
    Eigen::VectorXd g = Eigen::VectorXd::Zero(G);
    for (size_t a = 0; a < s.columns.size(); ++a) g(s.columns[a]) += s.score(a);
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(G, G);
    AddAtColumns(s.columns, s.h, &h);
    info.fisher += h;
    for (int c = 0; per_channel && c < 3; ++c) {
      AddAtColumns(s.columns, s.channel_h[c], &info.channel_fisher[c]);
      info.channel_sum_squares[c] += s.channel_sum_squares[c];
    }
    SegmentInformation si{segments_[k].log,
                          std::move(h),
                          g,
                          {},
                          {},
                          {},
                          s.sum_squares,
                          s.residuals,
                          use_pose(segments_[k].log) ? 6 : 3};
    if (s.extra_h.size() > 0) {
      si.extra_cross = Eigen::MatrixXd::Zero(s.extra_h.rows(), G);
      for (size_t a = 0; a < s.columns.size(); ++a) {
        si.extra_cross.col(s.columns[a]) += s.extra_cross.col(a);
      }
      si.extra_fisher = s.extra_h;
      si.extra_score = s.extra_score;
    }
    info.per_segment.push_back(std::move(si));
    info.segment_score_outer += g * g.transpose();
    log_score[segments_[k].log] += g;
    log_used[segments_[k].log] = true;
    info.sum_squares += s.sum_squares;
    info.residuals += s.residuals;
    ++info.segments;
  }
  for (size_t k = 0; k < logs_.size(); ++k) {
    if (!log_used[k]) continue;
    info.log_score_outer += log_score[k] * log_score[k].transpose();
    ++info.logs;
  }
  info.fisher = 0.5 * (info.fisher + info.fisher.transpose());
  return info;
}

Eigen::VectorXd TrajectoryProblem::SegmentResidualsWith(int segment,
                                                        const std::vector<char>* held_rows,
                                                        int substeps) const {
  const TrajectorySegment& seg = segments_[segment];
  SegmentCost cost(*logs_[seg.log], seg.first_row, seg.last_row, substeps, use_pose(seg.log),
                   FittedNuisances());
  cost.SetHeldRows(held_rows);
  const std::vector<const double*> params = ParametersOf(segment);
  Eigen::VectorXd r(cost.num_residuals());
  if (!cost.Residuals(params.data(), r.data(), false)) return Eigen::VectorXd();
  return r;
}

Eigen::VectorXd TrajectoryProblem::SegmentResiduals(int segment) const {
  const TrajectorySegment& seg = segments_[segment];
  const std::vector<const double*> params = ParametersOf(segment);
  Eigen::VectorXd r(seg.cost->num_residuals());
  if (!seg.cost->Residuals(params.data(), r.data(), false)) return Eigen::VectorXd();
  return r;
}

std::vector<double> TrajectoryProblem::StandardErrors(const std::vector<bool>& free) {
  const FitInformation info = Information();
  return StandardErrorsFrom(info.fisher, info.sum_squares, info.residuals, free);
}

std::vector<double> TrajectoryProblem::StandardErrorsFrom(const Eigen::MatrixXd& fisher,
                                                          double sum_squares, int residuals,
                                                          const std::vector<bool>& free) const {
  std::vector<int> idx;
  for (int i = 0; i < num_global(); ++i) {
    if (free[i]) idx.push_back(i);
  }
  std::vector<double> se(num_global(), 0.0);
  const int n = static_cast<int>(idx.size());
  const int dof = residuals - StateParameters() - n;
  if (dof <= 0 || n == 0) return se;
  Eigen::MatrixXd H(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) H(a, b) = fisher(idx[a], idx[b]);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success) return se;
  const Eigen::MatrixXd cov = ldlt.solve(Eigen::MatrixXd::Identity(n, n));
  for (int a = 0; a < n; ++a) {
    se[idx[a]] = std::sqrt(std::max(0.0, cov(a, a) * sum_squares / dof));
  }
  return se;
}

}  // namespace slideid
