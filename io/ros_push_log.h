#pragma once
// What the ROS log readers (io/rosbag_push.h: ROS 1 bags; io/mcap_push.h: ROS 2 MCAP) share:
// which topics hold the three streams of a push, the messages they may carry (poses as
// geometry_msgs PoseStamped, TransformStamped or tf2_msgs TFMessage; the force as
// geometry_msgs WrenchStamped), and how messages become the rows of an MIT push recording
// (io/mit_push_recording.h), which then goes through the same import as the MIT JSON files.
// A row's time is the message's header stamp; a zero stamp (never set by its publisher)
// falls back to the time the recorder received the message, and the report says so. Yaw is
// taken from the orientation quaternion.

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/mit_push_recording.h"

namespace slideid {

/// Which topics hold the streams. A topic of tf2_msgs/TFMessage (or TransformStamped) is
/// filtered by the child frame id of its transforms; a frame is required for a TFMessage.
struct RosTopics {
  std::string object_topic;  ///< the object's pose (the MIT object_pose stream)
  std::string tip_topic;     ///< the pusher tip's pose (tip_pose)
  std::string force_topic;   ///< the force on the sensor, geometry_msgs/WrenchStamped
  std::string object_frame;  ///< child_frame_id of the object's transform (empty: any)
  std::string tip_frame;     ///< child_frame_id of the tip's transform (empty: any)

  /// False (and why, naming the option) when a topic is missing.
  bool IsValid(std::string* why) const;
};

/// A bad ROS log: the message is "file: place: what", the place a topic (and message
/// number), a record offset or a chunk.
class RosLogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The message types the readers decode.
enum class RosMessageType { kPoseStamped, kTransformStamped, kTfMessage, kWrenchStamped, kOther };

/// The type of a ROS 1 ("geometry_msgs/PoseStamped") or ROS 2
/// ("geometry_msgs/msg/PoseStamped") type name.
RosMessageType ParseRosMessageType(const std::string& name);
/// The ROS 1 spelling of a decoded type ("geometry_msgs/PoseStamped").
const char* ToString(RosMessageType type);

/// A header stamp: seconds and nanoseconds (ROS 1 unsigned, ROS 2 signed seconds).
struct RosStamp {
  std::int64_t sec = 0;
  std::uint32_t nsec = 0;
  bool IsZero() const { return sec == 0 && nsec == 0; }
  double Seconds() const { return static_cast<double>(sec) + 1e-9 * nsec; }
};

/// The stamp nearest to `t_s` [s] (what a writer stores for a time).
RosStamp StampOfSeconds(double t_s);

/// A stamped pose or one transform of a TFMessage, as logged.
struct RosPose {
  RosStamp stamp;
  std::string frame_id;
  std::string child_frame_id;  ///< empty for a PoseStamped
  double x = 0, y = 0, z = 0;  ///< position or translation [m]
  double qx = 0, qy = 0, qz = 0, qw = 1;
};

/// A stamped wrench, as logged.
struct RosWrench {
  RosStamp stamp;
  std::string frame_id;
  double fx = 0, fy = 0, fz = 0;  ///< [N]
  double tx = 0, ty = 0, tz = 0;  ///< [N m]
};

/// Yaw [rad, (-pi, pi]] of the rotation (qx, qy, qz, qw): the angle about z of the rotated x
/// axis projected onto the x-y plane (ZYX Euler yaw). The quaternion need not be unit.
double QuaternionYaw(double qx, double qy, double qz, double qw);

/// The streams read from a ROS log, and facts for the import report's notes.
struct RosPushLog {
  MitPushRecording recording;
  std::vector<std::string> notes;
};

/// Collects the messages of one log into streams, in the order given (each stream keeps
/// its own order: the import sorts). Throws RosLogError naming the file, the topic and the
/// message for a non-finite value or a zero quaternion.
class RosStreamCollector {
 public:
  RosStreamCollector(std::string source, RosTopics topics);

  /// Whether `topic` holds a stream (other topics need not be decoded).
  bool Wanted(const std::string& topic) const;

  /// A pose (PoseStamped, TransformStamped, or one transform of a TFMessage) on `topic`,
  /// received (logged) at `receive_s`; kept for each stream whose topic and frame match.
  void AddPose(const std::string& topic, const RosPose& pose, double receive_s);
  /// A wrench on `topic`, received at `receive_s`.
  void AddWrench(const std::string& topic, const RosWrench& wrench, double receive_s);

  /// The streams. `topic_types`: every topic of the file and its type name as the file
  /// spells it. Throws RosLogError naming the topic when a stream's topic is not in the
  /// file, holds a type that cannot give that stream (or a TFMessage without the frame
  /// option that picks from it), or gave no row.
  RosPushLog Finish(const std::map<std::string, std::string>& topic_types);

 private:
  struct Stream;
  void Add(Stream* stream, const RosStamp& stamp, double receive_s, double a, double b, double c);

  std::string source_;
  RosTopics topics_;
  struct Stream {
    const char* name;  ///< "object", "tip", "force"
    std::string topic, frame, option;
    std::vector<MitStreamRow>* rows;
    int messages = 0, zero_stamps = 0;
  };
  RosPushLog log_;
  Stream object_, tip_, force_;
};

/// Why the streams cannot make a push when their time spans never overlap (the topics
/// stamped by different clocks), naming the topics and their spans; empty when each pair
/// overlaps. Every stream must hold at least one row.
std::string StreamOverlapProblem(const MitPushRecording& recording, const RosTopics& topics);

/// How the test writers (io/rosbag_push.h, io/mcap_push.h) store a recording: the tests'
/// synthetic ROS logs, the benchmarks' and the fuzz seeds.
struct RosPushWriteSpec {
  /// The topics; a transform's child frame is the stream's frame, or the stream's name
  /// ("object", "tip") when the frame is empty.
  RosTopics topics;
  RosMessageType object_type = RosMessageType::kPoseStamped;  ///< a pose type
  RosMessageType tip_type = RosMessageType::kPoseStamped;     ///< a pose type
  /// A message is received (logged) this long after its stamp [s], but never before the
  /// previous message of its stream: each stream's order in the file is its row order.
  double receive_delay_s = 2e-3;
  /// Every n-th message of each stream (0: none) has a zero stamp, received exactly at its
  /// row's time: the receive time stands in for the stamp.
  int zero_stamp_every = 0;
  /// Each TFMessage also holds a transform of another child frame ("camera"), which the
  /// reader must pass over.
  bool other_transform = true;
};

/// One message of a recording as a writer stores it.
struct RosMessageEvent {
  const std::string* topic = nullptr;
  RosMessageType type = RosMessageType::kPoseStamped;
  double receive_s = 0;
  std::vector<RosPose> poses;  ///< one, or a TFMessage's transforms
  RosWrench wrench;            ///< kWrenchStamped
};

/// The messages of `recording` in receive order (stable: each stream keeps its own order).
/// Throws std::invalid_argument for a stream type that cannot hold it.
std::vector<RosMessageEvent> RosMessagesOf(const MitPushRecording& recording,
                                           const RosPushWriteSpec& spec);

}  // namespace slideid
