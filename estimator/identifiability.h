#pragma once
// Which of the friction parameters (a, b, c) a least-squares fit in log-parameters actually
// determines, and how well. Shared by every Ceres-based estimator.
//
// Input: H = J^T J, the 3x3 information of the residuals with respect to
// theta = (log a, log b, log c), already marginalised over any nuisance parameters (Schur
// complement), and s^2 = sum r^2 / (N - n_free), the residual variance. The covariance of
// the identifiable log-parameters is s^2 H_S^-1 over the identifiable subset S.
//
// Rule, applied to the parameters marked active (the others were held by the caller):
//  (i)   a parameter whose diagonal information is not positive, or is below
//        kNegligibleInformationRatio times the largest diagonal, is not identifiable: the
//        residuals do not depend on it;
//  (ii)  normalise H over the remaining set to Hn = D H D, D = diag(H)^-1/2 (unit diagonal,
//        a correlation-like matrix). While the smallest eigenvalue of Hn is below
//        kCollinearEigenvalue, the parameter with the largest |component| of its
//        eigenvector is not identifiable (the data determine only a combination of it with
//        others); remove it and re-test the rest;
//  (iii) over what remains, the marginal standard error sqrt(s^2 (H_S^-1)_ii) of each
//        log-parameter; while the largest exceeds kMaxLogStdErr, that parameter is not
//        identifiable; remove it and recompute (removing one can shrink the others' errors);
//  (iv)  but a shrink that comes only from holding a removed parameter is not information:
//        each remaining one's error is recomputed with the removed ones free within
//        kMaxLogStdErr (a Gaussian prior of that width); one beyond it is not identifiable.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "estimator/estimate.h"

namespace slideid {

/// (i): diagonal information below this fraction of the largest counts as none. The
/// diagonal is a sum of squares, so rounding alone leaves a relative floor near 1e-16;
/// 1e-12 sits a few orders above it and far below any information a real log carries
/// (a parameter with 1e-12 of the information of another has ~1e6 times its error).
constexpr double kNegligibleInformationRatio = 1e-12;

/// (ii): an eigenvalue of the unit-diagonal Hn below this is an exact collinearity. Forming
/// J^T J squares the conditioning, so rounding puts eigenvalues of an exactly rank-deficient
/// Hn near 1e-16..1e-14; 1e-10 is clear of that and still means a correlation of
/// 1 - 5e-11 between parameters. Near-collinearities that are real but weak are judged
/// against the noise by (iii).
constexpr double kCollinearEigenvalue = 1e-10;

/// (iii): one-sigma error of a log-parameter above which it counts as undetermined: its 95%
/// interval would span more than a factor exp(2 * 1.96 * 0.5) = 7. On noisy logs without
/// any rotation, c picks up information only from fitted noise, with standard errors of
/// log c of 0.6 to 0.9 (intervals spanning factors 10 to 35): such a value says nothing
/// and is reported not identifiable. A parameter the log excites is determined far better
/// (log standard errors of 0.001 to 0.1 in the tests and benchmarks).
constexpr double kMaxLogStdErr = 0.5;

/// (ii): the parameters a near-null direction involves are those whose eigenvector
/// component is at least this fraction of the largest (a direction that is a fixed mixture
/// of two parameters has components of comparable size; noise in the others is far below).
constexpr double kInvolvedComponent = 0.3;

/// The verdict on one parameter.
struct ParameterIdentifiability {
  bool identifiable = false;
  /// One-sigma error of the parameter in the units it was assessed in (of log(parameter)
  /// for a, b, c: dimensionless), NaN when not identifiable.
  double stderr_log;
  /// The same with the parameters rule (iii) gave up free within their thresholds (rule
  /// (iv)); at least stderr_log. The excess of its square over stderr_log's is the variance
  /// that holding them hides, which an interval should carry. NaN when not identifiable.
  double stderr_log_partners_free;
  std::string note;  ///< why not identifiable (empty when it is)
};

/// Rules (i)-(iv) for any number of parameters (a, b, c in log form and sensor nuisances
/// in their own units), parameter i undetermined under (iii) when its standard error
/// exceeds max_stderr[i], and under (iv) when it does so once the parameters (iii) gave up
/// (of its priority or higher) are free within their own max_stderr: it was determined
/// only by holding them (identifiability.cc). Where (ii) or (iii) must give one up, the one of
/// lowest `priority` goes first (then the largest eigenvector component, or the furthest beyond its
/// threshold): a sensor nuisance confounded with a, say, is held rather than a. `fisher` is n x n
/// symmetric; `active`, `max_stderr` and `priority` (empty: all equal) have n entries. Throws
/// std::invalid_argument for a non-finite H, a negative variance or mismatched sizes.
std::vector<ParameterIdentifiability> AssessIdentifiability(const Eigen::MatrixXd& fisher,
                                                            double residual_variance,
                                                            const std::vector<bool>& active,
                                                            const std::vector<double>& max_stderr,
                                                            const std::vector<int>& priority = {});

/// Applies rules (i)-(iv) to `fisher_log` (3x3 symmetric, in order log a, log b, log c)
/// with residual variance `residual_variance` (>= 0). Parameters with active[i] == false
/// are reported not identifiable with the note "held constant by the caller" and do not
/// take part. Throws std::invalid_argument for a non-finite H or a negative variance.
std::array<ParameterIdentifiability, 3> AssessIdentifiability(const Eigen::Matrix3d& fisher_log,
                                                              double residual_variance,
                                                              const std::array<bool, 3>& active = {
                                                                  {true, true, true}});

/// An identifiable parameter from its log estimate and that estimate's one-sigma error:
/// value = exp(log_value), stderr = value * stderr_log (delta method), and the 95% interval
/// [exp(log_value - kZ95 stderr_log), exp(log_value + kZ95 stderr_log)] (asymmetric, > 0).
ParameterEstimate EstimateFromLog(double log_value, double stderr_log);
/// The same with the interval's quantile given (e.g. Student's t for few clusters):
/// [exp(log_value - quantile stderr_log), exp(log_value + quantile stderr_log)]. The standard
/// error reported is the one that interval implies, value * stderr_log * quantile / kZ95:
/// a user who reads value +- 1.96 stderr as the 95% band (a planner's Gaussian, a weighted
/// mean) gets the interval, not a band that a t quantile of 4 on 2 degrees of freedom would
/// make half as wide as the uncertainty.
ParameterEstimate EstimateFromLog(double log_value, double stderr_log, double quantile);

/// A parameter the data do not determine: value, stderr and interval NaN, held_at the value
/// it was held at (NaN if none), and the reason.
ParameterEstimate NotIdentifiable(double held_at, const std::string& reason);

}  // namespace slideid
