#pragma once
// Quasi-static observations: the wrench applied to a slider and the slider's twist, each
// averaged over one slow push, and a set of such pairs with the slider's known properties.
//
// In steady slow sliding, inertia is negligible: the friction wrench balances the applied
// one, lies on the ellipsoidal limit surface, and the twist is along the surface's normal
// (model.md, "Only three parameters matter", with the ECP under the CM and no tilting
// moments). For an applied wrench w = (f_x, f_y, m_z), normal force N and twist
// xi = (v_x, v_y, w_z), with the reduced parameters a, b, c:
//
//     w = a N (v_x, b^2 v_y, c^2 w_z) / sqrt(v_x^2 + b^2 v_y^2 + c^2 w_z^2)
//     (f_x / (a N))^2 + (f_y / (a b N))^2 + (m_z / (a c N))^2 = 1
//     xi is parallel to (f_x, f_y / b^2, m_z / c^2).
//
// The anisotropy axes (t, o) of b are the axes of the frame the pairs are written in. The
// paper's contact frame is parallel to the world frame; pairs written in the object frame
// (as the tripod importer writes them) make b an anisotropy along the object's axes.
// Moments are about the CM and velocities are those of the CM: a writer whose pairs refer
// to another point must move them with AboutPoint.

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "forward_model/slider.h"

namespace slideid {

/// One push's mean applied wrench and the slider's twist, in one planar frame whose origin
/// is the CM (moments about it, velocities of it).
struct WrenchTwistPair {
  double fx = 0.0, fy = 0.0;  ///< applied force on the slider [N], frame axes
  double fz = 0.0;            ///< vertical applied force [N], up; the normal force is m g - fz
  double mz = 0.0;            ///< applied moment about the CM [N m]
  double vx = 0.0, vy = 0.0;  ///< velocity of the CM [m/s], frame axes
  double wz = 0.0;            ///< spin [rad/s]

  Eigen::Vector3d Wrench() const { return {fx, fy, mz}; }  ///< (f_x, f_y, m_z) [N, N, N m]
  Eigen::Vector3d Twist() const { return {vx, vy, wz}; }   ///< (v_x, v_y, w_z) [m/s, m/s, rad/s]
};

/// The same pair seen from a frame whose axes are turned by `angle_rad` counter-clockwise
/// from the pair's frame (same origin): force and velocity are rotated by -angle_rad;
/// fz, mz and wz are unchanged.
WrenchTwistPair InRotatedFrame(const WrenchTwistPair& pair, double angle_rad);

/// The pair referred to `point` [m] (in the pair's frame, from its current reference point)
/// instead: the moment about `point`, m' = m_z - (p x f), and the velocity of the body point
/// at `point`, v' = v + w_z x p. Use it to bring pairs about another point to the CM.
WrenchTwistPair AboutPoint(const WrenchTwistPair& pair, const Eigen::Vector2d& point);

/// The applied wrench (f_x, f_y, m_z) [N, N, N m] that keeps the slider sliding at `twist`
/// quasi-statically: a N (v_x, b^2 v_y, c^2 w_z) / sqrt(v_x^2 + b^2 v_y^2 + c^2 w_z^2).
/// Throws std::invalid_argument for a zero or non-finite twist, non-positive N or friction.
Eigen::Vector3d QuasiStaticWrench(const Eigen::Vector3d& twist, const ReducedFriction& friction,
                                  double normal_force_n);

/// The twist direction that an applied wrench on the limit surface drives:
/// (f_x, f_y / b^2, m_z / c^2), not normalised [units of force, force, force/length].
Eigen::Vector3d LimitSurfaceNormal(const Eigen::Vector3d& wrench, const ReducedFriction& friction);

/// The constant body twist, per unit time, that carries a pose to the pose displaced by
/// `d` [m] (in the start pose's frame) and turned by `dtheta` [rad]: the SE(2) logarithm,
/// (v, dtheta) with d = V(dtheta) v. How a pair's twist follows from a push's two poses.
Eigen::Vector3d BodyTwistFromPoseChange(const Eigen::Vector2d& d, double dtheta);

/// The pose change (d_x, d_y in the start frame [m], dtheta [rad]) after time `s` [s] of the
/// constant body twist `twist` (v_x, v_y [m/s], w_z [rad/s]): the SE(2) exponential.
Eigen::Vector3d PoseChangeFromBodyTwist(const Eigen::Vector3d& twist, double s);

/// One pair with what a user needs to judge it. Importers fill what they know; unknown
/// numbers are NaN and an unknown sample count is 0.
struct WrenchTwistRow {
  int push = 0;  ///< the push's number in its source (1-based), 0 when none
  WrenchTwistPair pair;
  double duration_s = std::numeric_limits<double>::quiet_NaN();  ///< averaging window [s]
  /// Pose change over the push: CM displacement in the frame at the push start [m] and
  /// rotation [rad].
  double dx_m = std::numeric_limits<double>::quiet_NaN();
  double dy_m = std::numeric_limits<double>::quiet_NaN();
  double dtheta_rad = std::numeric_limits<double>::quiet_NaN();
  /// Mean contact point of the pusher in the pair's frame (from the CM) [m].
  double contact_x_m = std::numeric_limits<double>::quiet_NaN();
  double contact_y_m = std::numeric_limits<double>::quiet_NaN();
  double peak_force_n = std::numeric_limits<double>::quiet_NaN();  ///< largest |f| used [N]
  int samples = 0;  ///< force samples averaged, 0 when unknown
  int line = 0;     ///< line of the row in the file it was read from, 0 when not read
};

/// Pairs of one slider on one surface, with its known properties.
struct WrenchTwistData {
  double mass_kg = 0.0;                ///< m [kg], > 0
  double gravity_mps2 = 9.81;          ///< g [m/s^2], > 0
  std::optional<double> inertia_kgm2;  ///< I_z about the vertical axis through the CM
  std::optional<double> com_height_m;  ///< CM height above the support plane [m]
  /// How the slider stands: free text, e.g. "point x y; point x y; point x y" [m, frame of
  /// the pairs], empty when unknown.
  std::string supports;
  std::string source;  ///< where the pairs came from (a file, a simulation)
  std::optional<FrictionParameters> true_friction;  ///< synthetic pairs only
  /// Further `# key = value` metadata, in order.
  std::vector<std::pair<std::string, std::string>> extra_metadata;
  std::vector<WrenchTwistRow> rows;

  /// The pairs of all rows, in order.
  std::vector<WrenchTwistPair> Pairs() const;
  /// m g [N].
  double WeightN() const { return mass_kg * gravity_mps2; }
};

}  // namespace slideid
