#include "estimator/push_advice.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <stdexcept>

#include "estimator/internal/trajectory_problem.h"
#include "estimator/parallel_for.h"
#include "forward_model/constants.h"
#include "forward_model/number_format.h"
#include "forward_model/simulator.h"

namespace slideid {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// An eigenvalue of an information matrix below this fraction of its largest is a direction
// it does not determine: J^T J rounds to a relative 1e-16 of its scale, so 1e-13 is three
// orders above rounding, and a real direction that weak would mean a standard error 3e6
// times the best-known one's: unknown for any purpose of the advice.
constexpr double kUndeterminedEigenvalue = 1e-13;

// An information matrix whose asymmetry or negative eigenvalue exceeds this fraction of its
// scale was not formed as J^T J plus a covariance's inverse: bad input.
constexpr double kSymmetryTolerance = 1e-9;

double Reach(const ContactPatch& patch) {
  double reach = 0;
  for (const Eigen::Vector2d& p : patch.Outline()) reach = std::max(reach, p.norm());
  return reach;
}

double LogSd(const PriorRange& r) { return std::log(r.hi / r.lo) / (2 * kZ95); }

void CheckInformation(const Eigen::Matrix3d& h, const std::string& what) {
  if (!h.allFinite()) throw std::invalid_argument(what + ": the information is not finite");
  const double scale = std::max(h.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
  if ((h - h.transpose()).cwiseAbs().maxCoeff() > kSymmetryTolerance * scale) {
    throw std::invalid_argument(what + ": the information is not symmetric");
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(h);
  if (eig.eigenvalues()(0) < -kSymmetryTolerance * scale) {
    throw std::invalid_argument(what +
                                ": the information is not positive semidefinite (eigenvalue " +
                                ShortNumber(eig.eigenvalues()(0)) + ")");
  }
}

}  // namespace

const char* ToString(AdviceCriterion criterion) {
  return criterion == AdviceCriterion::kDOptimal ? "d-optimal" : "least-known";
}

bool ParseAdviceCriterion(const std::string& text, AdviceCriterion* criterion) {
  if (text == "least-known") {
    *criterion = AdviceCriterion::kLeastKnown;
  } else if (text == "d-optimal") {
    *criterion = AdviceCriterion::kDOptimal;
  } else {
    return false;
  }
  return true;
}

bool FrictionPrior::IsValid(std::string* why) const {
  const PriorRange* ranges[3] = {&a, &b, &c_fraction};
  const char* names[3] = {"a", "b", "c"};
  for (int i = 0; i < 3; ++i) {
    const PriorRange& r = *ranges[i];
    if (!(r.lo > 0 && r.hi > r.lo && std::isfinite(r.hi))) {
      if (why) {
        *why = Printf("the prior range of %s must be 0 < LO < HI, finite: %s:%s", names[i],
                      ShortNumber(r.lo), ShortNumber(r.hi));
      }
      return false;
    }
  }
  return true;
}

FrictionKnowledge KnowledgeFromPrior(const FrictionPrior& prior, const ContactPatch& patch) {
  std::string why;
  if (!prior.IsValid(&why)) throw std::invalid_argument(why);
  const double reach = Reach(patch);
  const PriorRange c{prior.c_fraction.lo * reach, prior.c_fraction.hi * reach};
  FrictionKnowledge k;
  k.estimate.a = std::sqrt(prior.a.lo * prior.a.hi);
  k.estimate.b = std::sqrt(prior.b.lo * prior.b.hi);
  k.estimate.c = std::sqrt(c.lo * c.hi);
  const double sd[3] = {LogSd(prior.a), LogSd(prior.b), LogSd(c)};
  for (int i = 0; i < 3; ++i) k.information_log(i, i) = 1.0 / (sd[i] * sd[i]);
  return k;
}

FrictionKnowledge KnowledgeFromResult(const EstimateResult& result,
                                      const FrictionKnowledge& prior) {
  FrictionKnowledge k = prior;
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = result.parameters[i];
    if (!p.identifiable) {
      // Not determined by the log: the prior's width, about what the fit held it at.
      if (p.held_at > 0 && std::isfinite(p.held_at)) k.estimate[i] = p.held_at;
      continue;
    }
    if (!(p.value > 0 && std::isfinite(p.value))) {
      throw std::invalid_argument(std::string("/") + ParameterName(i) +
                                  "/value: an identifiable parameter needs a positive value, not " +
                                  ShortNumber(p.value));
    }
    if (!(p.stderr_value > 0 && std::isfinite(p.stderr_value))) {
      throw std::invalid_argument(std::string("/") + ParameterName(i) +
                                  "/stderr: an identifiable parameter needs a positive, finite "
                                  "standard error, not " +
                                  ShortNumber(p.stderr_value));
    }
    k.estimate[i] = p.value;
    const double sd_log = p.stderr_value / p.value;
    k.information_log.row(i).setZero();
    k.information_log.col(i).setZero();
    k.information_log(i, i) = 1.0 / (sd_log * sd_log);
    k.from[i] = "estimate";
  }
  return k;
}

FrictionKnowledge WithCorrelations(const FrictionKnowledge& known,
                                   const Eigen::Matrix3d& log_information) {
  CheckInformation(known.information_log, "what is known");
  CheckInformation(log_information, "the logs' information");
  const std::array<double, 3> sd = RelativeStdErrors(known.information_log);
  for (double v : sd) {
    if (!std::isfinite(v)) return known;  // nothing known along some direction: as it is
  }
  const Eigen::Matrix3d joint = log_information + known.information_log;
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(joint);
  if (ldlt.info() != Eigen::Success || !(joint.determinant() > 0)) return known;
  const Eigen::Matrix3d c = ldlt.solve(Eigen::Matrix3d::Identity());
  Eigen::Matrix3d covariance;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      covariance(i, j) = c(i, j) / std::sqrt(c(i, i) * c(j, j)) * sd[i] * sd[j];
    }
  }
  FrictionKnowledge out = known;
  const Eigen::LDLT<Eigen::Matrix3d> inverse(covariance);
  if (inverse.info() != Eigen::Success) return known;
  const Eigen::Matrix3d solved = inverse.solve(Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d information = 0.5 * (solved + solved.transpose());
  if (!information.allFinite()) return known;
  out.information_log = information;
  return out;
}

bool PushAdviceOptions::IsValid(std::string* why) const {
  if (!candidates.IsValid(why)) return false;
  const auto fail = [&](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  if (!(pose_noise_m > 0 && std::isfinite(pose_noise_m))) {
    return fail("pose_noise_m must be > 0: " + ShortNumber(pose_noise_m));
  }
  if (!(log_rate_hz > 0 && std::isfinite(log_rate_hz))) {
    return fail("log_rate_hz must be > 0: " + ShortNumber(log_rate_hz));
  }
  if (threads < 1) return fail("threads must be >= 1");
  return true;
}

std::array<double, 3> RelativeStdErrors(const Eigen::Matrix3d& information_log) {
  std::array<double, 3> out{kInf, kInf, kInf};
  if (!information_log.allFinite()) return out;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(information_log);
  const Eigen::Vector3d lambda = eig.eigenvalues();
  const double largest = lambda.maxCoeff();
  if (!(largest > 0)) return out;
  // The covariance over the determined directions; a parameter with any weight on an
  // undetermined one is unknown (infinite), not merely large.
  Eigen::Vector3d var = Eigen::Vector3d::Zero();
  std::array<bool, 3> unknown{false, false, false};
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d v = eig.eigenvectors().col(k);
    if (lambda(k) > kUndeterminedEigenvalue * largest) {
      var += v.cwiseAbs2() / lambda(k);
    } else {
      for (int i = 0; i < 3; ++i) unknown[i] = unknown[i] || std::abs(v(i)) > 1e-6;
    }
  }
  for (int i = 0; i < 3; ++i) out[i] = unknown[i] ? kInf : std::sqrt(var(i));
  return out;
}

double AdviceScore(const Eigen::Matrix3d& information_log, AdviceCriterion criterion) {
  if (criterion == AdviceCriterion::kLeastKnown) {
    const std::array<double, 3> se = RelativeStdErrors(information_log);
    return *std::max_element(se.begin(), se.end());
  }
  const double det = information_log.determinant();
  return det > 0 && std::isfinite(det) ? 1.0 / det : kInf;
}

Eigen::Matrix3d LogInformation(const Trajectory& log, const ReducedFriction& friction,
                               double pose_noise_m, const TrajectoryOptions& trajectory) {
  IdentifyOptions options;
  options.method = EstimatorMethod::kTrajectory;
  options.trajectory = trajectory;
  options.trajectory.fit_force_bias = false;  // the friction's information alone
  options.trajectory.fit_delay = DelayFit::kNone;
  std::unique_ptr<TrajectoryProblem> problem;
  try {
    problem = std::make_unique<TrajectoryProblem>(std::vector<const Trajectory*>{&log}, options);
  } catch (const std::invalid_argument&) {
    return Eigen::Matrix3d::Zero();  // too short for one segment: nothing to learn
  }
  problem->SetFriction({friction.a, friction.b, friction.c});
  const FitInformation info = problem->Information();
  // Into a new matrix: h = f(h, h^T) in place would read entries it has already written.
  const Eigen::Matrix3d raw = info.fisher.topLeftCorner(3, 3);
  const Eigen::Matrix3d h = 0.5 * (raw + raw.transpose()) / (pose_noise_m * pose_noise_m);
  if (!h.allFinite()) return Eigen::Matrix3d::Zero();
  return h;
}

CandidateAdvice EvaluatePush(const SliderProperties& slider, const ContactPatch& patch,
                             const ReducedFriction& friction, const PushCandidate& push,
                             const PushAdviceOptions& options) {
  CandidateAdvice out;
  out.push = push;
  SimulationResult sim;
  try {
    const Scene scene =
        PushScene(slider, friction, patch, push, options.candidates, 1.0 / options.log_rate_hz);
    sim = Simulate(scene);
  } catch (const std::invalid_argument& e) {
    // A push that cannot be simulated at all (a step's force overflowing for a mu_p of
    // 1e300, more steps than the simulator allows at --rate 1e9): a failed candidate, said
    // in the table and exit code 3, not the bare "SolveStep: applied.fx must be finite" of
    // exit 1 that ended the whole run.
    out.failure = e.what();
    return out;
  }
  out.rows = static_cast<int>(sim.trajectory.samples.size());
  out.tip_touched = sim.summary.tip_stick_steps + sim.summary.tip_slide_steps > 0;
  if (!sim.trajectory.samples.empty()) {
    const PlanarState& end = sim.trajectory.samples.back().state;
    out.moved_m = std::hypot(end.x, end.y);
    out.turned_rad = std::abs(end.theta);
  }
  if (!sim.summary.ok()) {
    out.failure = std::string(ToString(sim.summary.status)) + ": " + sim.summary.message;
    return out;
  }
  out.simulated = true;
  out.information_log = LogInformation(sim.trajectory, friction, options.pose_noise_m);
  return out;
}

void RankCandidates(const Eigen::Matrix3d& prior_information, AdviceCriterion criterion,
                    std::vector<CandidateAdvice>* candidates) {
  std::vector<CandidateAdvice>& c = *candidates;
  for (CandidateAdvice& a : c) {
    const Eigen::Matrix3d after = prior_information + a.information_log;
    a.relative_stderr_after = RelativeStdErrors(after);
    a.score = AdviceScore(after, criterion);
  }
  std::vector<int> order(c.size());
  std::iota(order.begin(), order.end(), 0);
  // A failed simulation goes last whatever its score: it was not a push that can be made.
  std::stable_sort(order.begin(), order.end(), [&](int i, int j) {
    if (c[i].simulated != c[j].simulated) return c[i].simulated;
    return c[i].score < c[j].score;
  });
  std::vector<CandidateAdvice> sorted;
  sorted.reserve(c.size());
  for (int i : order) sorted.push_back(std::move(c[i]));
  c = std::move(sorted);
}

PushAdvice AdvisePush(const SliderProperties& slider, const ContactPatch& patch,
                      const FrictionKnowledge& knowledge, const PushAdviceOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("advise-push: " + why);
  CheckInformation(knowledge.information_log, "advise-push: what is known");
  const ReducedFriction& f = knowledge.estimate;
  if (!(f.a > 0 && f.b > 0 && f.c > 0 && std::isfinite(f.a) && std::isfinite(f.b) &&
        std::isfinite(f.c))) {
    throw std::invalid_argument(
        "advise-push: the estimate must be positive and finite: a = " + ShortNumber(f.a) +
        ", b = " + ShortNumber(f.b) + ", c = " + ShortNumber(f.c));
  }
  PushAdvice advice;
  advice.knowledge = knowledge;
  advice.criterion = options.criterion;
  advice.pose_noise_m = options.pose_noise_m;
  advice.relative_stderr_now = RelativeStdErrors(knowledge.information_log);
  const std::vector<PushCandidate> pushes = CandidatePushes(patch, options.candidates);
  advice.ranking.resize(pushes.size());
  ParallelFor(static_cast<int>(pushes.size()), options.threads, [&](int i) {
    advice.ranking[i] = EvaluatePush(slider, patch, f, pushes[i], options);
  });
  RankCandidates(knowledge.information_log, options.criterion, &advice.ranking);
  return advice;
}

}  // namespace slideid
