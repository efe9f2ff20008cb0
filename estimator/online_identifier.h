#pragma once
// Identification while pushing (issue 21): an extended Kalman filter on the state
// (x, y, theta, v_x, v_y, w_z) and the log-parameters (log a, log b, log c), one log row at
// a time, in O(1) time per row. Its model is the trajectory fit's (estimator/trajectory_fit.h):
// the step solver with exact sensitivities (estimator/step_sensitivity.h), the logged wrench,
// the logged poses; its parameters are the reduced friction a = e_t mu, b = e_o / e_t,
// c = e_r / e_t [m] (model.md, "Only three parameters matter"). A change of the friction
// within the log (a new surface) is found by a likelihood-ratio test on the innovations
// (Willsky and Jones' generalised likelihood ratio for a jump of the parameters), after
// which the filter forgets what it knew of the parameters and converges on the new ones.
// Why a filter and not a fixed-lag window of the multiple-shooting problem: docs/online.md.

#include <Eigen/Core>
#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// Options of the online identifier. Noise levels left at 0 are read off the log as it
/// comes (the MAD of the poses' third differences, as DiagnoseLog reads them).
struct OnlineOptions {
  /// Forward-model steps per log interval (backward Euler, the wrench held), as the
  /// trajectory fit's --substeps.
  int substeps = 1;
  /// Estimate the two model-mismatch nuisances of the trajectory fit with the state
  /// (estimator/internal/mismatch_nuisances.h): how far the log's motion leans towards a
  /// model with twice the substeps and one with the wrench interpolated within rows. A
  /// continuous motion (any real log) against one step per row biases a by about 1% without
  /// them. Costs three models per row instead of one.
  bool fit_mismatch = true;
  double pose_noise_m = 0;     ///< 0: read off the log
  double angle_noise_rad = 0;  ///< 0: read off the log
  /// Rows buffered before the filter starts, from which the noise is first read. The rows
  /// are then filtered at once, so every row is used.
  int warmup_rows = 16;
  /// Process noise: relative noise of the logged force and moment (1 sigma), the
  /// uncertainty a logged force carries into the velocity over a row (h sigma_f / m).
  /// 0: read off the log (the MAD of the force's third differences over its magnitude, in
  /// the rows that push), at least 0.5%, once the filter's variance factor is in (12
  /// degrees of freedom of completed change windows); 3% before, and again after a change.
  double force_noise_fraction = 0;
  /// Process noise: an acceleration [m/s^2] (and that over the radius of gyration, in
  /// rad/s^2) that the model may miss: a continuous motion against backward-Euler steps,
  /// force interpolation. White: over a 10 ms row it moves the velocity by this times 10 ms
  /// (1 sigma), over a row of h by sqrt(h / 10 ms) as much, so the allowance per second is
  /// the same at any log rate. Keeps the filter from trusting its own model further than the
  /// trajectory fit's shooting segments do.
  double model_acceleration_mps2 = 0.05;
  /// The prior of (a, b, c) before any row: (0.15, 1, L) with L the radius of gyration,
  /// each within a factor exp(prior_log_sigma) (1 sigma).
  double prior_log_sigma = 1.0;
  /// Change detection: the likelihood-ratio statistic (chi-square with 3 degrees of freedom
  /// under no change) over the variance factor must exceed this for an alarm. 36 is its
  /// 7.5e-8 tail: with two windows tested per row, at most 0.15 false alarms per million
  /// rows of a filter whose innovations are white. (The 1e-6 tail, 30.7, gave one alarm in
  /// 80,000 tested rows of unchanged logs, at 31.4: the filter is not that white.)
  double change_threshold = 36.0;
  /// Rows a change window spans; a new one starts every half of it, so a change is
  /// located within change_window_rows / 2 rows and tested over at least that many.
  int change_window_rows = 60;
  bool detect_changes = true;
  /// Each alarm is judged change_window_rows rows later: the filter restarted at it and one
  /// that went on without it both filter those rows, and the change stands where the first
  /// explains them better (the log-likelihood of their innovations); otherwise it is
  /// withdrawn (OnlineResult::withdrawn_changes) and the filter without it goes on. Model
  /// mismatch for a push or two (a violent push logged at 100-250 Hz, outliers) can raise an
  /// alarm; it does not last. Costs a second filter over those rows.
  bool confirm_changes = true;
  /// After a change, the parameters' prior is this wide (1 sigma, log) around the
  /// estimated new value: the filter forgets the old surface.
  double change_reset_log_sigma = 0.3;
  /// The batch check: when the rows since the filter started (or since the last change)
  /// reach batch_check_first_rows, then twice, four times as many, ... up to
  /// batch_check_max_rows, the trajectory fit (estimator/trajectory_fit.h) of those rows
  /// runs. Where it finds a, b and c ok and the filter's estimate of one of them lies more
  /// than batch_check_sigmas standard errors (the two estimates' combined) from the fit's,
  /// the filter has run off (it linearised far from the truth early, and the poses since
  /// could not bring it back): its parameters take the fit's estimate and covariance, and
  /// the rest of its state what it knows given them (docs/online.md, "The batch check").
  /// Costs about two batch fits of the log, amortised; an update that runs one takes the
  /// fit's time (1-2 ms per 100 rows: 0.61 s at 32768). 0: no check.
  int batch_check_first_rows = 128;
  int batch_check_max_rows = 32768;
  double batch_check_sigmas = 5.0;
  /// Run each check's fit on a thread of its own, so that no update waits for it (a control
  /// loop's); its verdict applies at the first update after it finished, which depends on
  /// the machine's timing: the answers are then not reproducible row for row. A check due
  /// while the last runs is skipped; the destructor waits for a running one.
  bool batch_check_thread = false;

  bool IsValid(std::string* why) const;
};

/// A change of the friction found in the log.
struct FrictionChange {
  int row = 0;           ///< first row of the window in which it happened
  double t_s = 0;        ///< that row's time [s]
  int detected_row = 0;  ///< the row at which the test raised the alarm
  double statistic = 0;  ///< the likelihood ratio (chi-square(3) under no change)
  /// Its size: new over old value of a, b, c (1: unchanged).
  std::array<double, 3> ratio{{1, 1, 1}};
  /// change_window_rows rows after the alarm, the rows since explained better with it than
  /// without (OnlineOptions::confirm_changes); until then, or without confirmation, false.
  bool confirmed = false;
};

/// What the identifier knows after a row.
struct OnlineResult {
  int rows = 0;          ///< rows received
  double t_s = 0;        ///< time of the last row [s]
  bool started = false;  ///< the filter runs (warm-up done)
  /// a, b, c with intervals exp(log +- z95 sigma) and verdicts: ok; not identifiable while
  /// the interval spans more than kMaxIntervalFactor (the prior's width); suspect where the
  /// batch fit's plausibility checks fail, or where the last batch check's fit lies more
  /// than 3 standard errors from the estimate without taking it over (the reason says).
  std::array<ParameterEstimate, 3> parameters;
  /// mu_p, the tip-edge friction, where the log has the tip's path, its radius and the
  /// outline (examined): the batch fit's estimate (estimator/pusher_friction.h) from the rows
  /// so far, as PusherFrictionStream keeps it: the median |f_t| / f_n over the rows where
  /// the tip slides along the edge, each row classified slip_half_window_rows (5) rows
  /// later. Not identifiable while the tip has not slid in enough rows; then
  /// mu_pusher_lower_bound, from the rows where it sticks, when it has pushed at all.
  bool mu_pusher_examined = false;
  ParameterEstimate mu_pusher;
  double mu_pusher_lower_bound = std::numeric_limits<double>::quiet_NaN();
  int mu_pusher_contact_rows = 0, mu_pusher_sliding_rows = 0;
  PlanarState state;  ///< the filter's state at the last row
  /// The last row's normalised innovation squared (chi-square(3) when the model fits).
  double nis = std::numeric_limits<double>::quiet_NaN();
  double pose_noise_m = 0, angle_noise_rad = 0;  ///< the noise the filter uses
  double force_noise_fraction = 0;               ///< the relative force noise it uses
  /// How much larger than the filter's own covariance of the log-parameters their
  /// innovations say it is (the mean likelihood ratio per degree of freedom of the completed
  /// change windows; 1 until four are in), as a quasi-likelihood scales its covariance: the
  /// change test's scale. docs/online.md.
  double variance_factor = 1;
  /// The factors the intervals of a, b, c are scaled by (their variances'): each
  /// parameter's own variance factor, from the windows' statistics in its directions, the
  /// completed windows' and those under way, not below 0.25; before the windows say
  /// anything, the mean NIS per degree of freedom, at least 1. An interval whose factor
  /// comes from few degrees of freedom takes Student's t quantile for them
  /// (ParameterEstimate::interval_quantile). docs/online.md, "Calibration".
  std::array<double, 3> interval_variance_factors{{1, 1, 1}};
  /// The change test runs (the filter has settled and its variance factor is known).
  bool change_test_armed = false;
  bool change_detected = false;  ///< at this row
  /// At this row the last alarm was confirmed or withdrawn (OnlineOptions::confirm_changes).
  bool change_judged = false;
  std::vector<FrictionChange> changes;  ///< every change so far, but those withdrawn
  /// Alarms withdrawn: the rows after them were explained better without the change
  /// (OnlineOptions::confirm_changes). Each was in `changes` until then.
  int withdrawn_changes = 0;
  /// Rows at which the filter had lost the motion (20 sigma off on 3 rows in a row) and
  /// restarted it from the poses, widening what it knew of the parameters.
  int relocations = 0;
  /// Times the rows so far were filtered again from a better linearisation (early in a log).
  int relinearisations = 0;
  int failed_steps = 0;  ///< rows whose step did not converge (the filter restarted its velocity)
  /// The batch check (OnlineOptions::batch_check_first_rows): fits run, and those the
  /// filter took over from (it had run off); the rows the last one taken covered.
  int batch_checks = 0, batch_takeovers = 0, batch_takeover_rows = 0;
};

class OnlineIdentifier {
 public:
  /// `metadata`: the log's slider properties (mass, inertia, com_height, gravity), and
  /// its patch and tip radius when it has them, and its columns (it must have poses; other
  /// motion columns are not used); its samples are ignored. Throws std::invalid_argument
  /// for invalid options or slider properties, or a log without poses.
  explicit OnlineIdentifier(const Trajectory& metadata, const OnlineOptions& options = {});
  ~OnlineIdentifier();
  OnlineIdentifier(OnlineIdentifier&&) noexcept;
  OnlineIdentifier& operator=(OnlineIdentifier&&) noexcept;

  /// Takes the next row (times strictly increasing; a row marked `start` restarts the
  /// filter's state after a gap) and returns the estimate. Throws std::invalid_argument for
  /// a row that goes back in time or has non-finite values, naming the row.
  const OnlineResult& Update(const TrajectorySample& row);
  const OnlineResult& result() const;
  /// With OnlineOptions::batch_check_thread: waits for a check running on its thread and
  /// applies its verdict (at the end of a log, say); the result after it. Otherwise the
  /// result as it is.
  const OnlineResult& WaitForBatchCheck();
  /// The filter's covariance of (log a, log b, log c).
  Eigen::Matrix3d LogParameterCovariance() const;

 private:
  struct Impl;
  static void Init(const Trajectory& metadata, const OnlineOptions& options, Impl* impl);
  void Relinearise();
  std::unique_ptr<Impl> impl_;
};

/// Runs every row of `log` through an identifier and returns the result after each row at
/// which `keep` is true (every row when empty). For tests and the batch comparison.
std::vector<OnlineResult> RunOnline(const Trajectory& log, const OnlineOptions& options,
                                    const std::vector<int>& keep_rows = {});

}  // namespace slideid
