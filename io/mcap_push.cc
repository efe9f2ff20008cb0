#include "io/mcap_push.h"

#include <cmath>

#include "io/ros2_cdr.h"

namespace slideid {
namespace {

/// The type of a channel's messages as the import names it: the schema's name, with the
/// encoding added when it is not CDR with a ros2msg schema (so that it matches no type).
std::string ChannelType(const McapChannel& channel, const McapSchema* schema) {
  std::string type = schema ? schema->name : "no schema";
  if (channel.message_encoding != "cdr" || !schema || schema->encoding != "ros2msg") {
    type += " (message encoding '" + channel.message_encoding + "', schema encoding '" +
            (schema ? schema->encoding : std::string()) + "'; the import reads cdr/ros2msg)";
  }
  return type;
}

/// An MCAP timestamp [ns] as seconds: whole seconds and nanoseconds apart, as a header stamp
/// (1e-9 times 1.5e18 ns would lose a few hundred nanoseconds to rounding).
double SecondsOfNs(std::uint64_t ns) {
  RosStamp s;
  s.sec = static_cast<std::int64_t>(ns / 1000000000u);
  s.nsec = static_cast<std::uint32_t>(ns % 1000000000u);
  return s.Seconds();
}

std::uint64_t NsOfSeconds(double t_s) {
  const RosStamp s = StampOfSeconds(t_s);
  return static_cast<std::uint64_t>(s.sec) * 1000000000u + s.nsec;
}

}  // namespace

RosPushLog ParseMcapPushLog(std::string_view bytes, const std::string& source,
                            const RosTopics& topics) {
  RosStreamCollector collector(source, topics);
  std::map<std::string, std::string> topic_types;
  struct ChannelInfo {
    bool wanted = false;
    RosMessageType type = RosMessageType::kOther;
  };
  std::map<std::uint16_t, ChannelInfo> channel_types;
  const McapContents contents = ReadMcap(
      bytes, source,
      [&](const McapChannel& channel, const McapSchema* schema, const McapMessage& m,
          const McapPlace& place) {
        // What a channel holds is worked out once per channel, not per message.
        auto known = channel_types.find(channel.id);
        if (known == channel_types.end()) {
          ChannelInfo info;
          info.wanted = collector.Wanted(channel.topic);
          const std::string type = ChannelType(channel, schema);
          info.type = ParseRosMessageType(type);
          if (info.wanted) {
            const auto [it, inserted] = topic_types.emplace(channel.topic, type);
            if (!inserted && it->second != type) {
              throw RosLogError(source + ": " + place.ToString() + ": topic '" + channel.topic +
                                "' has messages of two types, " + it->second + " and " + type);
            }
          }
          known = channel_types.emplace(channel.id, info).first;
        }
        if (!known->second.wanted) return;
        const std::string& type = topic_types.at(channel.topic);
        // Header stamps are ROS time; the log time is the recorder's receive time.
        const double receive_s = SecondsOfNs(m.log_time_ns);
        try {
          switch (known->second.type) {
            case RosMessageType::kPoseStamped:
              collector.AddPose(channel.topic, DecodeCdrPoseStamped(m.data), receive_s);
              break;
            case RosMessageType::kTransformStamped:
              collector.AddPose(channel.topic, DecodeCdrTransformStamped(m.data), receive_s);
              break;
            case RosMessageType::kTfMessage:
              for (const RosPose& p : DecodeCdrTfMessage(m.data))
                collector.AddPose(channel.topic, p, receive_s);
              break;
            case RosMessageType::kWrenchStamped:
              collector.AddWrench(channel.topic, DecodeCdrWrenchStamped(m.data), receive_s);
              break;
            case RosMessageType::kOther:
              break;  // Finish names the topic and its type
          }
        } catch (const CdrError& e) {
          throw RosLogError(source + ": " + place.ToString() + ": topic '" + channel.topic + "' (" +
                            type + "): " + e.what());
        }
      });
  // Topics that hold no stream are listed too, for the message naming a missing one.
  for (const auto& [id, channel] : contents.channels) {
    const McapSchema* schema = nullptr;
    if (channel.schema_id != 0) schema = &contents.schemas.at(channel.schema_id);
    topic_types.emplace(channel.topic, ChannelType(channel, schema));
  }
  return collector.Finish(topic_types);
}

RosPushLog ReadMcapPushLog(const std::string& path, const RosTopics& topics) {
  return ParseMcapPushLog(ReadFileBytes(path), path, topics);
}

std::string FormatMcapPushLog(const MitPushRecording& recording, const RosPushWriteSpec& spec,
                              const McapWriterOptions& options) {
  McapWriter writer(options);
  std::map<std::pair<std::string, RosMessageType>, std::uint16_t> channels;
  std::map<RosMessageType, std::uint16_t> schemas;
  auto channel_of = [&](const std::string& topic, RosMessageType type) {
    const auto key = std::make_pair(topic, type);
    auto it = channels.find(key);
    if (it != channels.end()) return it->second;
    if (!schemas.count(type)) {
      std::string name = ToString(type);
      name.insert(name.find('/'), "/msg");
      schemas[type] = writer.AddSchema(name, "ros2msg", Ros2MsgSchema(type));
    }
    const std::uint16_t id =
        writer.AddChannel(schemas[type], topic, "cdr", {{"offered_qos_profiles", ""}});
    channels.emplace(key, id);
    return id;
  };
  std::uint32_t sequence = 0;
  for (const RosMessageEvent& e : RosMessagesOf(recording, spec)) {
    std::string data;
    switch (e.type) {
      case RosMessageType::kPoseStamped:
        data = EncodeCdrPoseStamped(e.poses.front());
        break;
      case RosMessageType::kTransformStamped:
        data = EncodeCdrTransformStamped(e.poses.front());
        break;
      case RosMessageType::kTfMessage:
        data = EncodeCdrTfMessage(e.poses);
        break;
      case RosMessageType::kWrenchStamped:
        data = EncodeCdrWrenchStamped(e.wrench);
        break;
      case RosMessageType::kOther:
        continue;
    }
    McapMessage m;
    m.channel_id = channel_of(*e.topic, e.type);
    m.sequence = sequence++;
    m.log_time_ns = NsOfSeconds(e.receive_s);
    m.publish_time_ns = m.log_time_ns;
    m.data = data;
    writer.AddMessage(m);
  }
  return writer.Finish();
}

void WriteMcapPushLog(const MitPushRecording& recording, const RosPushWriteSpec& spec,
                      const std::string& path, const McapWriterOptions& options) {
  WriteFileBytes(FormatMcapPushLog(recording, spec, options), path);
}

}  // namespace slideid
