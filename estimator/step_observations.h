#pragma once
// Per-step quantities of a push log that every estimator uses: the measured friction
// impulses and ECP velocities of model.md, "Appendix A (identification), corrected".

#include <Eigen/Core>
#include <vector>

#include "forward_model/planar_state.h"
#include "forward_model/slider.h"
#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// One log interval u -> u+1, as measured.
struct StepObservation {
  int row = 0;                  ///< index u of the starting sample in the log
  double h_s = 0;               ///< t_{u+1} - t_u [s]
  PlanarState start, end;       ///< measured states at u and u+1
  AppliedWrench applied;        ///< held over the step (the row u wrench)
  double pn = 0;                ///< h (m g - f_z) [N s]
  /// (p_t, p_o, p_r) = M (nu' - nu) - applied, with the coupling term (*) [N s, N s, N m s].
  Eigen::Vector3d friction_impulse = Eigen::Vector3d::Zero();
  /// (v_t, v_o, v_r) at the end of the step, at the ECP implied by friction_impulse.
  Eigen::Vector3d ecp_velocity = Eigen::Vector3d::Zero();
  /// The log says this step stuck (mode column), or, without a mode column, the end
  /// velocity is exactly zero.
  bool logged_stick = false;
  /// False for the first step of a poses-only log: the kinematic map gives no velocity at
  /// the first row, so this step's start velocity is unknown.
  bool start_velocity_known = true;
};

/// All steps of a log (rows 0..N-2 start a step). Without the velocity columns, velocities
/// come from the poses by the kinematic map (SetVelocitiesFromPoses). The slider must have mass, inertia,
/// com_height and gravity set.
std::vector<StepObservation> ExtractStepObservations(const Trajectory& log);

/// Whether a step can inform a per-step estimate: it slid and its start velocity is known.
/// When not, records why in `result` ("sticking", "start velocity unknown").
bool InformativeStep(const StepObservation& step, EstimateResult* result);

}  // namespace slideid
