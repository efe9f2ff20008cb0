#include "estimator/identifiability.h"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "forward_model/number_format.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// H restricted to the indices in `set`.
Eigen::MatrixXd Sub(const Eigen::MatrixXd& h, const std::vector<int>& set) {
  const int n = static_cast<int>(set.size());
  Eigen::MatrixXd s(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) s(i, j) = h(set[i], set[j]);
  }
  return s;
}

void Remove(std::vector<int>* set, int position) { set->erase(set->begin() + position); }

/// One-sigma errors sqrt(s^2 (H^-1)_kk) of every parameter of the information `h`, inverted
/// in normalised form (D H D with unit diagonal: better conditioned), the scaling then
/// undone. Rules (iii) and (iv).
Eigen::VectorXd MarginalStdErrs(const Eigen::MatrixXd& h, double residual_variance) {
  const Eigen::VectorXd d = h.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd hn = d.asDiagonal() * h * d.asDiagonal();
  const Eigen::MatrixXd inv_n = hn.ldlt().solve(Eigen::MatrixXd::Identity(hn.rows(), hn.cols()));
  Eigen::VectorXd se(h.rows());
  for (int k = 0; k < h.rows(); ++k) {
    se(k) = std::sqrt(residual_variance * std::max(d(k) * inv_n(k, k) * d(k), 0.0));
  }
  return se;
}

// (iv) A parameter is determined only through a partner that (iii) gave up. Held, the partner
// sits wherever the fit left it, and a parameter correlated with it takes up the
// difference while its own standard error, computed with the partner held, does not show
// it (a 217-row log of a tall box: a held, b = 0.87 [0.74, 1.03] 'ok', truth 1.51). Each
// remaining parameter's error is recomputed with the given-up partners of equal or higher
// priority free within their own thresholds (a Gaussian prior of that width, their
// plausible range); one beyond its own threshold then is not determined either. Partners of
// lower priority (a sensor nuisance held at zero) are the caller's choice and stay held.
void HeldPartners(const Eigen::MatrixXd& h, double residual_variance,
                  const std::vector<double>& max_stderr, const std::vector<int>& priority,
                  std::vector<int> unconstrained, std::vector<int>* set,
                  std::vector<ParameterIdentifiability>* out) {
  auto rank = [&](int i) { return priority.empty() ? 0 : priority[i]; };
  bool changed = !unconstrained.empty() && residual_variance > 0;
  while (changed && !set->empty()) {
    changed = false;
    for (size_t k = 0; k < set->size(); ++k) {
      const int i = (*set)[k];
      std::vector<int> with = *set;
      for (int d : unconstrained) {
        if (rank(d) >= rank(i)) with.push_back(d);
      }
      if (with.size() == set->size()) continue;
      Eigen::MatrixXd s = Sub(h, with);
      for (size_t j = set->size(); j < with.size(); ++j) {
        s(j, j) += residual_variance / (max_stderr[with[j]] * max_stderr[with[j]]);
      }
      const double se = MarginalStdErrs(s, residual_variance)(k);
      (*out)[i].stderr_log_partners_free = std::max(se, (*out)[i].stderr_log);
      if (!(se > max_stderr[i])) continue;
      (*out)[i].identifiable = false;
      (*out)[i].stderr_log = (*out)[i].stderr_log_partners_free = kNaN;
      (*out)[i].note = Printf(
          "determined only with a parameter the log does not constrain held: with that one "
          "free over its plausible range, its standard error %.3g exceeds %.3g",
          se, max_stderr[i]);
      unconstrained.push_back(i);
      Remove(set, static_cast<int>(k));
      changed = true;
      break;
    }
  }
}

}  // namespace

std::vector<ParameterIdentifiability> AssessIdentifiability(const Eigen::MatrixXd& fisher_log,
                                                            double residual_variance,
                                                            const std::vector<bool>& active,
                                                            const std::vector<double>& max_stderr,
                                                            const std::vector<int>& priority) {
  const int n = static_cast<int>(fisher_log.rows());
  // The one to give up among candidates: the lowest priority, then the largest `score`.
  auto pick = [&](const std::vector<int>& set, const Eigen::VectorXd& score,
                  const std::vector<bool>& candidate) {
    int best = -1;
    for (int k = 0; k < static_cast<int>(set.size()); ++k) {
      if (!candidate[k]) continue;
      const int pk = priority.empty() ? 0 : priority[set[k]];
      const int pb = best < 0 || priority.empty() ? 0 : priority[set[best]];
      if (best < 0 || pk < pb || (pk == pb && score(k) > score(best))) best = k;
    }
    return best;
  };
  if (fisher_log.cols() != n || static_cast<int>(active.size()) != n ||
      static_cast<int>(max_stderr.size()) != n) {
    throw std::invalid_argument("AssessIdentifiability: sizes of H, active and max_stderr differ");
  }
  if (!fisher_log.allFinite()) {
    throw std::invalid_argument("AssessIdentifiability: information matrix is not finite");
  }
  if (!(residual_variance >= 0) || !std::isfinite(residual_variance)) {
    throw std::invalid_argument(
        Printf("AssessIdentifiability: residual variance must be finite and >= 0, got %g",
               residual_variance));
  }
  const Eigen::MatrixXd h = 0.5 * (fisher_log + fisher_log.transpose());
  std::vector<ParameterIdentifiability> out(n);
  for (auto& p : out) p.stderr_log = p.stderr_log_partners_free = kNaN;

  // (i) no or negligible information.
  double largest = 0;
  for (int i = 0; i < n; ++i) {
    if (active[i]) largest = std::max(largest, h(i, i));
  }
  std::vector<int> set;
  for (int i = 0; i < n; ++i) {
    if (!active[i]) {
      out[i].note = "held constant by the caller";
    } else if (!(h(i, i) > 0) || h(i, i) < kNegligibleInformationRatio * largest) {
      out[i].note =
          Printf("the residuals do not depend on it (information %.3g of the largest, below %.0e)",
                 largest > 0 ? h(i, i) / largest : 0.0, kNegligibleInformationRatio);
    } else {
      set.push_back(i);
    }
  }

  // (ii) exact collinearity in the normalised information.
  while (set.size() > 1) {
    const Eigen::MatrixXd s = Sub(h, set);
    const Eigen::VectorXd d = s.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd hn = d.asDiagonal() * s * d.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(hn);
    const double lambda_min = eig.eigenvalues()(0);  // ascending
    if (!(lambda_min < kCollinearEigenvalue)) break;
    // Of the parameters the near-null direction involves (a component at least kInvolved of
    // the largest), the one of lowest priority goes (a sensor nuisance before friction).
    const Eigen::VectorXd component = eig.eigenvectors().col(0).cwiseAbs();
    std::vector<bool> involved(set.size());
    for (size_t k = 0; k < set.size(); ++k) {
      involved[k] = component(k) >= kInvolvedComponent * component.maxCoeff();
    }
    const int worst = pick(set, component, involved);
    out[set[worst]].note = Printf(
        "only a combination with other parameters is determined (smallest eigenvalue of the "
        "normalised information %.3g, below %.0e)",
        lambda_min, kCollinearEigenvalue);
    Remove(&set, worst);
  }

  // (iii) too uncertain to be constrained.
  std::vector<int> unconstrained;
  while (!set.empty()) {
    const Eigen::VectorXd se = MarginalStdErrs(Sub(h, set), residual_variance);
    // The worst is the one furthest beyond its own threshold.
    Eigen::VectorXd excess(set.size());
    for (int k = 0; k < static_cast<int>(set.size()); ++k) excess(k) = se(k) / max_stderr[set[k]];
    std::vector<bool> over(set.size());
    for (size_t k = 0; k < set.size(); ++k) over[k] = excess(k) > 1.0;
    const int worst = pick(set, excess, over);
    if (worst < 0) {
      for (int k = 0; k < static_cast<int>(set.size()); ++k) {
        out[set[k]].identifiable = true;
        out[set[k]].stderr_log = se(k);
        out[set[k]].stderr_log_partners_free = se(k);
      }
      break;
    }
    out[set[worst]].note =
        Printf("the log does not constrain it: its standard error %.3g exceeds %.3g", se(worst),
               max_stderr[set[worst]]);
    unconstrained.push_back(set[worst]);
    Remove(&set, worst);
  }
  HeldPartners(h, residual_variance, max_stderr, priority, unconstrained, &set, &out);
  return out;
}

std::array<ParameterIdentifiability, 3> AssessIdentifiability(const Eigen::Matrix3d& fisher_log,
                                                              double residual_variance,
                                                              const std::array<bool, 3>& active) {
  const std::vector<ParameterIdentifiability> v = AssessIdentifiability(
      Eigen::MatrixXd(fisher_log), residual_variance, {active[0], active[1], active[2]},
      {kMaxLogStdErr, kMaxLogStdErr, kMaxLogStdErr}, {});
  return {v[0], v[1], v[2]};
}

ParameterEstimate EstimateFromLog(double log_value, double stderr_log) {
  return EstimateFromLog(log_value, stderr_log, kZ95);
}

ParameterEstimate EstimateFromLog(double log_value, double stderr_log, double quantile) {
  ParameterEstimate p;
  p.identifiable = true;
  p.verdict = Verdict::kOk;
  p.value = std::exp(log_value);
  p.stderr_value = p.value * stderr_log * quantile / kZ95;
  p.ci95_lo = std::exp(log_value - quantile * stderr_log);
  p.ci95_hi = std::exp(log_value + quantile * stderr_log);
  return p;
}

ParameterEstimate NotIdentifiable(double held_at, const std::string& reason) {
  ParameterEstimate p;
  p.identifiable = false;
  p.verdict = Verdict::kNotIdentifiable;
  p.held_at = held_at;
  p.reason = reason;
  return p;
}

}  // namespace slideid
