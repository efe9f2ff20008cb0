#pragma once
// One backward-Euler step of the planar sliding model (docs/model.md, "One step").
//
// The step first decides stick or slide from the impulse that would stop the slider. While
// sliding it solves the paper's four equations in (p_t, p_o, p_r, sigma), written on the
// unit sphere of the friction ellipsoid, by safeguarded Newton with the analytic Jacobian,
// started from the decoupled solution; where the sliding root is provably unique
// (StepEquations::UniqueSlidingRoot), by full Newton steps from that solution swept once
// through the ECP velocity (issue 19). Scenes that need less take an exact shortcut:
// no CM height and no tilting moments -> a monotone scalar root in the slip speed;
// pure translation with b = 1 -> the closed form (model.md, erratum 4).

#include <Eigen/Core>
#include <optional>
#include <string>

#include "forward_model/planar_state.h"
#include "forward_model/slider.h"

namespace slideid {

/// Options of SolveStep.
struct StepOptions {
  /// Relative residual at which Newton stops. 1e-12 leaves three to four digits of
  /// headroom over double rounding of the O(1)-scaled equations.
  double relative_tolerance = 1e-12;
  int max_iterations = 60;
  /// Take the decoupled / closed-form shortcuts where they are exact. Off forces the general
  /// Newton solve everywhere (tests compare the two).
  bool use_special_cases = true;
  /// Optional first guess for the general solve, in the scaled unknowns of a previous
  /// StepResult::scaled_solution (e.g. the same step at nearby parameters). Tried first;
  /// the usual guesses follow if Newton fails from it.
  std::optional<Eigen::Vector4d> initial_guess;

  bool IsValid(std::string* why) const;
};

enum class StepMode { kSlide, kStick };

/// Which solver produced the step.
enum class StepPath { kStick, kPureTranslation, kDecoupled, kGeneral };

enum class StepStatus {
  kConverged,      ///< the result is a solution of the step's equations
  kNoConvergence,  ///< Newton failed; the state fields are the unchanged start state
  kLiftOff,        ///< p_n <= 0: the applied vertical force lifts the slider
};

/// What one step produced. Fields other than status/message/iterations/residual are
/// meaningful only when status == kConverged.
struct StepResult {
  StepStatus status = StepStatus::kNoConvergence;
  std::string message;    ///< why it failed, empty on success
  PlanarState state;      ///< state at the end of the step
  double pt = 0, po = 0;  ///< friction impulses [N s], world axes
  double pr = 0;          ///< friction angular impulse [N m s]
  double sigma = 0;       ///< slip multiplier of model.md [m/s]; 0 when sticking
  double pn = 0;          ///< normal impulse h (m g - f_z) [N s]
  Eigen::Vector2d ecp_offset_world = Eigen::Vector2d::Zero();  ///< ECP - CM, world [m]
  Eigen::Vector2d ecp_world = Eigen::Vector2d::Zero();         ///< end-of-step CM + offset [m]
  StepMode mode = StepMode::kSlide;
  StepPath path = StepPath::kGeneral;
  /// The solution in the solver's scaled unknowns (tau_t, tau_o, tau_r, s) of
  /// step_equations.h, for StepOptions::initial_guess (zero when sticking).
  Eigen::Vector4d scaled_solution = Eigen::Vector4d::Zero();
  double residual = 0;  ///< relative residual of the four equations (0 when sticking)
  int iterations = 0;   ///< Newton (or scalar root) iterations

  bool ok() const { return status == StepStatus::kConverged; }
  /// The ECP offset in the body frame at the end of the step [m] (computed on demand: the
  /// estimators never need it, and its sine and cosine cost 5% of a fit).
  Eigen::Vector2d EcpBody() const;
};

/// Advances `state` by one step of length dt_s [s] under `applied` (held over the step),
/// with the friction given by the three combinations the motion depends on (model.md,
/// "Only three parameters matter"): the estimators' form, with no conversion per step.
/// StepResult::sigma is then sigma / e_t [m/s]. Throws std::invalid_argument for invalid
/// properties, parameters or step length; non-convergence and lift-off are statuses.
StepResult SolveStep(const SliderProperties& slider, const ReducedFriction& friction,
                     const PlanarState& state, const AppliedWrench& applied, double dt_s,
                     const StepOptions& options = {});

/// The same step with the paper's four friction parameters; sigma is the paper's.
StepResult SolveStep(const SliderProperties& slider, const FrictionParameters& friction,
                     const PlanarState& state, const AppliedWrench& applied, double dt_s,
                     const StepOptions& options = {});

/// Residuals of the four sliding equations of model.md at (p_t, p_o, p_r, sigma), in the
/// paper's own form (with e_t, e_o, e_r), each divided by the sum of the magnitudes of its
/// terms. Independent of the solver's internal scaling; used to verify solutions.
Eigen::Vector4d SlidingEquationResiduals(const SliderProperties& slider,
                                         const FrictionParameters& friction,
                                         const PlanarState& state, const AppliedWrench& applied,
                                         double dt_s, const Eigen::Vector4d& pt_po_pr_sigma);

const char* ToString(StepMode mode);
const char* ToString(StepPath path);

}  // namespace slideid
