#include "io/rosbag_push.h"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/WrenchStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sys/stat.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <map>

#include "io/internal/child_process.h"

namespace slideid {
namespace {

RosStamp StampOf(const ros::Time& t) { return RosStamp{t.sec, t.nsec}; }
ros::Time RosTimeOf(const RosStamp& s) {
  return ros::Time(static_cast<std::uint32_t>(s.sec), s.nsec);
}
double Seconds(const ros::Time& t) { return StampOf(t).Seconds(); }

RosPose PoseOf(const geometry_msgs::PoseStamped& m) {
  RosPose p;
  p.stamp = StampOf(m.header.stamp);
  p.frame_id = m.header.frame_id;
  p.x = m.pose.position.x;
  p.y = m.pose.position.y;
  p.z = m.pose.position.z;
  p.qx = m.pose.orientation.x;
  p.qy = m.pose.orientation.y;
  p.qz = m.pose.orientation.z;
  p.qw = m.pose.orientation.w;
  return p;
}

RosPose PoseOf(const geometry_msgs::TransformStamped& m) {
  RosPose p;
  p.stamp = StampOf(m.header.stamp);
  p.frame_id = m.header.frame_id;
  p.child_frame_id = m.child_frame_id;
  p.x = m.transform.translation.x;
  p.y = m.transform.translation.y;
  p.z = m.transform.translation.z;
  p.qx = m.transform.rotation.x;
  p.qy = m.transform.rotation.y;
  p.qz = m.transform.rotation.z;
  p.qw = m.transform.rotation.w;
  return p;
}

RosWrench WrenchOf(const geometry_msgs::WrenchStamped& m) {
  RosWrench w;
  w.stamp = StampOf(m.header.stamp);
  w.frame_id = m.header.frame_id;
  w.fx = m.wrench.force.x;
  w.fy = m.wrench.force.y;
  w.fz = m.wrench.force.z;
  w.tx = m.wrench.torque.x;
  w.ty = m.wrench.torque.y;
  w.tz = m.wrench.torque.z;
  return w;
}

/// Instantiates `m` as T; librosbag returns null when the connection's type is another.
template <typename T>
T Instantiate(const rosbag::MessageInstance& m) {
  const boost::shared_ptr<T> message = m.instantiate<T>();
  if (!message) {
    throw std::runtime_error("its connection's type " + m.getDataType() + " (md5 " + m.getMD5Sum() +
                             ") does not decode as " + ros::message_traits::DataType<T>::value());
  }
  return *message;
}

void Collect(const rosbag::MessageInstance& m, RosStreamCollector* collector) {
  const std::string& topic = m.getTopic();
  const double receive_s = Seconds(m.getTime());
  switch (ParseRosMessageType(m.getDataType())) {
    case RosMessageType::kPoseStamped:
      collector->AddPose(topic, PoseOf(Instantiate<geometry_msgs::PoseStamped>(m)), receive_s);
      break;
    case RosMessageType::kTransformStamped:
      collector->AddPose(topic, PoseOf(Instantiate<geometry_msgs::TransformStamped>(m)), receive_s);
      break;
    case RosMessageType::kTfMessage:
      for (const geometry_msgs::TransformStamped& t :
           Instantiate<tf2_msgs::TFMessage>(m).transforms) {
        collector->AddPose(topic, PoseOf(t), receive_s);
      }
      break;
    case RosMessageType::kWrenchStamped:
      collector->AddWrench(topic, WrenchOf(Instantiate<geometry_msgs::WrenchStamped>(m)),
                           receive_s);
      break;
    case RosMessageType::kOther:
      break;  // Finish names the topic and its type
  }
}

RosPushLog ReadInThisProcess(const std::string& path, const RosTopics& topics) {
  RosStreamCollector collector(path, topics);
  std::map<std::string, std::string> topic_types;
  std::map<std::string, int> counts;
  std::string at = "librosbag cannot open it (cut short? an unindexed bag needs `rosbag reindex`)";
  try {
    rosbag::Bag bag;
    bag.open(path, rosbag::bagmode::Read);
    // Only the streams' topics are read; the others are listed for the messages.
    rosbag::View all(bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections())
      topic_types.emplace(c->topic, c->datatype);
    rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{
                               topics.object_topic, topics.tip_topic, topics.force_topic}));
    for (const rosbag::MessageInstance& m : view) {
      const int n = ++counts[m.getTopic()];
      at = "topic '" + m.getTopic() + "', message " + std::to_string(n) + " (" + m.getDataType() +
           ")";
      Collect(m, &collector);
    }
  } catch (const RosLogError&) {
    throw;
  } catch (const std::exception& e) {  // rosbag::BagException, ros::Exception, ...
    throw RosLogError(path + ": " + at + ": " + e.what());
  }
  return collector.Finish(topic_types);
}

// librosbag trusts the offsets of a bag's index: a damaged bag makes it read out of bounds
// (Bag::readHeaderFromBuffer, SIGSEGV) on about 1 in 100 random one-byte changes. So the
// bag is read in a child process, which sends the streams (or its error) back through a
// pipe: a crash or hang inside the library becomes an unreadable file, never a crash of
// import-log. The child only reads and writes to the pipe, and leaves with _exit.

void PutBytes(std::string* out, const void* data, std::size_t n) {
  out->append(static_cast<const char*>(data), n);
}
void PutSize(std::string* out, std::uint64_t n) { PutBytes(out, &n, sizeof(n)); }
void PutText(std::string* out, const std::string& s) {
  PutSize(out, s.size());
  *out += s;
}

/// 'L' and the streams and notes.
std::string Serialize(const RosPushLog& log) {
  std::string out = "L";
  for (const auto* rows :
       {&log.recording.object_pose, &log.recording.tip_pose, &log.recording.ft_wrench}) {
    PutSize(&out, rows->size());
    PutBytes(&out, rows->data(), rows->size() * sizeof(MitStreamRow));
  }
  PutSize(&out, log.notes.size());
  for (const std::string& note : log.notes) PutText(&out, note);
  return out;
}

class Unpacker {
 public:
  explicit Unpacker(const std::string& bytes) : bytes_(bytes) {}
  std::uint64_t Size() {
    std::uint64_t n;
    Take(&n, sizeof(n));
    return n;
  }
  void Take(void* out, std::size_t n) {
    if (n > bytes_.size() - pos_) throw std::runtime_error("short message from the reader");
    std::memcpy(out, bytes_.data() + pos_, n);
    pos_ += n;
  }
  std::string Text() {
    std::string s(Size(), '\0');
    Take(s.data(), s.size());
    return s;
  }

 private:
  const std::string& bytes_;
  std::size_t pos_ = 1;
};

RosPushLog Deserialize(const std::string& bytes) {
  Unpacker in(bytes);
  RosPushLog log;
  for (auto* rows :
       {&log.recording.object_pose, &log.recording.tip_pose, &log.recording.ft_wrench}) {
    const std::uint64_t n = in.Size();
    if (n > bytes.size() / sizeof(MitStreamRow)) throw std::runtime_error("bad row count");
    rows->resize(n);
    in.Take(rows->data(), n * sizeof(MitStreamRow));
  }
  const std::uint64_t notes = in.Size();
  for (std::uint64_t i = 0; i < notes && i < bytes.size(); ++i) log.notes.push_back(in.Text());
  return log;
}

}  // namespace

RosPushLog ReadRosbagPushLog(const std::string& path, const RosTopics& topics) {
  struct stat info;
  if (stat(path.c_str(), &info) != 0) {
    throw RosLogError(path + ": cannot be opened for reading: " + std::strerror(errno));
  }
  if (!S_ISREG(info.st_mode)) throw RosLogError(path + ": not a regular file");
  const std::chrono::milliseconds limit = child_process::TimeLimitFor(info.st_size);
  const child_process::Outcome out = child_process::Run(
      [&] {
        // The errors come back as the answer: console_bridge's own prints of librosbag's
        // complaints ("Received an invalid TCPROS header") would only repeat them on stderr.
        console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
        return Serialize(ReadInThisProcess(path, topics));
      },
      limit);
  switch (out.ending) {
    case child_process::Ending::kAnswered:
      return Deserialize(out.answer);
    case child_process::Ending::kThrew:
      throw RosLogError(out.answer);
    case child_process::Ending::kTimedOut:
      throw RosLogError(path + ": librosbag did not finish reading it in " +
                        std::to_string(limit.count() / 1000) + " s (a damaged bag?)");
    case child_process::Ending::kCrashed:
      throw RosLogError(path + ": librosbag crashed reading it (signal " +
                        std::to_string(out.signal) +
                        "): the bag is damaged (its index points outside its data?)");
    case child_process::Ending::kSilent:
      break;
  }
  throw RosLogError(path + ": the bag reader ended without an answer (exit status " +
                    std::to_string(out.exit_status) + ")");
}

void WriteRosbagPushLog(const MitPushRecording& recording, const RosPushWriteSpec& spec,
                        const std::string& path, RosbagCompression compression) {
  const std::string tmp = path + ".tmp";
  try {
    rosbag::Bag bag(tmp, rosbag::bagmode::Write);
    bag.setCompression(compression == RosbagCompression::kBz2 ? rosbag::compression::BZ2
                       : compression == RosbagCompression::kLz4
                           ? rosbag::compression::LZ4
                           : rosbag::compression::Uncompressed);
    for (const RosMessageEvent& e : RosMessagesOf(recording, spec)) {
      const ros::Time receive = RosTimeOf(StampOfSeconds(e.receive_s));
      auto transform = [](const RosPose& p) {
        geometry_msgs::TransformStamped t;
        t.header.stamp = RosTimeOf(p.stamp);
        t.header.frame_id = p.frame_id;
        t.child_frame_id = p.child_frame_id;
        t.transform.translation.x = p.x;
        t.transform.translation.y = p.y;
        t.transform.translation.z = p.z;
        t.transform.rotation.x = p.qx;
        t.transform.rotation.y = p.qy;
        t.transform.rotation.z = p.qz;
        t.transform.rotation.w = p.qw;
        return t;
      };
      switch (e.type) {
        case RosMessageType::kPoseStamped: {
          const RosPose& p = e.poses.front();
          geometry_msgs::PoseStamped m;
          m.header.stamp = RosTimeOf(p.stamp);
          m.header.frame_id = p.frame_id;
          m.pose.position.x = p.x;
          m.pose.position.y = p.y;
          m.pose.position.z = p.z;
          m.pose.orientation.x = p.qx;
          m.pose.orientation.y = p.qy;
          m.pose.orientation.z = p.qz;
          m.pose.orientation.w = p.qw;
          bag.write(*e.topic, receive, m);
          break;
        }
        case RosMessageType::kTransformStamped:
          bag.write(*e.topic, receive, transform(e.poses.front()));
          break;
        case RosMessageType::kTfMessage: {
          tf2_msgs::TFMessage m;
          for (const RosPose& p : e.poses) m.transforms.push_back(transform(p));
          bag.write(*e.topic, receive, m);
          break;
        }
        case RosMessageType::kWrenchStamped: {
          geometry_msgs::WrenchStamped m;
          m.header.stamp = RosTimeOf(e.wrench.stamp);
          m.header.frame_id = e.wrench.frame_id;
          m.wrench.force.x = e.wrench.fx;
          m.wrench.force.y = e.wrench.fy;
          m.wrench.force.z = e.wrench.fz;
          m.wrench.torque.x = e.wrench.tx;
          m.wrench.torque.y = e.wrench.ty;
          m.wrench.torque.z = e.wrench.tz;
          bag.write(*e.topic, receive, m);
          break;
        }
        case RosMessageType::kOther:
          break;
      }
    }
    bag.close();
  } catch (const std::exception& e) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write '" + path + "': " + e.what());
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename '" + tmp + "' to '" + path + "'");
  }
}

}  // namespace slideid
