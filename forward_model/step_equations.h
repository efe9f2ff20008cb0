#pragma once
// The equations of one sliding step in scaled form, shared by the step solver and by the
// estimator's implicit-function derivatives (model.md, "One step" and "Only three
// parameters matter").
//
// Unknowns z = (tau_t, tau_o, tau_r, s): the friction impulse on the unit sphere of the
// ellipsoid, p = P (tau_t, b tau_o, c tau_r) with P = a p_n, and the slip speed
// s = sigma / e_t [m/s]. With u = (v_t, b v_o, c v_r) the weighted ECP velocity at the end
// of the step, the four equations are u + s tau = 0 and |tau|^2 = 1. Every entry is O(1)
// in velocity units, so a relative tolerance means the same in every scene.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "forward_model/adjugate3.h"
#include "forward_model/planar_state.h"
#include "forward_model/slider.h"

namespace slideid {

/// Everything that defines one step, in any scalar type (double, or ceres::Jet for the
/// estimator's derivatives): masses, CM height, normal impulse, (a, b, c), tilting
/// impulses h tx, h ty [N m s] and k = M nu + applied impulse [N s, N s, N m s].
template <typename T>
struct StepTerms {
  T m, I, qz, pn, a, b, c, ptx, pty;
  Eigen::Matrix<T, 3, 1> k;
};

/// (v_x', v_y', w_z') from Newton-Euler with the coupling term (*), for friction p.
template <typename T>
Eigen::Matrix<T, 3, 1> StepEndVelocity(const StepTerms<T>& s, const Eigen::Matrix<T, 3, 1>& p) {
  Eigen::Matrix<T, 3, 1> nu;
  nu << (s.k(0) + p(0)) / s.m, (s.k(1) + p(1)) / s.m,
      (s.k(2) + p(2) + (p(0) * s.ptx + p(1) * s.pty) / s.pn) / s.I;
  return nu;
}

/// ECP minus CM (world), from the x and y moment balances [m].
template <typename T>
Eigen::Matrix<T, 2, 1> StepEcpOffset(const StepTerms<T>& s, const Eigen::Matrix<T, 3, 1>& p) {
  Eigen::Matrix<T, 2, 1> r;
  r << (s.pty - s.qz * p(0)) / s.pn, (-s.ptx - s.qz * p(1)) / s.pn;
  return r;
}

/// Friction impulse from the scaled unknowns: p = a p_n (tau_t, b tau_o, c tau_r).
template <typename T>
Eigen::Matrix<T, 3, 1> StepImpulses(const StepTerms<T>& s, const Eigen::Matrix<T, 4, 1>& z) {
  const T P = s.a * s.pn;
  Eigen::Matrix<T, 3, 1> p;
  p << P * z(0), P * s.b * z(1), P * s.c * z(2);
  return p;
}

/// The four scaled equations (u + s tau, V (|tau|^2 - 1) / 2), u = (v_t, b v_o, c v_r).
template <typename T>
Eigen::Matrix<T, 4, 1> ScaledStepResidual(const StepTerms<T>& s, const Eigen::Matrix<T, 4, 1>& z,
                                          double velocity_scale) {
  const Eigen::Matrix<T, 3, 1> p = StepImpulses(s, z);
  const Eigen::Matrix<T, 3, 1> nu = StepEndVelocity(s, p);
  const Eigen::Matrix<T, 2, 1> r = StepEcpOffset(s, p);
  Eigen::Matrix<T, 4, 1> f;
  f(0) = nu(0) - nu(2) * r(1) + z(3) * z(0);
  f(1) = s.b * (nu(1) + nu(2) * r(0)) + z(3) * z(1);
  f(2) = s.c * nu(2) + z(3) * z(2);
  f(3) = T(0.5 * velocity_scale) * (z(0) * z(0) + z(1) * z(1) + z(2) * z(2) - T(1.0));
  return f;
}

class StepEquations {
 public:
  StepEquations(const SliderProperties& slider, const ReducedFriction& friction,
                const PlanarState& state, const AppliedWrench& applied, double dt_s);

  double pn() const { return t_.pn; }
  /// Friction impulse (p_t, p_o, p_r) that brings the slider to rest in this step.
  Eigen::Vector3d StoppingImpulse() const;
  /// (p_t)^2 + (p_o/b)^2 + (p_r/c)^2 <= (a p_n)^2. With `beyond`, also whether p is
  /// certainly further out than EllipsoidRatio(p) > 1 + beyond_ratio (the sums in squares,
  /// with a relative margin of kSquaresMargin over their rounding); false where that is not
  /// certain, and the ratio decides.
  bool InsideEllipsoid(const Eigen::Vector3d& p, double beyond_ratio = 0,
                       bool* beyond = nullptr) const;
  /// InsideEllipsoid's margin on its sums of squares against EllipsoidRatio's rounding.
  static constexpr double kSquaresMargin = 1e-4;

  /// (v_x', v_y', w_z') from Newton-Euler with the coupling term (*).
  Eigen::Vector3d EndVelocity(const Eigen::Vector3d& p) const;
  /// ECP minus CM in the world frame, from the x and y moment balances [m].
  Eigen::Vector2d EcpOffset(const Eigen::Vector3d& p) const;
  /// (v_t, v_o, v_r) at the end of the step and, if dv_dp is given, d(v)/d(p).
  Eigen::Vector3d EcpVelocity(const Eigen::Vector3d& p, Eigen::Matrix3d* dv_dp) const;

  Eigen::Vector3d Impulses(const Eigen::Vector4d& z) const;
  /// Residual F(z) (last entry scaled by the velocity scale) and its Jacobian dF/dz.
  void Evaluate(const Eigen::Vector4d& z, Eigen::Vector4d* f, Eigen::Matrix4d* jac) const;
  /// What the Jacobian shares with the residual at one z: w_z' and the ECP offset (r_x, r_y).
  struct Shared {
    double w, r0, r1;
  };
  /// The residual F(z) alone: ScaledStepResidual in doubles (to rounding: by reciprocals of
  /// m, p_n and I); with `shared`, also what JacobianBlock needs at the same z.
  void Residual(const Eigen::Vector4d& z, Eigen::Vector4d* f, Shared* shared = nullptr) const;
  /// End velocity (v_x', v_y', w_z') and ECP offset (world) at the scaled unknowns z, by the
  /// same arithmetic as Residual (EndVelocity and EcpOffset of Impulses(z), to rounding).
  void EndVelocityAndOffset(const Eigen::Vector4d& z, Eigen::Vector3d* nu,
                            Eigen::Vector2d* offset) const;
  /// The Jacobian's 3x3 block dF_1..3 / dtau (with s on its diagonal) at z. The rest of
  /// dF/dz is the border: dF_1..3 / ds = tau, dF_4 / dtau = V tau^T, dF_4 / ds = 0.
  void JacobianBlock(const Eigen::Vector4d& z, Eigen::Matrix3d* block) const;
  /// The same from what Residual shared at z.
  void JacobianBlock(const Eigen::Vector4d& z, const Shared& shared, Eigen::Matrix3d* block) const;
  /// max(|F_1..3| / (V + s), | |tau|^2 - 1 |): the solver's convergence measure.
  double RelativeResidual(const Eigen::Vector4d& z, const Eigen::Vector4d& f) const;
  /// max_i |F_i| / T_i over the three motion rows, T_i the sum of the magnitudes of row i's
  /// terms with the friction impulses at the size of the ellipsoid (its rounding floor is a
  /// few ulps of T_i). Stricter than RelativeResidual where one row's terms are much
  /// smaller than V (e.g. c |w| << V, or |v| << c |w|), as the paper-form residuals of
  /// SlidingEquationResiduals are (issue 5, docs/stability.md).
  double ComponentwiseResidual(const Eigen::Vector4d& z, const Eigen::Vector4d& f) const;
  /// T_i of ComponentwiseResidual at the ellipsoid's size (without s tau_i); cached,
  /// computed on the first call (for steps that slide). The solver calls it where other
  /// work waits on a chain (issue 19's sixth round).
  const Eigen::Vector3d& RowTerms() const;
  /// Largest of RelativeResidual and ComponentwiseResidual (the latter only evaluated once
  /// the former is below `tolerance`: it matters only near a root).
  double ConvergenceResidual(const Eigen::Vector4d& z, const Eigen::Vector4d& f,
                             double tolerance) const;
  /// False, with the reason in `why`, when a scale of the step is not a normal double:
  /// a p_n subnormal, zero or overflowed, or the momenta, tilting impulses or the free slip
  /// speed overflowed; with `with_equation_terms`, also the magnitudes of the scaled
  /// equations' terms (a domain limit of double precision, docs/stability.md).
  bool ScalesRepresentable(std::string* why, bool with_equation_terms = false) const {
    // Every step asks (issue 19's sixth round): a sum of finite values is finite unless it
    // overflows, and with an Inf or NaN among them it is not. The reasons one by one only
    // where that fails.
    if (!with_equation_terms && P_ >= std::numeric_limits<double>::min() &&
        std::isfinite(((P_ + velocity_scale_) + (t_.ptx + t_.pty)) +
                      ((t_.k(0) + t_.k(1)) + t_.k(2)))) {
      return true;
    }
    return ScalesRepresentableOneByOne(why, with_equation_terms);
  }
  /// |w| times the largest ECP offset the friction allows: the slip the spin about an ECP
  /// away from the CM adds, against the free slip speed V [m/s].
  double CouplingSpeed() const;
  /// True when the step's sliding root is provably unique: the weighted ECP velocity u(tau)
  /// is strictly monotone on the unit ball (the symmetric part of du/dtau positive definite
  /// there), so the sliding equations, a variational inequality on the ball, have at most
  /// one solution. A sufficient test (docs/performance.md, "The general step"): with S the
  /// symmetric part of u's linear part, x^T (du/dtau) x = x^T S x + b d (e . x)(g . x) on
  /// the ball (the spin about the displaced ECP: d = q_z a, g = dw'/dtau, |e . x| <= |x_12|),
  /// and alpha S - (b d / 2)(alpha^2 diag(1, 1, 0) + g g^T) positive definite for one of
  /// alpha = |g|, 2 |g|, |g| / 2 bounds that below. 991 of step_benchmark's 1024 general
  /// steps pass (issue 19's third round; 764 passed the second round's whole-ball bound);
  /// the most strongly coupled steps (large q_z a against c) do not.
  bool UniqueSlidingRoot() const;
  /// sqrt(p_t^2 + (p_o/b)^2 + (p_r/c)^2) / (a p_n): 1 on the ellipsoid.
  double EllipsoidRatio(const Eigen::Vector3d& p) const;

  /// No CM height and no tilting moments: the ECP stays under the CM.
  bool IsDecoupled() const { return t_.qz == 0.0 && t_.ptx == 0.0 && t_.pty == 0.0; }
  /// No spin, no spin impulse, no tilting moments: w_z' = 0 solves the step exactly.
  bool IsPureTranslation() const { return t_.k(2) == 0.0 && t_.ptx == 0.0 && t_.pty == 0.0; }
  bool IsotropicTranslation() const { return t_.b == 1.0; }

  /// Exact solution of the decoupled problem (coupling ignored) by a safeguarded Newton
  /// root of |tau(s)| = 1, monotone in s, to |1/|tau| - 1| <= tolerance (default: a few
  /// ulps). Returns false if it did not converge.
  /// With accept_after_step > 0, a Newton step taken from |g| <= accept_after_step ends the
  /// root without a check of g after it (for a first guess, where g squared is enough).
  bool SolveDecoupled(Eigen::Vector4d* z, int* iterations, double tolerance = 0.0,
                      double accept_after_step = 0.0) const;
  /// The decoupled solution as a first guess for the general solve (valid even where the
  /// decoupled problem itself would stick).
  Eigen::Vector4d DecoupledGuess() const;
  /// The same with the scalar root to `tolerance`, its Newton step from |g| <=
  /// `accept_after_step` taken unchecked (SolveDecoupled).
  Eigen::Vector4d DecoupledGuess(double tolerance, double accept_after_step) const;
  /// A first guess near the stick boundary: the direction of the stopping impulse, and the
  /// slip speed each axis alone would have (decoupled closed form), averaged by weight.
  Eigen::Vector4d StoppingGuess() const;
  /// A first guess near the stick boundary (stopping impulse just outside the ellipsoid):
  /// the ECP velocity linearised about the stopping impulse, u = A (tau - tau_stop), where
  /// it is zero, and s the root of |(A + s I)^-1 A tau_stop| = 1 (a scalar root, bracketed).
  /// Exact to second order in the distance to the boundary, where the direction of the
  /// stopping impulse alone leaves Newton crawling along a weakly stiff row (issue 5).
  Eigen::Vector4d LinearisedStopGuess() const;
  /// `sweeps` fixed-point sweeps of u(tau) + s tau = 0 from z: tau = -u / |u|, s = |u|, u the
  /// weighted ECP velocity at the impulses of the previous sweep. A first guess where the
  /// coupling moves the ECP far from the CM, so that the spin about it, not the free slip
  /// speed V, sets the slip speed (found by the stability sweep, docs/stability.md).
  Eigen::Vector4d EcpVelocityGuess(Eigen::Vector4d z, int sweeps) const;
  /// One sweep of EcpVelocityGuess by the arithmetic of Residual (u = F_1..3 - s tau), with
  /// one square root and one division (issue 19: the first guess where UniqueSlidingRoot).
  Eigen::Vector4d EcpVelocitySweep(const Eigen::Vector4d& z) const;
  /// A first guess from a rough one z (issue 19's fourth round, where UniqueSlidingRoot):
  /// u linearised about z's tau, u(tau) ~ u(tau0) + A (tau - tau0), A = du/dtau there, so
  /// that tau(s) = (A + s I)^-1 r, r = A tau0 - u(tau0); one Newton step from z's s on
  /// det(A + s I) / |adj(A + s I) r| = 1 / |tau(s)| = 1 (the adjugate and the determinant
  /// are polynomials in s: no solve per step), and tau = tau(s), of norm 1 to second order
  /// in that step. From tau = 0 it generalises the decoupled root (the same equation where
  /// the coupling vanishes); its error is u's quadratic part over tau - tau0. False, z
  /// unchanged, where a quantity it divides by vanishes or is not finite, or s <= 0.
  bool LinearisedCouplingGuess(Eigen::Vector4d* z) const;
  /// The same about tau0 = 0 from slip speed s (the first of SolveGeneral's two): u(0) by
  /// the constructor's reciprocals, without the products by tau0 = 0 (the same doubles).
  /// Where it returns false, z is not a guess.
  bool LinearisedCouplingGuessAtRest(double s, Eigen::Vector4d* z) const;
  /// The decoupled root's lower bound on s: each term of |tau(s)|^2 alone reaching 1.
  double DecoupledSlipLowerBound() const;
  /// Closed form for pure translation with b = 1 (model.md, erratum 4).
  Eigen::Vector4d PureTranslationClosedForm() const;
  /// The same step with q_z and the tilting impulses scaled by `scale` (continuation).
  StepEquations WithCouplingScaled(double scale) const;

  double velocity_scale() const { return velocity_scale_; }
  const StepTerms<double>& terms() const { return t_; }

 private:
  Eigen::Vector4d DecoupledAt(double s) const;
  /// ScalesRepresentable, each scale tested and named.
  bool ScalesRepresentableOneByOne(std::string* why, bool with_equation_terms) const;
  /// LinearisedCouplingGuess's scalar step and its tau(s), from A = du/dtau at tau0 and
  /// r = A tau0 - u(tau0).
  bool SecularGuess(const Eigen::Matrix3d& A, double r0, double r1, double r2, double s,
                    Eigen::Vector4d* z) const;
  /// Fills the constants of the Jacobian below from t_ and P_.
  void PrecomputeJacobianTerms();
  StepTerms<double> t_;
  mutable Eigen::Vector3d row_terms_;
  mutable bool row_terms_ready_ = false;
  double P_;               // a p_n
  double velocity_scale_;  // |k / M| weighted by (1, b, c): free slip speed [m/s]
  // Constants of the Jacobian, computed once per step (the solver evaluates it 4-5 times):
  // P (1, b, c), d w_z' / d p = (t_x / p_n / I, t_y / p_n / I, 1 / I), d r_x / d p_t =
  // d r_y / d p_o = -q_z / p_n, and 1 / m.
  double pw_[3];
  double dw_[3];
  double dr_;
  double inv_m_;
  // 1 / p_n and 1 / I, and whether 1 / m, 1 / p_n, 1 / I and their arguments are all normal
  // doubles (then Residual multiplies by them).
  double inv_pn_, inv_I_;
  bool reciprocals_ = false;
};

// The hot members of the Newton iteration, inline: the solver calls them a few times per
// step, and a call costs as much as their arithmetic.
inline void StepEquations::Residual(const Eigen::Vector4d& z, Eigen::Vector4d* f,
                                    Shared* shared) const {
  // ScaledStepResidual<double>, written out; with reciprocals of m, p_n and I where those
  // are normal doubles (all but the domain probes of issue 5): a division is on the
  // critical path of every Newton iteration, a product is a quarter of its latency.
  const double p0 = P_ * z(0), p1 = pw_[1] * z(1), p2 = pw_[2] * z(2);
  double nu0, nu1, nu2, r0, r1;
  if (reciprocals_) {
    nu0 = (t_.k(0) + p0) * inv_m_;
    nu1 = (t_.k(1) + p1) * inv_m_;
    nu2 = (t_.k(2) + p2 + (p0 * t_.ptx + p1 * t_.pty) * inv_pn_) * inv_I_;
    r0 = (t_.pty - t_.qz * p0) * inv_pn_;
    r1 = (-t_.ptx - t_.qz * p1) * inv_pn_;
  } else {
    nu0 = (t_.k(0) + p0) / t_.m;
    nu1 = (t_.k(1) + p1) / t_.m;
    nu2 = (t_.k(2) + p2 + (p0 * t_.ptx + p1 * t_.pty) / t_.pn) / t_.I;
    r0 = (t_.pty - t_.qz * p0) / t_.pn;
    r1 = (-t_.ptx - t_.qz * p1) / t_.pn;
  }
  (*f)(0) = nu0 - nu2 * r1 + z(3) * z(0);
  (*f)(1) = t_.b * (nu1 + nu2 * r0) + z(3) * z(1);
  (*f)(2) = t_.c * nu2 + z(3) * z(2);
  (*f)(3) = (0.5 * velocity_scale_) * (z(0) * z(0) + z(1) * z(1) + z(2) * z(2) - 1.0);
  if (shared) *shared = {nu2, r0, r1};
}

inline Eigen::Vector4d StepEquations::EcpVelocitySweep(const Eigen::Vector4d& z) const {
  Eigen::Vector4d f;
  Residual(z, &f);
  const double u0 = f(0) - z(3) * z(0), u1 = f(1) - z(3) * z(1), u2 = f(2) - z(3) * z(2);
  const double speed = std::sqrt(u0 * u0 + u1 * u1 + u2 * u2);
  if (!(speed > 0) || !(speed <= std::numeric_limits<double>::max())) return z;
  const double scale = -1.0 / speed;
  return {u0 * scale, u1 * scale, u2 * scale, speed};
}

inline bool StepEquations::LinearisedCouplingGuess(Eigen::Vector4d* z) const {
  const Eigen::Vector4d at((*z)(0), (*z)(1), (*z)(2), 0.0);
  Eigen::Vector4d f;
  Shared shared;
  Residual(at, &f, &shared);  // with s = 0: f_1..3 = u(tau0)
  Eigen::Matrix3d A;
  JacobianBlock(at, shared, &A);  // du/dtau at tau0 (s = 0 on the diagonal)
  const double t0 = at(0), t1 = at(1), t2 = at(2);
  const double r0 = A(0, 0) * t0 + A(0, 1) * t1 + A(0, 2) * t2 - f(0);
  const double r1 = A(1, 0) * t0 + A(1, 1) * t1 + A(1, 2) * t2 - f(1);
  const double r2 = A(2, 0) * t0 + A(2, 1) * t1 + A(2, 2) * t2 - f(2);
  return SecularGuess(A, r0, r1, r2, (*z)(3), z);
}

inline bool StepEquations::LinearisedCouplingGuessAtRest(double s, Eigen::Vector4d* z) const {
  if (!reciprocals_) {
    *z << 0.0, 0.0, 0.0, s;
    return LinearisedCouplingGuess(z);
  }
  // Residual at tau = 0, s = 0 (p = 0): exactly these doubles; and r = -u(0).
  const double w = t_.k(2) * inv_I_, q0 = t_.pty * inv_pn_, q1 = -t_.ptx * inv_pn_;
  Eigen::Matrix3d A;
  JacobianBlock(Eigen::Vector4d::Zero(), Shared{w, q0, q1}, &A);
  return SecularGuess(A, -(t_.k(0) * inv_m_ - w * q1), -(t_.b * (t_.k(1) * inv_m_ + w * q0)),
                      -(t_.c * w), s, z);
}

inline bool StepEquations::SecularGuess(const Eigen::Matrix3d& A, double r0, double r1, double r2,
                                        double s, Eigen::Vector4d* z) const {
  // adj(A + s I) = s^2 I + s (tr(A) I - A) + adj(A); det(A + s I) = s^3 + tr s^2 + m2 s + det.
  const Eigen::Matrix3d adj = Adjugate3(A);
  const double tr = A(0, 0) + A(1, 1) + A(2, 2);
  const double m2 = adj(0, 0) + adj(1, 1) + adj(2, 2);
  const double det = Determinant3(A, adj);
  // N(s) = adj(A + s I) r = s^2 r + s n1 + n0.
  const double n10 = tr * r0 - (A(0, 0) * r0 + A(0, 1) * r1 + A(0, 2) * r2);
  const double n11 = tr * r1 - (A(1, 0) * r0 + A(1, 1) * r1 + A(1, 2) * r2);
  const double n12 = tr * r2 - (A(2, 0) * r0 + A(2, 1) * r1 + A(2, 2) * r2);
  const double n00 = adj(0, 0) * r0 + adj(0, 1) * r1 + adj(0, 2) * r2;
  const double n01 = adj(1, 0) * r0 + adj(1, 1) * r1 + adj(1, 2) * r2;
  const double n02 = adj(2, 0) * r0 + adj(2, 1) * r1 + adj(2, 2) * r2;
  {
    // Newton on psi(s) = D / |N| - 1: psi / psi' = (D - |N|) |N|^2 / (D' |N|^2 - D N . N').
    const double N0 = (s * r0 + n10) * s + n00, N1 = (s * r1 + n11) * s + n01,
                 N2 = (s * r2 + n12) * s + n02;
    const double dN0 = 2.0 * s * r0 + n10, dN1 = 2.0 * s * r1 + n11, dN2 = 2.0 * s * r2 + n12;
    const double D = ((s + tr) * s + m2) * s + det, dD = (3.0 * s + 2.0 * tr) * s + m2;
    const double NN = N0 * N0 + N1 * N1 + N2 * N2;
    const double den = dD * NN - D * (N0 * dN0 + N1 * dN1 + N2 * dN2);
    if (den != 0.0) {
      // NN / den beside the square root, not after it (issue 19's fifth round: the two
      // guesses' longest links).
      const double next = s - (D - std::sqrt(NN)) * (NN / den);
      if (next > 0 && next <= std::numeric_limits<double>::max()) s = next;
    }
  }
  const double N0 = (s * r0 + n10) * s + n00, N1 = (s * r1 + n11) * s + n01,
               N2 = (s * r2 + n12) * s + n02;
  const double D = ((s + tr) * s + m2) * s + det;
  // tau = N / D: |tau| = 1 to second order in the scalar step (Newton's sphere row takes
  // the rest; a normalisation costs a square root and a division in series).
  if (!(s > 0) || !(D != 0.0) || !std::isfinite(D)) return false;
  const double scale = 1.0 / D;
  *z << N0 * scale, N1 * scale, N2 * scale, s;
  return true;
}

inline void StepEquations::EndVelocityAndOffset(const Eigen::Vector4d& z, Eigen::Vector3d* nu,
                                                Eigen::Vector2d* offset) const {
  if (!reciprocals_) {
    const Eigen::Vector3d p = Impulses(z);
    *nu = EndVelocity(p);
    *offset = EcpOffset(p);
    return;
  }
  const double p0 = P_ * z(0), p1 = pw_[1] * z(1), p2 = pw_[2] * z(2);
  *nu << (t_.k(0) + p0) * inv_m_, (t_.k(1) + p1) * inv_m_,
      (t_.k(2) + p2 + (p0 * t_.ptx + p1 * t_.pty) * inv_pn_) * inv_I_;
  *offset << (t_.pty - t_.qz * p0) * inv_pn_, (-t_.ptx - t_.qz * p1) * inv_pn_;
}

inline void StepEquations::JacobianBlock(const Eigen::Vector4d& z, Eigen::Matrix3d* block) const {
  // u = diag(1, b, c) v(p), p = P diag(1, b, c) tau: du/dtau = diag(1, b, c) dv/dp P diag(1,
  // b, c), with dv/dp as in EcpVelocity.
  const double p0 = P_ * z(0), p1 = pw_[1] * z(1), p2 = pw_[2] * z(2);
  const double w = (t_.k(2) + p2 + (p0 * t_.ptx + p1 * t_.pty) / t_.pn) / t_.I;
  const double r0 = (t_.pty - t_.qz * p0) / t_.pn, r1 = (-t_.ptx - t_.qz * p1) / t_.pn;
  JacobianBlock(z, Shared{w, r0, r1}, block);
}

inline void StepEquations::JacobianBlock(const Eigen::Vector4d& z, const Shared& shared,
                                         Eigen::Matrix3d* block) const {
  const double w = shared.w, r0 = shared.r0, r1 = shared.r1;
  const double wdr = w * dr_;
  const double d00 = inv_m_ - r1 * dw_[0], d01 = -r1 * dw_[1] - wdr, d02 = -r1 * dw_[2];
  const double d10 = r0 * dw_[0] + wdr, d11 = inv_m_ + r0 * dw_[1], d12 = r0 * dw_[2];
  const double bb = t_.b, cc = t_.c;
  Eigen::Matrix3d& A = *block;
  A(0, 0) = pw_[0] * d00 + z(3);
  A(0, 1) = pw_[0] * d01 * bb;
  A(0, 2) = pw_[0] * d02 * cc;
  A(1, 0) = pw_[1] * d10;
  A(1, 1) = pw_[1] * d11 * bb + z(3);
  A(1, 2) = pw_[1] * d12 * cc;
  A(2, 0) = pw_[2] * dw_[0];
  A(2, 1) = pw_[2] * dw_[1] * bb;
  A(2, 2) = pw_[2] * dw_[2] * cc + z(3);
}

inline double StepEquations::RelativeResidual(const Eigen::Vector4d& z,
                                              const Eigen::Vector4d& f) const {
  const double scale = velocity_scale_ + std::abs(z(3));
  const double motion =
      scale > 0 ? std::max(std::max(std::abs(f(0)), std::abs(f(1))), std::abs(f(2))) / scale : 0.0;
  const double sphere = velocity_scale_ > 0 ? 2.0 * std::abs(f(3)) / velocity_scale_ : 0.0;
  return std::max(motion, sphere);
}

}  // namespace slideid
