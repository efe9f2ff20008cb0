#include "forward_model/scene.h"

#include <algorithm>
#include <boost/program_options.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

namespace slideid {
namespace {

namespace po = boost::program_options;

constexpr double kPi = 3.14159265358979323846;

/// Every key a scene may hold, as Boost names it ("section.key").
const char* const kKnownKeys[] = {
    "slider.mass",    "slider.inertia", "slider.com_height", "slider.gravity",
    "friction.mu",    "friction.e_t",   "friction.e_o",      "friction.e_r",
    "patch.shape",    "patch.width",    "patch.length",      "patch.radius",
    "patch.inner_radius",               "patch.vertices",
    "initial.x",      "initial.y",      "initial.theta",
    "initial.vx",     "initial.vy",     "initial.wz",
    "push.point",     "push.height",    "push.direction",    "push.force",
    "push.amplitude", "push.period",    "push.start",        "push.stop",
    "sim.dt",         "sim.duration"};
const std::set<std::string> kKnownSections = {"slider", "friction", "patch",
                                              "initial", "push",    "sim"};
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

std::string FormatDouble(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
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

/// "slider.mass" -> "[slider] mass".
std::string Display(const std::string& key) {
  const auto dot = key.find('.');
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
  const auto in_section = [&](const auto& kv) { return kv.first.rfind(prefix, 0) == 0; };
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

void Reader::Fail(const std::string& key, const std::string& message) const {
  std::string where = source_ + ": " + Display(key);
  if (const auto it = values_.find(key); it != values_.end()) where += " = " + it->second;
  const auto line = layout_.key_lines.find(key);
  if (line == layout_.key_lines.end()) throw SceneError(where + ": " + message);
  throw SceneError(where + ": " + message + " (line " + std::to_string(line->second) + ")");
}

void Reader::FailAt(const std::string& message, int line) const {
  ThrowAt(source_, message, line);
}

/// Boost's parse; its exceptions become SceneError naming the file and the key.
po::parsed_options ParseWithBoost(const std::string& text, const po::options_description& options,
                                  const std::string& source, const Layout& layout) {
  std::istringstream in(text);
  try {
    return po::parse_config_file(in, options, /*allow_unregistered=*/false);
  } catch (const po::unknown_option& e) {
    const std::string key = e.get_option_name();
    const auto line = layout.key_lines.find(key);
    ThrowAt(source, "unknown key '" + key + "'",
            line == layout.key_lines.end() ? 0 : line->second);
  } catch (const po::invalid_config_file_syntax& e) {
    ThrowAt(source, "invalid line '" + e.tokens() + "': expected 'key = value' or '[section]'",
            LineOf(text, e.tokens()));
  } catch (const po::error& e) {
    throw SceneError(source + ": " + e.what());
  }
}

std::map<std::string, std::string> ParseKeyValues(const std::string& text,
                                                  const std::string& source,
                                                  const Layout& layout) {
  po::options_description options;
  for (const char* key : kKnownKeys) options.add_options()(key, po::value<std::string>());
  std::map<std::string, std::string> values;
  for (const po::option& option : ParseWithBoost(text, options, source, layout).options) {
    const std::string value = option.value.empty() ? "" : option.value.front();
    if (!values.emplace(option.string_key, value).second) {
      throw SceneError(source + ": " + Display(option.string_key) + ": given more than once");
    }
  }
  return values;
}

/// Boost skips empty sections silently; an unknown one is still a mistake.
void CheckSections(const Reader& reader, const Layout& layout) {
  for (const auto& [name, line] : layout.sections) {
    if (kKnownSections.count(name) == 0) reader.FailAt("unknown section [" + name + "]", line);
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

/// The cosine and the time window of a push; `p` holds the rest already.
void ReadPushTiming(const Reader& r, PushSpec& p) {
  using C = Reader::Check;
  p.amplitude_N = r.Number("push.amplitude", 0.0, C::kFinite);
  p.period_s = r.Number("push.period", 0.0, C::kNonNegative);
  if (p.amplitude_N != 0.0 && !(p.period_s > 0.0)) {
    r.Fail("push.period", "must be > 0 when amplitude = " + FormatDouble(p.amplitude_N));
  }
  p.start_s = r.Number("push.start", 0.0, C::kFinite);
  p.stop_s = r.Number("push.stop", 1e300, C::kFinite);
  if (!(p.stop_s > p.start_s)) r.Fail("push.stop", "must be > start = " + FormatDouble(p.start_s));
}

PushSpec ReadPush(const Reader& r, double com_height_m) {
  PushSpec p;
  p.point_body = r.Pair("push.point");
  p.height_m = r.Number("push.height", com_height_m, Reader::Check::kFinite);
  if (r.Has("push.direction")) {
    const Eigen::Vector2d d = r.Pair("push.direction");
    if (d.norm() == 0.0) r.Fail("push.direction", "must be non-zero");
    p.direction_body = d.normalized();
  }
  p.force_N = r.Number("push.force", Reader::Check::kFinite);
  ReadPushTiming(r, p);
  return p;
}

}  // namespace

double PushSpec::MagnitudeAt(double t_s) const {
  if (t_s < start_s || t_s >= stop_s) return 0.0;
  double magnitude = force_N;
  if (period_s > 0.0) magnitude += amplitude_N * std::cos(2.0 * kPi * t_s / period_s);
  return std::max(0.0, magnitude);  // a pusher cannot pull
}

AppliedWrench PushSpec::WrenchAt(double t_s, const PlanarState& pose, double com_height_m,
                                 Eigen::Vector3d* point_world) const {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const Eigen::Vector2d r_xy(c * point_body.x() - s * point_body.y(),
                             s * point_body.x() + c * point_body.y());
  const Eigen::Vector2d f =
      MagnitudeAt(t_s) * Eigen::Vector2d(c * direction_body.x() - s * direction_body.y(),
                                         s * direction_body.x() + c * direction_body.y());
  if (point_world != nullptr) *point_world = {pose.x + r_xy.x(), pose.y + r_xy.y(), height_m};
  return WrenchFromForceAt(f.x(), f.y(), 0.0, r_xy.x(), r_xy.y(), height_m - com_height_m);
}

Scene ParseScene(const std::string& ini_text, const std::string& source) {
  const Layout layout = ScanLayout(ini_text);
  const Reader r(source, ParseKeyValues(ini_text, source, layout), layout);
  CheckSections(r, layout);
  Scene scene;
  scene.source = source;
  scene.slider = ReadSlider(r);
  scene.friction = ReadFriction(r);
  scene.patch = ReadPatch(r);
  scene.initial = ReadInitial(r);
  if (r.HasSection("push")) scene.pushes.push_back(ReadPush(r, scene.slider.com_height_m));
  scene.dt_s = r.Number("sim.dt", Reader::Check::kPositive);
  scene.duration_s = r.Number("sim.duration", Reader::Check::kPositive);
  return scene;
}

Scene LoadScene(const std::string& path) {
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
