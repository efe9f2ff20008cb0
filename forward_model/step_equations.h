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

#include "forward_model/planar_state.h"
#include "forward_model/slider.h"

namespace slideid {

class StepEquations {
 public:
  StepEquations(const SliderProperties& slider, const ReducedFriction& friction,
                const PlanarState& state, const AppliedWrench& applied, double dt_s);

  double pn() const { return pn_; }
  /// Friction impulse (p_t, p_o, p_r) that brings the slider to rest in this step.
  Eigen::Vector3d StoppingImpulse() const;
  /// (p_t)^2 + (p_o/b)^2 + (p_r/c)^2 <= (a p_n)^2.
  bool InsideEllipsoid(const Eigen::Vector3d& p) const;

  /// (v_x', v_y', w_z') from Newton-Euler with the coupling term (*).
  Eigen::Vector3d EndVelocity(const Eigen::Vector3d& p) const;
  /// ECP minus CM in the world frame, from the x and y moment balances [m].
  Eigen::Vector2d EcpOffset(const Eigen::Vector3d& p) const;
  /// (v_t, v_o, v_r) at the end of the step and, if dv_dp is given, d(v)/d(p).
  Eigen::Vector3d EcpVelocity(const Eigen::Vector3d& p, Eigen::Matrix3d* dv_dp) const;

  Eigen::Vector3d Impulses(const Eigen::Vector4d& z) const;
  /// Residual F(z) (last entry scaled by the velocity scale) and its Jacobian dF/dz.
  void Evaluate(const Eigen::Vector4d& z, Eigen::Vector4d* f, Eigen::Matrix4d* jac) const;
  /// max(|F_1..3| / (V + s), | |tau|^2 - 1 |): the solver's convergence measure.
  double RelativeResidual(const Eigen::Vector4d& z, const Eigen::Vector4d& f) const;

  /// No CM height and no tilting moments: the ECP stays under the CM.
  bool IsDecoupled() const { return qz_ == 0.0 && ptx_ == 0.0 && pty_ == 0.0; }
  /// No spin, no spin impulse, no tilting moments: w_z' = 0 solves the step exactly.
  bool IsPureTranslation() const { return k_(2) == 0.0 && ptx_ == 0.0 && pty_ == 0.0; }
  bool IsotropicTranslation() const { return b_ == 1.0; }

  /// Exact solution of the decoupled problem (coupling ignored) by a safeguarded Newton
  /// root of |tau(s)| = 1, monotone in s. Returns false if it did not converge.
  bool SolveDecoupled(Eigen::Vector4d* z, int* iterations) const;
  /// The decoupled solution as a first guess for the general solve (valid even where the
  /// decoupled problem itself would stick).
  Eigen::Vector4d DecoupledGuess() const;
  /// A first guess near the stick boundary: the direction of the stopping impulse, and the
  /// slip speed each axis alone would have (decoupled closed form), averaged by weight.
  Eigen::Vector4d StoppingGuess() const;
  /// Closed form for pure translation with b = 1 (model.md, erratum 4).
  Eigen::Vector4d PureTranslationClosedForm() const;
  /// The same step with q_z and the tilting impulses scaled by `scale` (continuation).
  StepEquations WithCouplingScaled(double scale) const;

  double velocity_scale() const { return velocity_scale_; }

 private:
  Eigen::Vector4d DecoupledAt(double s) const;
  double m_, I_, qz_, pn_;
  double a_, b_, c_;
  double ptx_, pty_;          // tilting angular impulses h tx, h ty [N m s]
  Eigen::Vector3d k_;         // M nu + applied impulse: momentum before friction
  double P_;                  // a p_n
  double velocity_scale_;     // |k / M| weighted by (1, b, c): free slip speed [m/s]
};

}  // namespace slideid
