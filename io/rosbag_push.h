#pragma once
// A push recorded as a ROS 1 bag (`rosbag record`), read and written with Debian's
// librosbag-storage (rosbag::Bag, rosbag::View) and the message types of
// libgeometry-msgs-dev and libtf2-msgs-dev: the object's and the tip's poses and the force,
// on the topics named by io/ros_push_log.h's RosTopics. Read into an MIT push recording for
// the one import pipeline; written by the tests' writer. The ROS headers stay in the .cc.

#include <string>

#include "io/ros_push_log.h"

namespace slideid {

/// The streams of the bag at `path`. A row's time is its message's header stamp, or its
/// receive time when the stamp is zero (noted). Throws RosLogError naming the file and the
/// place (the topic and message, or what librosbag reports for a damaged file). librosbag
/// reads out of bounds on some damaged bags, so it runs in a child process (fork): its
/// crash, or a hang past a limit that grows with the file's size, is such an error too.
RosPushLog ReadRosbagPushLog(const std::string& path, const RosTopics& topics);

/// Compression of the bag's chunks (rosbag's own: none, bz2 or lz4).
enum class RosbagCompression { kNone, kBz2, kLz4 };

/// Writes a bag of `recording` to `path`, as `spec` says (topics, types, stamps), through
/// a temporary file and a rename. Throws std::runtime_error naming the path.
void WriteRosbagPushLog(const MitPushRecording& recording, const RosPushWriteSpec& spec,
                        const std::string& path,
                        RosbagCompression compression = RosbagCompression::kNone);

}  // namespace slideid
