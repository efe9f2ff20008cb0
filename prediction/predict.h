#pragma once
// What an identified friction predicts: a logged push replayed from its first state with
// the friction, driven either by the pusher's path (the log's tip_x, tip_y: what a planner
// commands; forward_model/pusher_step.h) or by the logged force (what a sensor read;
// ReplayLog), and how far the prediction lands from the log.
//
// The errors a planner cares about: where the object ends (position [m] and rotation
// [rad]), the same per 100 mm of the pusher's travel, the mean pose errors over the push,
// and when the prediction and the log part (the first row where the error passes a
// threshold, 5 mm or 5 deg by default).

#include <optional>
#include <string>

#include "forward_model/constants.h"
#include "forward_model/pusher_step.h"
#include "forward_model/simulator.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"

namespace slideid {

enum class PredictionDrive {
  kPusher,  ///< the tip follows the log's tip_x, tip_y; the contact force is predicted
  kForce,   ///< the logged force is applied as logged (world frame, at the logged point)
  /// The tip's path through the quasi-static ellipsoid model of the pushing literature
  /// (Lynch, Maekawa and Tanie 1992; Lynch and Mason 1996): no inertia, the slider's twist
  /// along the limit surface's normal at the tip's wrench, the tip sticking inside the
  /// motion cone and sliding on its edge outside it; the ECP under the CM. Only b, c and
  /// mu_p matter: a scales out.
  kQuasiStatic,
};

struct PredictionOptions {
  PredictionDrive drive = PredictionDrive::kPusher;
  /// Simulation steps per log interval (each interval divided evenly; an interval longer
  /// than the median, a gap in the record, gets this many per median interval in it).
  /// 1 to kMaxSubstepsPerInterval (forward_model/simulator.h).
  int substeps = 1;
  /// The prediction and the log part at the first row where the position error passes
  /// this [m] or the rotation error passes part_rotation_rad.
  double part_position_m = 5e-3;
  double part_rotation_rad = 5.0 * kPi / 180.0;
  PusherStepOptions step;  ///< the step solves (the pusher's and, inside, the support's)
  /// Pusher drive: the tip radius is set so that the tip touches the outline, on the
  /// median, in the rows where the log pushes (the logged radius plus the median gap there).
  /// The outline placed at the motion-capture pose and the robot's tip disagree by a
  /// millimetre or two on real logs (the MIT pushes: contact gap -1.3 to +1.1 mm per push),
  /// which would leave the tip pushing air or buried in the edge.
  bool register_tip = true;

  bool IsValid(std::string* why) const;
};

/// How far a prediction lands from the log. Errors compare poses at the log's rows.
struct PredictionErrors {
  double final_position_m = 0;    ///< |predicted - logged| CM position at the last row
  double final_rotation_rad = 0;  ///< |predicted - logged| theta at the last row
  double mean_position_m = 0;     ///< mean over the rows
  double mean_rotation_rad = 0;
  /// The pusher's travel over the log [m] (the tip's path; without it, the push point's,
  /// and without that, the CM's), and the errors per 100 mm of it [m, rad per 0.1 m].
  double travel_m = 0;
  std::string travel_of;  ///< "tip", "push point" or "object"
  double final_position_per_100mm_m = 0, final_rotation_per_100mm_rad = 0;
  /// The logged displacement of the CM, first row to last [m], and the final position error
  /// as a fraction of it (the dataset's repeatability is quoted that way).
  double logged_displacement_m = 0;
  double final_position_fraction = 0;
  /// Time of the first row where an error passes its threshold [s after the first row],
  /// absent when it never does.
  std::optional<double> parting_time_s;
};

struct Prediction {
  Trajectory predicted;       ///< rows at the log's times (up to a failing step)
  PredictionErrors errors;    ///< over the rows predicted
  SimulationSummary summary;  ///< the simulation's status; not ok: the errors cover less
  PredictionDrive drive = PredictionDrive::kPusher;
  double mu_pusher = 0;     ///< used (pusher drive)
  double tip_radius_m = 0;  ///< used (pusher drive): the log's, or registered
};

/// Predicts `log` with `friction` (and `mu_pusher`, the tip-edge friction, for the pusher
/// drive), from ReplayStart (forward_model/simulator.h). Throws std::invalid_argument when
/// the log cannot be driven that way: fewer than 2 rows; the pusher drive without the tip
/// columns, a tip radius, a patch (the outline the tip touches) or mu_pusher; the force
/// drive without forces. Numerical failures are in the summary.
Prediction PredictPush(const Trajectory& log, const ReducedFriction& friction,
                       std::optional<double> mu_pusher, const PredictionOptions& options = {});

/// The tip radius at which the log's tip touches the outline, on the median, in the rows
/// where the log pushes (PredictionOptions::register_tip); the logged radius when no row
/// pushes. The log must have the tip's path, its radius and a patch.
double RegisteredTipRadius(const Trajectory& log);

/// The errors of `predicted` against `log` (rows matched by index; the shorter decides).
PredictionErrors CompareWithLog(const Trajectory& log, const Trajectory& predicted,
                                const PredictionOptions& options);

const char* ToString(PredictionDrive drive);
/// "pusher", "force" or "quasi-static"; false for anything else.
bool ParsePredictionDrive(const std::string& text, PredictionDrive* drive);

}  // namespace slideid
