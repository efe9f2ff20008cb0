#include "io/ros2_cdr.h"

#include <cstring>

namespace slideid {
namespace {

constexpr std::size_t kEncapsulationBytes = 4;

/// Reads primitives from a CDR message, aligned relative to the end of the encapsulation
/// header, in the byte order that header names.
class CdrReader {
 public:
  explicit CdrReader(std::string_view message) : data_(message) {
    if (data_.size() < kEncapsulationBytes) Fail(0, "shorter than the 4-byte encapsulation header");
    if (data_[0] != 0 || (data_[1] != 0 && data_[1] != 1)) {
      Fail(0, "encapsulation " + std::to_string(static_cast<unsigned char>(data_[0])) + "," +
                  std::to_string(static_cast<unsigned char>(data_[1])) +
                  " is not plain CDR (0,0 big endian or 0,1 little endian)");
    }
    little_ = data_[1] == 1;
    pos_ = kEncapsulationBytes;
  }

  template <typename T>
  T Read() {
    Align(sizeof(T));
    Need(sizeof(T), "a number");
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, data_.data() + pos_, sizeof(T));
    if (little_ != HostIsLittle()) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
    }
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }

  std::string ReadString() {
    const std::size_t at = pos_;
    const std::uint32_t length = Read<std::uint32_t>();
    Need(length, "a string of " + std::to_string(length) + " bytes");
    std::string s(data_.substr(pos_, length));
    pos_ += length;
    // The length counts a terminating NUL; some writers store an empty string as 0.
    if (!s.empty()) {
      if (s.back() != '\0') Fail(at, "string not terminated by NUL");
      s.pop_back();
    }
    return s;
  }

  /// A sequence count, checked against the bytes left at `min_element_bytes` each.
  std::uint32_t ReadCount(std::size_t min_element_bytes) {
    const std::size_t at = pos_;
    const std::uint32_t count = Read<std::uint32_t>();
    if (count > (data_.size() - pos_) / min_element_bytes) {
      Fail(at, "sequence of " + std::to_string(count) + " elements runs past the end");
    }
    return count;
  }

  [[noreturn]] void Fail(std::size_t at, const std::string& what) const {
    throw CdrError("byte " + std::to_string(at) + ": " + what);
  }

 private:
  static bool HostIsLittle() {
    const std::uint16_t one = 1;
    unsigned char first;
    std::memcpy(&first, &one, 1);
    return first == 1;
  }
  void Align(std::size_t size) {
    const std::size_t offset = pos_ - kEncapsulationBytes;
    const std::size_t padded = (offset + size - 1) / size * size;
    Need(padded - offset, "alignment padding");
    pos_ = kEncapsulationBytes + padded;
  }
  void Need(std::size_t bytes, const std::string& what) const {
    if (bytes > data_.size() - pos_) {
      Fail(pos_,
           what + " runs past the end of the " + std::to_string(data_.size()) + "-byte message");
    }
  }

  std::string_view data_;
  std::size_t pos_ = 0;
  bool little_ = true;
};

/// Writes primitives in CDR, with the encapsulation header.
class CdrWriter {
 public:
  explicit CdrWriter(bool little_endian) : little_(little_endian) {
    out_ = std::string{'\0', little_endian ? '\1' : '\0', '\0', '\0'};
  }
  template <typename T>
  void Write(T value) {
    const std::size_t offset = out_.size() - kEncapsulationBytes;
    out_.append((sizeof(T) - offset % sizeof(T)) % sizeof(T), '\0');
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    const std::uint16_t one = 1;
    unsigned char first;
    std::memcpy(&first, &one, 1);
    if (little_ != (first == 1)) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
    }
    out_.append(reinterpret_cast<const char*>(bytes), sizeof(T));
  }
  void WriteString(const std::string& s) {
    Write(static_cast<std::uint32_t>(s.size() + 1));
    out_ += s;
    out_ += '\0';
  }
  std::string Take() { return std::move(out_); }

 private:
  bool little_;
  std::string out_;
};

void ReadHeader(CdrReader* in, RosStamp* stamp, std::string* frame_id) {
  stamp->sec = in->Read<std::int32_t>();
  stamp->nsec = in->Read<std::uint32_t>();
  *frame_id = in->ReadString();
}

void ReadPoseFields(CdrReader* in, RosPose* p) {
  p->x = in->Read<double>();
  p->y = in->Read<double>();
  p->z = in->Read<double>();
  p->qx = in->Read<double>();
  p->qy = in->Read<double>();
  p->qz = in->Read<double>();
  p->qw = in->Read<double>();
}

RosPose ReadTransformStamped(CdrReader* in) {
  RosPose p;
  ReadHeader(in, &p.stamp, &p.frame_id);
  p.child_frame_id = in->ReadString();
  ReadPoseFields(in, &p);
  return p;
}

void WriteHeader(CdrWriter* out, const RosStamp& stamp, const std::string& frame_id) {
  out->Write(static_cast<std::int32_t>(stamp.sec));
  out->Write(stamp.nsec);
  out->WriteString(frame_id);
}

void WritePoseFields(CdrWriter* out, const RosPose& p) {
  for (double v : {p.x, p.y, p.z, p.qx, p.qy, p.qz, p.qw}) out->Write(v);
}

void WriteTransformStamped(CdrWriter* out, const RosPose& p) {
  WriteHeader(out, p.stamp, p.frame_id);
  out->WriteString(p.child_frame_id);
  WritePoseFields(out, p);
}

// Smallest encoded TransformStamped: stamp (8), two empty strings (4 + 4), 7 doubles (56).
constexpr std::size_t kMinTransformBytes = 72;

}  // namespace

RosPose DecodeCdrPoseStamped(std::string_view message) {
  CdrReader in(message);
  RosPose p;
  ReadHeader(&in, &p.stamp, &p.frame_id);
  ReadPoseFields(&in, &p);
  return p;
}

RosPose DecodeCdrTransformStamped(std::string_view message) {
  CdrReader in(message);
  return ReadTransformStamped(&in);
}

std::vector<RosPose> DecodeCdrTfMessage(std::string_view message) {
  CdrReader in(message);
  const std::uint32_t count = in.ReadCount(kMinTransformBytes);
  std::vector<RosPose> transforms;
  transforms.reserve(count);
  for (std::uint32_t i = 0; i < count; ++i) transforms.push_back(ReadTransformStamped(&in));
  return transforms;
}

RosWrench DecodeCdrWrenchStamped(std::string_view message) {
  CdrReader in(message);
  RosWrench w;
  ReadHeader(&in, &w.stamp, &w.frame_id);
  w.fx = in.Read<double>();
  w.fy = in.Read<double>();
  w.fz = in.Read<double>();
  w.tx = in.Read<double>();
  w.ty = in.Read<double>();
  w.tz = in.Read<double>();
  return w;
}

std::string EncodeCdrPoseStamped(const RosPose& pose, bool little_endian) {
  CdrWriter out(little_endian);
  WriteHeader(&out, pose.stamp, pose.frame_id);
  WritePoseFields(&out, pose);
  return out.Take();
}

std::string EncodeCdrTransformStamped(const RosPose& pose, bool little_endian) {
  CdrWriter out(little_endian);
  WriteTransformStamped(&out, pose);
  return out.Take();
}

std::string EncodeCdrTfMessage(const std::vector<RosPose>& transforms, bool little_endian) {
  CdrWriter out(little_endian);
  out.Write(static_cast<std::uint32_t>(transforms.size()));
  for (const RosPose& p : transforms) WriteTransformStamped(&out, p);
  return out.Take();
}

std::string EncodeCdrWrenchStamped(const RosWrench& w, bool little_endian) {
  CdrWriter out(little_endian);
  WriteHeader(&out, w.stamp, w.frame_id);
  for (double v : {w.fx, w.fy, w.fz, w.tx, w.ty, w.tz}) out.Write(v);
  return out.Take();
}

namespace {

constexpr const char* kSeparator =
    "================================================================================\n";
constexpr const char* kHeader =
    "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n";
constexpr const char* kTime = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
constexpr const char* kVector3 = "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n";
constexpr const char* kQuaternion =
    "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";

std::string Join(std::initializer_list<const char*> parts) {
  std::string s;
  bool first = true;
  for (const char* p : parts) {
    if (!first) s += kSeparator;
    s += p;
    first = false;
  }
  return s;
}

}  // namespace

std::string Ros2MsgSchema(RosMessageType type) {
  const char* transform_stamped =
      "std_msgs/Header header\nstring child_frame_id\nTransform transform\n";
  const char* transform =
      "MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n";
  switch (type) {
    case RosMessageType::kPoseStamped:
      return Join({"std_msgs/Header header\nPose pose\n", kHeader, kTime,
                   "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation\n",
                   "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n", kQuaternion});
    case RosMessageType::kTransformStamped:
      return Join({transform_stamped, kHeader, kTime, transform, kVector3, kQuaternion});
    case RosMessageType::kTfMessage:
      return Join(
          {"geometry_msgs/TransformStamped[] transforms\n",
           (std::string("MSG: geometry_msgs/TransformStamped\n") + transform_stamped).c_str(),
           kHeader, kTime, transform, kVector3, kQuaternion});
    case RosMessageType::kWrenchStamped:
      return Join({"std_msgs/Header header\nWrench wrench\n", kHeader, kTime,
                   "MSG: geometry_msgs/Wrench\nVector3 force\nVector3 torque\n", kVector3});
    case RosMessageType::kOther:
      break;
  }
  return "";
}

}  // namespace slideid
