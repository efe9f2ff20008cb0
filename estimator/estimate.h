#pragma once
// What an identification returns (its Summary: estimates, verdicts, how it ended), and the
// options of each method. The identifiable parameters are a = e_t mu, b = e_o / e_t and
// c = e_r / e_t [m] (model.md, "Only three parameters matter").

#include <array>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace slideid {

enum class EstimatorMethod {
  kClosedForm,
  kEquationError,
  kTrajectory,
  kQuasiStatic,  ///< wrench-twist pairs, not a push log (estimator/quasi_static_fit.h)
};
enum class RobustLoss { kNone, kHuber, kCauchy };

/// "closed-form", "equation-error", "trajectory", "quasi-static"
const char* ToString(EstimatorMethod method);
const char* ToString(RobustLoss loss);  ///< "none", "huber", "cauchy"

/// Index of a parameter in EstimateResult::parameters.
enum ParameterIndex { kA = 0, kB = 1, kC = 2 };
/// JSON / table names: e_t_mu, e_o_over_e_t, e_r_over_e_t.
const char* ParameterName(int index);

/// How far an estimate can be trusted.
enum class Verdict {
  kOk,               ///< determined by the log, and every plausibility check passed
  kSuspect,          ///< determined, but a check failed (the reason says which): doubtful
  kNotIdentifiable,  ///< the log does not determine it; it was held, and has no value
};
const char* ToString(Verdict verdict);  ///< "ok", "suspect", "not identifiable"

/// How an identification ended, as Ceres' TerminationType says how a solve ended.
enum class TerminationStatus {
  kConverged,             ///< converged, and every parameter is ok
  kConvergedWithCaveats,  ///< converged, but a parameter is suspect or not identifiable
  kNoConvergence,         ///< the fit did not converge; its estimates are not to be used
  kTooLittleExcitation,   ///< the log determines no parameter (too little sliding, a dead
                          ///< force channel, too short); the message says which
};
/// "converged", "converged with caveats", "no convergence", "too little excitation".
const char* ToString(TerminationStatus status);

/// One estimated parameter. value, stderr and the interval are NaN when not identifiable.
struct ParameterEstimate {
  bool identifiable = false;  ///< verdict != kNotIdentifiable
  Verdict verdict = Verdict::kNotIdentifiable;
  double value = std::numeric_limits<double>::quiet_NaN();
  double stderr_value = std::numeric_limits<double>::quiet_NaN();  ///< standard error
  double ci95_lo = std::numeric_limits<double>::quiet_NaN();
  double ci95_hi = std::numeric_limits<double>::quiet_NaN();
  /// The interval's quantile: Student's t on the covariance's degrees of freedom, or kZ95.
  /// stderr_value is the interval's (half-width over kZ95, in logs); the covariance's own
  /// standard error is stderr_value * kZ95 / interval_quantile.
  double interval_quantile = 1.959963984540054;
  /// The trajectory fit: the value at its cost's minimum, before the model-mismatch
  /// correction moved it to `value` (equal to it when none was applied). Which minimum
  /// the fit ended in is judged on this one (fixtures/suite_check.h). NaN for the other
  /// methods and when not identifiable.
  double minimum_value = std::numeric_limits<double>::quiet_NaN();
  /// The value it was held at when not identifiable (it then does not affect the fit).
  double held_at = std::numeric_limits<double>::quiet_NaN();
  /// Why it is suspect or not identifiable (empty when ok).
  std::string reason;
  /// How the interval was formed, when that is worth knowing (e.g. widened by the
  /// cluster-robust covariance).
  std::string note;
};

/// A sensor nuisance fitted jointly with (a, b, c): a constant force offset of a log's force
/// channel, or a delay of its force stream against its poses. Values may be negative, so
/// the interval is value +- 1.96 stderr.
struct NuisanceEstimate {
  std::string name;  ///< "force_bias_x_n", "force_bias_y_n" or "delay_s"
  std::string log;   ///< the log it belongs to ("" when one value is shared by all)
  bool identifiable = false;
  Verdict verdict = Verdict::kNotIdentifiable;
  double value = std::numeric_limits<double>::quiet_NaN();
  double stderr_value = std::numeric_limits<double>::quiet_NaN();
  double ci95_lo = std::numeric_limits<double>::quiet_NaN();
  double ci95_hi = std::numeric_limits<double>::quiet_NaN();
  double held_at = std::numeric_limits<double>::quiet_NaN();
  std::string reason;
};

/// A per-step residual for --residuals: what the fit could not explain at a log row.
struct StepResidual {
  int log = 0;  ///< index of the log in a pooled fit
  int row = 0;
  double t_s = 0;
  std::array<double, 3> value{};  ///< method-specific channels, named in residual_names
  bool used = true;
};

/// One iteration of one least-squares solve of the fit, from Ceres' Summary: the
/// optimisation trace. Costs of different solves are of different problems (the segments'
/// heads, the plain and the robust loss) and are compared within a solve only.
struct SolverIteration {
  std::string stage;  ///< which solve: "seed (segment heads)", "least squares", "robust", ...
  int iteration = 0;  ///< within its solve; 0 is the point the solve starts from
  double cost = 0;    ///< Ceres' cost: half the sum of the squared (robustified) residuals
  double gradient_max_norm = 0;  ///< of the cost, in the solver's parameters
  double step_norm = 0;          ///< of the step that led here (0 at iteration 0)
};

/// One log of a pooled identification, fitted on its own.
struct LogResult {
  std::string name;      ///< its source (file name), or "log N"
  bool skipped = false;  ///< unreadable or unusable, and --skip-bad was given
  std::string skip_reason;
  int rows = 0;
  int steps_used = 0;
  TerminationStatus status = TerminationStatus::kConverged;
  std::string message;  ///< how its own fit ended
  std::array<ParameterEstimate, 3> parameters;
};

/// Whether the logs of a pooled fit agree on a parameter within their own noise: Cochran's
/// Q of the per-log estimates of log(parameter), weighted by their inverse variances, with
/// the DerSimonian-Laird between-log spread. Tested only with two or more logs that each
/// identify the parameter.
struct Heterogeneity {
  bool tested = false;
  int logs = 0;  ///< logs that identify the parameter
  double q = std::numeric_limits<double>::quiet_NaN();
  double p_value = std::numeric_limits<double>::quiet_NaN();  ///< of Q under chi2(logs - 1)
  double i2 = std::numeric_limits<double>::quiet_NaN();       ///< share of spread beyond noise
  /// Between-log standard deviation of log(parameter) (DerSimonian-Laird): 0.1 means the
  /// logs' true values spread by about 10%.
  double tau_log = std::numeric_limits<double>::quiet_NaN();
  bool consistent = true;  ///< p_value >= kHeterogeneityAlpha
};

/// A correlation matrix of unknown entries (EstimateResult::correlation's default).
inline std::array<std::array<double, 3>, 3> NaNCorrelation() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {{{nan, nan, nan}, {nan, nan, nan}, {nan, nan, nan}}};
}

/// The Summary of an identification: estimates with verdicts, how the fit ended, and what
/// the log (or logs) told it.
struct EstimateResult {
  EstimatorMethod method = EstimatorMethod::kTrajectory;
  TerminationStatus status = TerminationStatus::kConverged;
  std::array<ParameterEstimate, 3> parameters;  ///< a, b, c (ParameterIndex)
  /// The tip-edge friction mu_p, for logs with the tip's path (estimator/pusher_friction.h);
  /// examined says whether they had one. Not identifiable when the tip never slides along
  /// the edge: mu_pusher_lower_bound then says how large it is at least (NaN otherwise).
  bool mu_pusher_examined = false;
  ParameterEstimate mu_pusher;
  double mu_pusher_lower_bound = std::numeric_limits<double>::quiet_NaN();
  std::vector<NuisanceEstimate> nuisance;  ///< force offsets and delays, when fitted
  int steps_total = 0;
  int steps_used = 0;
  /// Reasons steps were left out, with counts ("sticking", "v_t near zero", ...).
  std::vector<std::pair<std::string, int>> steps_excluded;
  /// The noise the log itself shows (from its high-frequency content), and the RMS of the
  /// fit's residuals in the same channels [m or m/s; the equation error: impulses over p_n,
  /// dimensionless]; NaN where not computed.
  double log_noise = std::numeric_limits<double>::quiet_NaN();
  double residual_rms = std::numeric_limits<double>::quiet_NaN();
  double final_cost = 0;
  int iterations = 0;
  /// The trajectory fit: every iteration of its least-squares solves, in order (the
  /// optimisation trace; empty for the other methods). Of the pooled fit when pooled.
  std::vector<SolverIteration> trace;
  /// The trajectory fit: the correlations of the estimates of log a, log b and log c, from
  /// the covariance its intervals come from (ParameterIndex order; NaN where a parameter is
  /// not identifiable, or for the other methods).
  std::array<std::array<double, 3>, 3> correlation = NaNCorrelation();
  double seconds = 0;
  bool converged = true;  ///< status is kConverged or kConvergedWithCaveats
  std::string message;    ///< how the solve ended
  std::array<std::string, 3> residual_names{{"r0", "r1", "r2"}};
  std::vector<StepResidual> residuals;
  /// Pooled fits: every log fitted on its own (in input order), and whether they agree.
  std::vector<LogResult> logs;
  std::array<Heterogeneity, 3> heterogeneity;

  void Exclude(const std::string& reason, int count = 1);
  /// Sets status (and converged) from the solve's outcome and the verdicts.
  void Conclude(bool solve_converged);
};

/// Options of the closed form (model.md, Appendix A, corrected).
struct ClosedFormOptions {
  /// A divisor of an Appendix A formula counts as near zero below this fraction of its
  /// step's own scale (estimator/closed_form.h).
  double divisor_fraction = 0.1;
  bool IsValid(std::string* why) const;
};

/// Options shared by the least-squares methods.
struct LossOptions {
  RobustLoss loss = RobustLoss::kHuber;
  /// Robust loss scale in units of the residuals' estimated standard deviation.
  double loss_scale_sigmas = 3.0;
  int max_iterations = 100;  ///< Ceres iterations per solve
  bool IsValid(std::string* why) const;
};

/// Options of the equation-error fit (estimator/equation_error.h).
struct EquationErrorOptions : LossOptions {
  /// Correct the fit for the bias the log's noise gives it (estimator/simex.h):
  /// kSimexReplicates Gauss-Newton steps on noisier copies (about 3x the fit's time).
  bool correct_noise_bias = true;
};

/// How the trajectory fit treats the delay of the force stream against the poses.
enum class DelayFit { kNone, kPerLog, kShared };

/// Options of the trajectory fit (estimator/trajectory_fit.h).
struct TrajectoryOptions : LossOptions {
  /// Log intervals per shooting segment; 0 adapts it to the log (TrajectorySegmentSteps).
  int segment_steps = 0;
  int substeps = 1;  ///< forward-model steps per log interval
  /// Fit a constant offset (x, y) [N] of each log's force channel.
  bool fit_force_bias = false;
  /// Fit a delay of the force stream against the poses, per log or one for all.
  DelayFit fit_delay = DelayFit::kNone;
  double max_delay_s = 0.1;  ///< |delay| searched up to this [s]
  /// Correct the estimate for the mismatch between the fit's model (backward-Euler steps,
  /// the wrench held over each row) and a continuous motion, by two linearised nuisances
  /// per log whose uncertainty the intervals carry (estimator/internal/mismatch_nuisances.h).
  bool correct_mismatch = true;
  /// Start the fit a second time from longer segments and keep the lower of the two minima
  /// of its cost (trajectory_fit.cc, "a second start"). Off: the first start's minimum.
  bool second_start = false;
  /// On a log of at most 300 rows, fit it again over long segments and mark
  /// an estimate suspect when that fit lands outside its interval (trajectory_fit.cc, "a
  /// cross-check"). Off: no second fit.
  bool cross_check = true;
  bool IsValid(std::string* why) const;
};

/// Options of the quasi-static fit of wrench-twist pairs (estimator/quasi_static_fit.h).
struct QuasiStaticOptions : LossOptions {};

/// Everything Identify needs: which method, and each method's own options.
struct IdentifyOptions {
  EstimatorMethod method = EstimatorMethod::kTrajectory;
  int threads = 1;  ///< Ceres threads
  ClosedFormOptions closed_form;
  EquationErrorOptions equation_error;
  TrajectoryOptions trajectory;
  QuasiStaticOptions quasi_static;
  /// Fill EstimateResult::residuals (for --residuals and --report). False leaves them out of
  /// the trajectory fit's and the closed form's results, and nothing else: 48 bytes a row,
  /// 48 MB of a 1e6-row log, that `identify` keeps only when asked for them.
  bool keep_residuals = true;
  bool IsValid(std::string* why) const;
};

/// Standard normal quantile of a two-sided 95% interval.
constexpr double kZ95 = 1.959963984540054;

}  // namespace slideid
