#pragma once
// Which push next (advise-push, slideid.advise_push; issue 21): given what is known of the
// friction (an estimate and its covariance, or a prior), the candidate pushes
// (estimator/push_candidates.h) ranked by what each is expected to teach.
//
// For each candidate: the push is simulated at the current estimate by the pusher-driven
// forward model (forward_model/pusher_step.h), sampled as a log at `log_rate_hz` with the
// tip's contact force as its force channel, and the trajectory fit's own information of
// that log is taken at the estimate: J^T J of (log a, log b, log c) through the fit's
// shooting segments with their states marginalised out (the machinery identify --check
// uses; exact step sensitivities, estimator/step_sensitivity.h), over the pose noise
// sigma^2. What the push would leave is (P + J^T J / sigma^2)^-1, P the information
// known so far; the candidates are ranked by it.
//
// The criteria, on the relative standard errors (those of log a, log b, log c):
//  - least-known (the default): the largest of the three after the push, smallest first.
//    The question asked of an experiment is "is every parameter known to x%?", which the
//    worst one answers; D-optimality can buy a better a at the expense of a c still
//    unknown (the determinant does not care which parameter it shrinks);
//  - d-optimal: the determinant of the covariance after the push, smallest first.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "estimator/push_candidates.h"
#include "forward_model/contact_patch.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"

namespace slideid {

enum class AdviceCriterion { kLeastKnown, kDOptimal };
const char* ToString(AdviceCriterion criterion);  ///< "least-known", "d-optimal"
/// Parses the names above; false for anything else.
bool ParseAdviceCriterion(const std::string& text, AdviceCriterion* criterion);

/// What is known of the friction before the next push: a point and the information
/// (inverse covariance) of (log a, log b, log c) about it.
struct FrictionKnowledge {
  ReducedFriction estimate;
  Eigen::Matrix3d information_log = Eigen::Matrix3d::Zero();
  /// Where it came from, per parameter: "estimate" or "prior" (and overall, for the report).
  std::array<std::string, 3> from{{"prior", "prior", "prior"}};
};

/// A range of a parameter that the prior holds with 95%: its centre is the geometric mean,
/// its log-standard deviation ln(hi / lo) / (2 * 1.96).
struct PriorRange {
  double lo = 0, hi = 0;
};

/// The stated prior when nothing has been identified yet: a in [0.1, 1] (from ice on steel
/// to rubber on wood), b in [0.5, 2] (an anisotropy of up to 2 either way), c in
/// [0.1, 1] times the outline's largest distance from the CM (a patch's e_r / e_t lies in
/// it: 2 R / 3 for a uniformly pressed disk of radius R, make-dataset's draws 0.1 to 1 of it).
struct FrictionPrior {
  PriorRange a{0.1, 1.0};
  PriorRange b{0.5, 2.0};
  /// As fractions of the outline's largest distance from the CM (dimensionless).
  PriorRange c_fraction{0.1, 1.0};

  bool IsValid(std::string* why) const;
};

/// The prior's knowledge for a slider with `patch` (c scaled by its outline's reach). Throws
/// std::invalid_argument for an invalid prior.
FrictionKnowledge KnowledgeFromPrior(const FrictionPrior& prior, const ContactPatch& patch);

/// The knowledge an identify result carries: each identifiable parameter's value and its
/// standard error as that of its log (stderr / value), uncorrelated (a result file holds no
/// correlations); a parameter not identifiable keeps the prior's (at its held value when it
/// has one). Throws std::invalid_argument naming the parameter for an identifiable one
/// without a positive finite value and standard error.
FrictionKnowledge KnowledgeFromResult(const EstimateResult& result, const FrictionKnowledge& prior);

/// `known`'s standard errors, with the correlations that `log_information` implies: the
/// information of the logs the result came from at its estimate (LogInformation, summed
/// over them). A result file holds standard errors, not correlations; without them a push
/// that pins down only a combination of a and b (sliding one way) looks as if it had
/// pinned down both, and the advice repeats it. The correlations are those of
/// (log_information + known.information_log)^-1 (what is known keeps a direction the logs
/// leave open finite); the standard errors stay known's. Throws std::invalid_argument for a
/// non-finite or non-symmetric matrix.
FrictionKnowledge WithCorrelations(const FrictionKnowledge& known,
                                   const Eigen::Matrix3d& log_information);

struct PushAdviceOptions {
  PushCandidateOptions candidates;
  AdviceCriterion criterion = AdviceCriterion::kLeastKnown;
  /// Standard deviation of each pose residual the fit sees (x, y and the heading times the
  /// radius of gyration) [m]: 0.3 mm, the motion capture of make-dataset's logs and the
  /// bundled log, unless a result says what its residuals were.
  double pose_noise_m = 3e-4;
  /// The log's rate [Hz]: the push is simulated at one step a row, so that the log's
  /// force, held over each row, replays it exactly in the fit's model (> 0).
  double log_rate_hz = 100.0;
  int threads = 1;  ///< candidates simulated at once (>= 1)

  bool IsValid(std::string* why) const;
};

/// One candidate, what its simulation showed and what it would leave.
struct CandidateAdvice {
  PushCandidate push;
  /// Whether its simulation ran to the end; if not, `failure` says why (toppling, no
  /// convergence) and it teaches nothing (information zero).
  bool simulated = false;
  std::string failure;
  /// J^T J / sigma^2 of (log a, log b, log c) of this push alone.
  Eigen::Matrix3d information_log = Eigen::Matrix3d::Zero();
  /// The relative standard errors (of log a, log b, log c) after the push.
  std::array<double, 3> relative_stderr_after{};
  double score = 0;       ///< the criterion's value (smaller is better)
  int rows = 0;           ///< rows of its log
  double moved_m = 0;     ///< how far the slider's CM ends from where it started [m]
  double turned_rad = 0;  ///< how far it turns [rad]
  bool tip_touched = false;
};

/// The ranking.
struct PushAdvice {
  FrictionKnowledge knowledge;  ///< what it started from
  std::array<double, 3> relative_stderr_now{};
  AdviceCriterion criterion = AdviceCriterion::kLeastKnown;
  double pose_noise_m = 0;
  std::vector<CandidateAdvice> ranking;  ///< every candidate, best first
};

/// The relative standard errors (of log a, log b, log c) that `information_log` implies:
/// sqrt of the diagonal of its inverse, infinite along directions it does not determine
/// (never NaN: a singular matrix is inverted over its determined part only).
std::array<double, 3> RelativeStdErrors(const Eigen::Matrix3d& information_log);

/// The criterion's score of the knowledge `information_log` (smaller is better): the
/// largest relative standard error, or the determinant of the covariance (of log a, b, c;
/// infinite when singular).
double AdviceScore(const Eigen::Matrix3d& information_log, AdviceCriterion criterion);

/// The information J^T J / sigma^2 of (log a, log b, log c) that the trajectory fit would
/// draw from `log` at `friction` (slider properties set): its shooting segments' states
/// marginalised out (`trajectory` says how it cuts them; its nuisances are not fitted).
/// Zero when the log is too short for one segment.
Eigen::Matrix3d LogInformation(const Trajectory& log, const ReducedFriction& friction,
                               double pose_noise_m, const TrajectoryOptions& trajectory = {});

/// Simulates `push` at `friction` as a log at `options.log_rate_hz` and takes its
/// information (LogInformation). Never throws for a failed simulation: it is a status.
CandidateAdvice EvaluatePush(const SliderProperties& slider, const ContactPatch& patch,
                             const ReducedFriction& friction, const PushCandidate& push,
                             const PushAdviceOptions& options);

/// Orders candidates by the criterion applied to prior + each one's information, best
/// first (ties: the earlier candidate first); fills relative_stderr_after and score.
void RankCandidates(const Eigen::Matrix3d& prior_information, AdviceCriterion criterion,
                    std::vector<CandidateAdvice>* candidates);

/// The advice: every candidate of options.candidates evaluated at knowledge.estimate and
/// ranked. Throws std::invalid_argument for invalid options or a non-finite, non-symmetric
/// or non-positive-semidefinite information.
PushAdvice AdvisePush(const SliderProperties& slider, const ContactPatch& patch,
                      const FrictionKnowledge& knowledge, const PushAdviceOptions& options);

}  // namespace slideid
