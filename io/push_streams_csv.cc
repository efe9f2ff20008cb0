#include "io/push_streams_csv.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "forward_model/constants.h"
#include "forward_model/number_format.h"
#include "io/atomic_file.h"
#include "io/push_log.h"
#include "io/ros_push_log.h"
#include "io/text_lines.h"

namespace slideid {
namespace {

/// The keys of a mapping that name columns, in the order the writer puts them.
constexpr std::array<const char*, 8> kPoseKeys = {"t", "x", "y", "theta", "qx", "qy", "qz", "qw"};
constexpr std::array<const char*, 4> kForceKeys = {"t", "fx", "fy", "tz"};
constexpr std::array<const char*, 4> kQuaternionKeys = {"qx", "qy", "qz", "qw"};

bool IsColumnKey(PushStream stream, const std::string& key) {
  if (stream == PushStream::kForce) {
    return std::find(kForceKeys.begin(), kForceKeys.end(), key) != kForceKeys.end();
  }
  return std::find(kPoseKeys.begin(), kPoseKeys.end(), key) != kPoseKeys.end();
}

std::string KeyList(PushStream stream) {
  return stream == PushStream::kForce ? "t, fx, fy, tz, unit, frame, yaw"
                                      : "t, x, y, theta or qx, qy, qz, qw, unit";
}

std::string Trimmed(std::string_view s) { return std::string(text::Trim(s)); }

/// The number of a time cell in `digits` powers of ten below seconds, in seconds, rounded
/// once: the cell's decimal exponent is shifted, so "1476728847123.25" ms is read as
/// "1476728847.12325" s would be (a division by 1000 would round twice).
std::optional<double> ParseTime(std::string_view cell, int digits) {
  const std::optional<double> plain = text::ParseFiniteNumber(cell);
  if (!plain || digits == 0) return plain;
  const std::string_view s = text::Trim(cell);
  const std::size_t e = s.find_first_of("eE");
  long exponent = 0;
  if (e != std::string_view::npos) {
    const std::string tail(s.substr(e + 1));
    char* end = nullptr;
    exponent = std::strtol(tail.c_str(), &end, 10);
    if (end == tail.c_str() || *end != '\0') return std::nullopt;
  }
  const std::string shifted = std::string(s.substr(0, e)) + "e" + std::to_string(exponent - digits);
  return text::ParseFiniteNumber(shifted);
}

/// `t_s` at full precision in `digits` powers of ten below seconds: the decimal point of its
/// shortest exact text moved, so that ParseTime reads back the same double.
std::string FormatTime(double t_s, int digits) {
  std::string s = ExactNumber(t_s);
  if (digits == 0) return s;
  const std::size_t e = s.find_first_of("eE");
  if (e != std::string::npos) {
    return s.substr(0, e) + "e" + std::to_string(std::stol(s.substr(e + 1)) + digits);
  }
  std::string sign;
  if (s[0] == '-') {
    sign = "-";
    s.erase(0, 1);
  }
  const std::size_t dot = s.find('.');
  std::string whole = dot == std::string::npos ? s : s.substr(0, dot);
  std::string fraction = dot == std::string::npos ? "" : s.substr(dot + 1);
  fraction.resize(std::max<std::size_t>(fraction.size(), digits), '0');
  whole += fraction.substr(0, digits);
  fraction.erase(0, digits);
  const std::size_t first = whole.find_first_not_of('0');
  whole = first == std::string::npos ? "0" : whole.substr(first);
  return sign + whole + (fraction.empty() ? "" : "." + fraction);
}

const char* UnitName(int digits) {
  switch (digits) {
    case 3:
      return "ms";
    case 6:
      return "us";
    case 9:
      return "ns";
    default:
      return "s";
  }
}

/// The tip's yaw against time, for a force logged in a sensor frame that turns with the tip:
/// sorted, repeated times dropped (the first kept, as the import does), unwrapped, and
/// linear between samples (held beyond the ends).
class TipYaw {
 public:
  explicit TipYaw(const std::vector<MitStreamRow>& tip) {
    std::vector<MitStreamRow> rows = tip;
    std::stable_sort(rows.begin(), rows.end(),
                     [](const MitStreamRow& a, const MitStreamRow& b) { return a[0] < b[0]; });
    for (const MitStreamRow& r : rows) {
      if (!t_.empty() && r[0] == t_.back()) continue;
      double yaw = r[3];
      if (!yaw_.empty()) {
        const double step = yaw - yaw_.back();
        yaw = yaw_.back() + std::remainder(step, 2.0 * kPi);
      }
      t_.push_back(r[0]);
      yaw_.push_back(yaw);
    }
  }
  double At(double t) const {
    if (t_.empty()) return 0.0;
    if (t <= t_.front()) return yaw_.front();
    if (t >= t_.back()) return yaw_.back();
    const std::size_t k = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin();
    const double w = (t - t_[k - 1]) / (t_[k] - t_[k - 1]);
    return yaw_[k - 1] + w * (yaw_[k] - yaw_[k - 1]);
  }

 private:
  std::vector<double> t_, yaw_;
};

/// Turns (fx, fy) of each row by the sensor's yaw (`sign` +1: sensor to world; -1: back).
void TurnForce(std::vector<MitStreamRow>* force, const StreamCsvMapping& m,
               const std::vector<MitStreamRow>& tip, double sign) {
  if (!m.sensor_frame) return;
  const TipYaw tip_yaw(m.sensor_yaw_rad ? std::vector<MitStreamRow>{} : tip);
  for (MitStreamRow& r : *force) {
    const double yaw = sign * (m.sensor_yaw_rad ? *m.sensor_yaw_rad : tip_yaw.At(r[0]));
    const double c = std::cos(yaw), s = std::sin(yaw);
    const double fx = c * r[1] - s * r[2], fy = s * r[1] + c * r[2];
    r[1] = fx;
    r[2] = fy;
  }
}

std::string Describe(const StreamCsvMapping& m) {
  std::string s = std::string(ToString(m.stream)) + " " + m.path + " (";
  bool first = true;
  for (const auto& [key, column] : m.columns) {
    s += (first ? "" : ", ") + key + "=" + column;
    first = false;
  }
  s += std::string("; times in ") + UnitName(m.time_digits);
  if (m.stream == PushStream::kForce) {
    s += m.sensor_frame ? (m.sensor_yaw_rad
                               ? "; sensor frame at yaw " + ExactNumber(*m.sensor_yaw_rad) + " rad"
                               : std::string("; sensor frame at the tip's yaw"))
                        : "; world frame";
  }
  return s + ")";
}

/// One stream's rows from its lines.
std::vector<MitStreamRow> ReadStream(TextLines& in, const StreamCsvMapping& m) {
  const std::string& file = in.name();
  std::vector<std::string_view> cells;
  std::vector<std::string> header;
  int header_line = 0;
  while (const auto raw = in.Next()) {
    const std::string_view line = text::Trim(*raw);
    if (line.empty() || line.front() == '#') continue;
    header_line = in.LineNumber();
    text::SplitCells(line, cells);
    for (std::string_view c : cells) header.emplace_back(c);
    break;
  }
  if (header_line == 0) {
    throw LogError(file, 0, "",
                   std::string(in.Empty() ? "empty file" : "no header line (only comments)") +
                       ": expected a header naming the " + ToString(m.stream) +
                       " stream's columns");
  }
  // The four values of a row: t and three (pose: x, y, yaw; force: fx, fy, tz), each from a
  // column, or (tip without orientation, force without tz) a constant 0.
  const std::vector<std::string> keys =
      m.stream == PushStream::kForce
          ? std::vector<std::string>{"t", "fx", "fy", "tz"}
          : (m.Quaternion() ? std::vector<std::string>{"t", "x", "y", "qx", "qy", "qz", "qw"}
                            : std::vector<std::string>{"t", "x", "y", "theta"});
  std::vector<int> field(keys.size(), -1);
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const auto it = m.columns.find(keys[k]);
    if (it == m.columns.end()) continue;  // optional and not mapped
    const auto at = std::find(header.begin(), header.end(), it->second);
    if (at == header.end()) {
      std::string present;
      for (const std::string& h : header) present += (present.empty() ? "" : ", ") + h;
      throw LogError(file, header_line, it->second,
                     "not in the header (" + m.option + " maps " + keys[k] +
                         " to it; the header's columns: " + present + ")");
    }
    if (std::find(at + 1, header.end(), it->second) != header.end()) {
      throw LogError(file, header_line, it->second, "appears twice in the header");
    }
    field[k] = static_cast<int>(at - header.begin());
  }
  std::vector<MitStreamRow> rows;
  std::vector<double> v(keys.size(), 0.0);
  while (const auto raw = in.Next()) {
    const std::string_view line = text::Trim(*raw);
    if (line.empty() || line.front() == '#') continue;
    const int line_no = in.LineNumber();
    text::SplitCells(line, cells);
    for (std::size_t k = 0; k < keys.size(); ++k) {
      if (field[k] < 0) {
        v[k] = 0.0;
        continue;
      }
      const std::string& column = header[field[k]];
      if (static_cast<std::size_t>(field[k]) >= cells.size()) {
        throw LogError(file, line_no, column,
                       "missing: the row has " + std::to_string(cells.size()) +
                           " cells, the header " + std::to_string(header.size()));
      }
      const std::string_view cell = cells[field[k]];
      const std::optional<double> x =
          k == 0 ? ParseTime(cell, m.time_digits) : text::ParseFiniteNumber(cell);
      if (!x) {
        throw LogError(file, line_no, column,
                       "not a finite number: '" + text::Excerpt(text::Trim(cell)) + "'" +
                           (k == 0 ? std::string(" (a time in ") + UnitName(m.time_digits) + ")"
                                   : std::string()));
      }
      v[k] = *x;
    }
    if (m.Quaternion()) {
      const double norm2 = v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6];
      if (!(norm2 > 0.0) || !std::isfinite(norm2)) {
        throw LogError(file, line_no, m.columns.at("qw"), "the quaternion is zero or too large");
      }
      rows.push_back({v[0], v[1], v[2], QuaternionYaw(v[3], v[4], v[5], v[6])});
    } else {
      rows.push_back({v[0], v[1], v[2], v[3]});
    }
  }
  if (rows.empty()) throw LogError(file, 0, "", "no rows (a header and no data)");
  return rows;
}

PushStreamsRead Read(const PushStreamsCsv& files, TextLines& pose, TextLines& tip,
                     TextLines& force) {
  if (files.force.sensor_frame && !files.force.sensor_yaw_rad &&
      !files.tip.columns.count("theta") && !files.tip.Quaternion()) {
    throw LogError(files.force.path, 0, "",
                   files.force.option +
                       " yaw=tip needs the tip's orientation (theta= or qx, qy, qz, qw= in " +
                       files.tip.option + ")");
  }
  PushStreamsRead read;
  read.recording.object_pose = ReadStream(pose, files.pose);
  read.recording.tip_pose = ReadStream(tip, files.tip);
  read.recording.ft_wrench = ReadStream(force, files.force);
  TurnForce(&read.recording.ft_wrench, files.force, read.recording.tip_pose, +1.0);
  read.notes.push_back("streams: " + Describe(files.pose) + ", " + Describe(files.tip) + ", " +
                       Describe(files.force));
  return read;
}

}  // namespace

const char* ToString(PushStream stream) {
  switch (stream) {
    case PushStream::kPose:
      return "pose";
    case PushStream::kTip:
      return "tip";
    case PushStream::kForce:
      return "force";
  }
  return "?";
}

StreamCsvMapping ParseStreamMapping(PushStream stream, const std::string& option,
                                    const std::string& text) {
  StreamCsvMapping m;
  m.stream = stream;
  m.option = option;
  auto fail = [&](const std::string& what) { throw std::invalid_argument(option + ": " + what); };
  const std::size_t colon = text.find_last_of(':');
  m.path = text.substr(0, colon);
  if (m.path.empty()) fail("no file given (FILE or FILE:key=column,...)");
  std::optional<std::string> frame, yaw, unit;
  if (colon != std::string::npos) {
    std::string_view rest(text);
    rest.remove_prefix(colon + 1);
    while (true) {
      const std::size_t comma = rest.find(',');
      const std::string item = Trimmed(rest.substr(0, comma));
      if (item.empty()) fail("an empty item in '" + text.substr(colon + 1) + "'");
      const std::size_t eq = item.find('=');
      const std::string key = Trimmed(item.substr(0, eq));
      const std::string value = eq == std::string::npos ? key : Trimmed(item.substr(eq + 1));
      if (value.empty()) fail("key '" + key + "' has no value");
      const bool known = IsColumnKey(stream, key) || key == "unit" ||
                         (stream == PushStream::kForce && (key == "frame" || key == "yaw"));
      if (!known) fail("unknown key '" + key + "' (keys: " + KeyList(stream) + ")");
      const bool seen = m.columns.count(key) || (key == "unit" && unit) ||
                        (key == "frame" && frame) || (key == "yaw" && yaw);
      if (seen) fail("key '" + key + "' given twice");
      if (key == "unit") {
        const std::map<std::string, int> units = {{"s", 0}, {"ms", 3}, {"us", 6}, {"ns", 9}};
        const auto it = units.find(value);
        if (it == units.end()) {
          fail("unknown time unit '" + value + "' in unit=" + value + " (s, ms, us or ns)");
        }
        m.time_digits = it->second;
        unit = value;
      } else if (key == "frame") {
        frame = value;
      } else if (key == "yaw") {
        yaw = value;
      } else {
        m.columns[key] = value;
      }
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
  }
  if (frame && *frame != "world" && *frame != "sensor") {
    fail("unknown frame '" + *frame + "' (world or sensor)");
  }
  m.sensor_frame = frame && *frame == "sensor";
  if (yaw && !m.sensor_frame) fail("yaw= applies to frame=sensor only");
  if (m.sensor_frame) {
    if (!yaw) fail("frame=sensor needs yaw=RAD (a fixed sensor yaw) or yaw=tip (the tip's yaw)");
    if (*yaw != "tip") {
      const std::optional<double> v = text::ParseFiniteNumber(*yaw);
      if (!v) fail("yaw=" + *yaw + " is neither a finite number [rad] nor 'tip'");
      m.sensor_yaw_rad = *v;
    }
  }
  int quaternion = 0;
  for (const char* q : kQuaternionKeys) quaternion += static_cast<int>(m.columns.count(q));
  if (quaternion != 0 && quaternion != 4) fail("a quaternion needs all of qx, qy, qz and qw");
  if (quaternion == 4 && m.columns.count("theta")) fail("give theta or qx, qy, qz, qw, not both");
  // Unmapped keys name columns like themselves; the tip's orientation is optional (the
  // import does not use it), as is the force's tz.
  const std::vector<const char*> defaults = stream == PushStream::kForce
                                                ? std::vector<const char*>{"t", "fx", "fy"}
                                            : stream == PushStream::kPose && quaternion == 0
                                                ? std::vector<const char*>{"t", "x", "y", "theta"}
                                                : std::vector<const char*>{"t", "x", "y"};
  for (const char* key : defaults) m.columns.emplace(key, key);
  // Two keys on one column (x=px,y=px) is a slip of the mapping, never a layout.
  for (auto a = m.columns.begin(); a != m.columns.end(); ++a) {
    for (auto b = std::next(a); b != m.columns.end(); ++b) {
      if (a->second == b->second) {
        fail("keys '" + a->first + "' and '" + b->first + "' both name column '" + a->second + "'");
      }
    }
  }
  return m;
}

PushStreamsRead ReadPushStreamsCsv(const PushStreamsCsv& files) {
  const auto pose = TextLines::OpenFile(files.pose.path);
  const auto tip = TextLines::OpenFile(files.tip.path);
  const auto force = TextLines::OpenFile(files.force.path);
  return Read(files, *pose, *tip, *force);
}

PushStreamsRead ParsePushStreamsCsv(const PushStreamsCsv& files, std::string_view pose_text,
                                    std::string_view tip_text, std::string_view force_text) {
  const auto pose = TextLines::FromMemory(pose_text, files.pose.path);
  const auto tip = TextLines::FromMemory(tip_text, files.tip.path);
  const auto force = TextLines::FromMemory(force_text, files.force.path);
  return Read(files, *pose, *tip, *force);
}

std::string StreamFilesOverlapProblem(const MitPushRecording& rec, const PushStreamsCsv& files) {
  struct Span {
    const StreamCsvMapping* m;
    double first, last;
  };
  auto span = [](const StreamCsvMapping& m, const std::vector<MitStreamRow>& rows) {
    Span s{&m, rows.empty() ? 0.0 : rows[0][0], rows.empty() ? 0.0 : rows[0][0]};
    for (const MitStreamRow& r : rows) {
      s.first = std::min(s.first, r[0]);
      s.last = std::max(s.last, r[0]);
    }
    return s;
  };
  const Span spans[] = {span(files.pose, rec.object_pose), span(files.tip, rec.tip_pose),
                        span(files.force, rec.ft_wrench)};
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      const Span &p = spans[i], &q = spans[j];
      if (p.last < q.first || q.last < p.first) {
        return Printf(
            "the clocks never overlap: the %s file %s spans %.3f to %.3f s and the %s file %s "
            "%.3f to %.3f s (another clock, or another time unit than unit= says?)",
            ToString(p.m->stream), p.m->path.c_str(), p.first, p.last, ToString(q.m->stream),
            q.m->path.c_str(), q.first, q.last);
      }
    }
  }
  return "";
}

std::string FormatPushStreamCsv(const MitPushRecording& recording, const StreamCsvMapping& m) {
  std::vector<MitStreamRow> rows = m.stream == PushStream::kPose  ? recording.object_pose
                                   : m.stream == PushStream::kTip ? recording.tip_pose
                                                                  : recording.ft_wrench;
  TurnForce(&rows, m, recording.tip_pose, -1.0);
  std::vector<std::string> keys;
  if (m.stream == PushStream::kForce) {
    for (const char* k : kForceKeys)
      if (m.columns.count(k)) keys.push_back(k);
  } else {
    for (const char* k : kPoseKeys)
      if (m.columns.count(k)) keys.push_back(k);
  }
  std::string out = "seq";
  for (const std::string& k : keys) out += "," + m.columns.at(k);
  out += "\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const MitStreamRow& r = rows[i];
    out += std::to_string(i);
    for (const std::string& k : keys) {
      double v = 0;
      if (k == "t") {
        out += "," + FormatTime(r[0], m.time_digits);
        continue;
      }
      if (k == "x" || k == "fx") v = r[1];
      if (k == "y" || k == "fy") v = r[2];
      if (k == "theta" || k == "tz") v = r[3];
      if (k == "qz") v = std::sin(0.5 * r[3]);
      if (k == "qw") v = std::cos(0.5 * r[3]);
      out += "," + ExactNumber(v);
    }
    out += "\n";
  }
  return out;
}

void WritePushStreamsCsv(const MitPushRecording& recording, const PushStreamsCsv& files) {
  for (const StreamCsvMapping* m : {&files.pose, &files.tip, &files.force}) {
    WriteFileAtomically(m->path, std::string(ToString(m->stream)) + " stream CSV",
                        FormatPushStreamCsv(recording, *m));
  }
}

}  // namespace slideid
