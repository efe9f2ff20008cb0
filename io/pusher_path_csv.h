#pragma once
// A pusher's path from a CSV file: columns t, x, y (found by name, any order, others
// ignored; '#' comment lines), the tip centre in the world frame [s, m], times strictly
// increasing. What a robot's commanded or recorded tip trajectory exports to; a scene's
// [pusher] path_file reads it (io/scene_file.h).

#include <string>

#include "forward_model/pusher.h"

namespace slideid {

/// Reads the path; throws std::runtime_error naming the file, the line and the column for
/// a missing column, a cell that is not a finite number, or a time not after the previous.
PusherPath ReadPusherPathCsv(const std::string& path);

}  // namespace slideid
