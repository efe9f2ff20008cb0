#pragma once
// The trajectory fit's Gauss-Newton step in its global parameters, every segment's state
// marginalised out, and the settle rule that reads it (estimator/trajectory_problem.cc,
// SettledCallback). Internal: tests check the step against one computed without the
// marginalisation, and the rule on hand-made steps.

#include <Eigen/Core>
#include <vector>

namespace slideid {

/// SettledCallback: a free global parameter whose iteration step is below this fraction of
/// its standard error has settled (its estimate would not move its interval visibly)...
constexpr double kSettledFraction = 0.02;
/// ... or, for the fit's last solve, one such iteration after which the Gauss-Newton step
/// would move every one by less than kSettledFraction too and lower the sum of squares,
/// states and globals together, by at most this many times the residuals' mean square:
/// what one parameter off by a standard error adds to it (kStatisticalTolerance in
/// trajectory_problem.cc). The states still creeping along the kinks (the 1,000,000-row
/// log's last iteration lowered it by about 4,600 mean squares, the benchmark's by 0.6)
/// keep the taken second look.
constexpr double kSettledDecrease = 1.0;

/// A segment's Gauss-Newton system with its 6-dim state (the first 6 rows and columns of
/// H) marginalised out, by the Schur complement with H_ss's pseudo-inverse (a state the
/// segment does not determine, e.g. one at rest, adds nothing instead of poisoning it).
struct StateMarginal {
  Eigen::MatrixXd h;          ///< H_rr - H_rs H_ss^+ H_sr over the rest of H's columns
  Eigen::VectorXd gradient;   ///< g_r - H_rs H_ss^+ g_s (empty without a gradient)
  double state_decrease = 0;  ///< g_s^T H_ss^+ g_s: the state's own step's decrease
};

/// Marginalises the state out of (H, gradient); `gradient` may be empty (only h then). H
/// must be exactly symmetric: H_rs is read as H_sr^T.
StateMarginal MarginaliseState(const Eigen::MatrixXd& H, const Eigen::VectorXd& gradient = {});

/// The globals' Gauss-Newton matrix (the information, marginalised over the segments'
/// states) and gradient, the sum of squares and the residuals, at the solver's last
/// evaluation with derivatives; and by how much the states' own steps, the globals held,
/// would lower the sum of squares.
struct LastGaussNewton {
  Eigen::MatrixXd fisher;
  Eigen::VectorXd gradient;
  double sum_squares = 0;
  int residuals = 0;
  double state_decrease = 0;
};

/// The Gauss-Newton step from a LastGaussNewton: each free global's move (0 for the held
/// ones), and by how much the whole step, states and globals, would lower the sum of
/// squares: the states' own steps' decrease plus the globals' g^T H^-1 g of the
/// marginalised problem (block elimination of g^T (J^T J)^-1 g).
struct GaussNewtonStep {
  std::vector<double> moves;  ///< empty where the free globals' information is singular
  double decrease = 0;
};

/// The size of each free global's move in the Gauss-Newton step from `at` (every segment's
/// state moving with it: the step of the marginalised problem), 0 for the held ones; empty
/// where the free globals' information is not positive definite. The step Ceres takes next
/// from there: Levenberg-Marquardt's damping is negligible once its steps succeed.
GaussNewtonStep GaussNewtonMoves(const LastGaussNewton& at, const std::vector<bool>& free);

/// Every free global's `moves` within `fraction` of its standard error (false if empty).
bool MovesWithin(const std::vector<double>& moves, const std::vector<bool>& free,
                 const std::vector<double>& standard_errors, double fraction);

/// The second look of a solve that settles at kSettledFraction (SettledCallback): the
/// Gauss-Newton step from `at` moves every free global within `fraction` of its standard
/// error and lowers the sum of squares by at most kSettledDecrease mean squares.
bool PredictedStepSettled(const LastGaussNewton& at, const std::vector<bool>& free,
                          const std::vector<double>& standard_errors, double fraction);

}  // namespace slideid
