#pragma once
// Planar state of the slider and the wrench applied to it.

#include <cmath>

namespace slideid {

/// Pose of the CM projected on the plane and its twist (world frame, SI units).
struct PlanarState {
  double x = 0.0, y = 0.0;    ///< CM position [m]
  double theta = 0.0;         ///< yaw [rad], unwrapped
  double vx = 0.0, vy = 0.0;  ///< CM velocity [m/s]
  double wz = 0.0;            ///< spin [rad/s]
};

/// Applied force (world axes) and moment about the CM, held over a step.
/// fz is positive up and reduces the normal force; tx, ty are the tilting moments.
struct AppliedWrench {
  double fx = 0.0, fy = 0.0, fz = 0.0;  ///< [N]
  double tx = 0.0, ty = 0.0, tz = 0.0;  ///< [N m] about the CM

  bool IsZero() const {
    return fx == 0.0 && fy == 0.0 && fz == 0.0 && tx == 0.0 && ty == 0.0 && tz == 0.0;
  }
};

/// Moment about the CM of force f applied at r (from the CM, world axes): r x f.
inline AppliedWrench WrenchFromForceAt(double fx, double fy, double fz, double rx, double ry,
                                       double rz) {
  return {fx, fy, fz, ry * fz - rz * fy, rz * fx - rx * fz, rx * fy - ry * fx};
}

}  // namespace slideid
