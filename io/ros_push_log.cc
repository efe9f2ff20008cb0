#include "io/ros_push_log.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "forward_model/number_format.h"

namespace slideid {

bool RosTopics::IsValid(std::string* why) const {
  const std::pair<const std::string*, const char*> required[] = {{&object_topic, "--object-topic"},
                                                                 {&tip_topic, "--tip-topic"},
                                                                 {&force_topic, "--force-topic"}};
  for (const auto& [topic, option] : required) {
    if (topic->empty()) {
      if (why) *why = std::string(option) + " is required (the topic that holds that stream)";
      return false;
    }
  }
  return true;
}

RosMessageType ParseRosMessageType(const std::string& name) {
  // ROS 2 spells "pkg/msg/Type"; ROS 1 "pkg/Type".
  std::string n = name;
  const std::size_t msg = n.find("/msg/");
  if (msg != std::string::npos) n.erase(msg, 4);
  if (n == "geometry_msgs/PoseStamped") return RosMessageType::kPoseStamped;
  if (n == "geometry_msgs/TransformStamped") return RosMessageType::kTransformStamped;
  if (n == "tf2_msgs/TFMessage") return RosMessageType::kTfMessage;
  if (n == "geometry_msgs/WrenchStamped") return RosMessageType::kWrenchStamped;
  return RosMessageType::kOther;
}

const char* ToString(RosMessageType type) {
  switch (type) {
    case RosMessageType::kPoseStamped:
      return "geometry_msgs/PoseStamped";
    case RosMessageType::kTransformStamped:
      return "geometry_msgs/TransformStamped";
    case RosMessageType::kTfMessage:
      return "tf2_msgs/TFMessage";
    case RosMessageType::kWrenchStamped:
      return "geometry_msgs/WrenchStamped";
    case RosMessageType::kOther:
      break;
  }
  return "another type";
}

RosStamp StampOfSeconds(double t_s) {
  RosStamp s;
  s.sec = static_cast<std::int64_t>(std::floor(t_s));
  // t_s - sec is exact (a double minus its integer part); rounding to 1 ns keeps the
  // nearest double of sec + nsec 1e-9 equal to t_s while its spacing is above 2 ns.
  double nsec = std::round((t_s - static_cast<double>(s.sec)) * 1e9);
  if (nsec >= 1e9) {
    ++s.sec;
    nsec -= 1e9;
  }
  s.nsec = static_cast<std::uint32_t>(nsec);
  return s;
}

double QuaternionYaw(double qx, double qy, double qz, double qw) {
  return std::atan2(2.0 * (qw * qz + qx * qy), qw * qw + qx * qx - qy * qy - qz * qz);
}

RosStreamCollector::RosStreamCollector(std::string source, RosTopics topics)
    : source_(std::move(source)), topics_(std::move(topics)) {
  object_ = {"object", topics_.object_topic, topics_.object_frame, "--object-frame",
             &log_.recording.object_pose};
  tip_ = {"tip", topics_.tip_topic, topics_.tip_frame, "--tip-frame", &log_.recording.tip_pose};
  force_ = {"force", topics_.force_topic, "", "", &log_.recording.ft_wrench};
}

bool RosStreamCollector::Wanted(const std::string& topic) const {
  return topic == object_.topic || topic == tip_.topic || topic == force_.topic;
}

void RosStreamCollector::Add(Stream* s, const RosStamp& stamp, double receive_s, double a, double b,
                             double c) {
  ++s->messages;
  double t = stamp.Seconds();
  if (stamp.IsZero()) {  // never stamped by its publisher: the recorder's clock
    ++s->zero_stamps;
    t = receive_s;
  }
  if (!std::isfinite(t) || !std::isfinite(a) || !std::isfinite(b) || !std::isfinite(c)) {
    throw RosLogError(source_ + ": topic '" + s->topic + "', message " +
                      std::to_string(s->messages) + " of the " + s->name +
                      " stream: a value is not finite");
  }
  s->rows->push_back({t, a, b, c});
}

void RosStreamCollector::AddPose(const std::string& topic, const RosPose& pose, double receive_s) {
  for (Stream* s : {&object_, &tip_}) {
    if (topic != s->topic) continue;
    if (!s->frame.empty() && pose.child_frame_id != s->frame) continue;
    const double norm2 =
        pose.qx * pose.qx + pose.qy * pose.qy + pose.qz * pose.qz + pose.qw * pose.qw;
    if (!(norm2 > 0.0)) {
      throw RosLogError(source_ + ": topic '" + topic + "', message " +
                        std::to_string(s->messages + 1) + " of the " + s->name +
                        " stream: the orientation quaternion is zero or not finite");
    }
    Add(s, pose.stamp, receive_s, pose.x, pose.y,
        QuaternionYaw(pose.qx, pose.qy, pose.qz, pose.qw));
  }
}

void RosStreamCollector::AddWrench(const std::string& topic, const RosWrench& w, double receive_s) {
  if (topic == force_.topic) Add(&force_, w.stamp, receive_s, w.fx, w.fy, w.tz);
}

RosPushLog RosStreamCollector::Finish(const std::map<std::string, std::string>& topic_types) {
  for (Stream* s : {&object_, &tip_, &force_}) {
    const auto it = topic_types.find(s->topic);
    if (it == topic_types.end()) {
      std::string present;
      for (const auto& [topic, type] : topic_types)
        present += (present.empty() ? "" : ", ") + topic + " (" + type + ")";
      throw RosLogError(source_ + ": topic '" + s->topic + "' (the " + s->name +
                        " stream) is not in the file; its topics: " +
                        (present.empty() ? std::string("none") : present));
    }
    const RosMessageType type = ParseRosMessageType(it->second);
    const bool is_force = s == &force_;
    const bool fits = is_force ? type == RosMessageType::kWrenchStamped
                               : (type == RosMessageType::kPoseStamped ||
                                  type == RosMessageType::kTransformStamped ||
                                  type == RosMessageType::kTfMessage);
    if (!fits) {
      throw RosLogError(source_ + ": topic '" + s->topic + "' (the " + s->name + " stream) holds " +
                        it->second + ", not " +
                        (is_force ? "geometry_msgs/WrenchStamped"
                                  : "geometry_msgs/PoseStamped, TransformStamped or "
                                    "tf2_msgs/TFMessage"));
    }
    if (type == RosMessageType::kTfMessage && s->frame.empty()) {
      throw RosLogError(source_ + ": topic '" + s->topic + "' (the " + s->name +
                        " stream) holds tf2_msgs/TFMessage: give " + s->option +
                        " to choose its transform by child frame id");
    }
  }
  for (Stream* s : {&object_, &tip_, &force_}) {
    if (s->rows->empty()) {
      throw RosLogError(source_ + ": topic '" + s->topic + "' (the " + s->name + " stream) has " +
                        (s->frame.empty() ? std::string("no message")
                                          : "no transform with child frame '" + s->frame + "'"));
    }
    if (s->zero_stamps > 0) {
      log_.notes.push_back(
          Printf("%s topic %s: %d of %d messages have a zero header stamp; their "
                 "receive time is used",
                 s->name, s->topic.c_str(), s->zero_stamps, s->messages));
    }
  }
  return std::move(log_);
}

namespace {

struct Span {
  const char* name;
  const std::string* topic;
  double first = 0, last = 0;
};

Span SpanOf(const char* name, const std::string* topic, const std::vector<MitStreamRow>& rows) {
  Span s{name, topic};
  s.first = s.last = rows.front()[0];
  for (const MitStreamRow& r : rows) {
    s.first = std::min(s.first, r[0]);
    s.last = std::max(s.last, r[0]);
  }
  return s;
}

}  // namespace

std::string StreamOverlapProblem(const MitPushRecording& rec, const RosTopics& topics) {
  const Span spans[] = {SpanOf("object", &topics.object_topic, rec.object_pose),
                        SpanOf("tip", &topics.tip_topic, rec.tip_pose),
                        SpanOf("force", &topics.force_topic, rec.ft_wrench)};
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      const Span &p = spans[i], &q = spans[j];
      if (p.last < q.first || q.last < p.first) {
        return Printf(
            "the clocks never overlap: the %s topic %s spans %.3f to %.3f s and the %s topic %s "
            "%.3f to %.3f s (stamped by different clocks?)",
            p.name, p.topic->c_str(), p.first, p.last, q.name, q.topic->c_str(), q.first, q.last);
      }
    }
  }
  return "";
}

namespace {

RosStamp StampOf(double t_s, int index, int zero_every) {
  if (zero_every > 0 && index % zero_every == zero_every - 1) return RosStamp{};
  return StampOfSeconds(t_s);
}

/// Receive times of a stream: its stamps plus the delay, kept in row order (1 us apart at
/// least); a zero-stamped message is received exactly at its row's time.
std::vector<double> ReceiveTimes(const std::vector<MitStreamRow>& rows,
                                 const RosPushWriteSpec& spec) {
  std::vector<double> out;
  double last = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const bool zero = StampOf(rows[i][0], static_cast<int>(i), spec.zero_stamp_every).IsZero();
    const double t = zero ? rows[i][0] : std::max(rows[i][0] + spec.receive_delay_s, last + 1e-6);
    out.push_back(t);
    last = std::max(last, t);
  }
  return out;
}

}  // namespace

std::vector<RosMessageEvent> RosMessagesOf(const MitPushRecording& rec,
                                           const RosPushWriteSpec& spec) {
  std::vector<RosMessageEvent> events;
  auto poses = [&](const std::vector<MitStreamRow>& rows, const std::string& topic,
                   RosMessageType type, const std::string& frame, const char* name) {
    if (type != RosMessageType::kPoseStamped && type != RosMessageType::kTransformStamped &&
        type != RosMessageType::kTfMessage) {
      throw std::invalid_argument(std::string("the ") + name + " stream cannot be written as " +
                                  ToString(type));
    }
    const std::vector<double> receive = ReceiveTimes(rows, spec);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      RosMessageEvent e;
      e.topic = &topic;
      e.type = type;
      e.receive_s = receive[i];
      RosPose p;
      p.stamp = StampOf(rows[i][0], static_cast<int>(i), spec.zero_stamp_every);
      p.frame_id = "world";
      if (type != RosMessageType::kPoseStamped) p.child_frame_id = frame.empty() ? name : frame;
      p.x = rows[i][1];
      p.y = rows[i][2];
      p.qz = std::sin(0.5 * rows[i][3]);
      p.qw = std::cos(0.5 * rows[i][3]);
      if (type == RosMessageType::kTfMessage && spec.other_transform) {
        RosPose other = p;
        other.child_frame_id = "camera";
        other.x += 1.0;
        e.poses.push_back(other);
      }
      e.poses.push_back(p);
      events.push_back(std::move(e));
    }
  };
  poses(rec.object_pose, spec.topics.object_topic, spec.object_type, spec.topics.object_frame,
        "object");
  poses(rec.tip_pose, spec.topics.tip_topic, spec.tip_type, spec.topics.tip_frame, "tip");
  const std::vector<double> receive = ReceiveTimes(rec.ft_wrench, spec);
  for (std::size_t i = 0; i < rec.ft_wrench.size(); ++i) {
    RosMessageEvent e;
    e.topic = &spec.topics.force_topic;
    e.type = RosMessageType::kWrenchStamped;
    e.receive_s = receive[i];
    e.wrench.stamp = StampOf(rec.ft_wrench[i][0], static_cast<int>(i), spec.zero_stamp_every);
    e.wrench.frame_id = "ft_sensor";
    e.wrench.fx = rec.ft_wrench[i][1];
    e.wrench.fy = rec.ft_wrench[i][2];
    e.wrench.tz = rec.ft_wrench[i][3];
    events.push_back(std::move(e));
  }
  std::stable_sort(
      events.begin(), events.end(),
      [](const RosMessageEvent& a, const RosMessageEvent& b) { return a.receive_s < b.receive_s; });
  return events;
}

}  // namespace slideid
