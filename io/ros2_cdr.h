#pragma once
// ROS 2 messages in CDR (OMG XCDR version 1, the encoding of rmw's Fast DDS and Cyclone
// DDS, and of the `cdr` message encoding of MCAP's ros2 profile), for just the message
// types the ROS log import reads: geometry_msgs/msg/PoseStamped, TransformStamped,
// WrenchStamped and tf2_msgs/msg/TFMessage. A message starts with a 4-byte encapsulation
// header (0x00 0x00: big endian, 0x00 0x01: little endian, then two option bytes); every
// primitive is aligned to its size counted from the end of that header; a string is a
// uint32 length (its bytes and a NUL) and the bytes; a sequence a uint32 count and the
// elements. Decoding checks every length against the bytes left, so a bad message throws
// CdrError with the byte offset, never reads past the end.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "io/ros_push_log.h"

namespace slideid {

/// A malformed CDR message: "byte N: what" (N from the start of the message).
class CdrError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// geometry_msgs/msg/PoseStamped (child_frame_id left empty).
RosPose DecodeCdrPoseStamped(std::string_view message);
/// geometry_msgs/msg/TransformStamped.
RosPose DecodeCdrTransformStamped(std::string_view message);
/// tf2_msgs/msg/TFMessage: its transforms.
std::vector<RosPose> DecodeCdrTfMessage(std::string_view message);
/// geometry_msgs/msg/WrenchStamped.
RosWrench DecodeCdrWrenchStamped(std::string_view message);

/// The encodings of the same types (what the test writer stores), little or big endian.
std::string EncodeCdrPoseStamped(const RosPose& pose, bool little_endian = true);
std::string EncodeCdrTransformStamped(const RosPose& pose, bool little_endian = true);
std::string EncodeCdrTfMessage(const std::vector<RosPose>& transforms, bool little_endian = true);
std::string EncodeCdrWrenchStamped(const RosWrench& wrench, bool little_endian = true);

/// The ros2msg schema text of each type (the MCAP Schema record's data), as `ros2 bag
/// record` writes it: the type's fields, then each nested type's after a separator line.
std::string Ros2MsgSchema(RosMessageType type);

}  // namespace slideid
