#pragma once
// A push recorded as a ROS 2 bag in MCAP (`ros2 bag record -s mcap`): the object's and the
// tip's poses and the force, on topics named by io/ros_push_log.h's RosTopics, CDR-encoded
// (io/ros2_cdr.h) with `ros2msg` schemas identified by name. Read into an MIT push
// recording for the one import pipeline; written by the tests' writer.

#include <string>
#include <string_view>

#include "io/mcap_file.h"
#include "io/ros_push_log.h"

namespace slideid {

/// The streams of the MCAP file at `path`. A row's time is its message's header stamp, or
/// its log time when the stamp is zero (noted). Throws RosLogError or McapError naming the
/// file and the place (topic and message, record offset, chunk).
RosPushLog ReadMcapPushLog(const std::string& path, const RosTopics& topics);
/// Same, from the bytes of a file; `source` names it in messages.
RosPushLog ParseMcapPushLog(std::string_view bytes, const std::string& source,
                            const RosTopics& topics);

/// The bytes of an MCAP file of `recording`, as `spec` says (topics, types, stamps).
std::string FormatMcapPushLog(const MitPushRecording& recording, const RosPushWriteSpec& spec,
                              const McapWriterOptions& options = {});
/// Writes FormatMcapPushLog to `path` through a temporary file and a rename.
void WriteMcapPushLog(const MitPushRecording& recording, const RosPushWriteSpec& spec,
                      const std::string& path, const McapWriterOptions& options = {});

}  // namespace slideid
