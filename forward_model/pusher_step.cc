#include "forward_model/pusher_step.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

namespace slideid {
namespace {

// A tangential impulse within this relative margin of the friction cone still sticks: the
// stick solve meets its conditions only to the tolerance.
constexpr double kConeMargin = 1e-9;
// Doublings of the bracket of the sliding solve's normal impulse before it gives up: from
// the rigid-body estimate, 2^60 covers any support friction.
constexpr int kMaxBracketDoublings = 60;
// Broyden's Jacobian is reset to the rigid-body one after this many iterations without a
// smaller residual.
constexpr int kBroydenPatience = 4;
// An overlap of the tip and the slider below this [m] at the end of a step is no overlap:
// the contact geometry is linearised at the step's start, and rounding leaves about 1e-12 m
// after each step in contact. Without the allowance, a slider resting against a still tip
// must be shifted by that picometre, which takes an impulse at its static friction limit,
// a root the support's step resolves only to its own tolerance.
constexpr double kGapAllowanceM = 1e-9;

/// The tip's conditions as functions of its impulse: each evaluation is one support step.
class TipProblem {
 public:
  struct Eval {
    StepResult step;
    AppliedWrench applied;
    double lambda_n = 0, lambda_t = 0;
    double gap_rate = 0;  ///< (g0 - h u_n) / h [m/s]: >= 0 apart, 0 in contact
    double slip = 0;      ///< u_t [m/s]: the contact point along t relative to the tip
  };

  TipProblem(const SliderProperties& slider, const ReducedFriction& friction, const Pusher& pusher,
             const PlanarState& state, const TipContact& contact,
             const Eigen::Vector2d& tip_velocity, const AppliedWrench& applied, double h,
             const PusherStepOptions& options)
      : slider_(slider),
        friction_(friction),
        state_(state),
        applied_(applied),
        h_(h),
        options_(options),
        contact_(contact) {
    n_ = contact.normal_world;
    t_ = Eigen::Vector2d(-n_.y(), n_.x());
    arm_ = contact.point_world - Eigen::Vector2d(state.x, state.y);
    rz_ = pusher.height_m ? *pusher.height_m - slider.com_height_m : 0.0;
    tip_slip_ = tip_velocity.dot(t_);
    cn_ << n_.x(), n_.y(), arm_.x() * n_.y() - arm_.y() * n_.x();
    ct_ << t_.x(), t_.y(), arm_.x() * t_.y() - arm_.y() * t_.x();
    const Eigen::Vector3d m_inv(1 / slider.mass_kg, 1 / slider.mass_kg, 1 / slider.inertia_kgm2);
    const double wnn = cn_.dot(m_inv.cwiseProduct(cn_)), wtt = ct_.dot(m_inv.cwiseProduct(ct_));
    const double wnt = cn_.dot(m_inv.cwiseProduct(ct_));
    rigid_ << wnn, -wnt, -wnt, wtt;
    const Eigen::Vector3d v0(state.vx, state.vy, state.wz);
    scale_ = std::max({tip_velocity.norm(), std::abs(cn_.dot(v0)), std::abs(ct_.dot(v0)),
                       std::abs(contact.gap_m) / h, friction.a * slider.gravity_mps2 * h,
                       std::numeric_limits<double>::min()});
  }

  Eval At(double lambda_n, double lambda_t) {
    ++evaluations_;
    Eval e;
    e.lambda_n = lambda_n;
    e.lambda_t = lambda_t;
    const Eigen::Vector2d force = (-lambda_n * n_ + lambda_t * t_) / h_;
    const AppliedWrench tip = WrenchFromForceAt(force.x(), force.y(), 0.0, arm_.x(), arm_.y(), rz_);
    e.applied = applied_;
    e.applied.fx += tip.fx;
    e.applied.fy += tip.fy;
    e.applied.tx += tip.tx;
    e.applied.ty += tip.ty;
    e.applied.tz += tip.tz;
    StepOptions step_options = options_.step;
    if (warm_) step_options.initial_guess = warm_;
    e.step = SolveStep(slider_, friction_, state_, e.applied, h_, step_options);
    if (!e.step.ok()) return e;
    if (e.step.mode == StepMode::kSlide) warm_ = e.step.scaled_solution;
    const Eigen::Vector3d v(e.step.state.vx, e.step.state.vy, e.step.state.wz);
    e.gap_rate = contact_.gap_m / h_ - cn_.dot(v);
    e.slip = ct_.dot(v) - tip_slip_;
    return e;
  }

  double Tolerance() const { return options_.relative_tolerance * scale_; }
  /// The gap condition's tolerance [m/s]: the relative one, or the allowance over h.
  double GapTolerance() const { return std::max(Tolerance(), kGapAllowanceM / h_); }
  double h() const { return h_; }
  double scale() const { return scale_; }
  const Eigen::Matrix2d& rigid() const { return rigid_; }
  /// d gap_rate / d lambda_n of the frictionless support when sliding with lambda_t = s mu
  /// lambda_n (> 0 for any mu when the contact normal passes near the CM).
  double RigidGapSlope(double s_mu) const { return rigid_(0, 0) + s_mu * rigid_(0, 1); }
  int evaluations() const { return evaluations_; }
  const Eigen::Vector2d& n() const { return n_; }
  const Eigen::Vector2d& t() const { return t_; }

 private:
  const SliderProperties& slider_;
  const ReducedFriction& friction_;
  PlanarState state_;
  AppliedWrench applied_;
  double h_;
  const PusherStepOptions& options_;
  TipContact contact_;
  Eigen::Vector2d n_, t_, arm_;
  double rz_ = 0, tip_slip_ = 0, scale_ = 1;
  Eigen::Vector3d cn_, ct_;
  Eigen::Matrix2d rigid_;
  std::optional<Eigen::Vector4d> warm_;
  int evaluations_ = 0;
};

double StickResidual(const TipProblem::Eval& e) {
  return std::max(std::abs(e.gap_rate), std::abs(e.slip));
}

/// Sticking: gap_rate = 0 and slip = 0 by Broyden's method from the rigid-body response.
std::optional<TipProblem::Eval> SolveStick(TipProblem& p, const TipProblem::Eval& free,
                                           int max_iterations) {
  Eigen::Matrix2d jacobian = p.rigid();
  Eigen::Vector2d r(free.gap_rate, free.slip);
  Eigen::Vector2d lambda(0, 0);
  TipProblem::Eval best = free;
  int stalled = 0;
  for (int k = 0; k < max_iterations; ++k) {
    Eigen::Vector2d step = -jacobian.partialPivLu().solve(r);
    if (!step.allFinite()) {  // Broyden's update went singular: start it again
      jacobian = p.rigid();
      step = -jacobian.partialPivLu().solve(r);
    }
    const Eigen::Vector2d next = lambda + step;
    const TipProblem::Eval e = p.At(next.x(), next.y());
    if (!e.step.ok()) return std::nullopt;
    const Eigen::Vector2d r_next(e.gap_rate, e.slip);
    const Eigen::Vector2d s = next - lambda;
    if (s.squaredNorm() > 0)
      jacobian += (r_next - r - jacobian * s) * s.transpose() / s.squaredNorm();
    lambda = next;
    r = r_next;
    if (StickResidual(e) < StickResidual(best)) {
      best = e;
      stalled = 0;
    } else if (++stalled >= kBroydenPatience) {
      jacobian = p.rigid();
      stalled = 0;
    }
    if (std::abs(best.gap_rate) <= p.GapTolerance() && std::abs(best.slip) <= p.Tolerance()) {
      return best;
    }
  }
  return std::nullopt;
}

/// Sliding along the edge with lambda_t = s mu lambda_n: the scalar root of gap_rate in
/// lambda_n >= 0, bracketed from the rigid-body estimate and closed by the Illinois method.
std::optional<TipProblem::Eval> SolveSlide(TipProblem& p, const TipProblem::Eval& free, double s_mu,
                                           int max_iterations) {
  auto at = [&](double ln) { return p.At(ln, s_mu * ln); };
  TipProblem::Eval lo = free;  // gap_rate < 0: the tip would overlap
  const double slope = p.RigidGapSlope(s_mu);
  double guess = slope > 0 ? -free.gap_rate / slope : -free.gap_rate / p.rigid()(0, 0);
  TipProblem::Eval hi = at(guess);
  for (int k = 0; hi.step.ok() && hi.gap_rate < 0 && k < kMaxBracketDoublings; ++k) {
    lo = hi;
    guess *= 2;
    hi = at(guess);
  }
  if (!hi.step.ok() || hi.gap_rate < 0) return std::nullopt;
  if (hi.gap_rate <= p.GapTolerance()) return hi;
  int side = 0;  // Illinois: halve the weight of an end kept twice
  double flo = lo.gap_rate, fhi = hi.gap_rate;
  for (int k = 0; k < max_iterations; ++k) {
    const double ln = (lo.lambda_n * fhi - hi.lambda_n * flo) / (fhi - flo);
    const TipProblem::Eval e = at(ln);
    if (!e.step.ok()) return std::nullopt;
    if (std::abs(e.gap_rate) <= p.GapTolerance()) return e;
    if (e.gap_rate < 0) {
      lo = e;
      flo = e.gap_rate;
      if (side == -1) fhi *= 0.5;
      side = -1;
    } else {
      hi = e;
      fhi = e.gap_rate;
      if (side == 1) flo *= 0.5;
      side = 1;
    }
    if (hi.lambda_n - lo.lambda_n <= 1e-15 * hi.lambda_n)
      return std::abs(flo) < std::abs(fhi) ? lo : hi;
  }
  return std::nullopt;
}

/// Sticking as the root in rho of the slip, between rho = -mu (slip < 0) and rho = mu
/// (slip > 0), each rho's normal impulse the root of the gap (SolveSlide), by Illinois.
std::optional<TipProblem::Eval> SolveStickOnRatio(TipProblem& p, const TipProblem::Eval& free,
                                                  double mu, TipProblem::Eval lo,
                                                  TipProblem::Eval hi, int max_iterations) {
  double rlo = -mu, rhi = mu, flo = lo.slip, fhi = hi.slip;
  int side = 0;
  for (int k = 0; k < max_iterations; ++k) {
    const double rho = (rlo * fhi - rhi * flo) / (fhi - flo);
    const std::optional<TipProblem::Eval> e = SolveSlide(p, free, rho, max_iterations);
    if (!e) return std::nullopt;
    if (std::abs(e->slip) <= p.Tolerance()) return e;
    if (e->slip < 0) {
      rlo = rho;
      flo = e->slip;
      if (side == -1) fhi *= 0.5;
      side = -1;
    } else {
      rhi = rho;
      fhi = e->slip;
      if (side == 1) flo *= 0.5;
      side = 1;
    }
    if (rhi - rlo <= 1e-15 * mu) break;  // rho at rounding: the slip is what it is
  }
  return std::nullopt;
}

PusherStepResult Finish(const TipProblem& p, const TipProblem::Eval& e, TipMode mode,
                        const TipContact& contact, double h) {
  PusherStepResult r;
  r.step = e.step;
  r.tip_mode = mode;
  r.contact = contact;
  r.lambda_n = e.lambda_n;
  r.lambda_t = e.lambda_t;
  r.impulse_world = -e.lambda_n * p.n() + e.lambda_t * p.t();
  r.applied = e.applied;
  r.gap_end_m = e.gap_rate * h;
  r.slip_mps = e.slip;
  r.iterations = p.evaluations();
  const double slip_violation =
      mode == TipMode::kStick ? std::abs(e.slip)
      : mode == TipMode::kSlide
          ? std::max(0.0, e.lambda_t * e.slip /
                              std::max(std::abs(e.lambda_t), std::numeric_limits<double>::min()))
          : 0.0;
  const double gap_violation = std::max(
      0.0, (mode == TipMode::kApart ? -e.gap_rate : std::abs(e.gap_rate)) - kGapAllowanceM / p.h());
  r.residual = std::max(slip_violation, gap_violation) / p.scale();
  return r;
}

}  // namespace

bool PusherStepOptions::IsValid(std::string* why) const {
  if (!step.IsValid(why)) return false;
  if (!(relative_tolerance > 0 && relative_tolerance < 1e-2)) {
    if (why) *why = "pusher step relative_tolerance must be in (0, 0.01)";
    return false;
  }
  if (max_iterations < 1) {
    if (why) *why = "pusher step max_iterations must be >= 1";
    return false;
  }
  return true;
}

PusherStepResult SolvePusherStep(const SliderProperties& slider, const ReducedFriction& friction,
                                 const ContactPatch& patch, const Pusher& pusher,
                                 const PlanarState& state, const Eigen::Vector2d& tip_start,
                                 const Eigen::Vector2d& tip_end, const AppliedWrench& applied,
                                 double dt_s, const PusherStepOptions& options) {
  std::string why;
  if (!options.IsValid(&why) || !pusher.IsValid(&why)) {
    throw std::invalid_argument("SolvePusherStep: " + why);
  }
  if (!tip_start.allFinite() || !tip_end.allFinite()) {
    throw std::invalid_argument("SolvePusherStep: the tip positions must be finite");
  }
  if (!(std::isfinite(dt_s) && dt_s > 0)) {
    throw std::invalid_argument("SolvePusherStep: time step must be > 0");
  }
  const TipContact contact = ContactWithTip(patch, state, tip_end, pusher.tip_radius_m);
  TipProblem p(slider, friction, pusher, state, contact, (tip_end - tip_start) / dt_s, applied,
               dt_s, options);
  const TipProblem::Eval free = p.At(0, 0);
  if (!free.step.ok() || free.gap_rate >= -kGapAllowanceM / dt_s) {
    PusherStepResult r = Finish(p, free, TipMode::kApart, contact, dt_s);
    r.message = free.step.message;
    return r;
  }
  const double mu = pusher.mu;
  if (mu > 0) {  // the fast path: Broyden on the sticking conditions
    const std::optional<TipProblem::Eval> stick = SolveStick(p, free, options.max_iterations);
    if (stick && stick->lambda_n >= 0 &&
        std::abs(stick->lambda_t) <= mu * stick->lambda_n * (1 + kConeMargin)) {
      return Finish(p, *stick, TipMode::kStick, contact, dt_s);
    }
  }
  // The robust path, on the ratio rho = lambda_t / lambda_n in [-mu, mu], each rho's normal
  // impulse the root of the gap: the slip grows with rho (more impulse along t moves the
  // contact point along t), so the tip slides one way when even rho = mu leaves slip <= 0,
  // the other when rho = -mu leaves slip >= 0, and sticks at the root in between.
  const double tolerance = p.Tolerance();
  const std::optional<TipProblem::Eval> plus = SolveSlide(p, free, mu, options.max_iterations);
  if (plus && (mu == 0 || plus->slip <= tolerance)) {
    return Finish(p, *plus, TipMode::kSlide, contact, dt_s);
  }
  const std::optional<TipProblem::Eval> minus = SolveSlide(p, free, -mu, options.max_iterations);
  if (minus && minus->slip >= -tolerance) return Finish(p, *minus, TipMode::kSlide, contact, dt_s);
  std::optional<TipProblem::Eval> stick;
  if (plus && minus) stick = SolveStickOnRatio(p, free, mu, *minus, *plus, options.max_iterations);
  if (stick) return Finish(p, *stick, TipMode::kStick, contact, dt_s);
  PusherStepResult failed = Finish(p, plus ? *plus : free, TipMode::kSlide, contact, dt_s);
  failed.step.status = StepStatus::kNoConvergence;
  failed.message =
      "the pusher's contact did not converge: no sticking or sliding impulse meets "
      "the tip's conditions (relative residual " +
      std::to_string(failed.residual) + ")";
  failed.step.message = failed.message;
  return failed;
}

const char* ToString(TipMode mode) {
  switch (mode) {
    case TipMode::kApart:
      return "apart";
    case TipMode::kStick:
      return "stick";
    case TipMode::kSlide:
      return "slide";
  }
  return "?";
}

}  // namespace slideid
