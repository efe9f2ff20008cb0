#include "forward_model/step_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "forward_model/adjugate3.h"
#include "forward_model/step_equations.h"

namespace slideid {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Armijo constant and the bound on halvings of the Newton line search.
constexpr double kArmijo = 1e-4;
constexpr int kMaxHalvings = 40;
// Newton never takes s below this fraction of its current value (s must stay > 0).
constexpr double kMinSlipFraction = 0.1;
// Relative size below which the 3x3 block (or the border) counts as singular.
constexpr double kSingularBlock = 1e-12;
// Coupling scales of the continuation used only when Newton from the decoupled guess fails.
constexpr double kContinuation[] = {0.125, 0.25, 0.5, 0.75, 1.0};
// Fixed-point sweeps of the ECP-velocity guess: each contracts by about the ratio of the
// friction's effect on the ECP velocity to the slip speed; three bring the far-ECP cases of
// the stability sweep within Newton's reach (docs/stability.md).
constexpr int kEcpVelocitySweeps = 3;
// Ratio of StepEquations::CouplingSpeed to V above which the spin about a far ECP, not
// the friction, dominates the ECP velocity: the ECP-velocity guess goes first. (The
// failing case of the sweep had 575; cases that converge from the decoupled guess, 0.1.)
constexpr double kFarEcpRatio = 10.0;
// Where the sliding root is unique (issue 19), the first guess is the coupling linearised
// twice (StepEquations::LinearisedCouplingGuess: about tau = 0 from the decoupled root's
// lower bound on s, then about that). Where the first fails, the decoupled root to 1e-2
// (its last Newton step from 1e-1 unchecked) takes its place; where the second fails, one
// sweep of the ECP velocity.
constexpr double kRoughGuessTolerance = 1e-2;
constexpr double kRoughGuessAccept = 1e-1;
// Newton iterations allowed to that speculative first try: where its guess is right it
// converges in a handful; where it is not, the usual guesses follow.
constexpr int kSpeculativeIterations = 12;
// A stopping impulse within this many ulps (relative) of the ellipsoid is on it: the stick
// test and the sliding solve round it differently, and the sliding root is then s = 0
// within rounding, i.e. the slider stops at the end of the step (issue 5).
constexpr double kBoundaryUlps = 16.0;
// Stopping impulse within this relative distance outside the ellipsoid: the slide ends
// nearly at rest, its friction impulse nearly the stopping one; Newton starts from that.
constexpr double kNearStickBoundary = 1e-3;
// SlidingEquationResiduals counts each friction impulse at least at this fraction of the
// ellipsoid's half-axis (as StepEquations::ComponentwiseResidual does).
constexpr double kEllipsoidFloor = 1e-6;

// x > 0 and finite (false for NaN).
bool PositiveFinite(double x) { return x > 0 && x <= std::numeric_limits<double>::max(); }

void Validate(const SliderProperties& slider, const ReducedFriction& f, double dt_s) {
  // One test for the valid case; the messages below only when it fails.
  if (PositiveFinite(slider.mass_kg) && PositiveFinite(slider.inertia_kgm2) &&
      slider.com_height_m >= 0 && slider.com_height_m <= std::numeric_limits<double>::max() &&
      PositiveFinite(slider.gravity_mps2) && PositiveFinite(f.a) && PositiveFinite(f.b) &&
      PositiveFinite(f.c) && PositiveFinite(dt_s)) {
    return;
  }
  auto require = [](bool ok, const char* what, double value) {
    if (!ok) {
      std::ostringstream msg;
      msg << "SolveStep: " << what << " (got " << value << ")";
      throw std::invalid_argument(msg.str());
    }
  };
  require(std::isfinite(slider.mass_kg) && slider.mass_kg > 0, "mass must be > 0", slider.mass_kg);
  require(std::isfinite(slider.inertia_kgm2) && slider.inertia_kgm2 > 0, "inertia must be > 0",
          slider.inertia_kgm2);
  require(std::isfinite(slider.com_height_m) && slider.com_height_m >= 0, "com_height must be >= 0",
          slider.com_height_m);
  require(std::isfinite(slider.gravity_mps2) && slider.gravity_mps2 > 0, "gravity must be > 0",
          slider.gravity_mps2);
  require(std::isfinite(f.a) && f.a > 0, "a = e_t mu must be > 0", f.a);
  require(std::isfinite(f.b) && f.b > 0, "b = e_o / e_t must be > 0", f.b);
  require(std::isfinite(f.c) && f.c > 0, "c = e_r / e_t must be > 0", f.c);
  require(std::isfinite(dt_s) && dt_s > 0, "time step must be > 0", dt_s);
}

// Issue 5: a NaN or Inf in the state or the wrench went through as "did not converge
// (relative residual nan)"; it is bad input and says which field.
void ValidateFinite(const PlanarState& s, const AppliedWrench& w) {
  // v * 0 is 0 for every finite v, NaN for Inf or NaN: one test.
  const double probe =
      (s.x * 0.0 + s.y * 0.0 + s.theta * 0.0 + s.vx * 0.0 + s.vy * 0.0 + s.wz * 0.0) +
      (w.fx * 0.0 + w.fy * 0.0 + w.fz * 0.0 + w.tx * 0.0 + w.ty * 0.0 + w.tz * 0.0);
  if (probe == 0.0) return;
  const std::pair<const char*, double> fields[] = {
      {"state.x", s.x},     {"state.y", s.y},     {"state.theta", s.theta}, {"state.vx", s.vx},
      {"state.vy", s.vy},   {"state.wz", s.wz},   {"applied.fx", w.fx},     {"applied.fy", w.fy},
      {"applied.fz", w.fz}, {"applied.tx", w.tx}, {"applied.ty", w.ty},     {"applied.tz", w.tz}};
  for (const auto& [name, value] : fields) {
    if (!std::isfinite(value)) {
      std::ostringstream msg;
      msg << "SolveStep: " << name << " must be finite (got " << value << ")";
      throw std::invalid_argument(msg.str());
    }
  }
}

// The Jacobian is bordered, [[A, tau], [V tau^T, 0]]: eliminate through the 3x3 block A
// by its adjugate, nine 2x2 cofactors and no pivot search (issue 19); fall back to pivoted
// LU of the whole Jacobian where A is near singular (the same threshold on det A as
// before) or the border is degenerate. Inlined, the LU out of line (issue 19): A then
// stays in registers from JacobianBlock to the adjugate, where the call stored and loaded
// it again on the chain of every Newton iteration (1.5% of the general step).
#if defined(__GNUC__)
#define SLIDEID_ALWAYS_INLINE inline __attribute__((always_inline))
#define SLIDEID_NOINLINE __attribute__((noinline))
#else
#define SLIDEID_ALWAYS_INLINE inline
#define SLIDEID_NOINLINE
#endif
SLIDEID_NOINLINE bool SolveNewtonSystemLU(const Eigen::Matrix3d& A, const Eigen::Vector4d& z,
                                          double V, const Eigen::Vector4d& f, Eigen::Vector4d* dz);
SLIDEID_ALWAYS_INLINE bool SolveNewtonSystem(const Eigen::Matrix3d& A, const Eigen::Vector4d& z,
                                             double V, const Eigen::Vector4d& f,
                                             Eigen::Vector4d* dz) {
  const Eigen::Matrix3d adj = Adjugate3(A);
  const double det = Determinant3(A, adj);
  if (std::abs(det) > kSingularBlock * A.cwiseAbs().maxCoeff()) {
    // With y1 = -adj(A) f_1..3 and y2 = adj(A) tau (A^-1 = adj(A) / det):
    // x1 = -A^-1 f_1..3 = y1 / det, x2 = A^-1 tau = y2 / det, and the slip step
    // ds = (g x1 + f_4) / (g x2) = (g y1 + det f_4) / (g y2) with g = V tau^T. 1 / det is
    // then off the critical path (issue 19: the iteration is a chain of dependent
    // operations, and a division is its longest link).
    const double t0 = z(0), t1 = z(1), t2 = z(2);
    const double y10 = -(adj(0, 0) * f(0) + adj(0, 1) * f(1) + adj(0, 2) * f(2));
    const double y11 = -(adj(1, 0) * f(0) + adj(1, 1) * f(1) + adj(1, 2) * f(2));
    const double y12 = -(adj(2, 0) * f(0) + adj(2, 1) * f(1) + adj(2, 2) * f(2));
    const double y20 = adj(0, 0) * t0 + adj(0, 1) * t1 + adj(0, 2) * t2;
    const double y21 = adj(1, 0) * t0 + adj(1, 1) * t1 + adj(1, 2) * t2;
    const double y22 = adj(2, 0) * t0 + adj(2, 1) * t1 + adj(2, 2) * t2;
    const double inv_det = 1.0 / det;
    // The border test |g x2| > k |g| |x2|, in squares (no square roots) while those are
    // finite: with y2 = det x2 on both sides, det cancels.
    const double g0 = V * t0, g1 = V * t1, g2 = V * t2;
    const double border = g0 * y20 + g1 * y21 + g2 * y22;
    const double g_sq = g0 * g0 + g1 * g1 + g2 * g2, y2_sq = y20 * y20 + y21 * y21 + y22 * y22;
    const double bound_sq = g_sq * y2_sq;
    const bool border_ok =
        std::isfinite(bound_sq) && bound_sq > 0
            ? border * border > kSingularBlock * kSingularBlock * bound_sq
            : std::abs(border) > kSingularBlock * std::sqrt(g_sq) * std::sqrt(y2_sq);
    if (border_ok) {
      const double ds = (g0 * y10 + g1 * y11 + g2 * y12 + det * f(3)) / border;
      *dz << (y10 - y20 * ds) * inv_det, (y11 - y21 * ds) * inv_det, (y12 - y22 * ds) * inv_det, ds;
      if (dz->allFinite()) return true;
    }
  }
  return SolveNewtonSystemLU(A, z, V, f, dz);
}

// The pivoted LU of the whole bordered Jacobian (SolveNewtonSystem's fallback).
bool SolveNewtonSystemLU(const Eigen::Matrix3d& A, const Eigen::Vector4d& z, double V,
                         const Eigen::Vector4d& f, Eigen::Vector4d* dz) {
  Eigen::Matrix4d jac;
  jac.topLeftCorner<3, 3>() = A;
  jac.topRightCorner<3, 1>() = z.head<3>();
  jac.bottomLeftCorner<1, 3>() = V * z.head<3>().transpose();
  jac(3, 3) = 0.0;
  *dz = Eigen::PartialPivLU<Eigen::Matrix4d>(jac).solve(-f);
  return dz->allFinite();
}

// Newton on the scaled equations from `z`; returns true when converged. The residual is
// evaluated at every trial point, the Jacobian only at accepted points that have not
// converged.
bool Newton(const StepEquations& eq, const StepOptions& options, Eigen::Vector4d* z,
            int* iterations, double* relative_residual, bool line_search = true) {
  Eigen::Vector4d f;
  StepEquations::Shared shared;
  eq.Residual(*z, &f, &shared);
  const double tol = options.relative_tolerance;
  const double V = eq.velocity_scale();
  // ConvergenceResidual, keeping its normwise part for the choice of step below.
  auto convergence = [&](const Eigen::Vector4d& at, const Eigen::Vector4d& f_at, double* normwise) {
    *normwise = eq.RelativeResidual(at, f_at);
    if (!(*normwise <= tol)) return *normwise;
    return std::max(*normwise, eq.ComponentwiseResidual(at, f_at));
  };
  double normwise = 0;
  for (int it = 0; it < options.max_iterations; ++it) {
    *relative_residual = convergence(*z, f, &normwise);
    if (*relative_residual <= tol) return (*z)(3) > 0;
    Eigen::Matrix3d A;
    eq.JacobianBlock(*z, shared, &A);
    Eigen::Vector4d dz;
    if (!SolveNewtonSystem(A, *z, V, f, &dz)) return false;
    double alpha = 1.0;
    if ((*z)(3) + dz(3) < kMinSlipFraction * (*z)(3)) {
      alpha = (1.0 - kMinSlipFraction) * (*z)(3) / -dz(3);
    }
    Eigen::Vector4d trial, trial_f;
    StepEquations::Shared trial_shared;
    if (normwise <= tol) {
      // Polishing (issue 5): only a row whose terms are much smaller than V is left above
      // tolerance. The merit |F|^2 is at rounding level and cannot rank the steps; take the
      // Newton step while it lowers the convergence residual.
      trial = *z + alpha * dz;
      eq.Residual(trial, &trial_f, &trial_shared);
      double trial_normwise = 0;
      if (!(convergence(trial, trial_f, &trial_normwise) < *relative_residual)) return false;
    } else if (!line_search) {
      // Full steps (but for the guard on s): where the root is unique (SolveGeneral).
      trial = *z + alpha * dz;
      eq.Residual(trial, &trial_f, &trial_shared);
    } else {
      const double merit = 0.5 * f.squaredNorm();
      for (int halvings = 0;; ++halvings) {
        trial = *z + alpha * dz;
        eq.Residual(trial, &trial_f, &trial_shared);
        if (0.5 * trial_f.squaredNorm() <= (1.0 - 2.0 * kArmijo * alpha) * merit) break;
        if (halvings == kMaxHalvings) return false;
        alpha *= 0.5;
      }
    }
    *z = trial;
    f = trial_f;
    shared = trial_shared;
    *iterations = it + 1;
  }
  *relative_residual = eq.ConvergenceResidual(*z, f, tol);
  return *relative_residual <= tol && (*z)(3) > 0;
}

// Newton's full steps from `z`, where the root is unique (SolveGeneral): the loop of Newton
// without its line search and with the normwise test in products, until that test holds;
// Newton's own tests (and polishing) from there.
bool NewtonFullSteps(const StepEquations& eq, const StepOptions& options, Eigen::Vector4d* z,
                     int* iterations, double* relative_residual) {
  const double tol = options.relative_tolerance;
  const double V = eq.velocity_scale();
  Eigen::Vector4d f;
  StepEquations::Shared shared;
  eq.Residual(*z, &f, &shared);
  int it = 0;
  for (; it < options.max_iterations; ++it) {
    // RelativeResidual(z, f) <= tol, without its divisions (V > 0 here: the step slides).
    const double motion = std::max(std::max(std::abs(f(0)), std::abs(f(1))), std::abs(f(2)));
    if (motion <= tol * (V + std::abs((*z)(3))) && 2.0 * std::abs(f(3)) <= tol * V) {
      // Newton's test, ConvergenceResidual.
      *relative_residual = std::max(eq.RelativeResidual(*z, f), eq.ComponentwiseResidual(*z, f));
      if (*relative_residual <= tol) {
        *iterations = it;
        return (*z)(3) > 0;
      }
      break;  // polishing, in Newton
    }
    Eigen::Matrix3d A;
    eq.JacobianBlock(*z, shared, &A);
    Eigen::Vector4d dz;
    if (!SolveNewtonSystem(A, *z, V, f, &dz)) {
      *iterations = it;
      *relative_residual = eq.RelativeResidual(*z, f);
      return false;
    }
    double alpha = 1.0;
    if ((*z)(3) + dz(3) < kMinSlipFraction * (*z)(3)) {
      alpha = (1.0 - kMinSlipFraction) * (*z)(3) / -dz(3);
    }
    *z += alpha * dz;
    eq.Residual(*z, &f, &shared);
  }
  if (it == options.max_iterations) {
    *iterations = it;
    *relative_residual = eq.ConvergenceResidual(*z, f, tol);
    return *relative_residual <= tol && (*z)(3) > 0;
  }
  StepOptions rest = options;
  rest.max_iterations = options.max_iterations - it;
  int its = 0;
  const bool ok = Newton(eq, rest, z, &its, relative_residual, false);
  *iterations = it + its;
  return ok;
}

// The slip speed set by the spin about a far ECP (SolveGeneral).
bool FarEcp(const StepEquations& eq) {
  return eq.CouplingSpeed() > kFarEcpRatio * eq.velocity_scale();
}

// Where the sliding root is provably unique (issue 19), any guess and any path that
// converge find the root the decoupled guess would: the coupling linearised about tau = 0
// and again about that guess (LinearisedCouplingGuess; a median 3e-9 from the root on
// step_benchmark's steps), then Newton's full steps (the line search's halvings only slow
// it there). (Without coupling the decoupled guess is the root already.)
struct CertifiedStart {
  Eigen::Vector4d guess;
  bool unique;   // UniqueSlidingRoot: Newton's full steps from the guess
  bool far_ecp;  // FarEcp: the guess is not tried
};

// The tests between and after the guesses (issue 19's sixth round): each guess ends in a
// chain of a few dozen dependent operations (a square root and two divisions in series),
// and the tests, which depend on neither, run beside those chains instead of before them:
// the componentwise test's row terms (cached for Newton's last test) and the far-ECP test
// beside the first, the uniqueness test (the longest) beside the second and Newton's first
// residual: about 30 ns of about 310 in step_benchmark (all of them after the second guess:
// about 5 ns; the uniqueness test beside the first, the rest after the second: about 15).
// The guesses are wasted where a test fails (3% of step_benchmark's steps).
CertifiedStart LinearisedStart(const StepEquations& eq) {
  CertifiedStart start;
  if (!eq.LinearisedCouplingGuessAtRest(eq.DecoupledSlipLowerBound(), &start.guess)) {
    start.guess = eq.DecoupledGuess(kRoughGuessTolerance, kRoughGuessAccept);
  }
  eq.RowTerms();
  start.far_ecp = FarEcp(eq);
  if (!eq.LinearisedCouplingGuess(&start.guess)) start.guess = eq.EcpVelocitySweep(start.guess);
  start.unique = eq.UniqueSlidingRoot();
  return start;
}

// Newton from the decoupled guess; where that fails (typically near the stick boundary,
// where the decoupled problem sticks but the coupled one slides), from the stopping
// impulse's direction; then from the ECP-velocity guess; last, continuation in the
// coupling strength. Within kNearStickBoundary of the ellipsoid the linearisation about
// the stopping impulse is the better guess and goes first (issue 5: from the decoupled
// guess Newton drove s to 0 with tau off the stopping direction, and spent its 60
// iterations there).
bool SolveGeneral(const StepEquations& eq, const StepOptions& options, bool near_stick,
                  Eigen::Vector4d* z, int* iterations, double* relative_residual) {
  *iterations = 0;
  auto attempt = [&](const Eigen::Vector4d& guess, int max_iterations = 0,
                     bool line_search = true) {
    int its = 0;
    *z = guess;
    StepOptions limited = options;
    if (max_iterations > 0) {
      limited.max_iterations = std::min(options.max_iterations, max_iterations);
    }
    const bool ok = line_search ? Newton(eq, limited, z, &its, relative_residual)
                                : NewtonFullSteps(eq, limited, z, &its, relative_residual);
    *iterations += its;
    return ok;
  };
  if (options.initial_guess && options.initial_guess->allFinite() &&
      (*options.initial_guess)(3) > 0 && attempt(*options.initial_guess)) {
    return true;
  }
  if (near_stick && attempt(eq.LinearisedStopGuess())) return true;
  // The ECP far from the CM (large q_z or tilting moments with a fast spin): the slip
  // speed is set by the spin about the ECP, far from V, and the decoupled guess is off by
  // more than the whole velocity scale (issue 5, docs/stability.md). Try that guess first
  // there, last elsewhere.
  bool far_ecp = false;
  if (eq.IsDecoupled()) {
    far_ecp = FarEcp(eq);
  } else {
    const CertifiedStart start = LinearisedStart(eq);
    far_ecp = start.far_ecp;
    if (start.unique && !far_ecp && attempt(start.guess, kSpeculativeIterations, false)) {
      return true;
    }
    // Where that fails, the usual guesses follow.
  }
  const Eigen::Vector4d decoupled = eq.DecoupledGuess();
  if (far_ecp &&
      attempt(eq.EcpVelocityGuess(decoupled, kEcpVelocitySweeps), kSpeculativeIterations)) {
    return true;
  }
  if (attempt(decoupled)) return true;
  // The stopping guess is built only when needed: it is rarely needed.
  if (attempt(eq.StoppingGuess())) return true;
  if (!far_ecp && attempt(eq.EcpVelocityGuess(decoupled, kEcpVelocitySweeps))) return true;
  *z = decoupled;
  for (double scale : kContinuation) {
    int its = 0;
    const bool ok = Newton(eq.WithCouplingScaled(scale), options, z, &its, relative_residual);
    *iterations += its;
    if (!ok) return false;
  }
  return true;
}

// The end of a step with friction impulse p, end velocity nu and ECP offset (world).
StepResult Finish(const PlanarState& state, double dt_s, const StepEquations& eq,
                  const Eigen::Vector3d& p, double slip, const Eigen::Vector3d& nu,
                  const Eigen::Vector2d& ecp_offset) {
  StepResult r;
  r.status = StepStatus::kConverged;
  r.pt = p(0);
  r.po = p(1);
  r.pr = p(2);
  r.pn = eq.pn();
  r.sigma = slip;
  r.state.vx = nu(0);
  r.state.vy = nu(1);
  r.state.wz = nu(2);
  r.state.x = state.x + dt_s * nu(0);
  r.state.y = state.y + dt_s * nu(1);
  r.state.theta = state.theta + dt_s * nu(2);
  r.ecp_offset_world = ecp_offset;
  r.ecp_world = Eigen::Vector2d(r.state.x, r.state.y) + r.ecp_offset_world;
  return r;
}

// The step ends at rest with the stopping impulse p_stop (model.md, "Sticking").
StepResult Stick(const PlanarState& state, double dt_s, const StepEquations& eq,
                 const Eigen::Vector3d& p_stop) {
  StepResult r = Finish(state, dt_s, eq, p_stop, 0.0, eq.EndVelocity(p_stop), eq.EcpOffset(p_stop));
  r.state.vx = r.state.vy = r.state.wz = 0.0;  // exact zero, not rounding residue
  r.state.x = state.x;
  r.state.y = state.y;
  r.state.theta = state.theta;
  r.ecp_world = Eigen::Vector2d(state.x, state.y) + r.ecp_offset_world;
  r.mode = StepMode::kStick;
  r.path = StepPath::kStick;
  return r;
}

}  // namespace

bool StepOptions::IsValid(std::string* why) const {
  if (!(relative_tolerance > 0 && relative_tolerance < 1)) {
    if (why) *why = "relative_tolerance must be in (0, 1)";
    return false;
  }
  if (max_iterations < 1) {
    if (why) *why = "max_iterations must be >= 1";
    return false;
  }
  return true;
}

StepResult SolveStep(const SliderProperties& slider, const FrictionParameters& friction,
                     const PlanarState& state, const AppliedWrench& applied, double dt_s,
                     const StepOptions& options) {
  auto require = [](double value, const char* name) {
    if (!PositiveFinite(value)) {
      std::ostringstream msg;
      msg << "SolveStep: " << name << " must be > 0 (got " << value << ")";
      throw std::invalid_argument(msg.str());
    }
  };
  if (!(PositiveFinite(friction.mu) && PositiveFinite(friction.e_t) &&
        PositiveFinite(friction.e_o) && PositiveFinite(friction.e_r))) {
    require(friction.mu, "mu");
    require(friction.e_t, "e_t");
    require(friction.e_o, "e_o");
    require(friction.e_r, "e_r");
  }
  StepResult r = SolveStep(slider, ReducedFriction::From(friction), state, applied, dt_s, options);
  r.sigma *= friction.e_t;  // the reduced step's slip is sigma / e_t
  return r;
}

StepResult SolveStep(const SliderProperties& slider, const ReducedFriction& friction,
                     const PlanarState& state, const AppliedWrench& applied, double dt_s,
                     const StepOptions& options) {
  Validate(slider, friction, dt_s);
  ValidateFinite(state, applied);
  std::string why;
  if (!(options.relative_tolerance > 0 && options.relative_tolerance < 1 &&
        options.max_iterations >= 1) &&
      !options.IsValid(&why)) {
    throw std::invalid_argument("SolveStep: " + why);
  }

  // The result of a step that failed: the start state, with a status and a message.
  auto failure = [&state](StepStatus status, std::string message) {
    StepResult fail;
    fail.state = state;
    fail.status = status;
    fail.message = std::move(message);
    return fail;
  };
  const double net_weight = slider.mass_kg * slider.gravity_mps2 - applied.fz;
  const double pn = dt_s * net_weight;
  if (!(net_weight > 0)) {
    return failure(StepStatus::kLiftOff,
                   "normal impulse p_n <= 0: the applied vertical force lifts the slider");
  }
  const StepEquations eq(slider, friction, state, applied, dt_s);

  // Stick when the impulse that stops the slider lies inside the ellipsoid (model.md).
  const Eigen::Vector3d p_stop = eq.StoppingImpulse();
  bool far_outside = false;  // certainly beyond kNearStickBoundary
  if (eq.InsideEllipsoid(p_stop, kNearStickBoundary, &far_outside)) {
    return Stick(state, dt_s, eq, p_stop);
  }

  // Domain limits of double (issue 5): p_n, a p_n, the momenta, V or the terms of the
  // scaled equations under- or overflow (far outside any physical slider: e.g.
  // h m g < 1e-308 N s, or c > 1e150 m). A status naming the scale, not a NaN residual.
  const bool pn_normal = std::isnormal(pn);
  if (!pn_normal || !eq.ScalesRepresentable(&why)) {
    std::ostringstream msg;
    msg << "step outside the range of double: ";
    if (!pn_normal) {
      msg << "p_n = h (m g - f_z) = " << dt_s << " * " << net_weight << " = " << pn;
    } else {
      msg << why;
    }
    return failure(StepStatus::kNoConvergence, msg.str());
  }

  Eigen::Vector4d z;
  int iterations = 0;
  double residual = 0;
  StepPath path = StepPath::kGeneral;
  bool ok = false;
  if (options.use_special_cases && eq.IsPureTranslation() && eq.IsotropicTranslation()) {
    z = eq.PureTranslationClosedForm();
    path = StepPath::kPureTranslation;
    ok = true;
  } else if (options.use_special_cases && (eq.IsDecoupled() || eq.IsPureTranslation())) {
    ok = eq.SolveDecoupled(&z, &iterations);
    path = StepPath::kDecoupled;
  } else {
    // The ratio (three divisions and a square root) only where the squares of the stick
    // test leave it in doubt (issue 19's fifth round): the same decision.
    const bool near_stick = !far_outside && eq.EllipsoidRatio(p_stop) < 1.0 + kNearStickBoundary;
    ok = SolveGeneral(eq, options, near_stick, &z, &iterations, &residual);
  }
  // Newton's own test is ConvergenceResidual already. The special paths satisfy the three
  // motion rows exactly to rounding by construction (tau_i explicit in s): their test is
  // the normwise one, which holds the sphere they solve for.
  if (ok && path != StepPath::kGeneral) {
    Eigen::Vector4d f;
    eq.Evaluate(z, &f, nullptr);
    residual = eq.RelativeResidual(z, f);
    ok = z(3) > 0 && residual <= options.relative_tolerance;
  }
  if (!ok && eq.EllipsoidRatio(p_stop) <= 1.0 + kBoundaryUlps * kEps) {
    // Stick-slip boundary (issue 5): the slide root is at s = 0 within rounding (the
    // decoupled root or the closed form find s <= 0): the slider stops, with the stopping
    // impulse, on the ellipsoid to rounding.
    return Stick(state, dt_s, eq, p_stop);
  }
  if (!ok && !eq.ScalesRepresentable(&why, true)) {
    // The terms of the scaled equations overflow (e.g. c = 1e300 m): say so (issue 5).
    return failure(StepStatus::kNoConvergence, "step outside the range of double: " + why);
  }
  if (!ok) {
    StepResult fail = failure(StepStatus::kNoConvergence, "");
    fail.iterations = iterations;
    fail.residual = residual;
    std::ostringstream msg;
    msg << "step did not converge (" << ToString(path) << " path, " << iterations
        << " iterations, relative residual " << residual << ")";
    if (!std::isfinite(residual)) {
      // Issue 5: scales near the limits of double (e.g. h = 1e200 s with tilting moments).
      msg << ": an intermediate product of the step's equations overflowed";
    }
    fail.message = msg.str();
    return fail;
  }
  Eigen::Vector3d nu;
  Eigen::Vector2d ecp_offset;
  eq.EndVelocityAndOffset(z, &nu, &ecp_offset);
  StepResult r = Finish(state, dt_s, eq, eq.Impulses(z), z(3), nu, ecp_offset);
  r.mode = StepMode::kSlide;
  r.path = path;
  r.residual = residual;
  r.iterations = iterations;
  r.scaled_solution = z;
  return r;
}

Eigen::Vector4d SlidingEquationResiduals(const SliderProperties& slider,
                                         const FrictionParameters& f, const PlanarState& state,
                                         const AppliedWrench& applied, double dt_s,
                                         const Eigen::Vector4d& x) {
  const double m = slider.mass_kg, I = slider.inertia_kgm2, qz = slider.com_height_m;
  const double pn = dt_s * (m * slider.gravity_mps2 - applied.fz);
  const double px = dt_s * applied.fx, py = dt_s * applied.fy;
  const double ptx = dt_s * applied.tx, pty = dt_s * applied.ty, ptz = dt_s * applied.tz;
  const double pt = x(0), po = x(1), pr = x(2), sigma = x(3);
  // Newton-Euler (*) and the ECP lines of model.md, written out independently of the solver.
  const double coupling = (pt * ptx + po * pty) / pn;
  const double vx = state.vx + (pt + px) / m;
  const double vy = state.vy + (po + py) / m;
  const double wz = state.wz + (pr + ptz + coupling) / I;
  const double ry = (-ptx - qz * po) / pn;
  const double rx = (pty - qz * pt) / pn;
  const double vt = vx - wz * ry, vo = vy + wz * rx, vr = wz;
  const double k = f.mu * pn;
  // Scales: the magnitudes of the terms, w_z' and the ECP offsets by their terms'
  // magnitudes too, and each friction impulse plus kEllipsoidFloor of the ellipsoid's
  // half-axis (k e_t, k e_o, k e_r). Issue 5: a row whose exact value is zero (no spin:
  // p_r = 0) was measured against its own rounding residue and reported 1 for a correct
  // solution.
  const double cap_t = kEllipsoidFloor * k * f.e_t, cap_o = kEllipsoidFloor * k * f.e_o,
               cap_r = kEllipsoidFloor * k * f.e_r;
  const double abs_vr =
      std::abs(state.wz) +
      (std::abs(pr) + cap_r + std::abs(ptz) + (std::abs(pt * ptx) + std::abs(po * pty)) / pn) / I;
  const double abs_ry = (std::abs(ptx) + qz * (std::abs(po) + cap_o)) / pn;
  const double abs_rx = (std::abs(pty) + qz * (std::abs(pt) + cap_t)) / pn;
  const double abs_vt =
      std::abs(state.vx) + (std::abs(pt) + cap_t + std::abs(px)) / m + abs_vr * abs_ry;
  const double abs_vo =
      std::abs(state.vy) + (std::abs(po) + cap_o + std::abs(py)) / m + abs_vr * abs_rx;
  auto relative = [](double value, double scale) { return scale > 0 ? value / scale : value; };
  const double abs_sigma = std::abs(sigma);
  Eigen::Vector4d r;
  r(0) = relative(k * f.e_t * f.e_t * vt + pt * sigma,
                  k * f.e_t * f.e_t * abs_vt + (std::abs(pt) + cap_t) * abs_sigma);
  r(1) = relative(k * f.e_o * f.e_o * vo + po * sigma,
                  k * f.e_o * f.e_o * abs_vo + (std::abs(po) + cap_o) * abs_sigma);
  r(2) = relative(k * f.e_r * f.e_r * vr + pr * sigma,
                  k * f.e_r * f.e_r * abs_vr + (std::abs(pr) + cap_r) * abs_sigma);
  const double qt = pt / f.e_t, qo = po / f.e_o, qr = pr / f.e_r;
  r(3) = relative(k * k - qt * qt - qo * qo - qr * qr, k * k + qt * qt + qo * qo + qr * qr);
  return r;
}

Eigen::Vector2d StepResult::EcpBody() const {
  const double c = std::cos(state.theta), s = std::sin(state.theta);
  return {c * ecp_offset_world(0) + s * ecp_offset_world(1),
          -s * ecp_offset_world(0) + c * ecp_offset_world(1)};
}

const char* ToString(StepMode mode) { return mode == StepMode::kStick ? "stick" : "slide"; }

const char* ToString(StepPath path) {
  switch (path) {
    case StepPath::kStick:
      return "stick";
    case StepPath::kPureTranslation:
      return "pure-translation";
    case StepPath::kDecoupled:
      return "decoupled";
    case StepPath::kGeneral:
      return "general";
  }
  return "?";
}

}  // namespace slideid
