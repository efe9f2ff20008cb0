#pragma once
// The one data type that flows end to end: simulate makes it, the push-log CSV writer and
// reader round-trip it (io/push_log.h; docs/log-format.md), identify reads it. Physics only:
// what a log file says beyond it stays in io/ (PushLogFile).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "forward_model/contact_patch.h"
#include "forward_model/planar_state.h"
#include "forward_model/slider.h"

namespace slideid {

/// Mode column of a log row. `start` marks the first row of a run: the first row, and the
/// first row after a hole in the record (a motion-capture gap), where the step into the row
/// is not modelled and a pose-only log knows no velocity.
enum class SampleMode { kStart, kSlide, kStick };

/// One log row at time t: what a measured log can hold (176 bytes). What only a simulator
/// knows of the step into the row is a StepRecord, kept apart: Trajectory::steps.
struct TrajectorySample {
  double t_s = 0.0;
  PlanarState state;  ///< pose and twist at t (fields absent from a log stay 0)
  /// Total wrench applied over [t, t_next), moments about the CM (world axes), including
  /// r x f of a force applied at push_point_world.
  AppliedWrench applied;
  /// Where (fx, fy, fz) acts, world frame [m], when the log has px, py, pz.
  std::optional<Eigen::Vector3d> push_point_world;
  SampleMode mode = SampleMode::kSlide;  ///< the simulator and the readers set kStart on row 0
  /// The pusher tip's centre at t, world frame [m], when the log has tip_x, tip_y.
  std::optional<Eigen::Vector2d> tip_world;
};

/// The simulated step that ended at a row (zero on the first row): the unknowns the step
/// solved for besides the state, and its ECP. Only simulated logs have it.
struct StepRecord {
  double pt = 0.0, po = 0.0, pr = 0.0;                  ///< friction impulses
  double sigma = 0.0;                                   ///< [m/s]
  Eigen::Vector2d ecp_world = Eigen::Vector2d::Zero();  ///< ax, ay [m]
};

/// Which quantities the samples carry, measured or simulated; the others are left 0 or
/// absent. The fits, the replays and the plots use only what is there. (The push-log reader
/// sets these from a log's columns and the writer writes the columns they name: io/push_log.h.)
struct Measurements {
  bool pose = true;         ///< x, y, theta
  bool velocity = true;     ///< vx, vy, wz
  bool force = true;        ///< fx, fy
  bool fz = false;          ///< fz
  bool moments = false;     ///< tx, ty, tz of their own, beyond r x f of a push point
  bool push_point = false;  ///< where the force acts (push_point_world)
  /// The simulator's step quantities: ECP, impulses, sigma (Trajectory::steps) and each
  /// row's mode.
  bool step_info = true;
  /// Each row's mode alone (a log whose rows are split into runs by gaps).
  bool mode = false;
  bool tip = false;  ///< the pusher's tip centre (tip_world)
};

/// A push log: known slider properties, optional truth, and samples. What a file says beyond
/// the physics (its other metadata, the patch's text) is io's (PushLogFile, io/push_log.h).
struct Trajectory {
  /// Where it came from (a file name), for messages and pooled results; may be empty.
  std::string source;
  SliderProperties slider;
  std::optional<ContactPatch> patch;  ///< the support's contact patch, when known
  /// The pusher tip's radius [m], when the log has the tip's path.
  std::optional<double> tip_radius_m;
  std::optional<FrictionParameters> true_friction;  ///< simulated logs only
  Measurements measured;
  std::vector<TrajectorySample> samples;
  /// steps[u] is the step that ended at samples[u]: one per sample, or empty when the log
  /// holds no step information (a measured log; read as zeros). Kept apart from the samples
  /// so that a measured log does not carry it (48 bytes a row). Read through StepAt.
  std::vector<StepRecord> steps;
};

/// The step that ended at `row`: log.steps[row], or a zero record when the log holds none.
const StepRecord& StepAt(const Trajectory& log, std::size_t row);

/// Keeps the first `rows` rows of `log` (samples and steps), dropping the rest.
void KeepFirstRows(Trajectory* log, std::size_t rows);

/// Whether `row` starts a run: the first row, or a row marked `start` after a gap.
bool StartsRun(const Trajectory& log, std::size_t row);

/// Whether any row after the first starts a run (the log has gaps).
bool HasGaps(const Trajectory& log);

/// The runs of rows between gaps, as (first row, last row), in order; the whole log when
/// it has none. Empty for an empty log.
std::vector<std::pair<int, int>> Runs(const Trajectory& log);

/// The median interval between consecutive rows [s] (the mean of the two middle ones for an
/// even count), gaps before a run's start left out; 0 for a log of fewer than 2 rows.
double MedianInterval(const Trajectory& log);

/// Overwrites every sample's velocity by the backward-Euler kinematic map of the poses,
/// v^{u+1} = (q^{u+1} - q^u) / (t_{u+1} - t_u) (log-format.md); a run's first row's is set to
/// 0 (unknown). What a poses-only log means, wherever it came from.
void SetVelocitiesFromPoses(Trajectory* log);

/// Row `row`'s state with the velocity SetVelocitiesFromPoses would give it (the same
/// arithmetic), without copying the log.
PlanarState StateWithPoseVelocity(const Trajectory& log, std::size_t row);

}  // namespace slideid
