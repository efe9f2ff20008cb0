#pragma once
// The slider's known mechanical properties and its friction parameters.

namespace slideid {

/// Rigid slider on a horizontal plane (SI units). Invariant: mass, inertia, gravity > 0,
/// com_height >= 0.
struct SliderProperties {
  double mass_kg = 1.0;        ///< m [kg]
  double inertia_kgm2 = 1.0;   ///< I_z about the vertical axis through the CM [kg m^2]
  double com_height_m = 0.0;   ///< q_z, CM height above the support plane [m]
  double gravity_mps2 = 9.81;  ///< g [m/s^2]
};

/// The paper's friction ellipsoid: mu and the constants e_t, e_o (dimensionless), e_r [m].
struct FrictionParameters {
  double mu = 0.3;
  double e_t = 1.0;
  double e_o = 1.0;
  double e_r = 0.01;  ///< [m]
};

/// The identifiable combinations (model.md, "Only three parameters matter"):
/// a = e_t mu, b = e_o / e_t, c = e_r / e_t [m]. Invariant: all > 0.
struct ReducedFriction {
  double a = 0.3;
  double b = 1.0;
  double c = 0.01;  ///< [m]

  static ReducedFriction From(const FrictionParameters& f) {
    return {f.e_t * f.mu, f.e_o / f.e_t, f.e_r / f.e_t};
  }
  /// The friction parameters with e_t = 1 that give the same motion.
  FrictionParameters ToFrictionParameters() const { return {a, 1.0, b, c}; }

  /// a, b, c by index 0, 1, 2 (estimator's ParameterIndex), for what is done to each of the
  /// three alike (search bounds, intervals, verdicts); named fields everywhere else.
  constexpr double operator[](int i) const { return i == 0 ? a : i == 1 ? b : c; }
  constexpr double& operator[](int i) { return i == 0 ? a : i == 1 ? b : c; }

  friend bool operator==(const ReducedFriction& x, const ReducedFriction& y) {
    return x.a == y.a && x.b == y.b && x.c == y.c;
  }
  friend bool operator!=(const ReducedFriction& x, const ReducedFriction& y) { return !(x == y); }
};

}  // namespace slideid
