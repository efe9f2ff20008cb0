#pragma once
// Whether a log's force pushes the object the way the object moves: a pusher does positive
// work at the contact while it pushes a sliding object. A force logged with the wrong sign
// (a sensor's reading of the force on the pusher, the reaction) does negative work in
// nearly every such row, and one logged in the object's own frame (a sensor riding on it)
// instead of world axes does positive work only where the object has not turned much. The
// fits then find nothing or mark everything suspect, without saying why; the reader
// (io/push_log.h) warns, naming which reading of the force would do the work.

#include "forward_model/trajectory.h"

namespace slideid {

/// The rows that push the object while its contact point moves, and in how many the logged
/// force does positive work: as logged, and were it given in the object's frame (rotated
/// by the row's heading into world axes).
struct ForceWork {
  int rows = 0;
  int positive = 0;
  int positive_in_object_frame = 0;
};

/// A row pushes where its horizontal force is at least this fraction of the log's largest.
constexpr double kForceWorkPushFraction = 0.2;
/// And its contact point moves where it travels over the interval at least this many times
/// the poses' noise (estimator/log_diagnostics.h).
constexpr double kForceWorkMovingOverNoise = 10.0;
/// Fewest such rows to judge the force by.
constexpr int kMinForceWorkRows = 20;
/// A force doing positive work in under this share of the rows is not the force on the
/// object in world axes.
constexpr double kForceWorkMinPositiveShare = 0.2;

/// The work the force of each row does over the interval to the next (where the model
/// holds it), at the push point where the log has one, else at the CM. Zero rows for a
/// log without poses or a force channel.
ForceWork MeasureForceWork(const Trajectory& log);

/// The same for the turn: the rows that push well off the CM (a moment about z of at least
/// kForceWorkPushFraction of the pushing rows' largest) while the slider turns (by more than
/// kSpinOverNoise times the heading's noise over the interval), and in how many it turns the
/// moment's way. A push turns the slider its way: under the limit surface the twist follows
/// the wrench's normal, so the spin has the moment's sign. A heading measured clockwise (or
/// a y axis flipped in the poses but not in the push points) turns it the other way in
/// nearly every such row.
struct SpinWork {
  int rows = 0;
  int positive = 0;
};
constexpr double kSpinOverNoise = 3.0;
SpinWork MeasureSpinWork(const Trajectory& log);

/// Both at once, from one reading of the log's noise (what the reader uses).
struct PushWork {
  ForceWork force;
  SpinWork spin;
};
PushWork MeasurePushWork(const Trajectory& log);

}  // namespace slideid
