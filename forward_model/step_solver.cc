#include "forward_model/step_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "forward_model/step_equations.h"

namespace slideid {
namespace {


// Armijo constant and the bound on halvings of the Newton line search.
constexpr double kArmijo = 1e-4;
constexpr int kMaxHalvings = 40;
// Newton never takes s below this fraction of its current value (s must stay > 0).
constexpr double kMinSlipFraction = 0.1;
// Relative size below which the 3x3 block (or the border) counts as singular.
constexpr double kSingularBlock = 1e-12;
// Coupling scales of the continuation used only when Newton from the decoupled guess fails.
constexpr double kContinuation[] = {0.125, 0.25, 0.5, 0.75, 1.0};

void Validate(const SliderProperties& slider, const FrictionParameters& f, double dt_s) {
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
  require(std::isfinite(slider.com_height_m) && slider.com_height_m >= 0,
          "com_height must be >= 0", slider.com_height_m);
  require(std::isfinite(slider.gravity_mps2) && slider.gravity_mps2 > 0, "gravity must be > 0",
          slider.gravity_mps2);
  require(std::isfinite(f.mu) && f.mu > 0, "mu must be > 0", f.mu);
  require(std::isfinite(f.e_t) && f.e_t > 0, "e_t must be > 0", f.e_t);
  require(std::isfinite(f.e_o) && f.e_o > 0, "e_o must be > 0", f.e_o);
  require(std::isfinite(f.e_r) && f.e_r > 0, "e_r must be > 0", f.e_r);
  require(std::isfinite(dt_s) && dt_s > 0, "time step must be > 0", dt_s);
}

// The Jacobian is bordered, [[A, tau], [V tau^T, 0]]: eliminate through the 3x3 block A
// (cofactor inverse, cheaper than a 4x4 LU); fall back to pivoted LU where A is singular
// or the border is degenerate.
bool SolveNewtonSystem(const Eigen::Matrix4d& jac, const Eigen::Vector4d& f,
                       Eigen::Vector4d* dz) {
  const Eigen::Matrix3d A = jac.topLeftCorner<3, 3>();
  Eigen::Matrix3d A_inv;
  bool invertible = false;
  A.computeInverseWithCheck(A_inv, invertible, kSingularBlock * A.cwiseAbs().maxCoeff());
  if (invertible) {
    const Eigen::Vector3d x1 = -(A_inv * f.head<3>());
    const Eigen::Vector3d x2 = A_inv * jac.topRightCorner<3, 1>();
    const Eigen::RowVector3d g = jac.bottomLeftCorner<1, 3>();
    const double border = g.dot(x2);
    if (std::abs(border) > kSingularBlock * g.norm() * x2.norm()) {
      const double ds = (g.dot(x1) + f(3)) / border;
      dz->head<3>() = x1 - x2 * ds;
      (*dz)(3) = ds;
      if (dz->allFinite()) return true;
    }
  }
  *dz = Eigen::PartialPivLU<Eigen::Matrix4d>(jac).solve(-f);
  return dz->allFinite();
}

// Newton on the scaled equations from `z`; returns true when converged.
bool Newton(const StepEquations& eq, const StepOptions& options, Eigen::Vector4d* z,
            int* iterations, double* relative_residual) {
  Eigen::Vector4d f;
  Eigen::Matrix4d jac;
  eq.Evaluate(*z, &f, &jac);
  for (int it = 0; it < options.max_iterations; ++it) {
    *relative_residual = eq.RelativeResidual(*z, f);
    if (*relative_residual <= options.relative_tolerance) return (*z)(3) > 0;
    Eigen::Vector4d dz;
    if (!SolveNewtonSystem(jac, f, &dz)) return false;
    double alpha = 1.0;
    if ((*z)(3) + dz(3) < kMinSlipFraction * (*z)(3)) {
      alpha = (1.0 - kMinSlipFraction) * (*z)(3) / -dz(3);
    }
    const double merit = 0.5 * f.squaredNorm();
    Eigen::Vector4d trial_f;
    Eigen::Matrix4d trial_jac;
    int halvings = 0;
    for (;; ++halvings) {
      const Eigen::Vector4d trial = *z + alpha * dz;
      eq.Evaluate(trial, &trial_f, &trial_jac);
      if (0.5 * trial_f.squaredNorm() <= (1.0 - 2.0 * kArmijo * alpha) * merit) break;
      if (halvings == kMaxHalvings) return false;
      alpha *= 0.5;
    }
    *z += alpha * dz;
    f = trial_f;
    jac = trial_jac;
    *iterations = it + 1;
  }
  *relative_residual = eq.RelativeResidual(*z, f);
  return *relative_residual <= options.relative_tolerance && (*z)(3) > 0;
}

// Newton from the decoupled guess; where that fails (typically near the stick boundary,
// where the decoupled problem sticks but the coupled one slides), from the stopping
// impulse's direction; last, continuation in the coupling strength.
bool SolveGeneral(const StepEquations& eq, const StepOptions& options, Eigen::Vector4d* z,
                  int* iterations, double* relative_residual) {
  int its = 0;
  *iterations = 0;
  if (options.initial_guess && options.initial_guess->allFinite() &&
      (*options.initial_guess)(3) > 0) {
    *z = *options.initial_guess;
    if (Newton(eq, options, z, &its, relative_residual)) {
      *iterations = its;
      return true;
    }
    *iterations = its;
    its = 0;
  }
  *z = eq.DecoupledGuess();
  bool ok = Newton(eq, options, z, &its, relative_residual);
  *iterations += its;
  if (ok) return true;
  *z = eq.StoppingGuess();  // built only when needed: it is rarely needed
  its = 0;
  ok = Newton(eq, options, z, &its, relative_residual);
  *iterations += its;
  if (ok) return true;
  *z = eq.DecoupledGuess();
  for (double scale : kContinuation) {
    its = 0;
    const bool ok = Newton(eq.WithCouplingScaled(scale), options, z, &its, relative_residual);
    *iterations += its;
    if (!ok) return false;
  }
  return true;
}

StepResult Finish(const SliderProperties& slider, const FrictionParameters& friction,
                  const PlanarState& state, double dt_s, const StepEquations& eq,
                  const Eigen::Vector3d& p, double slip) {
  StepResult r;
  r.status = StepStatus::kConverged;
  r.pt = p(0);
  r.po = p(1);
  r.pr = p(2);
  r.pn = eq.pn();
  r.sigma = friction.e_t * slip;
  const Eigen::Vector3d nu = eq.EndVelocity(p);
  r.state.vx = nu(0);
  r.state.vy = nu(1);
  r.state.wz = nu(2);
  r.state.x = state.x + dt_s * nu(0);
  r.state.y = state.y + dt_s * nu(1);
  r.state.theta = state.theta + dt_s * nu(2);
  r.ecp_offset_world = eq.EcpOffset(p);
  r.ecp_world = Eigen::Vector2d(r.state.x, r.state.y) + r.ecp_offset_world;
  const double c = std::cos(r.state.theta), s = std::sin(r.state.theta);
  r.ecp_body << c * r.ecp_offset_world(0) + s * r.ecp_offset_world(1),
      -s * r.ecp_offset_world(0) + c * r.ecp_offset_world(1);
  (void)slider;
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
  Validate(slider, friction, dt_s);
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("SolveStep: " + why);

  StepResult fail;
  fail.state = state;
  const double pn = dt_s * (slider.mass_kg * slider.gravity_mps2 - applied.fz);
  if (!(pn > 0)) {
    fail.status = StepStatus::kLiftOff;
    fail.message = "normal impulse p_n <= 0: the applied vertical force lifts the slider";
    return fail;
  }
  const StepEquations eq(slider, ReducedFriction::From(friction), state, applied, dt_s);

  // Stick when the impulse that stops the slider lies inside the ellipsoid (model.md).
  const Eigen::Vector3d p_stop = eq.StoppingImpulse();
  if (eq.InsideEllipsoid(p_stop)) {
    StepResult r = Finish(slider, friction, state, dt_s, eq, p_stop, 0.0);
    r.state.vx = r.state.vy = r.state.wz = 0.0;  // exact zero, not rounding residue
    r.state.x = state.x;
    r.state.y = state.y;
    r.state.theta = state.theta;
    r.ecp_world = Eigen::Vector2d(state.x, state.y) + r.ecp_offset_world;
    r.mode = StepMode::kStick;
    r.path = StepPath::kStick;
    return r;
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
    ok = SolveGeneral(eq, options, &z, &iterations, &residual);
  }
  if (ok) {
    Eigen::Vector4d f;
    eq.Evaluate(z, &f, nullptr);
    residual = eq.RelativeResidual(z, f);
    ok = z(3) > 0 && residual <= options.relative_tolerance;
  }
  if (!ok) {
    fail.status = StepStatus::kNoConvergence;
    fail.iterations = iterations;
    fail.residual = residual;
    std::ostringstream msg;
    msg << "step did not converge (" << ToString(path) << " path, " << iterations
        << " iterations, relative residual " << residual << ")";
    fail.message = msg.str();
    return fail;
  }
  StepResult r = Finish(slider, friction, state, dt_s, eq, eq.Impulses(z), z(3));
  r.mode = StepMode::kSlide;
  r.path = path;
  r.residual = residual;
  r.iterations = iterations;
  r.scaled_solution = z;
  return r;
}

Eigen::Vector4d SlidingEquationResiduals(const SliderProperties& slider,
                                         const FrictionParameters& f,
                                         const PlanarState& state,
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
  const double abs_vt = std::abs(state.vx) + (std::abs(pt) + std::abs(px)) / m +
                        std::abs(wz * ry);
  const double abs_vo = std::abs(state.vy) + (std::abs(po) + std::abs(py)) / m +
                        std::abs(wz * rx);
  const double abs_vr = std::abs(state.wz) + (std::abs(pr) + std::abs(ptz) + std::abs(coupling)) / I;
  const double k = f.mu * pn;
  auto relative = [](double value, double scale) {
    return scale > 0 ? value / scale : value;
  };
  Eigen::Vector4d r;
  r(0) = relative(k * f.e_t * f.e_t * vt + pt * sigma,
                  k * f.e_t * f.e_t * abs_vt + std::abs(pt * sigma));
  r(1) = relative(k * f.e_o * f.e_o * vo + po * sigma,
                  k * f.e_o * f.e_o * abs_vo + std::abs(po * sigma));
  r(2) = relative(k * f.e_r * f.e_r * vr + pr * sigma,
                  k * f.e_r * f.e_r * abs_vr + std::abs(pr * sigma));
  const double qt = pt / f.e_t, qo = po / f.e_o, qr = pr / f.e_r;
  r(3) = relative(k * k - qt * qt - qo * qo - qr * qr, k * k + qt * qt + qo * qo + qr * qr);
  return r;
}

const char* ToString(StepMode mode) { return mode == StepMode::kStick ? "stick" : "slide"; }

const char* ToString(StepPath path) {
  switch (path) {
    case StepPath::kStick: return "stick";
    case StepPath::kPureTranslation: return "pure-translation";
    case StepPath::kDecoupled: return "decoupled";
    case StepPath::kGeneral: return "general";
  }
  return "?";
}

}  // namespace slideid
