#pragma once
// The content of one MIT push-dataset file (Yu, Bauza, Fazeli, Rodriguez, "More than a
// Million Ways to Be Pushed", IROS 2016): three unsynchronised streams of 4-number rows, as
// stored, in file order. Format and known problems: docs/real-data.md. Plain data and header
// only, so that datasets/ can make synthetic files without linking io/, which reads
// (io/mit_push_json.h) and imports (io/mit_push_import.h) them.

#include <array>
#include <vector>

namespace slideid {

/// One row of a stream: time [s, Unix epoch] and three values (units per stream).
using MitStreamRow = std::array<double, 4>;

/// The three streams of one push, each in file order (unsorted, possibly with repeats).
struct MitPushRecording {
  /// t, x [m], y [m], theta [rad]: the object frame in the robot base frame (Vicon).
  std::vector<MitStreamRow> object_pose;
  /// t, x [m], y [m], yaw [rad]: the centre of the cylindrical pusher tip (robot).
  std::vector<MitStreamRow> tip_pose;
  /// t, fx [N], fy [N], tz [N m]: the force-torque sensor behind the pusher, robot axes.
  std::vector<MitStreamRow> ft_wrench;
};

}  // namespace slideid
