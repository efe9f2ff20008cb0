#include "io/scene_file.h"

#include <algorithm>
#include <boost/program_options.hpp>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

#include "datasets/push_program.h"
#include "forward_model/constants.h"
#include "forward_model/number_format.h"
#include "io/pusher_path_csv.h"
#include "io/text_lines.h"

namespace slideid {
namespace {

namespace po = boost::program_options;

// Simulated after a pusher's path ends when [sim] gives no duration [s]: a pushed object
// stops within a few tens of milliseconds (v / (a g): 0.1 m/s at a = 0.3 takes 34 ms).
constexpr double kPusherRunOut_s = 0.2;

/// Every key a scene may hold, as Boost names it ("section.key").
const char* const kKnownKeys[] = {"slider.mass",
                                  "slider.inertia",
                                  "slider.com_height",
                                  "slider.gravity",
                                  "friction.mu",
                                  "friction.e_t",
                                  "friction.e_o",
                                  "friction.e_r",
                                  "patch.shape",
                                  "patch.width",
                                  "patch.length",
                                  "patch.radius",
                                  "patch.inner_radius",
                                  "patch.vertices",
                                  "initial.x",
                                  "initial.y",
                                  "initial.theta",
                                  "initial.vx",
                                  "initial.vy",
                                  "initial.wz",
                                  "push.point",
                                  "push.height",
                                  "push.direction",
                                  "push.force",
                                  "push.amplitude",
                                  "push.period",
                                  "push.start",
                                  "push.stop",
                                  "sim.dt",
                                  "sim.duration",
                                  "sim.log_every",
                                  "log.write",
                                  "log.push",
                                  "log.step_info",
                                  "log.wrap_theta",
                                  "log.wrench",
                                  "noise.pose",
                                  "noise.angle",
                                  "noise.velocity",
                                  "noise.spin",
                                  "noise.force_relative",
                                  "noise.force",
                                  "noise.outlier_fraction",
                                  "noise.outlier",
                                  "noise.seed",
                                  "noise.force_bias_x",
                                  "noise.force_bias_y",
                                  "noise.force_delay",
                                  "noise.push_point",
                                  "program.random",
                                  "program.seed",
                                  "program.force",
                                  "program.amplitude_fraction",
                                  "program.period",
                                  "program.duration",
                                  "program.rest",
                                  "program.height",
                                  "program.spread",
                                  "program.through_cm",
                                  "program.start",
                                  "program.max_lever",
                                  "program.time_grid",
                                  "pusher.tip_radius",
                                  "pusher.mu",
                                  "pusher.height",
                                  "pusher.point",
                                  "pusher.direction",
                                  "pusher.distance",
                                  "pusher.speed",
                                  "pusher.start",
                                  "pusher.path",
                                  "pusher.start_time",
                                  "pusher.path_file"};
const std::set<std::string> kKnownSections = {"slider",  "friction", "patch", "initial", "push",
                                              "program", "sim",      "log",   "noise",   "pusher"};
/// The keys of a [push] section, also those of each [push.N].
const char* const kPushKeys[] = {"point",     "height", "direction", "force",
                                 "amplitude", "period", "start",     "stop"};

/// N of a section named "push.N" (N a positive integer without sign or leading zero), or 0.
long PushSectionNumber(const std::string& section) {
  if (section.rfind("push.", 0) != 0 || section.size() == 5 || section[5] == '0') return 0;
  for (size_t i = 5; i < section.size(); ++i) {
    if (section[i] < '0' || section[i] > '9' || i > 12) return 0;
  }
  return std::stol(section.substr(5));
}
/// Patch keys, and which of them each shape uses.
const char* const kPatchKeys[] = {"width", "length", "radius", "inner_radius", "vertices"};
const std::map<std::string, std::set<std::string>> kShapeKeys = {
    {"rectangle", {"width", "length"}},
    {"disk", {"radius"}},
    {"ring", {"radius", "inner_radius"}},
    {"polygon", {"vertices"}}};

std::string Trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r\n") - first + 1);
}

/// Where keys and section headers sit in the text (1-based lines), found the way Boost's
/// config-file parser reads lines, so that messages can point at a line.
struct Layout {
  std::map<std::string, int> key_lines;  // first occurrence
  std::vector<std::pair<std::string, int>> sections;
};

Layout ScanLayout(const std::string& text) {
  Layout layout;
  std::istringstream in(text);
  std::string line, prefix;
  for (int number = 1; std::getline(in, line); ++number) {
    line = Trim(line.substr(0, line.find('#')));
    if (line.size() >= 2 && line.front() == '[' && line.back() == ']') {
      prefix = Trim(line.substr(1, line.size() - 2));
      layout.sections.emplace_back(prefix, number);
      prefix += ".";
    } else if (const auto eq = line.find('='); eq != std::string::npos) {
      layout.key_lines.emplace(prefix + Trim(line.substr(0, eq)), number);
    }
  }
  return layout;
}

/// Throws "source: message (line N)"; line <= 0: unknown.
[[noreturn]] void ThrowAt(const std::string& source, const std::string& message, int line) {
  if (line <= 0) throw SceneError(source + ": " + message);
  throw SceneError(source + ": " + message + " (line " + std::to_string(line) + ")");
}

/// Line (1-based) whose content, without comment, is `content`; 0 if none.
int LineOf(const std::string& text, const std::string& content) {
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (Trim(line.substr(0, line.find('#'))) == content) return number;
  }
  return 0;
}

/// "slider.mass" -> "[slider] mass"; "push.2.force" -> "[push.2] force".
std::string Display(const std::string& key) {
  const auto dot = key.rfind('.');
  if (dot == std::string::npos) return key;
  return "[" + key.substr(0, dot) + "] " + key.substr(dot + 1);
}

/// Typed, checked access to the key = value pairs of one scene file.
class Reader {
 public:
  enum class Check { kFinite, kPositive, kNonNegative };

  Reader(std::string source, std::map<std::string, std::string> values, Layout layout)
      : source_(std::move(source)), values_(std::move(values)), layout_(std::move(layout)) {}

  bool Has(const std::string& key) const { return values_.count(key) != 0; }
  bool HasSection(const std::string& section) const;

  /// Required text value.
  const std::string& Text(const std::string& key) const;
  /// Required number.
  double Number(const std::string& key, Check check) const;
  /// Optional number with a default (the default is not checked).
  double Number(const std::string& key, double fallback, Check check) const;
  /// Required "x y" pair.
  Eigen::Vector2d Pair(const std::string& key) const;
  /// Whitespace-separated numbers.
  std::vector<double> Numbers(const std::string& key) const;
  /// Optional non-negative integer >= `min` with a default.
  std::uint64_t Integer(const std::string& key, std::uint64_t fallback, std::uint64_t min) const;
  /// Optional true/false (also yes/no, 1/0) with a default.
  bool Bool(const std::string& key, bool fallback) const;
  /// Optional "lo hi" range (or one number for lo = hi) with a default.
  ValueRange Range(const std::string& key, const ValueRange& fallback, Check check) const;
  std::optional<ValueRange> Range(const std::string& key, Check check) const;

  /// Throws "source: [section] key = value: message (line N)".
  [[noreturn]] void Fail(const std::string& key, const std::string& message) const;
  /// Throws "source: message (line N)" for problems not tied to one value.
  [[noreturn]] void FailAt(const std::string& message, int line) const;

 private:
  double ParseValue(const std::string& key, const std::string& token) const;

  std::string source_;
  std::map<std::string, std::string> values_;
  Layout layout_;
};

bool Reader::HasSection(const std::string& section) const {
  const auto named = [&](const auto& s) { return s.first == section; };
  const std::string prefix = section + ".";
  const auto in_section = [&](const auto& kv) {  // "push.force", not "push.1.force"
    return kv.first.rfind(prefix, 0) == 0 && kv.first.find('.', prefix.size()) == std::string::npos;
  };
  return std::any_of(layout_.sections.begin(), layout_.sections.end(), named) ||
         std::any_of(values_.begin(), values_.end(), in_section);
}

const std::string& Reader::Text(const std::string& key) const {
  const auto it = values_.find(key);
  if (it == values_.end()) {
    throw SceneError(source_ + ": " + Display(key) + ": missing required key");
  }
  return it->second;
}

double Reader::ParseValue(const std::string& key, const std::string& token) const {
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  if (token.empty() || *end != '\0') Fail(key, "'" + token + "' is not a number");
  if (!std::isfinite(value)) Fail(key, "'" + token + "' is not finite");
  return value;
}

double Reader::Number(const std::string& key, Check check) const {
  const double value = ParseValue(key, Text(key));
  if (check == Check::kPositive && !(value > 0.0)) Fail(key, "must be > 0");
  if (check == Check::kNonNegative && !(value >= 0.0)) Fail(key, "must be >= 0");
  return value;
}

double Reader::Number(const std::string& key, double fallback, Check check) const {
  return Has(key) ? Number(key, check) : fallback;
}

std::vector<double> Reader::Numbers(const std::string& key) const {
  std::string text = Text(key);
  // Tolerate "x y" written with its quotes.
  if (text.size() >= 2 && text.front() == '"' && text.back() == '"') {
    text = text.substr(1, text.size() - 2);
  }
  std::istringstream in(text);
  std::vector<double> out;
  for (std::string token; in >> token;) out.push_back(ParseValue(key, token));
  return out;
}

Eigen::Vector2d Reader::Pair(const std::string& key) const {
  const std::vector<double> v = Numbers(key);
  if (v.size() != 2) Fail(key, "needs two numbers \"x y\", got " + std::to_string(v.size()));
  return {v[0], v[1]};
}

std::uint64_t Reader::Integer(const std::string& key, std::uint64_t fallback,
                              std::uint64_t min) const {
  if (!Has(key)) return fallback;
  const std::string& text = Text(key);
  char* end = nullptr;
  errno = 0;
  const unsigned long long value = std::strtoull(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || text.find_first_not_of("0123456789") != std::string::npos) {
    Fail(key, "'" + text + "' is not a non-negative integer");
  }
  if (errno == ERANGE) Fail(key, "'" + text + "' is too large");
  if (value < min) Fail(key, "must be >= " + std::to_string(min));
  return value;
}

bool Reader::Bool(const std::string& key, bool fallback) const {
  if (!Has(key)) return fallback;
  const std::string& text = Text(key);
  if (text == "true" || text == "yes" || text == "1") return true;
  if (text == "false" || text == "no" || text == "0") return false;
  Fail(key, "must be true or false");
}

std::optional<ValueRange> Reader::Range(const std::string& key, Check check) const {
  if (!Has(key)) return std::nullopt;
  const std::vector<double> v = Numbers(key);
  if (v.empty() || v.size() > 2) {
    Fail(key, "needs \"lo hi\" (or one number), got " + std::to_string(v.size()) + " numbers");
  }
  const ValueRange range{v.front(), v.back()};
  if (!(range.lo <= range.hi)) Fail(key, "needs lo <= hi");
  if (check == Check::kPositive && !(range.lo > 0.0)) Fail(key, "must be > 0");
  if (check == Check::kNonNegative && !(range.lo >= 0.0)) Fail(key, "must be >= 0");
  return range;
}

ValueRange Reader::Range(const std::string& key, const ValueRange& fallback, Check check) const {
  return Range(key, check).value_or(fallback);
}

void Reader::Fail(const std::string& key, const std::string& message) const {
  std::string where = source_ + ": " + Display(key);
  if (const auto it = values_.find(key); it != values_.end()) where += " = " + it->second;
  const auto line = layout_.key_lines.find(key);
  if (line == layout_.key_lines.end()) throw SceneError(where + ": " + message);
  throw SceneError(where + ": " + message + " (line " + std::to_string(line->second) + ")");
}

void Reader::FailAt(const std::string& message, int line) const { ThrowAt(source_, message, line); }

/// Boost's parse; its exceptions become SceneError naming the file and the key.
po::parsed_options ParseWithBoost(const std::string& text, const po::options_description& options,
                                  const std::string& source, const Layout& layout) {
  std::istringstream in(text);
  try {
    return po::parse_config_file(in, options, /*allow_unregistered=*/false);
  } catch (const po::unknown_option& e) {
    const std::string key = e.get_option_name();
    const auto line = layout.key_lines.find(key);
    ThrowAt(source, "unknown key '" + key + "'", line == layout.key_lines.end() ? 0 : line->second);
  } catch (const po::invalid_config_file_syntax& e) {
    ThrowAt(source, "invalid line '" + e.tokens() + "': expected 'key = value' or '[section]'",
            LineOf(text, e.tokens()));
  } catch (const po::error& e) {
    throw SceneError(source + ": " + e.what());
  }
}

std::map<std::string, std::string> ParseKeyValues(const std::string& text,
                                                  const std::string& source, const Layout& layout) {
  po::options_description options;
  for (const char* key : kKnownKeys) options.add_options()(key, po::value<std::string>());
  std::set<std::string> push_sections;  // [push.N]: their keys are those of [push]
  for (const auto& section : layout.sections) {
    if (PushSectionNumber(section.first) > 0) push_sections.insert(section.first);
  }
  for (const std::string& section : push_sections) {
    for (const char* key : kPushKeys) {
      options.add_options()((section + "." + key).c_str(), po::value<std::string>());
    }
  }
  std::map<std::string, std::string> values;
  for (const po::option& option : ParseWithBoost(text, options, source, layout).options) {
    const std::string value = option.value.empty() ? "" : option.value.front();
    if (!values.emplace(option.string_key, value).second) {
      throw SceneError(source + ": " + Display(option.string_key) + ": given more than once");
    }
  }
  return values;
}

/// A misnumbered [push.N] section: its keys would otherwise be reported as unknown keys.
void CheckPushSections(const std::string& source, const Layout& layout) {
  for (const auto& [name, line] : layout.sections) {
    if (name.rfind("push.", 0) == 0 && PushSectionNumber(name) == 0) {
      ThrowAt(source, "unknown section [" + name + "]: push sections are [push.1], [push.2], ...",
              line);
    }
  }
}

/// Boost skips empty sections silently; an unknown one is still a mistake.
void CheckSections(const Reader& reader, const Layout& layout) {
  for (const auto& [name, line] : layout.sections) {
    if (kKnownSections.count(name) == 0 && PushSectionNumber(name) == 0) {
      reader.FailAt("unknown section [" + name + "]", line);
    }
  }
}

SliderProperties ReadSlider(const Reader& r) {
  using C = Reader::Check;
  SliderProperties s;
  s.mass_kg = r.Number("slider.mass", C::kPositive);
  s.inertia_kgm2 = r.Number("slider.inertia", C::kPositive);
  s.com_height_m = r.Number("slider.com_height", C::kNonNegative);
  s.gravity_mps2 = r.Number("slider.gravity", 9.81, C::kPositive);
  return s;
}

FrictionParameters ReadFriction(const Reader& r) {
  using C = Reader::Check;
  return {r.Number("friction.mu", C::kPositive), r.Number("friction.e_t", C::kPositive),
          r.Number("friction.e_o", C::kPositive), r.Number("friction.e_r", C::kPositive)};
}

/// Builds the patch once its keys are known to fit the shape; ContactPatch's own checks
/// (ring inner < outer, simple CCW polygon) are blamed on `blame`.
ContactPatch BuildPatch(const Reader& r, const std::string& shape) {
  using C = Reader::Check;
  std::string blame = "patch.shape";
  try {
    if (shape == "rectangle") {
      return ContactPatch::Rectangle(r.Number("patch.width", C::kPositive),
                                     r.Number("patch.length", C::kPositive));
    }
    if (shape == "disk") return ContactPatch::Disk(r.Number("patch.radius", C::kPositive));
    if (shape == "ring") {
      const double outer = r.Number("patch.radius", C::kPositive);
      blame = "patch.inner_radius";
      return ContactPatch::Ring(outer, r.Number("patch.inner_radius", C::kNonNegative));
    }
    blame = "patch.vertices";
    const std::vector<double> xy = r.Numbers(blame);
    if (xy.size() % 2 != 0) r.Fail(blame, "needs pairs \"x1 y1 x2 y2 ...\" (odd count)");
    std::vector<Eigen::Vector2d> vertices;
    for (size_t i = 0; i + 1 < xy.size(); i += 2) vertices.emplace_back(xy[i], xy[i + 1]);
    return ContactPatch::Polygon(vertices);
  } catch (const std::invalid_argument& e) {
    r.Fail(blame, e.what());
  }
}

ContactPatch ReadPatch(const Reader& r) {
  const std::string& shape = r.Text("patch.shape");
  const auto uses = kShapeKeys.find(shape);
  if (uses == kShapeKeys.end()) {
    r.Fail("patch.shape", "unknown shape (rectangle, disk, ring, polygon)");
  }
  for (const char* name : kPatchKeys) {
    if (r.Has(std::string("patch.") + name) && uses->second.count(name) == 0) {
      r.Fail(std::string("patch.") + name, "not used by shape '" + shape + "'");
    }
  }
  return BuildPatch(r, shape);
}

PlanarState ReadInitial(const Reader& r) {
  const auto get = [&](const char* key) {
    return r.Number(std::string("initial.") + key, 0.0, Reader::Check::kFinite);
  };
  PlanarState s;
  s.x = get("x");
  s.y = get("y");
  s.theta = get("theta");
  s.vx = get("vx");
  s.vy = get("vy");
  s.wz = get("wz");
  return s;
}

/// The cosine and the time window of a push in `section`; `p` holds the rest already.
void ReadPushTiming(const Reader& r, const std::string& section, PushSpec& p) {
  using C = Reader::Check;
  const std::string k = section + ".";
  p.amplitude_n = r.Number(k + "amplitude", 0.0, C::kFinite);
  p.period_s = r.Number(k + "period", 0.0, C::kNonNegative);
  if (p.amplitude_n != 0.0 && !(p.period_s > 0.0)) {
    r.Fail(k + "period", "must be > 0 when amplitude = " + ExactNumber(p.amplitude_n));
  }
  p.start_s = r.Number(k + "start", 0.0, C::kFinite);
  p.stop_s = r.Number(k + "stop", 1e300, C::kFinite);
  if (!(p.stop_s > p.start_s)) r.Fail(k + "stop", "must be > start = " + ExactNumber(p.start_s));
}

/// One push from `section` ("push" or "push.N").
PushSpec ReadPush(const Reader& r, const std::string& section, double com_height_m) {
  const std::string k = section + ".";
  PushSpec p;
  p.point_body = r.Pair(k + "point");
  p.height_m = r.Number(k + "height", com_height_m, Reader::Check::kFinite);
  if (r.Has(k + "direction")) {
    const Eigen::Vector2d d = r.Pair(k + "direction");
    if (d.norm() == 0.0) r.Fail(k + "direction", "must be non-zero");
    p.direction_body = d.normalized();
  }
  p.force_n = r.Number(k + "force", Reader::Check::kFinite);
  ReadPushTiming(r, section, p);
  return p;
}

/// [push], then [push.N] in increasing N.
std::vector<PushSpec> ReadPushes(const Reader& r, const Layout& layout, double com_height_m) {
  std::vector<PushSpec> pushes;
  if (r.HasSection("push")) pushes.push_back(ReadPush(r, "push", com_height_m));
  std::map<long, std::string> numbered;
  for (const auto& section : layout.sections) {
    if (const long n = PushSectionNumber(section.first); n > 0) numbered[n] = section.first;
  }
  for (const auto& [n, section] : numbered) pushes.push_back(ReadPush(r, section, com_height_m));
  return pushes;
}

/// The world point of body point `p` with the slider at `pose`.
Eigen::Vector2d ToWorld(const PlanarState& pose, const Eigen::Vector2d& p) {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  return {pose.x + c * p.x() - s * p.y(), pose.y + s * p.x() + c * p.y()};
}

/// Where the tip centre starts so that, moving along `direction` towards `point` (on the
/// outline), the tip just touches the outline: from beyond the patch's reach, the travel to
/// the touch (TravelToTouch).
Eigen::Vector2d TouchingStart(const ContactPatch& patch, const PlanarState& pose,
                              const Eigen::Vector2d& point, const Eigen::Vector2d& direction,
                              double tip_radius_m) {
  double reach = 0;
  for (const Eigen::Vector2d& p : patch.Outline()) reach = std::max(reach, p.norm());
  const double back = 2 * reach + tip_radius_m + 1e-3;  // the tip apart from the slider there
  const Eigen::Vector2d from = point - back * direction;
  return from + TravelToTouch(patch, pose, from, direction, tip_radius_m, back) * direction;
}

/// The tip's path of [pusher]: either a straight push from a point of the outline (`point`,
/// `direction` in the body frame at the initial pose, `distance`, `speed`), the tip centre
/// starting behind the point along the direction, just touching; or waypoints (`start`, `path` "x1
/// y1 x2 y2 ..." in the world frame, `speed` one for all segments or one each). `start_time` delays
/// it.
PusherPath ReadPusherPath(const Reader& r, const PlanarState& initial, const ContactPatch& patch,
                          double tip_radius_m, const std::string& directory) {
  using C = Reader::Check;
  const double start_s = r.Number("pusher.start_time", 0.0, C::kNonNegative);
  const bool straight = r.Has("pusher.point"), waypoints = r.Has("pusher.path");
  const bool file = r.Has("pusher.path_file");
  if (straight + waypoints + file != 1) {
    r.Fail(straight ? (waypoints ? "pusher.path" : "pusher.path_file") : "pusher.point",
           "[pusher] needs one of: point, direction, distance and speed (a straight push); "
           "start, path and speed (waypoints); or path_file (a CSV of t, x, y)");
  }
  if (file) {
    std::string path = r.Text("pusher.path_file");
    if (!path.empty() && path.front() != '/' && !directory.empty()) path = directory + "/" + path;
    try {
      const PusherPath read = ReadPusherPathCsv(path);
      std::vector<double> times = read.times_s();
      for (double& t : times) t += start_s;
      return PusherPath(times, read.points_m());
    } catch (const std::exception& e) {
      r.Fail("pusher.path_file", e.what());
    }
  }
  const std::vector<double> speeds = r.Numbers("pusher.speed");
  for (double v : speeds) {
    if (!(v > 0)) r.Fail("pusher.speed", "must be > 0");
  }
  try {
    if (straight) {
      if (speeds.size() != 1) r.Fail("pusher.speed", "a straight push has one speed");
      const Eigen::Vector2d d = r.Pair("pusher.direction");
      if (d.norm() == 0.0) r.Fail("pusher.direction", "must be non-zero");
      const Eigen::Vector2d dir = (ToWorld(initial, d) - ToWorld(initial, {0, 0})).normalized();
      const Eigen::Vector2d point = ToWorld(initial, r.Pair("pusher.point"));
      const Eigen::Vector2d start = TouchingStart(patch, initial, point, dir, tip_radius_m);
      const double distance = r.Number("pusher.distance", C::kPositive);
      return PusherPath::Polyline(start_s, start, {start + distance * dir}, speeds);
    }
    const std::vector<double> xy = r.Numbers("pusher.path");
    if (xy.empty() || xy.size() % 2 != 0) {
      r.Fail("pusher.path", "needs pairs \"x1 y1 x2 y2 ...\" (world frame, m)");
    }
    std::vector<Eigen::Vector2d> points;
    for (size_t i = 0; i + 1 < xy.size(); i += 2) points.emplace_back(xy[i], xy[i + 1]);
    std::vector<double> each = speeds;
    if (each.size() == 1) each.assign(points.size(), speeds.front());
    if (each.size() != points.size()) {
      r.Fail("pusher.speed",
             "needs one speed, or one per path segment (" + std::to_string(points.size()) + ")");
    }
    return PusherPath::Polyline(start_s, r.Pair("pusher.start"), points, each);
  } catch (const std::invalid_argument& e) {
    r.Fail(straight ? "pusher.point" : "pusher.path", e.what());
  }
}

/// [pusher]: a position-controlled tip (forward_model/pusher.h).
Pusher ReadPusher(const Reader& r, const PlanarState& initial, const ContactPatch& patch,
                  const std::string& directory) {
  using C = Reader::Check;
  Pusher p;
  p.tip_radius_m = r.Number("pusher.tip_radius", p.tip_radius_m, C::kNonNegative);
  p.mu = r.Number("pusher.mu", p.mu, C::kNonNegative);
  if (r.Has("pusher.height")) p.height_m = r.Number("pusher.height", C::kNonNegative);
  p.path = ReadPusherPath(r, initial, patch, p.tip_radius_m, directory);
  return p;
}

/// [program]: the random program's spec (random = N is required in the section).
RandomProgramSpec ReadProgramSpec(const Reader& r) {
  using C = Reader::Check;
  RandomProgramSpec spec;
  const std::uint64_t count = r.Integer("program.random", 0, 1);
  if (!r.Has("program.random")) r.Text("program.random");  // throws "missing required key"
  if (count > 10000) r.Fail("program.random", "must be <= 10000");
  spec.count = static_cast<int>(count);
  spec.seed = r.Integer("program.seed", spec.seed, 0);
  spec.force_n = r.Range("program.force", C::kPositive);
  spec.amplitude_fraction =
      r.Range("program.amplitude_fraction", spec.amplitude_fraction, C::kNonNegative);
  spec.period_s = r.Range("program.period", spec.period_s, C::kPositive);
  spec.duration_s = r.Range("program.duration", spec.duration_s, C::kPositive);
  spec.rest_s = r.Range("program.rest", spec.rest_s, C::kNonNegative);
  spec.height_m = r.Range("program.height", C::kFinite);
  spec.spread_rad = r.Number("program.spread", spec.spread_rad, C::kNonNegative);
  if (!(spec.spread_rad <= kPi / 2)) r.Fail("program.spread", "must be <= pi/2 rad");
  spec.max_lever_fraction = r.Number("program.max_lever", spec.max_lever_fraction, C::kNonNegative);
  if (!(spec.max_lever_fraction <= 1.0)) r.Fail("program.max_lever", "must be <= 1");
  spec.through_cm = r.Bool("program.through_cm", spec.through_cm);
  spec.time_grid_s = r.Number("program.time_grid", 0.0, C::kNonNegative);
  spec.start_s = r.Number("program.start", spec.start_s, C::kNonNegative);
  return spec;
}

NoiseSpec ReadNoise(const Reader& r) {
  using C = Reader::Check;
  NoiseSpec n;
  n.pose_m = r.Number("noise.pose", 0.0, C::kNonNegative);
  n.angle_rad = r.Number("noise.angle", 0.0, C::kNonNegative);
  n.velocity_mps = r.Number("noise.velocity", 0.0, C::kNonNegative);
  n.spin_radps = r.Number("noise.spin", 0.0, C::kNonNegative);
  n.force_relative = r.Number("noise.force_relative", 0.0, C::kNonNegative);
  n.force_n = r.Number("noise.force", 0.0, C::kNonNegative);
  n.push_point_m = r.Number("noise.push_point", 0.0, C::kNonNegative);
  n.outlier_fraction = r.Number("noise.outlier_fraction", 0.0, C::kNonNegative);
  if (!(n.outlier_fraction <= 1.0)) r.Fail("noise.outlier_fraction", "must be <= 1");
  n.outlier_m = r.Number("noise.outlier", 0.0, C::kNonNegative);
  n.seed = r.Integer("noise.seed", n.seed, 0);
  n.force_bias_x_n = r.Number("noise.force_bias_x", 0.0, C::kFinite);
  n.force_bias_y_n = r.Number("noise.force_bias_y", 0.0, C::kFinite);
  n.force_delay_s = r.Number("noise.force_delay", 0.0, C::kFinite);
  return n;
}

/// [sim] log_every, [log] and [noise].
LogSpec ReadLogSpec(const Reader& r, bool has_pushes) {
  LogSpec log;
  const std::uint64_t every = r.Integer("sim.log_every", 1, 1);
  if (every > 1000000) r.Fail("sim.log_every", "must be <= 1000000");
  log.log_every = static_cast<int>(every);
  if (r.Has("log.write") && !ParseLogMotion(r.Text("log.write"), &log.motion)) {
    r.Fail("log.write", "must be poses, velocities or both");
  }
  if (r.Has("log.push") && !ParseLogPush(r.Text("log.push"), &log.push)) {
    r.Fail("log.push", "must be point or moments");
  }
  if (log.motion == LogMotion::kVelocities && log.push == LogPush::kPoint && has_pushes) {
    r.Fail("log.write", "velocities only needs [log] push = moments (push points need poses)");
  }
  if (r.Has("log.wrench") && !ParseLogWrench(r.Text("log.wrench"), &log.wrench)) {
    r.Fail("log.wrench", "must be at-row-time or interval-mean");
  }
  if (log.wrench == LogWrench::kIntervalMean && log.push == LogPush::kPoint && has_pushes) {
    r.Fail("log.wrench",
           "interval-mean needs [log] push = moments (a mean wrench has no push "
           "point)");
  }
  if (r.Has("log.step_info")) log.step_info = r.Bool("log.step_info", true);
  log.wrap_theta = r.Bool("log.wrap_theta", false);
  log.noise = ReadNoise(r);
  return log;
}

}  // namespace

LoggedScene ParseScene(const std::string& text, const std::string& source) {
  // Left in, a byte-order mark made the first line "invalid line '\xEF\xBB\xBF'".
  const std::string ini_text(text::WithoutByteOrderMark(text));
  const Layout layout = ScanLayout(ini_text);
  CheckPushSections(source, layout);
  const Reader r(source, ParseKeyValues(ini_text, source, layout), layout);
  CheckSections(r, layout);
  LoggedScene scene;
  scene.source = source;
  scene.slider = ReadSlider(r);
  scene.friction = ReadFriction(r);
  scene.patch = ReadPatch(r);
  scene.initial = ReadInitial(r);
  scene.pushes = ReadPushes(r, layout, scene.slider.com_height_m);
  if (r.HasSection("pusher")) {
    if (!scene.pushes.empty() || r.HasSection("program")) {
      r.FailAt(
          "[pusher] cannot be combined with [push] or [program] sections: a scene is "
          "driven by forces or by a pusher",
          LineOf(ini_text, "[pusher]"));
    }
    // A path file is found beside the scene file (source is its path when it has one).
    const auto slash = source.find_last_of('/');
    scene.pusher =
        ReadPusher(r, scene.initial, scene.patch,
                   slash == std::string::npos ? std::string(".") : source.substr(0, slash));
  }
  scene.dt_s = r.Number("sim.dt", Reader::Check::kPositive);
  if (r.HasSection("program")) {
    if (!scene.pushes.empty()) {
      r.FailAt("[program] cannot be combined with [push] sections: use one or the other",
               LineOf(ini_text, "[program]"));
    }
    RandomProgramSpec spec = ReadProgramSpec(r);
    if (spec.time_grid_s > 0.0) {
      if (!(spec.time_grid_s > scene.dt_s)) r.Fail("program.time_grid", "must be > [sim] dt");
      spec.grid_lead_s = scene.dt_s / 2;  // switch half a step early: see RandomProgramSpec
    }
    const PushProgram program =
        RandomPushProgram(spec, scene.patch, scene.slider, scene.friction.reduced());
    scene.pushes = program.pushes;
    scene.duration_s = r.Number("sim.duration", program.end_s, Reader::Check::kPositive);
  } else {
    // A pusher's scene runs to the end of its path and a little beyond, to the slider's rest.
    scene.duration_s = scene.pusher && !r.Has("sim.duration")
                           ? scene.pusher->path.end_s() + kPusherRunOut_s
                           : r.Number("sim.duration", Reader::Check::kPositive);
  }
  scene.log = ReadLogSpec(r, !scene.pushes.empty() || scene.pusher.has_value());
  return scene;
}

LoggedScene LoadScene(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SceneError(path + ": cannot open scene file for reading");
  std::string text;
  try {  // libstdc++ throws from the read itself, e.g. for a directory
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::exception& e) {
    throw SceneError(path + ": cannot read scene file: " + e.what());
  }
  if (in.bad()) throw SceneError(path + ": cannot read scene file");
  return ParseScene(text, path);
}

}  // namespace slideid
