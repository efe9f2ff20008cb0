#include "estimator/online_identifier.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <future>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "estimator/identify.h"
#include "estimator/internal/log_friction.h"
#include "estimator/internal/mismatch_nuisances.h"
#include "estimator/internal/trajectory_problem.h"
#include "estimator/log_diagnostics.h"
#include "estimator/plausibility.h"
#include "estimator/pooling.h"
#include "estimator/pusher_friction.h"
#include "estimator/robust_statistics.h"
#include "estimator/step_sensitivity.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {

// The filter's state: x, y, theta, v_x, v_y, w_z, log a, log b, log c, and the two
// mismatch nuisances (discretisation, force hold).
constexpr int kN = 11;
using Vector9 = Eigen::Matrix<double, kN, 1>;
using Matrix9 = Eigen::Matrix<double, kN, kN>;
using Matrix93 = Eigen::Matrix<double, kN, 3>;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix69 = Eigen::Matrix<double, 6, 9>;
constexpr int kVel = 3, kPar = 6, kLam = 9;

/// Third differences of white noise have variance 20 sigma^2 (log_diagnostics.h).
constexpr double kThirdDifferenceVariance = 20.0;
/// The noise is read off the last this many third differences (per channel)...
constexpr int kNoiseRing = 512;
/// ... again every this many rows (a median of the ring: O(1) per row amortised).
constexpr int kNoiseRefreshRows = 64;
/// Noise floors: a log without noise (exact simulation) still needs an invertible
/// innovation covariance; 1 um and 1 urad are far below any motion capture.
constexpr double kMinPoseNoise_m = 1e-6;
constexpr double kMinAngleNoise_rad = 1e-6;
/// The relative force noise (OnlineOptions::force_noise_fraction = 0): 3% until the filter's
/// variance factor is in, a floor of 0.5% after (a force sensor's calibration), read off at
/// least this many pushing rows' third differences. The noise is read along the force:
/// the median of |d3 f . f| / (sqrt(20) |f|^2) is sigma times the median of a half-normal.
constexpr double kDefaultForceNoiseFraction = 0.03;
constexpr double kMinForceNoiseFraction = 0.005;
constexpr int kMinForceNoiseSamples = 32;
constexpr double kHalfNormalMedian = 0.6744897501960817;
/// The lever's noise (the push point's and the pose's, in the logged moment r x f) is read
/// off at least this many pushing rows' third differences of r; the pose's noise before.
constexpr int kMinLeverNoiseSamples = 32;
/// The start velocity is unknown: within 0.3 m/s (1 sigma), a fast push.
constexpr double kStartSpeedSigma_mps = 0.3;
/// The row over which OnlineOptions::model_acceleration_mps2 moves the velocity by that
/// acceleration times the row (1 sigma) [s]: a 100 Hz row, the rate it was set at. Over a row
/// of h it moves it by sqrt(h / this) as much. (Before 2026-11-28 every row took the
/// acceleration times its own length, so a 1 kHz log had a tenth of the allowance per second
/// of a 100 Hz log, and at the end c's intervals held the truth in 75-76% of the scene
/// suite's held-out 1 kHz logs: docs/online.md.)
constexpr double kModelAccelerationRow_s = 0.01;
/// A row whose innovation exceeds this NIS (the 1e-4 tail of chi-square(3)) is weighted
/// down as Huber weights a residual (an outlier of motion capture: a marker swap).
constexpr double kOutlierNis = 21.1;
/// One row's update moves no log-parameter further than this (a factor 1.65): further, and
/// the row is weighted down (LimitParameterStep). A filter linearised far from the truth
/// early can otherwise leap to where its model is flat: users log 146 of the coverage suite
/// took c from 0.03 to 1e-6 m, the search range's bound, in five rows, and stayed there.
constexpr double kMaxLogStepPerRow = 0.5;
constexpr int kMaxStepLimitRounds = 8;
/// A filter whose innovations exceed this NIS (20 sigma) on kLostRows rows in a row has
/// lost the motion (Relocate).
constexpr double kLostNis = 400;
constexpr int kLostRows = 3;
/// The mismatch nuisances' prior: 0 (the model as it is) within 3 (1 sigma); a continuous
/// motion gives l_d about 2 and l_h about 1 (mismatch_nuisances.h).
constexpr double kMismatchPriorSigma = 3.0;
/// The change test starts once log a is known within this (1 sigma): before, the
/// filter's own convergence would read as a change.
constexpr double kChangeStartLogSigma = 0.05;
/// A window's direction of the parameters counts in the test only where it knows a jump
/// within 0.5 in log (1 sigma, a factor 1.65): the rest would test noise in directions the
/// window hardly excites (and gave jumps of factors 1e8).
constexpr double kMinJumpInformation = 1.0 / (0.5 * 0.5);
/// The variance factor (Kappa) is read once this many degrees of freedom are in (four
/// windows that determine all three parameters), and not below kMinKappa.
constexpr int kMinKappaRanks = 12;
/// Also the floor of the intervals' factors (CalibrationOf): where the filter's process
/// noise exceeds what its rows carry, its own covariance is too wide (c covered the truth
/// in 97-98% of exact-force logs with a floor of 1).
constexpr double kMinKappa = 0.25;
/// The intervals' variance factor (CalibrationOf) is read once this many degrees of freedom
/// are in, over completed windows and those under way: a window's statistic sits a few
/// rows after the filter settles, where a factor read only from four completed windows came
/// 120 rows later, and short logs' early intervals were the filter's own (too narrow: c
/// held the truth in 70-85% of the coverage suite's short logs at a quarter of their rows).
constexpr int kMinIntervalRanks = 3;
/// A parameter's own variance factor needs its directions to weigh this much (two
/// directions' worth); less, and the overall factor is used.
constexpr double kMinParameterWeight = 2.0;
/// The change test is disarmed while the variance factor exceeds this: a filter whose
/// innovations are that much larger than it says does not describe its log, and the
/// windows' statistics measure its misfit. On a coverage-suite log whose fast-spinning
/// pushes the filter had not followed (a 4% off at the end, the variance factor 17-28),
/// the misfit raised an alarm at a gate of 10.
constexpr double kMaxArmedKappa = 5.0;
/// A change window is tested once it holds this many rows (fewer say too little).
constexpr int kMinChangeRows = 10;
/// Eigenvalues of the change information below this fraction of its largest are
/// directions the window did not excite: left out of the test.
constexpr double kChangeRankFraction = 1e-8;

/// The prior's a. Low: a model whose a is too high sticks where the log slides, and a
/// sticking step says nothing about the friction (its derivatives are zero), while one
/// whose a is too low slides and is pulled up by the poses.
constexpr double kPriorA = 0.15;
/// The rows at which the filter is run again over the rows so far, linearised from where it
/// has got to (OnlineIdentifier::Relinearise), in half warm-ups (warmup_rows / 2): 1.5, 2, 3
/// and 4 warm-ups, each a third to a half more rows than the last. Before the first batch
/// check (batch_check_first_rows), so a replay runs no fit.
constexpr int kRelineariseHalfWarmups[] = {3, 4, 6, 8};
/// A batch check's fit that determines a parameter ok more than this many standard errors
/// (the two estimates' variances added) from the filter's marks the filter's suspect until
/// the next check (but a takeover, batch_check_sigmas, moves it there instead). Two
/// calibrated estimates of the same rows lie so far apart in 0.27% of logs, or less where
/// their errors are correlated.
constexpr double kCheckDoubtSigmas = 3.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool Fail(std::string* why, const std::string& text) {
  if (why) *why = text;
  return false;
}

double HorizontalForce(const AppliedWrench& w) { return std::hypot(w.fx, w.fy); }

AppliedWrench Lerp(const AppliedWrench& a, const AppliedWrench& b, double s) {
  auto l = [s](double x, double y) { return x + s * (y - x); };
  return {l(a.fx, b.fx), l(a.fy, b.fy), l(a.fz, b.fz), l(a.tx, b.tx), l(a.ty, b.ty), l(a.tz, b.tz)};
}

bool Finite(const TrajectorySample& r) {
  const PlanarState& s = r.state;
  const AppliedWrench& w = r.applied;
  for (double v : {r.t_s, s.x, s.y, s.theta, s.vx, s.vy, s.wz, w.fx, w.fy, w.fz, w.tx, w.ty, w.tz})
    if (!std::isfinite(v)) return false;
  return true;
}

/// A pointer that a copy of its owner does not share: what an identifier holds only while
/// it decides (a batch check's fit under way, the change confirmation's second filter) is
/// not copied with it.
template <typename T>
struct NotCopied {
  T value;
  NotCopied() = default;
  NotCopied(const NotCopied&) {}
  NotCopied& operator=(const NotCopied&) {
    value = T{};
    return *this;
  }
  NotCopied(NotCopied&&) noexcept = default;
  NotCopied& operator=(NotCopied&&) noexcept = default;
};

/// The running noise of one channel from its third differences.
class NoiseReader {
 public:
  void Add(double value) {
    last_[0] = last_[1];
    last_[1] = last_[2];
    last_[2] = last_[3];
    last_[3] = value;
    if (++seen_ < 4) return;
    const double d3 = last_[3] - 3 * last_[2] + 3 * last_[1] - last_[0];
    ++samples_;
    if (static_cast<int>(ring_.size()) < kNoiseRing) {
      ring_.push_back(std::abs(d3));
    } else {
      ring_[next_] = std::abs(d3);
      next_ = (next_ + 1) % kNoiseRing;
    }
  }
  /// The channel's run breaks (a push ends): differences start again at the next value.
  void Break() { seen_ = 0; }
  /// sigma = 1.4826 median |d3| / sqrt(20); 0 before any difference.
  double Sigma() const {
    if (ring_.empty()) return 0;
    return kMadToSigma * Median(ring_) / std::sqrt(kThirdDifferenceVariance);
  }
  /// Third differences taken so far.
  int samples() const { return samples_; }

 private:
  double last_[4] = {0, 0, 0, 0};
  int seen_ = 0, samples_ = 0;
  std::vector<double> ring_;
  int next_ = 0;
};

/// The running relative noise of the logged force, from its third differences over its
/// magnitude in the rows that push (a force above `min_force_n`).
class ForceNoiseReader {
 public:
  void Add(const AppliedWrench& w, double min_force_n) {
    for (int k = 0; k < 3; ++k) last_[k] = last_[k + 1];
    last_[3] = w;
    if (++seen_ < 4) return;
    const double f = std::hypot(w.fx, w.fy);
    if (!(f > min_force_n) || !(f > 0)) return;
    for (int k = 0; k < 3; ++k)
      if (!(std::hypot(last_[k].fx, last_[k].fy) > min_force_n)) return;  // a push starts
    auto d3 = [&](double AppliedWrench::*c) {
      return last_[3].*c - 3 * (last_[2].*c) + 3 * (last_[1].*c) - last_[0].*c;
    };
    // Along the force: a relative noise on each component (a sensor's gain) is largest
    // there, and it is the push's direction that the noise moves the slider in.
    const double r = std::abs(d3(&AppliedWrench::fx) * w.fx + d3(&AppliedWrench::fy) * w.fy) /
                     (std::sqrt(kThirdDifferenceVariance) * f * f);
    if (static_cast<int>(ring_.size()) < kNoiseRing) {
      ring_.push_back(r);
    } else {
      ring_[next_] = r;
      next_ = (next_ + 1) % kNoiseRing;
    }
  }
  /// sigma, or 0 before kMinForceNoiseSamples.
  double Fraction() const {
    if (static_cast<int>(ring_.size()) < kMinForceNoiseSamples) return 0;
    return Median(ring_) / kHalfNormalMedian;
  }

 private:
  AppliedWrench last_[4];
  int seen_ = 0;
  std::vector<double> ring_;
  int next_ = 0;
};

/// One window of the change test: the signature of a jump of the log-parameters at its
/// start in the filter's later innovations (Willsky and Jones 1976), and the information
/// it has gathered about such a jump.
struct ChangeWindow {
  int start_row = 0;
  double start_t_s = 0;
  int rows = 0;
  Matrix93 gamma = Matrix93::Zero();  // d(state error) / d(jump), after the last update
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  Eigen::Vector3d score = Eigen::Vector3d::Zero();
  // The filter after its first row's update: where a change found in it is filtered
  // again from.
  Vector9 x0 = Vector9::Zero();
  Matrix9 P0 = Matrix9::Zero();
  TrajectorySample last0, last_logged0;
};

/// b^T A^+ b over the directions A determines, and the jump A^+ b.
double LikelihoodRatio(const ChangeWindow& w, Eigen::Vector3d* jump, int* rank,
                       Eigen::Vector3d* parameter_statistic = nullptr,
                       Eigen::Vector3d* parameter_weight = nullptr) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(w.info);
  const Eigen::Vector3d lambda = eig.eigenvalues();
  const double largest = lambda.maxCoeff();
  jump->setZero();
  *rank = 0;
  if (!(largest > 0)) return 0;
  double stat = 0;
  for (int i = 0; i < 3; ++i) {
    if (!(lambda(i) > kChangeRankFraction * largest) || !(lambda(i) >= kMinJumpInformation)) {
      continue;
    }
    ++*rank;
    const double along = eig.eigenvectors().col(i).dot(w.score);
    stat += along * along / lambda(i);
    *jump += eig.eigenvectors().col(i) * (along / lambda(i));
    if (parameter_statistic) {
      const Eigen::Vector3d share = eig.eigenvectors().col(i).cwiseAbs2();
      *parameter_statistic += share * (along * along / lambda(i));
      *parameter_weight += share;
    }
  }
  return stat;
}

/// `log` without its rows: what the identifier keeps of it (a batch check's log, a replay).
Trajectory MetadataOf(const Trajectory& log) {
  Trajectory m;
  m.source = log.source;
  m.slider = log.slider;
  m.patch = log.patch;
  m.tip_radius_m = log.tip_radius_m;
  m.measured = log.measured;
  return m;
}

/// What a batch check's trajectory fit says of log a, log b, log c: per parameter the fit
/// finds ok, its log value and its interval's standard error (t widened; NaN for the
/// others), and where it finds all three ok their covariance (with the fit's correlations).
struct BatchCheckFit {
  Eigen::Vector3d log_value = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d log_sd = Eigen::Vector3d::Constant(kNaN);
  std::optional<Eigen::Matrix3d> covariance;
  std::size_t rows = 0;  ///< the rows it fitted
};

/// The trajectory fit of `log` for the batch check; no parameter and no covariance where the
/// fit refuses the rows (too short, say) or does not converge.
BatchCheckFit FitRowsSoFar(const Trajectory& log, int substeps, bool correct_mismatch) {
  BatchCheckFit out;
  out.rows = log.samples.size();
  IdentifyOptions o;
  o.method = EstimatorMethod::kTrajectory;
  o.threads = 1;
  o.keep_residuals = false;
  o.trajectory.substeps = substeps;
  o.trajectory.correct_mismatch = correct_mismatch;
  EstimateResult fit;
  try {
    fit = Identify(log, o);
  } catch (const std::exception&) {
    return out;
  }
  if (!fit.converged) return out;
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = fit.parameters[i];
    if (p.verdict != Verdict::kOk) continue;
    const double sd = std::log(p.ci95_hi / p.ci95_lo) / (2 * kZ95);  // the interval's, t widened
    if (!(sd > 0) || !std::isfinite(sd + std::log(p.value))) continue;
    out.log_value(i) = std::log(p.value);
    out.log_sd(i) = sd;
  }
  if (!out.log_sd.allFinite()) return out;
  Eigen::Matrix3d covariance;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double r = i == j ? 1.0 : fit.correlation[i][j];
      if (!std::isfinite(r)) return out;
      covariance(i, j) = r * out.log_sd(i) * out.log_sd(j);
    }
  }
  out.covariance = covariance;
  return out;
}

}  // namespace

bool OnlineOptions::IsValid(std::string* why) const {
  if (substeps < 1) return Fail(why, "substeps must be >= 1");
  if (!(pose_noise_m >= 0) || !std::isfinite(pose_noise_m))
    return Fail(why, "pose_noise_m must be a finite number >= 0");
  if (!(angle_noise_rad >= 0) || !std::isfinite(angle_noise_rad))
    return Fail(why, "angle_noise_rad must be a finite number >= 0");
  if (warmup_rows < kMinDiagnosticRows)
    return Fail(why, "warmup_rows must be >= " + std::to_string(kMinDiagnosticRows));
  if (!(force_noise_fraction >= 0) || !std::isfinite(force_noise_fraction))
    return Fail(why, "force_noise_fraction must be a finite number >= 0");
  if (!(model_acceleration_mps2 >= 0) || !std::isfinite(model_acceleration_mps2))
    return Fail(why, "model_acceleration_mps2 must be a finite number >= 0");
  if (!(prior_log_sigma > 0) || !std::isfinite(prior_log_sigma))
    return Fail(why, "prior_log_sigma must be a finite number > 0");
  if (!(change_threshold > 0) || !std::isfinite(change_threshold))
    return Fail(why, "change_threshold must be a finite number > 0");
  if (change_window_rows < 2 * kMinChangeRows)
    return Fail(why, "change_window_rows must be >= " + std::to_string(2 * kMinChangeRows));
  if (!(change_reset_log_sigma > 0) || !std::isfinite(change_reset_log_sigma))
    return Fail(why, "change_reset_log_sigma must be a finite number > 0");
  if (batch_check_first_rows < 0) return Fail(why, "batch_check_first_rows must be >= 0");
  if (batch_check_first_rows > 0 && batch_check_max_rows < batch_check_first_rows)
    return Fail(why, "batch_check_max_rows must be >= batch_check_first_rows");
  if (!(batch_check_sigmas > 0) || !std::isfinite(batch_check_sigmas))
    return Fail(why, "batch_check_sigmas must be a finite number > 0");
  return true;
}

struct OnlineIdentifier::Impl {
  OnlineOptions options;
  SliderProperties slider;
  double radius_m = 0;  // radius of gyration L
  Vector9 prior_mean = Vector9::Zero();
  OnlineResult result;

  NoiseReader noise_x, noise_y, noise_theta;
  ForceNoiseReader noise_force;
  // r = push point - CM over the pushing rows: its noise is what the logged moment's lever
  // carries (the push point's tracker and the pose's).
  NoiseReader noise_lever_x, noise_lever_y;
  double sigma_p = 0, sigma_theta = 0;
  double sigma_lever = 0;       // [m], per component
  double force_noise_read = 0;  // the reader's, at the last ReadNoise
  int rows_since_noise = 0;

  std::vector<TrajectorySample> warmup;
  TrajectorySample last, last_logged;  // the last row filtered, and the one before
  int lost_rows = 0;                   // consecutive rows beyond kLostNis
  double largest_push_n = 0;
  Vector9 x = Vector9::Zero();
  Matrix9 P = Matrix9::Zero();
  std::vector<Eigen::Vector4d> warm_base, warm_fine, warm_hold;  // per substep
  std::vector<ChangeWindow> windows;
  bool mismatch_released = false;
  ChangeWindow found;  // the window of the last change found
  Eigen::Vector3d size_before_change = Eigen::Vector3d::Zero();  // log a, b, c then
  int rows_to_refine_size = 0;                                   // RefineChangeSize
  Eigen::Vector3d found_jump = Eigen::Vector3d::Zero();
  std::deque<std::pair<int, TrajectorySample>> recent;  // the last rows filtered
  int rows_filtered = 0;
  double nis_sum = 0;  // InnovationKappa
  int nis_rows = 0;
  Eigen::Vector3d quantile_dof = Eigen::Vector3d::Zero(), quantile_value;  // IntervalQuantile
  double window_statistics = 0;  // sum of completed windows' likelihood ratios
  int window_ranks = 0;          // and of their degrees of freedom
  // The same per parameter: each direction's chi-square(1) term shared out by the squares of
  // its eigenvector's components, and the shares' sums (CalibrationOf).
  Eigen::Vector3d parameter_statistics = Eigen::Vector3d::Zero();
  Eigen::Vector3d parameter_weights = Eigen::Vector3d::Zero();
  Eigen::Vector3d open_statistics = Eigen::Vector3d::Zero(), open_weights = Eigen::Vector3d::Zero();
  double open_total = 0;
  int open_ranks = 0;
  int row_index = 0;  // of the row being filtered
  // The batch check (OnlineOptions::batch_check_first_rows): the log's metadata with the
  // rows since the start or the last change, the row count of the next fit, and the
  // information of (log a, log b, log c) of the last fit taken over (the intervals widen only
  // what the filter added since, IntervalVariances).
  Trajectory batch_log;
  std::size_t next_check_rows = 0;
  // A check on its own thread (OnlineOptions::batch_check_thread), and the surface (counted
  // by changes found) whose rows it fits.
  NotCopied<std::future<BatchCheckFit>> pending_check;
  int surface = 0, pending_surface = 0;
  // Per parameter, why the last check's fit doubts the filter's estimate (empty: it does
  // not): marked suspect until a later check finds no doubt (MarkWhatTheCheckDoubts).
  std::array<std::string, 3> check_doubt;
  bool taken_over = false;
  Eigen::Matrix3d takeover_information = Eigen::Matrix3d::Zero();
  std::optional<PusherFrictionStream> tip;  // mu_p, where the log has the tip
  // Relinearisation (OnlineIdentifier::Relinearise): the log's metadata and its rows so far,
  // kept while a replay may come; the prior mean of (log a, log b, log c) the filter's own
  // prior has (prior_mean, which a replay moves to linearise from there).
  Trajectory metadata;
  std::vector<TrajectorySample> early_rows;
  Eigen::Vector3d own_prior_mean = Eigen::Vector3d::Zero();
  bool replaying = false;
  // The change confirmation (OnlineOptions::confirm_changes): from an alarm until
  // change_window_rows rows later, the filter as it was at the alarm, going on as if there
  // had been none, and the rows left; each filter's log-likelihood of its innovations since
  // the alarm.
  NotCopied<std::unique_ptr<Impl>> unchanged;
  int rows_to_confirm = 0;
  double loglik_since_alarm = 0;

  void ReadNoise() {
    sigma_p = options.pose_noise_m > 0
                  ? options.pose_noise_m
                  : std::max(kMinPoseNoise_m, std::sqrt(0.5 * (std::pow(noise_x.Sigma(), 2) +
                                                               std::pow(noise_y.Sigma(), 2))));
    sigma_theta = options.angle_noise_rad > 0 ? options.angle_noise_rad
                                              : std::max(kMinAngleNoise_rad, noise_theta.Sigma());
    force_noise_read = noise_force.Fraction();
    const double lever_read =
        std::sqrt(0.5 * (std::pow(noise_lever_x.Sigma(), 2) + std::pow(noise_lever_y.Sigma(), 2)));
    // r is the push point less the pose, so its noise is at least the pose's.
    sigma_lever =
        noise_lever_x.samples() >= kMinLeverNoiseSamples ? std::max(sigma_p, lever_read) : sigma_p;
    rows_since_noise = 0;
  }

  // The state at a run's first row: its pose, an unknown velocity; the parameters keep
  // what they know.
  void StartRun(const TrajectorySample& row) {
    x(0) = row.state.x;
    x(1) = row.state.y;
    x(2) = row.state.theta;
    x.segment<3>(kVel).setZero();
    P.topRows<kPar>().setZero();
    P.leftCols<kPar>().setZero();
    P(0, 0) = P(1, 1) = sigma_p * sigma_p;
    P(2, 2) = sigma_theta * sigma_theta;
    P(3, 3) = P(4, 4) = kStartSpeedSigma_mps * kStartSpeedSigma_mps;
    P(5, 5) = std::pow(kStartSpeedSigma_mps / radius_m, 2);
    for (auto* warm : {&warm_base, &warm_fine, &warm_hold})
      std::fill(warm->begin(), warm->end(), Eigen::Vector4d::Zero());
    windows.clear();
    ClearOpenWindows();
    last = row;
  }

  void ClearOpenWindows() {
    open_statistics.setZero();
    open_weights.setZero();
    open_total = 0;
    open_ranks = 0;
  }

  void Start() {
    ReadNoise();
    x = prior_mean;
    P.setZero();
    P.block<3, 3>(kPar, kPar) =
        Eigen::Matrix3d::Identity() * options.prior_log_sigma * options.prior_log_sigma;
    mismatch_released = false;  // ReleaseMismatch
    StartRun(warmup.front());
    // The first row's velocity from the poses of the rows after it (the log may start in
    // the middle of a push).
    const TrajectorySample& second = warmup[2];
    const double span = second.t_s - warmup.front().t_s;
    if (second.mode != SampleMode::kStart && warmup[1].mode != SampleMode::kStart) {
      x(3) = (second.state.x - warmup.front().state.x) / span;
      x(4) = (second.state.y - warmup.front().state.y) / span;
      x(5) = (second.state.theta - warmup.front().state.theta) / span;
    }
    result.started = true;
    const int first = result.rows - static_cast<int>(warmup.size());
    for (size_t i = 1; i < warmup.size(); ++i) Filter(warmup[i], first + static_cast<int>(i));
    warmup.clear();
    warmup.shrink_to_fit();
  }

  // One model of the row: `substeps` backward-Euler steps from the filter's state, the
  // wrench held or interpolated. Writes the state at the row's end and its derivatives
  // with respect to (pose, velocity, log abc); false when a step fails.
  bool RunModel(const TrajectorySample& next, int substeps, bool interpolate,
                std::vector<Eigen::Vector4d>* warm, Vector6* end, Matrix69* jacobian) const {
    const double h = (next.t_s - last.t_s) / substeps;
    const ReducedFriction abc = FromLogParameters(x.data() + kPar);
    PlanarState s{x(0), x(1), x(2), x(3), x(4), x(5)};
    jacobian->setZero();
    jacobian->leftCols<6>().setIdentity();
    for (int k = 0; k < substeps; ++k) {
      const AppliedWrench w =
          interpolate ? Lerp(last.applied, next.applied, (k + 0.5) / substeps) : last.applied;
      StepOptions step_options;
      if ((*warm)[k](3) > 0) step_options.initial_guess = (*warm)[k];
      StepSensitivity sens;
      if (!SolveStepWithSensitivity(slider, abc, s, w, h, &sens, step_options)) return false;
      (*warm)[k] =
          sens.step.mode == StepMode::kSlide ? sens.step.scaled_solution : Eigen::Vector4d::Zero();
      s = sens.step.state;
      // nu' = f(nu, log abc); q' = q + h nu' (segment_cost.cc, the same chain rule).
      Eigen::Matrix<double, 3, 9> dnu = sens.dnu_dnu * jacobian->bottomRows<3>();
      dnu.rightCols<3>() += sens.dnu_dlogabc;
      jacobian->bottomRows<3>() = dnu;
      jacobian->topRows<3>() += h * dnu;
    }
    *end << s.x, s.y, s.theta, s.vx, s.vy, s.wz;
    return true;
  }

  // The transition of one row, Phi = d(filter state after) / d(filter state before), and
  // the state after. The model is the trajectory fit's, with its two mismatch nuisances
  // (estimator/internal/mismatch_nuisances.h) as states: end = e + l_d (e_fine - e) +
  // l_h (e_interp - e), e with `substeps` steps and the wrench held, e_fine with twice the
  // steps, e_interp with the wrench interpolated between this row and the next while both
  // push.
  bool Propagate(const TrajectorySample& next, Matrix9* phi) {
    const int n = options.substeps;
    Vector6 e;
    Matrix69 J;
    if (!RunModel(next, n, false, &warm_base, &e, &J)) return false;
    phi->setIdentity();
    Vector6 end = e;
    Matrix69 J_end = J;
    if (options.fit_mismatch) {
      const double contact = kContactForceFraction * largest_push_n;
      const bool interpolate = contact > 0 && HorizontalForce(last.applied) > contact &&
                               HorizontalForce(next.applied) > contact;
      Vector6 e_fine, e_hold = e;
      Matrix69 J_fine, J_hold = J;
      if (!RunModel(next, 2 * n, false, &warm_fine, &e_fine, &J_fine)) return false;
      if (interpolate && !RunModel(next, n, true, &warm_hold, &e_hold, &J_hold)) return false;
      const double ld = x(kLam), lh = x(kLam + 1);
      end += ld * (e_fine - e) + lh * (e_hold - e);
      J_end += ld * (J_fine - J) + lh * (J_hold - J);
      phi->block<6, 1>(0, kLam) = e_fine - e;
      phi->block<6, 1>(0, kLam + 1) = e_hold - e;
    }
    phi->topLeftCorner<6, 9>() = J_end;
    x.head<6>() = end;
    return true;
  }

  // Weights the row down (its pose noise R scaled up, as Huber does) until the update moves
  // no log-parameter by more than kMaxLogStepPerRow: one row's linearisation is not to be
  // trusted further. Up to kMaxStepLimitRounds rounds (each shrinks the step about r^2-fold
  // where R dominates S).
  void LimitParameterStep(const Eigen::Vector3d& nu, Eigen::Matrix3d* R, Eigen::Matrix3d* S,
                          Eigen::LLT<Eigen::Matrix3d>* llt) const {
    for (int round = 0; round < kMaxStepLimitRounds; ++round) {
      const Eigen::Vector3d step = P.block<3, 3>(kPar, 0) * llt->solve(nu);
      const double r = step.cwiseAbs().maxCoeff() / kMaxLogStepPerRow;
      if (!(r > 1)) return;
      *R *= r * r;
      *S = P.topLeftCorner<3, 3>() + *R;
      llt->compute(*S);
    }
  }

  // The relative force noise of the process noise (OnlineOptions::force_noise_fraction).
  double ForceNoiseFraction() const {
    if (options.force_noise_fraction > 0) return options.force_noise_fraction;
    if (!(ForceNoiseRead() > 0)) return kDefaultForceNoiseFraction;
    return std::clamp(force_noise_read, kMinForceNoiseFraction, kDefaultForceNoiseFraction);
  }

  // The relative force noise read off the log, once the filter's variance factor is in (0
  // before): the sensor's, where ForceNoiseFraction adds the allowances.
  double ForceNoiseRead() const {
    if (options.force_noise_fraction > 0) return options.force_noise_fraction;
    return window_ranks < kMinKappaRanks ? 0.0 : force_noise_read;
  }

  // What the model may miss over a row of length h: the logged wrench's noise and an
  // acceleration, as a velocity random walk (and the pose it moves).
  Matrix9 ProcessNoise(double h) const {
    const Eigen::Matrix3d q = WrenchNoise(h);
    Matrix9 Q = Matrix9::Zero();
    Q.block<3, 3>(kVel, kVel) = q;
    Q.block<3, 3>(0, 0) = q * (h * h / 3);
    Q.block<3, 3>(0, kVel) = Q.block<3, 3>(kVel, 0) = q * (h / 2);
    return Q;
  }

  // The covariance of (v_x, v_y, w_z) a row of length h adds. The force's relative noise s
  // moves the velocity by h s |f| / m. The moment: where the row has a push point, it is
  // r x f with r from the logged pose to the logged point, so it carries r x (the force's
  // noise), correlated with the force's, and (r's noise) x f, r's noise the point's and the
  // pose's. That part is sizeable where the push passes near the CM, which s t_z would
  // call exact: with it left out, the spin's innovations were larger than the filter said,
  // and the change test raised 50 alarms over the 2200 unchanged logs of the coverage
  // suite (200 per condition), 17 of 100 in force-3% (docs/online.md, "Change detection").
  // The force noise read off the log goes through the lever; the rest of s (the 3% before
  // it is read, the floor beyond it) stays on s t_z, as it stands in for the model's misfit
  // more than for a sensor's noise. Without a push point the logged moment is the sensor's:
  // s t_z.
  Eigen::Matrix3d WrenchNoise(double h) const {
    const AppliedWrench& w = last.applied;
    const double s = ForceNoiseFraction();
    const double acc = options.model_acceleration_mps2;
    // A white acceleration: its velocity variance grows with h, whatever the log's rate.
    const double qa = acc * acc * kModelAccelerationRow_s * h;
    const double hm = h / slider.mass_kg, hi = h / slider.inertia_kgm2;
    const double f2 = std::pow(HorizontalForce(w), 2);
    Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
    q(0, 0) = q(1, 1) = hm * hm * s * s * f2 + qa;
    q(2, 2) = qa / (radius_m * radius_m);
    if (!last.push_point_world || !(f2 > 0)) {
      q(2, 2) += std::pow(hi * s * w.tz, 2);
      return q;
    }
    const double s_lever = std::min(s, ForceNoiseRead());
    const double rx = last.push_point_world->x() - x(0), ry = last.push_point_world->y() - x(1);
    q(2, 2) += hi * hi *
               (s_lever * s_lever * f2 * (rx * rx + ry * ry) + sigma_lever * sigma_lever * f2 +
                (s * s - s_lever * s_lever) * w.tz * w.tz);
    q(0, 2) = q(2, 0) = -hm * hi * s_lever * s_lever * f2 * ry;
    q(1, 2) = q(2, 1) = hm * hi * s_lever * s_lever * f2 * rx;
    return q;
  }

  void Filter(const TrajectorySample& row, int index) {
    row_index = index;
    largest_push_n = std::max(largest_push_n, HorizontalForce(row.applied));
    if (row.mode == SampleMode::kStart) {
      StartRun(row);
      return;
    }
    const double h = row.t_s - last.t_s;
    Matrix9 phi;
    if (!Propagate(row, &phi)) {
      // The step did not converge from this state: start the motion afresh at this row
      // (what the parameters know is kept).
      ++result.failed_steps;
      StartRun(row);
      return;
    }
    P = phi * P * phi.transpose() + ProcessNoise(h);
    last_logged = last;
    last = row;
    ++rows_filtered;

    // The update with the logged pose.
    Eigen::Vector3d z(row.state.x, row.state.y, row.state.theta);
    Eigen::Vector3d nu = z - x.head<3>();
    Eigen::Matrix3d R =
        Eigen::Vector3d(sigma_p * sigma_p, sigma_p * sigma_p, sigma_theta * sigma_theta)
            .asDiagonal();
    Eigen::Matrix3d S = P.topLeftCorner<3, 3>() + R;
    Eigen::LLT<Eigen::Matrix3d> llt(S);
    double nis = nu.dot(llt.solve(nu));
    lost_rows = nis > kLostNis ? lost_rows + 1 : 0;
    if (lost_rows >= kLostRows) {
      Relocate(row, h);
      return;
    }
    if (nis > kOutlierNis) {
      // Huber: weight the row down to the threshold's influence.
      R *= nis / kOutlierNis;
      S = P.topLeftCorner<3, 3>() + R;
      llt.compute(S);
    }
    result.nis = nis;
    nis_sum += std::min(nis, kLostNis);
    ++nis_rows;
    LimitParameterStep(nu, &R, &S, &llt);
    const Eigen::Matrix3d S_inv = llt.solve(Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d L = llt.matrixL();  // log det S = 2 sum log L_ii
    loglik_since_alarm -= 0.5 * (nu.dot(S_inv * nu) + 2 * L.diagonal().array().log().sum());
    const Matrix93 K = P.leftCols<3>() * S_inv;

    UpdateChangeWindows(phi, K, S_inv, nu, row);

    x += K * nu;
    Matrix9 IKH = Matrix9::Identity();
    IKH.leftCols<3>() -= K;
    P = IKH * P * IKH.transpose() + K * R * K.transpose();  // Joseph: stays symmetric
    for (int i = 0; i < 3; ++i)
      x(kPar + i) = std::clamp(x(kPar + i), std::log(kFrictionLowerBound[i]),
                               std::log(kFrictionUpperBound[i]));
    ReleaseMismatch();
    if (!windows.empty() && windows.back().rows == 1 && windows.back().start_row == index) {
      ChangeWindow& w = windows.back();
      w.x0 = x;
      w.P0 = P;
      w.last0 = last;
      w.last_logged0 = last_logged;
    }
    recent.emplace_back(index, row);
    while (static_cast<int>(recent.size()) > options.change_window_rows + 1) recent.pop_front();
    if (result.change_detected) {
      KeepUnchangedFilter();
      RefilterAfterChange();
    } else {
      RefineChangeSize();
    }
  }

  // One row: the noise readers, the filter (or its warm-up), the batch check, mu_p and the
  // result. Update's, after it has checked the row.
  void TakeRow(const TrajectorySample& row) {
    const int index = result.rows;
    result.change_judged = false;
    ++result.rows;
    result.t_s = row.t_s;
    noise_x.Add(row.state.x);
    noise_y.Add(row.state.y);
    noise_theta.Add(row.state.theta);
    noise_force.Add(row.applied, kContactForceFraction * largest_push_n);
    AddLeverRow(row);
    const std::size_t changes = result.changes.size();
    if (!result.started) {
      warmup.push_back(row);
      if (static_cast<int>(warmup.size()) >= options.warmup_rows) Start();
    } else {
      if (++rows_since_noise >= kNoiseRefreshRows) ReadNoise();
      Filter(row, index);
    }
    CollectBatchCheck(false);
    // A change found at this row restarted the batch check's rows with this one among them.
    if (result.changes.size() == changes) AddBatchRow(row);
    AddTipRow(row);
    Report();
  }

  // At an alarm: a copy of the filter as it is, which goes on as if there had been no
  // change, until change_window_rows rows decide between the two (ConfirmOrWithdrawChange).
  void KeepUnchangedFilter() {
    if (!options.confirm_changes || !options.detect_changes) return;
    auto copy = std::make_unique<Impl>(*this);
    copy->options.detect_changes = false;
    copy->result.changes.pop_back();
    copy->result.change_detected = false;
    copy->loglik_since_alarm = 0;
    copy->tip.reset();  // mu_p does not depend on the friction: this filter's stays
    unchanged.value = std::move(copy);
    rows_to_confirm = options.change_window_rows;
  }

  // change_window_rows rows after an alarm: the change stands where the filter restarted at
  // it explains the rows since better than the one that went on without it (the
  // log-likelihood of their innovations, each filter's own covariance priced in, by more
  // than the jump's parameters cost); otherwise the filter without it replaces this one and
  // the change is withdrawn. The rows that raised the alarm are not among those that judge
  // it.
  void ConfirmOrWithdrawChange() {
    if (!unchanged.value || --rows_to_confirm > 0) return;
    std::unique_ptr<Impl> other = std::move(unchanged.value);
    // The restarted filter spends three parameters on the jump: the Bayesian information
    // criterion charges (3 / 2) log n for them, n the innovations' components judged.
    const double penalty = 1.5 * std::log(3.0 * options.change_window_rows);
    if (loglik_since_alarm - other->loglik_since_alarm > penalty) {
      result.changes.back().confirmed = true;
      result.change_judged = true;
      return;
    }
    // What does not depend on the friction stays this filter's: the rows, mu_p.
    const OnlineOptions own_options = options;
    const OnlineResult own = result;
    std::optional<PusherFrictionStream> own_tip = std::move(tip);
    *this = std::move(*other);
    options = own_options;
    tip = std::move(own_tip);
    result.rows = own.rows;
    result.t_s = own.t_s;
    result.mu_pusher = own.mu_pusher;
    result.mu_pusher_lower_bound = own.mu_pusher_lower_bound;
    result.mu_pusher_contact_rows = own.mu_pusher_contact_rows;
    result.mu_pusher_sliding_rows = own.mu_pusher_sliding_rows;
    result.withdrawn_changes = own.withdrawn_changes + 1;
    result.change_judged = true;
    Report();
  }

  // After a change found in window `found`: the filter goes back to the window's start,
  // takes the jump into the parameters, forgets what it knew of them (and of the mismatch
  // nuisances, which absorbed part of the change meanwhile), and filters the rows since
  // again: the rows between the change and the alarm no longer pull the new estimate
  // towards the old surface. Rare, and at most change_window_rows rows: O(1) amortised.
  void RefilterAfterChange() {
    const ChangeWindow w = found;
    x = w.x0;
    P = w.P0;
    last = w.last0;
    last_logged = w.last_logged0;
    // The filter starts again from the lower of the old a and the jump's: a model whose a
    // is too high sticks where the log slides and learns nothing there (kPriorA); the
    // jump's own estimate, from a window's linearisation, overshot by up to half of it.
    // b and c start from where they were, within the prior the reset gives them.
    x(kPar) += std::min(0.0, found_jump(0));
    for (int i = 0; i < 3; ++i)
      x(kPar + i) = std::clamp(x(kPar + i), std::log(kFrictionLowerBound[i]),
                               std::log(kFrictionUpperBound[i]));
    for (auto* warm : {&warm_base, &warm_fine, &warm_hold})
      std::fill(warm->begin(), warm->end(), Eigen::Vector4d::Zero());
    ResetAfterChange();
    std::deque<std::pair<int, TrajectorySample>> again;
    for (const auto& r : recent)
      if (r.first > w.start_row) again.push_back(r);
    recent.clear();
    lost_rows = 0;
    ++surface;
    check_doubt = {};
    if (options.batch_check_first_rows > 0) {
      batch_log.samples.clear();
      for (const auto& r : again) batch_log.samples.push_back(r.second);
      next_check_rows = options.batch_check_first_rows;
      result.batch_takeover_rows = 0;
    }
    for (const auto& [index, row] : again) Filter(row, index);
    loglik_since_alarm = 0;
    result.change_detected = true;
    // The change's size is refined once the filter has re-converged (RefineChangeSize).
    size_before_change = w.x0.segment<3>(kPar);
    rows_to_refine_size = options.change_window_rows;
  }

  // change_window_rows rows after an alarm, the change's size becomes the re-converged
  // estimate over the one at its window's start: the jump's own estimate, from a window that
  // may start before the change, can be well short of it (a x 1.08 for a truth of 1.33,
  // with the process noise read off an exact-force log).
  void RefineChangeSize() {
    if (rows_to_refine_size <= 0 || --rows_to_refine_size > 0 || result.changes.empty()) return;
    for (int i = 0; i < 3; ++i)
      result.changes.back().ratio[i] = std::exp(x(kPar + i) - size_before_change(i));
  }

  // The generalised likelihood ratio of a parameter jump at each window's start, from the
  // innovation nu of this row (before the update with gain K).
  void UpdateChangeWindows(const Matrix9& phi, const Matrix93& K, const Eigen::Matrix3d& S_inv,
                           const Eigen::Vector3d& nu, const TrajectorySample& row) {
    result.change_detected = false;
    ClearOpenWindows();
    const int half = options.change_window_rows / 2;
    // Before the filter knows a, a change is indistinguishable from its convergence.
    const bool settled = P(kPar, kPar) < kChangeStartLogSigma * kChangeStartLogSigma;
    if (settled && rows_filtered % half == 0) {
      ChangeWindow w;
      w.start_row = row_index;
      w.start_t_s = row.t_s;
      w.gamma.middleRows<3>(kPar).setIdentity();
      // The jump acts from this row's propagation on: its signature starts before it.
      windows.push_back(w);
    }
    double best = 0;
    int best_index = -1;
    Eigen::Vector3d best_jump = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < windows.size(); ++i) {
      ChangeWindow& w = windows[i];
      const Matrix93 prior = w.rows == 0 ? w.gamma : Matrix93(phi * w.gamma);
      const Eigen::Matrix3d G = prior.topRows<3>();
      w.info += G.transpose() * S_inv * G;
      w.score += G.transpose() * S_inv * nu;
      w.gamma = prior - K * G;
      ++w.rows;
      if (w.rows < kMinChangeRows) continue;
      Eigen::Vector3d jump;
      int rank = 0;
      const bool complete = w.rows == options.change_window_rows;
      // Windows under way count towards the intervals' variance factor (CalibrationOf).
      const bool open = !complete;
      const double raw =
          LikelihoodRatio(w, &jump, &rank, complete ? &parameter_statistics : &open_statistics,
                          complete ? &parameter_weights : &open_weights);
      if (complete) {
        window_statistics += raw;
        window_ranks += rank;
      }
      if (open) {
        open_total += raw;
        open_ranks += rank;
      }
      // A filter whose innovations are noisier than it says in every window is not
      // changing: the test is on the statistic over its own typical level.
      const double stat = raw / std::max(1.0, Kappa());
      if (stat > best) {
        best = stat;
        best_index = static_cast<int>(i);
        best_jump = jump;
      }
    }
    // Alarms wait for the variance factor: until four windows are in, the filter's own
    // settling (its linearisation still moving) reads as changes.
    // Nor does a filter that does not describe its log (a variance factor beyond
    // kMaxArmedKappa: the windows' statistics then measure its misfit, not a change).
    const bool armed = window_ranks >= kMinKappaRanks && Kappa() <= kMaxArmedKappa;
    result.change_test_armed = options.detect_changes && armed;
    if (options.detect_changes && armed && best_index >= 0 && best > options.change_threshold) {
      const ChangeWindow& w = windows[best_index];
      FrictionChange change;
      change.row = w.start_row;
      change.t_s = w.start_t_s;
      change.detected_row = row_index;
      change.statistic = best;
      for (int i = 0; i < 3; ++i) change.ratio[i] = std::exp(best_jump(i));
      found = w;
      found_jump = best_jump;
      result.changes.push_back(change);
      result.change_detected = true;
    }
    // Windows older than a window's span have said what they can.
    windows.erase(
        std::remove_if(windows.begin(), windows.end(),
                       [&](const ChangeWindow& w) { return w.rows >= options.change_window_rows; }),
        windows.end());
  }

  // How much larger the parameter-direction innovations are than the filter says: the mean
  // over completed change windows of their likelihood ratio per degree of freedom (1 for
  // a consistent filter). 1 until kMinKappaRanks degrees of freedom are in.
  double Kappa() const {
    if (window_ranks < kMinKappaRanks) return 1.0;
    return std::max(kMinKappa, window_statistics / window_ranks);
  }

  // What parameter i's interval is calibrated by: its variance factor, and the degrees of
  // freedom the factor is read from (0: not from the windows).
  struct IntervalCalibration {
    double kappa = 1;
    double dof = 0;
  };

  // The factor is the mean likelihood ratio per degree of freedom in i's directions (each
  // direction's chi-square(1) term shared out by the squares of its eigenvector's
  // components), over the completed windows and those under way (from kMinChangeRows rows),
  // once kMinIntervalRanks degrees of freedom are in (the interval then takes Student's t
  // for them); the overall factor, or the innovations' if larger, while i's directions weigh
  // less than kMinParameterWeight; the innovations' (InnovationKappa, at least 1) before.
  // Not below kMinKappa. docs/online.md, "Calibration".
  IntervalCalibration CalibrationOf(int i) const {
    const int ranks = window_ranks + open_ranks;
    if (ranks < kMinIntervalRanks) return {std::max(1.0, InnovationKappa()), 0};
    const double weight = parameter_weights(i) + open_weights(i);
    if (weight >= kMinParameterWeight) {
      return {std::max(kMinKappa, (parameter_statistics(i) + open_statistics(i)) / weight), weight};
    }
    const double overall = (window_statistics + open_total) / ranks;
    return {std::max(kMinKappa, std::max(InnovationKappa(), overall)), static_cast<double>(ranks)};
  }

  // Student's t quantile for `dof` of parameter i's calibration; kZ95 where the factor is
  // not read from the windows, or after a takeover (the fit's covariance is calibrated).
  // Below kStudentT95ExpansionDof, kept per parameter while its degrees of freedom stay the
  // same: there a quantile costs microseconds (Boost's inverse incomplete beta), and three a
  // row tripled the update's time.
  double IntervalQuantile(int i, double dof) {
    if (taken_over || dof <= 0) return kZ95;
    if (dof != quantile_dof[i]) {
      quantile_dof[i] = dof;
      quantile_value[i] = StudentT95Fast(dof);
    }
    return quantile_value[i];
  }

  // The mean NIS per degree of freedom over the rows since the start (or the last change),
  // each capped at kLostNis: how much larger the innovations are than the filter says, in
  // every direction. The intervals' factor where the windows say nothing of a parameter yet:
  // a filter whose model misses its rows early (NIS in the hundreds) has narrow intervals in
  // the wrong place (users log 73: c 250 times the truth at a quarter of its rows, on an
  // interval of a factor 4).
  double InnovationKappa() const { return nis_rows > 0 ? nis_sum / nis_rows / 3 : 1.0; }

  // The filter lost the motion (its model stuck while the slider slid, say): the motion
  // restarts from the last two rows, and what the parameters know is widened.
  void Relocate(const TrajectorySample& row, double h) {
    const Eigen::Vector3d previous(last_logged.state.x, last_logged.state.y,
                                   last_logged.state.theta);
    StartRun(row);
    x.segment<3>(kVel) = (x.head<3>() - previous) / h;
    const double s2 = options.change_reset_log_sigma * options.change_reset_log_sigma;
    for (int i = 0; i < 3; ++i) P(kPar + i, kPar + i) = std::max(P(kPar + i, kPar + i), s2);
    taken_over = false;  // the parameters' covariance no longer grows from the fit's
    ++result.relocations;
    lost_rows = 0;
  }

  // The mismatch nuisances are held at their values until the filter knows a (as the
  // trajectory fit fits them only at its end, from its minimum): while the parameters are
  // far off, they would explain what the parameters should (on the bundled log, a pair of
  // nuisances driven off in the first push's rows kept a 5% off to the end).
  void ReleaseMismatch() {
    if (!options.fit_mismatch || mismatch_released) return;
    if (!(P(kPar, kPar) < kChangeStartLogSigma * kChangeStartLogSigma)) return;
    P(kLam, kLam) = P(kLam + 1, kLam + 1) = kMismatchPriorSigma * kMismatchPriorSigma;
    mismatch_released = true;
  }

  // After a change: the old surface's information is forgotten.
  void ResetAfterChange() {
    const double s2 = options.change_reset_log_sigma * options.change_reset_log_sigma;
    // The parameters, and the mismatch nuisances, which absorbed part of the change
    // before the alarm, start again from their current values.
    P.bottomRows<kN - kPar>().setZero();
    P.rightCols<kN - kPar>().setZero();
    P.block<3, 3>(kPar, kPar) = Eigen::Matrix3d::Identity() * s2;
    mismatch_released = false;
    windows.clear();
    taken_over = false;
    // The new surface's filter earns its own variance factor, and its alarms wait for it.
    window_statistics = 0;
    window_ranks = 0;
    nis_sum = 0;
    nis_rows = 0;
    parameter_statistics.setZero();
    parameter_weights.setZero();
    ClearOpenWindows();
  }

  // r = push point - pose on the rows that push (a force above kContactForceFraction of the
  // largest so far), for the lever's noise; a row that does not push breaks the differences.
  void AddLeverRow(const TrajectorySample& row) {
    if (!row.push_point_world ||
        !(HorizontalForce(row.applied) > kContactForceFraction * largest_push_n) ||
        !(HorizontalForce(row.applied) > 0)) {
      noise_lever_x.Break();
      noise_lever_y.Break();
      return;
    }
    noise_lever_x.Add(row.push_point_world->x() - row.state.x);
    noise_lever_y.Add(row.push_point_world->y() - row.state.y);
  }

  // The pose noise so far: the filter's once it runs, the readers' before.
  void AddTipRow(const TrajectorySample& row) {
    if (!tip) return;
    if (result.started) {
      tip->Add(row, sigma_p, sigma_theta);
    } else {
      tip->Add(row, std::sqrt(0.5 * (std::pow(noise_x.Sigma(), 2) + std::pow(noise_y.Sigma(), 2))),
               noise_theta.Sigma());
    }
    const PusherFrictionResult& r = tip->result();
    result.mu_pusher = r.mu;
    result.mu_pusher_lower_bound = r.lower_bound;
    result.mu_pusher_contact_rows = r.contact_rows;
    result.mu_pusher_sliding_rows = r.sliding_rows;
  }

  void Report() {
    result.state = {x(0), x(1), x(2), x(3), x(4), x(5)};
    result.pose_noise_m = sigma_p;
    result.angle_noise_rad = sigma_theta;
    result.variance_factor = Kappa();
    result.force_noise_fraction = ForceNoiseFraction();
    std::array<IntervalCalibration, 3> calibration;
    for (int i = 0; i < 3; ++i) {
      calibration[i] = CalibrationOf(i);
      result.interval_variance_factors[i] = calibration[i].kappa;
    }
    const Eigen::Vector3d interval_variance = IntervalVariances();
    for (int i = 0; i < 3; ++i) {
      ParameterEstimate& p = result.parameters[i];
      p = ParameterEstimate{};
      if (!result.started) {
        p.reason = "the filter starts after " + std::to_string(options.warmup_rows) +
                   " rows (from which it reads the noise)";
        continue;
      }
      const double sd = std::sqrt(std::max(0.0, interval_variance(i)));
      const double q = IntervalQuantile(i, calibration[i].dof);
      const double lo = std::exp(x(kPar + i) - q * sd), hi = std::exp(x(kPar + i) + q * sd);
      if (!(hi / lo <= kMaxIntervalFactor)) {
        p.held_at = std::exp(x(kPar + i));
        p.reason = "the rows so far do not determine it (95% interval spans a factor " +
                   ShortNumber(hi / lo) + ")";
        continue;
      }
      p.identifiable = true;
      p.verdict = Verdict::kOk;
      p.value = std::exp(x(kPar + i));
      // The interval's, as ParameterEstimate has it: its half-width over kZ95 (delta method).
      p.stderr_value = p.value * sd * q / kZ95;
      p.ci95_lo = lo;
      p.ci95_hi = hi;
      p.interval_quantile = q;
    }
    JudgeEstimates(Plausibility(), &result.parameters);
    MarkWhatTheCheckDoubts();
  }

  // Where the last check's fit and the filter disagree (kCheckDoubtSigmas) without a
  // takeover, one of them is wrong: the filter's estimate is marked suspect (not withdrawn:
  // the fit of a prefix cut within a push is the less reliable of the two as often).
  void MarkWhatTheCheckDoubts() {
    for (int i = 0; i < 3; ++i) {
      ParameterEstimate& p = result.parameters[i];
      if (check_doubt[i].empty() || p.verdict != Verdict::kOk) continue;
      p.verdict = Verdict::kSuspect;
      p.reason = check_doubt[i];
    }
  }

  // The variances of log a, b, c the intervals come from: the filter's, each widened by its
  // factor (CalibrationOf); after a batch takeover, the fit's information plus what the
  // filter added since, only the latter widened: the batch fit's covariance is calibrated.
  Eigen::Vector3d IntervalVariances() const {
    const Eigen::Matrix3d Ppp = P.block<3, 3>(kPar, kPar);
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v(i) = Ppp(i, i) * result.interval_variance_factors[i];
    if (!taken_over) return v;
    const Eigen::LDLT<Eigen::Matrix3d> now(Ppp);
    if (now.info() != Eigen::Success || !now.isPositive()) return v;
    // The information the rows since the takeover added; no direction may lose any.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> added(now.solve(Eigen::Matrix3d::Identity()) -
                                                         takeover_information);
    const Eigen::Vector3d gain = added.eigenvalues().cwiseMax(0.0);
    const Eigen::Matrix3d added_psd =
        added.eigenvectors() * gain.asDiagonal() * added.eigenvectors().transpose();
    Eigen::Vector3d shrink;
    for (int i = 0; i < 3; ++i) shrink(i) = 1.0 / std::sqrt(result.interval_variance_factors[i]);
    const Eigen::Matrix3d total =
        takeover_information + shrink.asDiagonal() * added_psd * shrink.asDiagonal();
    const Eigen::LDLT<Eigen::Matrix3d> t(total);
    if (t.info() != Eigen::Success || !t.isPositive()) return v;
    return t.solve(Eigen::Matrix3d::Identity()).diagonal();
  }

  // Keeps `row` for the batch check and runs one when the rows since the start (or the last
  // change) reach the next count: batch_check_first_rows, twice that, ... (amortised O(1)).
  void AddBatchRow(const TrajectorySample& row) {
    if (options.batch_check_first_rows <= 0) return;
    if (batch_log.samples.size() >= static_cast<std::size_t>(options.batch_check_max_rows)) return;
    batch_log.samples.push_back(row);
    if (!result.started || batch_log.samples.size() < next_check_rows) return;
    next_check_rows *= 2;
    BatchCheck();
  }

  // Runs the check: here, or on a thread of its own (OnlineOptions::batch_check_thread),
  // whose verdict the first update after it finished applies (CollectBatchCheck). One at a
  // time: a check due while the last still runs is skipped.
  void BatchCheck() {
    if (options.batch_check_thread) {
      if (pending_check.value.valid()) return;
      try {
        pending_check.value = std::async(std::launch::async, [log = batch_log, o = options] {
          return FitRowsSoFar(log, o.substeps, o.fit_mismatch);
        });
        ++result.batch_checks;
        pending_surface = surface;
        return;
      } catch (const std::system_error&) {
        // No thread to be had: the check runs here instead.
      }
    }
    ++result.batch_checks;
    ApplyCheck(FitRowsSoFar(batch_log, options.substeps, options.fit_mismatch));
  }

  // The verdict of a check run on its thread, once it is in (`wait`: waiting for it).
  void CollectBatchCheck(bool wait) {
    if (!pending_check.value.valid()) return;
    if (!wait && pending_check.value.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
      return;
    const BatchCheckFit fit = pending_check.value.get();
    // A fit of the rows before a change found since says nothing of the new surface.
    if (pending_surface == surface) ApplyCheck(fit);
  }

  // A check's verdict. Where the fit finds a, b and c ok and the filter's estimate of one
  // lies more than batch_check_sigmas from the fit's, the filter ran off: it takes the fit's
  // estimate and covariance (TakeOver). Otherwise it goes on as it was (taking the fit's
  // every time ties the online estimate to fits of a prefix, whose intervals on a few
  // segments are less reliable than the filter's: docs/online.md), and each parameter the
  // fit finds ok more than kCheckDoubtSigmas away is doubted, replacing the last check's
  // doubts. Distances in standard errors, the two estimates' variances added.
  void ApplyCheck(const BatchCheckFit& fit) {
    Eigen::Vector3d apart;  // NaN where the fit has no estimate
    for (int i = 0; i < 3; ++i) {
      const double sd = std::sqrt(fit.log_sd(i) * fit.log_sd(i) + P(kPar + i, kPar + i));
      apart(i) = std::abs(fit.log_value(i) - x(kPar + i)) / sd;
    }
    const bool took_over =
        fit.covariance && apart.maxCoeff() > options.batch_check_sigmas && TakeOver(fit);
    const std::string rows = std::to_string(fit.rows);
    for (int i = 0; i < 3; ++i) {
      check_doubt[i].clear();
      if (took_over || !(apart(i) > kCheckDoubtSigmas)) continue;
      check_doubt[i] = Printf(
          "a trajectory fit of the first %s rows (the last batch check) lies %.1f standard "
          "errors from the filter's estimate",
          rows, apart(i));
    }
  }

  // The filter takes the fit's estimate and covariance of the parameters; false where the
  // covariance is not positive definite (nothing taken).
  bool TakeOver(const BatchCheckFit& fit) {
    const Eigen::LDLT<Eigen::Matrix3d> c(*fit.covariance);
    if (c.info() != Eigen::Success || !c.isPositive()) return false;
    if (!TakeParameters(fit.log_value, *fit.covariance)) return false;
    takeover_information = c.solve(Eigen::Matrix3d::Identity());
    taken_over = true;
    ++result.batch_takeovers;
    result.batch_takeover_rows = static_cast<int>(fit.rows);
    // The change windows' signatures are of the filter before its parameters moved.
    windows.clear();
    ClearOpenWindows();
    return true;
  }

  // The parameters' marginal becomes N(mean, covariance); the other states' conditional on
  // them stays: with K = P_.p P_pp^-1, x += K (mean - x_p) and P += K (covariance - P_pp) K^T
  // (the p rows of K are the identity).
  bool TakeParameters(const Eigen::Vector3d& mean, const Eigen::Matrix3d& covariance) {
    const Eigen::Matrix3d Ppp = P.block<3, 3>(kPar, kPar);
    const Eigen::LLT<Eigen::Matrix3d> llt(Ppp);
    if (llt.info() != Eigen::Success) return false;
    const Matrix93 K = llt.solve(P.middleCols<3>(kPar).transpose()).transpose();
    x += K * (mean - x.segment<3>(kPar));
    P += K * (covariance - Ppp) * K.transpose();
    P = 0.5 * (P + P.transpose()).eval();
    x.segment<3>(kPar) = mean;  // exactly, not to rounding
    return true;
  }

  // The batch fit's checks of a believable value (plausibility.h), with the prior as the
  // seed: a filter that linearised far from the truth early can settle on a narrow interval
  // orders of magnitude off (c of 5.5 m for a truth of 3 cm, on 1000 rows with pose
  // outliers), and that must read as suspect, not ok.
  PlausibilityContext Plausibility() const {
    PlausibilityContext c;
    c.seed = FromLogParameters(own_prior_mean.data());
    c.lower = kFrictionLowerBound;
    c.upper = kFrictionUpperBound;
    c.logs.push_back({slider.mass_kg * slider.gravity_mps2, largest_push_n});
    return c;
  }
};

OnlineIdentifier::OnlineIdentifier(const Trajectory& metadata, const OnlineOptions& options)
    : impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("online identifier: " + why);
  const SliderProperties& s = metadata.slider;
  if (!(s.mass_kg > 0) || !(s.inertia_kgm2 > 0) || !(s.gravity_mps2 > 0) ||
      !(s.com_height_m >= 0) ||
      !std::isfinite(s.mass_kg * s.inertia_kgm2 * s.gravity_mps2 * s.com_height_m)) {
    throw std::invalid_argument(
        "online identifier: the slider's mass, inertia and gravity must be finite and > 0 and "
        "its com_height finite and >= 0 (mass = " +
        ShortNumber(s.mass_kg) + ", inertia = " + ShortNumber(s.inertia_kgm2) + ")");
  }
  if (!metadata.measured.pose) {
    // Its update is with the logged pose; a log of velocities alone would read as a slider
    // resting at the origin.
    throw std::invalid_argument(
        "online identifier: the log has no poses (x, y, theta); it identifies from poses");
  }
  Init(metadata, options, impl_.get());
}

void OnlineIdentifier::Init(const Trajectory& metadata, const OnlineOptions& options, Impl* impl) {
  const SliderProperties& s = metadata.slider;
  Impl& m = *impl;
  m.options = options;
  m.slider = s;
  m.metadata = MetadataOf(metadata);
  m.radius_m = std::sqrt(s.inertia_kgm2 / s.mass_kg);
  m.prior_mean(kPar) = std::log(kPriorA);
  m.prior_mean(kPar + 1) = 0;
  m.prior_mean(kPar + 2) = std::log(m.radius_m);
  m.own_prior_mean = m.prior_mean.segment<3>(kPar);
  m.warm_base.assign(options.substeps, Eigen::Vector4d::Zero());
  m.warm_fine.assign(2 * options.substeps, Eigen::Vector4d::Zero());
  m.warm_hold.assign(options.substeps, Eigen::Vector4d::Zero());
  if (options.batch_check_first_rows > 0) {
    m.batch_log = MetadataOf(metadata);
    m.next_check_rows = options.batch_check_first_rows;
  }
  if (PusherFrictionStream::Applies(metadata)) {
    m.tip.emplace(metadata);
    m.result.mu_pusher_examined = true;
    m.result.mu_pusher = m.tip->result().mu;
  }
  m.Report();
}

OnlineIdentifier::~OnlineIdentifier() = default;
OnlineIdentifier::OnlineIdentifier(OnlineIdentifier&&) noexcept = default;
OnlineIdentifier& OnlineIdentifier::operator=(OnlineIdentifier&&) noexcept = default;

const OnlineResult& OnlineIdentifier::Update(const TrajectorySample& row) {
  Impl& m = *impl_;
  const int index = m.result.rows;
  if (!Finite(row)) {
    throw std::invalid_argument("online identifier: row " + std::to_string(index) +
                                " has a non-finite value");
  }
  const double previous_t = m.result.rows > 0 ? m.result.t_s : -HUGE_VAL;
  if (!(row.t_s > previous_t)) {
    throw std::invalid_argument(
        "online identifier: row " + std::to_string(index) + " at t = " + ShortNumber(row.t_s) +
        " s does not come after the previous row (t = " + ShortNumber(previous_t) + " s)");
  }
  const bool confirming = m.unchanged.value != nullptr;
  m.TakeRow(row);
  if (confirming) {
    m.unchanged.value->TakeRow(row);
    m.ConfirmOrWithdrawChange();
  } else if (m.unchanged.value) {  // an alarm at this row: the other filter has filtered it
    m.unchanged.value->AddBatchRow(row);
  }
  if (m.replaying) return m.result;
  const int rows = m.result.rows;
  const int last_replay_rows =
      kRelineariseHalfWarmups[std::size(kRelineariseHalfWarmups) - 1] * m.options.warmup_rows / 2;
  if (rows <= last_replay_rows) m.early_rows.push_back(row);
  for (int w : kRelineariseHalfWarmups) {
    if (rows == w * m.options.warmup_rows / 2) {
      Relinearise();  // may replace *impl_: `m` is not used after it
      break;
    }
  }
  if (rows >= last_replay_rows) impl_->early_rows.clear();
  return impl_->result;
}

// An extended Kalman filter linearises each row once, at the estimate it has then: rows
// filtered while the estimate was far from where it ends (the prior's a is 0.15) leave their
// error in it, and it decays only as rows come. On a noise-free free slide of the scene suite
// (log 12112: a flat box thrown spinning at 17 rad/s, 200 Hz) the estimate of a was 6% over
// the truth 20 rows in and 1.2% over 120 rows in, where started at the truth it stays there.
// So at kRelineariseHalfWarmups the rows so far are filtered again from the start, the prior's
// mean moved to the estimate (which linearises the early rows there), and the result
// corrected back to the prior's own mean: for a linear model the posterior mean moves by
// P_.p Sigma0^-1 (m0 - m1) when the prior mean of the parameters moves from m1 to m0
// (Sigma0 the prior's covariance), exactly. The replay is kept only where its innovations
// are no larger in sum than the first pass's (a linearisation that explains the rows better).
void OnlineIdentifier::Relinearise() {
  Impl& first = *impl_;
  // Not after a change, a relocation or a batch check (with batch_check_first_rows under the
  // replays' rows): a replay would run its fit again, or start from another surface's rows.
  if (!first.result.started || first.result.change_detected || !first.result.changes.empty() ||
      first.result.batch_checks > 0 || first.result.relocations > 0) {
    return;
  }
  auto replay = std::make_unique<Impl>();
  Init(first.metadata, first.options, replay.get());
  replay->prior_mean.segment<3>(kPar) = first.x.segment<3>(kPar);
  replay->replaying = true;
  std::swap(impl_, replay);  // replay: the first pass, for now
  for (const TrajectorySample& row : replay->early_rows) Update(row);
  Impl& again = *impl_;
  again.replaying = false;
  if (!(again.nis_sum <= replay->nis_sum) || again.result.changes.size() > 0 ||
      again.result.relocations > 0) {
    std::swap(impl_, replay);  // the first pass stays
    return;
  }
  const double prior_information =
      1.0 / (again.options.prior_log_sigma * again.options.prior_log_sigma);
  const Eigen::Vector3d back =
      prior_information * (again.own_prior_mean - again.prior_mean.segment<3>(kPar));
  again.x += again.P.middleCols<3>(kPar) * back;
  again.early_rows = std::move(replay->early_rows);
  again.result.relinearisations = replay->result.relinearisations + 1;
  again.Report();
}

const OnlineResult& OnlineIdentifier::WaitForBatchCheck() {
  impl_->CollectBatchCheck(true);
  impl_->Report();
  return impl_->result;
}

const OnlineResult& OnlineIdentifier::result() const { return impl_->result; }

Eigen::Matrix3d OnlineIdentifier::LogParameterCovariance() const {
  return impl_->P.block<3, 3>(kPar, kPar);
}

std::vector<OnlineResult> RunOnline(const Trajectory& log, const OnlineOptions& options,
                                    const std::vector<int>& keep_rows) {
  OnlineIdentifier id(log, options);
  std::vector<OnlineResult> out;
  size_t next = 0;
  for (size_t u = 0; u < log.samples.size(); ++u) {
    const OnlineResult& r = id.Update(log.samples[u]);
    if (keep_rows.empty()) {
      out.push_back(r);
    } else if (next < keep_rows.size() && static_cast<int>(u) == keep_rows[next]) {
      out.push_back(r);
      ++next;
    }
  }
  return out;
}

}  // namespace slideid
