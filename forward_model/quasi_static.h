#pragma once
// Quasi-static pushing in closed form (paper, equations quasi_1..3; Lynch et al. 1992 with
// the origin at the CM): inertia neglected, ECP under the CM, isotropic friction (b = 1),
// and the pusher's contact point moving with the slider (no slip at the pusher).

#include <Eigen/Core>

namespace slideid {

/// Slider twist (v_x, v_y, w_z) [m/s, m/s, rad/s] for a contact point at
/// `contact_from_cm` (x_c - q_x, y_c - q_y) [m] moving at `contact_velocity` [m/s], with
/// c = e_r / e_t [m] > 0.
Eigen::Vector3d QuasiStaticTwist(const Eigen::Vector2d& contact_from_cm,
                                 const Eigen::Vector2d& contact_velocity, double c_m);

}  // namespace slideid
