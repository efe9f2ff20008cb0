#include "io/zhou_tripod_log.h"

#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <ostream>
#include <stdexcept>

#include "forward_model/number_format.h"
#include "io/atomic_file.h"
#include "io/text_lines.h"

namespace slideid {
namespace {

constexpr std::array<const char*, 7> kPoseFields = {"x", "y", "z", "qw", "qx", "qy", "qz"};
constexpr std::array<const char*, 3> kForceFields = {"t", "fx", "fy"};
constexpr std::array<const char*, 8> kRobotFields = {"t", "x", "y", "z", "qw", "qx", "qy", "qz"};

/// "3 numbers: t fx fy", for messages.
template <std::size_t N>
std::string FieldList(const std::array<const char*, N>& names) {
  std::string s = std::to_string(N) + " numbers:";
  for (const char* n : names) s += std::string(" ") + n;
  return s;
}

/// Splits at blanks (spaces, tabs) into `fields` (cleared first).
void SplitBlanks(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i >= line.size()) break;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    fields.push_back(line.substr(i, j - i));
    i = j;
  }
}

std::string Fields(std::size_t n) { return std::to_string(n) + (n == 1 ? " field" : " fields"); }

/// The last count read, for messages about a count that does not match its lines.
struct LastCount {
  std::string what;  ///< "force count of push 3"
  int line = 0;
  long long value = 0;
  long long read = 0;     ///< lines of it read so far
  std::size_t width = 0;  ///< fields of each of its lines
};

class TripodReader {
 public:
  explicit TripodReader(TextLines& in) : in_(in) {}

  TripodLog Read() {
    if (!Next()) {
      Fail(0, "",
           in_.Empty() ? "the file is empty: expected the number of pushes on line 1"
                       : "the file holds only blank lines: expected the number of "
                         "pushes");
    }
    const long long pushes = Count("the number of pushes", kMaxTripodPushes);
    const int pushes_line = line_;
    if (pushes == 0) Fail(line_, "count", "the file announces 0 pushes");
    TripodLog log;
    log.pushes.reserve(static_cast<std::size_t>(pushes));
    for (long long p = 1; p <= pushes; ++p) log.pushes.push_back(ReadPush(p, pushes));
    if (Next()) {
      Fail(line_, "",
           "data after the last of the " + std::to_string(pushes) + " pushes announced on line " +
               std::to_string(pushes_line) + ": a count smaller than its lines (the last: " +
               last_.what + " on line " + std::to_string(last_.line) +
               "), or a wrong number of "
               "pushes");
    }
    return log;
  }

 private:
  /// Moves to the next non-blank line; false at the end of the text.
  bool Next() {
    while (const auto raw = in_.Next()) {
      SplitBlanks(*raw, fields_);
      if (!fields_.empty()) {
        line_ = in_.LineNumber();
        return true;
      }
    }
    line_ = in_.LineNumber();
    return false;
  }

  [[noreturn]] void Fail(int line, const std::string& column, const std::string& what) const {
    throw LogError(in_.name(), line, column, what);
  }

  /// Fails at the end of the text while `expected` was due.
  [[noreturn]] void FailCutShort(const std::string& expected) const {
    std::string what = "the file ends here, but " + expected +
                       " was expected: the file is cut "
                       "short";
    if (last_.line > 0 && last_.read < last_.value) {
      what += " (or the " + last_.what + " on line " + std::to_string(last_.line) + ", " +
              std::to_string(last_.value) + ", is larger than its " + std::to_string(last_.read) +
              " lines)";
    }
    Fail(line_, "", what);
  }

  /// Fails for a line whose field count is not the `expected` record's.
  [[noreturn]] void FailShape(const std::string& expected, const std::string& shape,
                              std::size_t wanted) const {
    std::string what = "expected " + expected + " (" + shape + "), found " + Fields(fields_.size());
    if (last_.line > 0 && wanted != 1 && fields_.size() == 1 && last_.read < last_.value) {
      what += ": the " + last_.what + " on line " + std::to_string(last_.line) + ", " +
              std::to_string(last_.value) + ", does not match its lines (only " +
              std::to_string(last_.read) + " follow it)";
    } else if (last_.line > 0 && last_.read == last_.value && fields_.size() == last_.width) {
      what += ": the " + last_.what + " on line " + std::to_string(last_.line) + ", " +
              std::to_string(last_.value) + ", may not match its lines (more seem to follow it)";
    }
    Fail(line_, "", what);
  }

  /// Reads a count line (the current line must be loaded).
  long long Count(const std::string& what, long long max_value) {
    if (fields_.size() != 1) FailShape(what, "one integer", 1);
    const auto value = text::ParseCount(fields_[0], max_value);
    if (!value) {
      Fail(line_, "count",
           "'" + text::Excerpt(fields_[0]) + "' is not " + what + " (a whole number from 0 to " +
               std::to_string(max_value) + ")");
    }
    return *value;
  }

  /// Loads the next line and reads it as `N` numbers named `names` into `out`.
  template <std::size_t N>
  void Numbers(const std::array<const char*, N>& names, const std::string& what, double* out) {
    if (!Next()) FailCutShort(what);
    if (fields_.size() != N) FailShape(what, FieldList(names), N);
    for (std::size_t i = 0; i < N; ++i) {
      const auto value = text::ParseFiniteNumber(fields_[i]);
      if (!value) {
        Fail(line_, names[i],
             "'" + text::Excerpt(fields_[i]) + "' is not a finite number (in " + what + ")");
      }
      out[i] = *value;
    }
  }

  TripodPose Pose(const std::string& what) {
    double v[7];
    Numbers(kPoseFields, what, v);
    return {v[0], v[1], v[2], v[3], v[4], v[5], v[6]};
  }

  /// Loads and reads a count line that starts a block of `block` lines.
  long long BlockCount(const std::string& what, const std::string& block, std::size_t width) {
    if (!Next()) FailCutShort(what);
    const long long n = Count(what, kMaxTripodSamples);
    last_ = {block, line_, n, 0, width};
    return n;
  }

  TripodPush ReadPush(long long p, long long pushes) {
    const std::string of = " of push " + std::to_string(p) + " of " + std::to_string(pushes);
    TripodPush push;
    push.pre = Pose("the pre-push object pose" + of);
    push.line = line_;
    push.post = Pose("the post-push object pose" + of);
    const long long k =
        BlockCount("the number of force samples" + of, "force count" + of, kForceFields.size());
    push.force_count_line = line_;
    push.forces.resize(static_cast<std::size_t>(k));
    for (long long i = 0; i < k; ++i) {
      double v[3];
      Numbers(kForceFields,
              "force sample " + std::to_string(i + 1) + " of " + std::to_string(k) + of, v);
      push.forces[i] = {v[0], v[1], v[2], line_};
      ++last_.read;
    }
    const long long m =
        BlockCount("the number of robot poses" + of, "robot pose count" + of, kRobotFields.size());
    push.robot_count_line = line_;
    push.robot.resize(static_cast<std::size_t>(m));
    for (long long i = 0; i < m; ++i) {
      double v[8];
      Numbers(kRobotFields, "robot pose " + std::to_string(i + 1) + " of " + std::to_string(m) + of,
              v);
      push.robot[i] = {v[0], {v[1], v[2], v[3], v[4], v[5], v[6], v[7]}, line_};
      ++last_.read;
    }
    return push;
  }

  TextLines& in_;
  std::vector<std::string_view> fields_;
  int line_ = 0;
  LastCount last_;
};

void WritePose(const TripodPose& p, std::ostream& out) {
  out << ShortNumber(p.x_mm) << ' ' << ShortNumber(p.y_mm) << ' ' << ShortNumber(p.z_mm) << ' '
      << ShortNumber(p.qw) << ' ' << ShortNumber(p.qx) << ' ' << ShortNumber(p.qy) << ' '
      << ShortNumber(p.qz);
}

void WriteUnchecked(const TripodLog& log, std::ostream& out) {
  out << log.pushes.size() << '\n';
  for (const TripodPush& push : log.pushes) {
    WritePose(push.pre, out);
    out << '\n';
    WritePose(push.post, out);
    out << '\n' << push.forces.size() << '\n';
    for (const TripodForceSample& s : push.forces) {
      out << ShortNumber(s.t_s) << ' ' << ShortNumber(s.fx_n) << ' ' << ShortNumber(s.fy_n) << '\n';
    }
    out << push.robot.size() << '\n';
    for (const TripodRobotSample& s : push.robot) {
      out << ShortNumber(s.t_s) << ' ';
      WritePose(s.pose, out);
      out << '\n';
    }
  }
}

}  // namespace

TripodLog ReadZhouTripodLog(const std::string& path) {
  const std::unique_ptr<TextLines> lines = TextLines::OpenFile(path);
  return TripodReader(*lines).Read();
}

TripodLog ParseZhouTripodLog(std::string_view text, const std::string& source) {
  const std::unique_ptr<TextLines> lines = TextLines::FromMemory(text, source);
  return TripodReader(*lines).Read();
}

void WriteZhouTripodLog(const TripodLog& log, std::ostream& out) {
  WriteUnchecked(log, out);
  out.flush();
  if (!out) throw std::runtime_error("writing the tripod log to a stream failed");
}

void WriteZhouTripodLog(const TripodLog& log, const std::string& path) {
  WriteFileAtomically(path, "tripod log", [&](std::ostream& out) { WriteUnchecked(log, out); });
}

}  // namespace slideid
