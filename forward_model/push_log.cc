#include "forward_model/push_log.h"

#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <ostream>
#include <string_view>
#include <system_error>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#include <libfccp/csv.h>
#pragma GCC diagnostic pop

namespace slideid {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kDefaultGravity = 9.81;  // log-format.md: gravity defaults to 9.81 m/s^2
// Writer: the residual moment is nudged by at most this many ulps so that the reader's sum
// (r x f) + residual reproduces the total bit for bit; 4 covers every rounding case that
// can be repaired at all (the plain difference is off by at most one or two ulps).
constexpr int kMaxResidualNudges = 4;

// ---------------------------------------------------------------------------------------
// Columns
// ---------------------------------------------------------------------------------------

/// The numeric columns the reader knows; `mode` is the only text column.
enum Col : int {
  kT, kX, kY, kTheta, kVx, kVy, kWz, kFx, kFy, kFz, kTx, kTy, kTz,
  kPx, kPy, kPz, kAx, kAy, kPt, kPo, kPr, kSigma, kNumNumeric
};
constexpr std::array<const char*, kNumNumeric> kColumnNames = {
    "t",  "x",  "y",  "theta", "vx", "vy", "wz", "fx", "fy", "fz",    "tx",
    "ty", "tz", "px", "py",    "pz", "ax", "ay", "pt", "po", "pr", "sigma"};
constexpr const char* kModeColumn = "mode";

/// Where each known column sits in the header (field index, -1 when absent).
struct Header {
  std::string text;  // for messages
  int line = 0;
  int num_fields = 0;
  std::array<int, kNumNumeric> field;
  int mode_field = -1;

  Header() { field.fill(-1); }
  bool Has(Col c) const { return field[c] >= 0; }
  bool HasAll(Col a, Col b, Col c) const { return Has(a) && Has(b) && Has(c); }
  bool HasAny(Col a, Col b, Col c) const { return Has(a) || Has(b) || Has(c); }
};

/// One data line, numbers of absent columns 0.
struct RawRow {
  int line = 0;
  std::array<double, kNumNumeric> v{};
  std::optional<SampleMode> mode;
};

/// `# key = value` comments before the header.
struct Metadata {
  std::map<std::string, std::pair<double, int>> numbers;  // key -> (value, line)
  std::optional<std::string> patch;
  std::vector<std::pair<std::string, std::string>> extra;
};

constexpr std::array<const char*, 4> kSliderKeys = {"mass", "inertia", "com_height",
                                                    "gravity"};
constexpr std::array<const char*, 4> kTruthKeys = {"mu", "e_t", "e_o", "e_r"};

// ---------------------------------------------------------------------------------------
// Text helpers
// ---------------------------------------------------------------------------------------

std::string_view Trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  for (;;) {
    const auto comma = line.find(',');
    fields.push_back(Trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) return fields;
    line.remove_prefix(comma + 1);
  }
}

bool IsIdentifier(std::string_view s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s.front()))) return false;
  for (char c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  }
  return true;
}

/// Whole-cell parse of a finite number; locale independent (std::from_chars), so "nan",
/// "inf", "1.2abc", "" and out-of-range values are all rejected.
std::optional<double> ParseFiniteNumber(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);  // from_chars rejects '+'
  if (s.empty() || s.front() == '+') return std::nullopt;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::string FormatNumber(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

/// Shortest text that reads back to `value`, for messages (the writer uses FormatNumber).
std::string ShortNumber(double value) {
  char buffer[40];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

const char* ModeName(SampleMode mode) {
  switch (mode) {
    case SampleMode::kStart: return "start";
    case SampleMode::kSlide: return "slide";
    case SampleMode::kStick: return "stick";
  }
  return "slide";
}

std::optional<SampleMode> ParseMode(std::string_view s) {
  if (s == "start") return SampleMode::kStart;
  if (s == "slide") return SampleMode::kSlide;
  if (s == "stick") return SampleMode::kStick;
  return std::nullopt;
}

template <std::size_t N>
bool Contains(const std::array<const char*, N>& keys, std::string_view key) {
  for (const char* k : keys) {
    if (key == k) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------
// Reader: preamble (metadata comments) and header
// ---------------------------------------------------------------------------------------

/// Context shared by the reader's phases.
struct ReadContext {
  const std::string& path;
  const LogReadOptions& options;
  LogReadReport& report;

  [[noreturn]] void Fail(int line, const std::string& column, const std::string& what) const {
    throw LogError(path, line, column, what);
  }
};

/// Adds one `# ...` comment line to the metadata when it has the `key = value` form.
void ParseCommentLine(const ReadContext& ctx, std::string_view line, int line_no,
                      Metadata& meta) {
  line.remove_prefix(1);  // '#'
  const auto eq = line.find('=');
  if (eq == std::string_view::npos) return;
  const std::string key(Trim(line.substr(0, eq)));
  if (!IsIdentifier(key)) return;  // prose that happens to contain '='
  const std::string value(Trim(line.substr(eq + 1)));
  if (key == "patch") {
    if (meta.patch) ctx.Fail(line_no, "", "metadata 'patch' given twice");
    meta.patch = value;
  } else if (Contains(kSliderKeys, key) || Contains(kTruthKeys, key)) {
    if (meta.numbers.count(key)) ctx.Fail(line_no, "", "metadata '" + key + "' given twice");
    const auto number = ParseFiniteNumber(value);
    if (!number) {
      ctx.Fail(line_no, "", "metadata '" + key + "': '" + value + "' is not a finite number");
    }
    meta.numbers[key] = {*number, line_no};
  } else {
    meta.extra.emplace_back(key, value);
  }
}

/// Reads comment and blank lines up to the header; returns the header line's text.
std::string ReadPreamble(const ReadContext& ctx, io::LineReader& in, Metadata& meta,
                         int& header_line) {
  while (const char* raw = in.next_line()) {
    const std::string_view line = Trim(raw);
    const int line_no = static_cast<int>(in.get_file_line());
    if (line.empty()) continue;
    if (line.front() == '#') {
      ParseCommentLine(ctx, line, line_no, meta);
      continue;
    }
    header_line = line_no;
    return std::string(line);
  }
  ctx.Fail(0, "", "no header line: the file is empty or holds only comments");
}

void RequireGroup(const ReadContext& ctx, const Header& h, Col a, Col b, Col c,
                  const char* group) {
  if (h.HasAny(a, b, c) && !h.HasAll(a, b, c)) {
    const Col missing = !h.Has(a) ? a : !h.Has(b) ? b : c;
    ctx.Fail(h.line, kColumnNames[missing],
             std::string("missing: the ") + group + " group needs all of " + kColumnNames[a] +
                 ", " + kColumnNames[b] + ", " + kColumnNames[c]);
  }
}

void CheckRequiredColumns(const ReadContext& ctx, const Header& h) {
  if (!h.Has(kT)) ctx.Fail(h.line, "t", "missing (column names are lower case)");
  RequireGroup(ctx, h, kX, kY, kTheta, "pose");
  RequireGroup(ctx, h, kVx, kVy, kWz, "velocity");
  RequireGroup(ctx, h, kPx, kPy, kPz, "push point");
  if (!h.Has(kX) && !h.Has(kVx)) {
    ctx.Fail(h.line, "", "neither the pose columns (x, y, theta) nor the velocity columns "
                         "(vx, vy, wz) are present");
  }
  if (h.Has(kPx) && !h.Has(kX)) {
    ctx.Fail(h.line, "px", "push points need the pose columns x, y, theta to form r");
  }
}

/// Records one header name: a known column's field index, or an unknown column.
void AddHeaderName(const ReadContext& ctx, Header& h, const std::string& name, int index) {
  if (name == kModeColumn) {
    h.mode_field = index;
    return;
  }
  for (int c = 0; c < kNumNumeric; ++c) {
    if (name == kColumnNames[c]) {
      h.field[c] = index;
      return;
    }
  }
  ctx.report.unknown_columns.push_back(name);
}

Header ParseHeader(const ReadContext& ctx, const std::string& text, int line) {
  Header h;
  h.text = text;
  h.line = line;
  const auto names = SplitFields(text);
  h.num_fields = static_cast<int>(names.size());
  std::map<std::string, int> seen;
  for (int i = 0; i < h.num_fields; ++i) {
    const std::string name(names[i]);
    if (ParseFiniteNumber(name)) {
      ctx.Fail(line, "", "no header: the first non-comment line holds numbers ('" + text +
                             "'); it must name the columns, e.g. t,x,y,theta");
    }
    if (name.empty()) ctx.Fail(line, "", "empty column name in field " + std::to_string(i + 1));
    if (!seen.emplace(name, i).second) ctx.Fail(line, name, "duplicate column name");
    AddHeaderName(ctx, h, name, i);
  }
  CheckRequiredColumns(ctx, h);
  return h;
}

// ---------------------------------------------------------------------------------------
// Reader: data rows
// ---------------------------------------------------------------------------------------

RawRow ParseRow(const ReadContext& ctx, const Header& h, std::string_view line, int line_no) {
  const auto cells = SplitFields(line);
  if (static_cast<int>(cells.size()) != h.num_fields) {
    ctx.Fail(line_no, "", "expected " + std::to_string(h.num_fields) +
                              " fields as in the header on line " + std::to_string(h.line) +
                              ", found " + std::to_string(cells.size()));
  }
  RawRow row;
  row.line = line_no;
  for (int c = 0; c < kNumNumeric; ++c) {
    if (!h.Has(static_cast<Col>(c))) continue;
    const std::string_view cell = cells[h.field[c]];
    const auto value = ParseFiniteNumber(cell);
    if (!value) {
      ctx.Fail(line_no, kColumnNames[c], "'" + std::string(cell) + "' is not a finite number");
    }
    row.v[c] = *value;
  }
  if (h.mode_field >= 0) {
    const std::string_view cell = cells[h.mode_field];
    row.mode = ParseMode(cell);
    if (!row.mode) {
      ctx.Fail(line_no, kModeColumn, "'" + std::string(cell) + "' is not start, slide or stick");
    }
  }
  return row;
}

std::vector<RawRow> ReadRows(const ReadContext& ctx, io::LineReader& in, const Header& h) {
  std::vector<RawRow> rows;
  while (const char* raw = in.next_line()) {
    const std::string_view line = Trim(raw);
    // fccp's comment policy would skip '#' lines anywhere; only those before the header
    // are metadata, later ones are plain comments.
    if (line.empty() || line.front() == '#') continue;
    rows.push_back(ParseRow(ctx, h, line, static_cast<int>(in.get_file_line())));
    if (rows.size() > 1) {
      const RawRow& prev = rows[rows.size() - 2];
      if (!(rows.back().v[kT] > prev.v[kT])) {
        ctx.Fail(rows.back().line, "t",
                 "t = " + ShortNumber(rows.back().v[kT]) + " is not greater than t = " +
                     ShortNumber(prev.v[kT]) + " on line " + std::to_string(prev.line));
      }
    }
  }
  if (rows.empty()) ctx.Fail(h.line, "", "the header is not followed by any data row");
  return rows;
}

// ---------------------------------------------------------------------------------------
// Reader: slider properties
// ---------------------------------------------------------------------------------------

/// One slider property: its metadata key, command-line option, override and range.
struct PropertySpec {
  const char* key;
  const char* option;
  std::optional<double> SliderOverrides::*override_value;
  double SliderProperties::*field;
  bool zero_allowed;  // com_height may be 0; mass, inertia, gravity must be > 0
};

constexpr std::array<PropertySpec, 4> kPropertySpecs = {{
    {"mass", "--mass", &SliderOverrides::mass_kg, &SliderProperties::mass_kg, false},
    {"inertia", "--inertia", &SliderOverrides::inertia_kgm2, &SliderProperties::inertia_kgm2,
     false},
    {"com_height", "--com-height", &SliderOverrides::com_height_m,
     &SliderProperties::com_height_m, true},
    {"gravity", "--gravity", &SliderOverrides::gravity_mps2, &SliderProperties::gravity_mps2,
     false},
}};

/// Sets one property from the override, else the metadata; returns whether it is known.
bool ResolveProperty(const ReadContext& ctx, const PropertySpec& spec, const Metadata& meta,
                     SliderProperties& slider) {
  const auto& override_value = ctx.options.overrides.*(spec.override_value);
  const auto it = meta.numbers.find(spec.key);
  if (!override_value && it == meta.numbers.end()) return false;
  const double value = override_value ? *override_value : it->second.first;
  const int line = override_value ? 0 : it->second.second;
  const bool ok = std::isfinite(value) && (spec.zero_allowed ? value >= 0.0 : value > 0.0);
  if (!ok) {
    ctx.Fail(line, "", std::string(spec.key) + " = " + ShortNumber(value) +
                           (override_value ? std::string(" (from ") + spec.option + ")"
                                           : std::string(" (metadata)")) +
                           (spec.zero_allowed ? " must be >= 0" : " must be > 0"));
  }
  slider.*(spec.field) = value;
  return true;
}

/// Slider properties from overrides and metadata; `known` says which ones were given.
SliderProperties ResolveSlider(const ReadContext& ctx, const Metadata& meta,
                               std::array<bool, 4>& known) {
  SliderProperties slider;
  slider.gravity_mps2 = kDefaultGravity;
  for (std::size_t i = 0; i < kPropertySpecs.size(); ++i) {
    const PropertySpec& spec = kPropertySpecs[i];
    known[i] = ResolveProperty(ctx, spec, meta, slider);
    const bool is_gravity = i + 1 == kPropertySpecs.size();
    if (!known[i] && !is_gravity && ctx.options.require_slider_properties) {
      ctx.Fail(0, "", std::string("slider ") + spec.key + " is not known: add '# " + spec.key +
                          " = ...' to the log or pass " + spec.option);
    }
  }
  return slider;
}

/// True friction when all four keys are present; partial truth is kept as extra metadata.
void ResolveTruth(const ReadContext& ctx, const Metadata& meta, Trajectory& trajectory) {
  std::size_t present = 0;
  for (const char* key : kTruthKeys) present += meta.numbers.count(key);
  if (present == kTruthKeys.size()) {
    trajectory.true_friction = FrictionParameters{
        meta.numbers.at("mu").first, meta.numbers.at("e_t").first,
        meta.numbers.at("e_o").first, meta.numbers.at("e_r").first};
    return;
  }
  for (const char* key : kTruthKeys) {
    const auto it = meta.numbers.find(key);
    if (it != meta.numbers.end()) {
      trajectory.extra_metadata.emplace_back(key, FormatNumber(it->second.first));
    }
  }
  if (present > 0) {
    ctx.report.notes.push_back("partial true friction (needs mu, e_t, e_o, e_r) kept as "
                               "extra metadata");
  }
}

// ---------------------------------------------------------------------------------------
// Reader: samples
// ---------------------------------------------------------------------------------------

/// Adds multiples of 2 pi so consecutive differences lie in (-pi, pi]; returns the number of
/// rows shifted. Rows needing no shift keep their value bit for bit.
int UnwrapTheta(std::vector<RawRow>& rows) {
  int shifted = 0;
  for (std::size_t u = 1; u < rows.size(); ++u) {
    const double prev = rows[u - 1].v[kTheta];
    const double raw = rows[u].v[kTheta];
    double k = std::round((prev - raw) / kTwoPi);
    // Rounding of the quotient can leave the difference just outside (-pi, pi].
    for (int i = 0; i < 2; ++i) {
      const double diff = raw + k * kTwoPi - prev;
      if (diff > kPi) k -= 1.0;
      else if (diff <= -kPi) k += 1.0;
    }
    if (k != 0.0) {
      rows[u].v[kTheta] = raw + k * kTwoPi;
      ++shifted;
    }
  }
  return shifted;
}

/// Total applied wrench of a row: f, the given moments, plus r x f at the push point.
AppliedWrench RowWrench(const RawRow& row, bool push_point, double com_height_m) {
  const auto& v = row.v;
  AppliedWrench w{v[kFx], v[kFy], v[kFz], 0.0, 0.0, 0.0};
  if (push_point) {
    w = WrenchFromForceAt(v[kFx], v[kFy], v[kFz], v[kPx] - v[kX], v[kPy] - v[kY],
                          v[kPz] - com_height_m);
  }
  // The writer's residual moments rely on this exact order: (r x f) + residual.
  w.tx += v[kTx];
  w.ty += v[kTy];
  w.tz += v[kTz];
  return w;
}

TrajectorySample RowSample(const RawRow& row, const Header& h, double com_height_m,
                           bool first) {
  const auto& v = row.v;
  TrajectorySample s;
  s.t_s = v[kT];
  s.state = PlanarState{v[kX], v[kY], v[kTheta], v[kVx], v[kVy], v[kWz]};
  s.applied = RowWrench(row, h.Has(kPx), com_height_m);
  if (h.Has(kPx)) s.push_point_world = Eigen::Vector3d(v[kPx], v[kPy], v[kPz]);
  s.ecp_world = Eigen::Vector2d(v[kAx], v[kAy]);
  s.pt = v[kPt];
  s.po = v[kPo];
  s.pr = v[kPr];
  s.sigma = v[kSigma];
  s.mode = row.mode ? *row.mode : (first ? SampleMode::kStart : SampleMode::kSlide);
  return s;
}

/// The normal force m g - fz must stay positive (log-format.md: fz reduces it).
void CheckNormalForce(const ReadContext& ctx, const std::vector<RawRow>& rows,
                      const SliderProperties& slider) {
  const double weight = slider.mass_kg * slider.gravity_mps2;
  for (const RawRow& row : rows) {
    if (!(weight - row.v[kFz] > 0.0)) {
      ctx.Fail(row.line, "fz", "vertical force lifts the slider: fz = " +
                                   ShortNumber(row.v[kFz]) + " N is not below m g = " +
                                   ShortNumber(weight) + " N");
    }
  }
}

LogColumns PresentColumns(const Header& h) {
  LogColumns c;
  c.pose = h.Has(kX);
  c.velocity = h.Has(kVx);
  c.force = h.Has(kFx) || h.Has(kFy);
  c.fz = h.Has(kFz);
  c.moments = h.HasAny(kTx, kTy, kTz);
  c.push_point = h.Has(kPx);
  c.step_info = h.Has(kAx) || h.Has(kAy) || h.HasAny(kPt, kPo, kPr) || h.Has(kSigma) ||
                h.mode_field >= 0;
  return c;
}

void FillSamples(const ReadContext& ctx, std::vector<RawRow>& rows, const Header& h,
                 Trajectory& trajectory) {
  const int shifted = h.Has(kTheta) ? UnwrapTheta(rows) : 0;
  if (shifted > 0) {
    ctx.report.notes.push_back("theta unwrapped: " + std::to_string(shifted) +
                               " rows shifted by multiples of 2 pi");
  }
  for (std::size_t u = 0; u < rows.size(); ++u) {
    trajectory.samples.push_back(
        RowSample(rows[u], h, trajectory.slider.com_height_m, u == 0));
  }
  if (!h.Has(kVx)) {
    SetVelocitiesFromPoses(&trajectory);
    ctx.report.velocities_from_poses = true;
    ctx.report.notes.push_back("velocities computed from poses (backward Euler)");
  }
}

void NoteUnknownColumns(const ReadContext& ctx) {
  if (ctx.report.unknown_columns.empty()) return;
  std::string note = "unknown columns ignored:";
  for (const auto& name : ctx.report.unknown_columns) note += " " + name;
  ctx.report.notes.push_back(note);
}

Trajectory ReadFromLines(const ReadContext& ctx, io::LineReader& in) {
  Metadata meta;
  int header_line = 0;
  const std::string header_text = ReadPreamble(ctx, in, meta, header_line);
  const Header header = ParseHeader(ctx, header_text, header_line);
  std::vector<RawRow> rows = ReadRows(ctx, in, header);

  Trajectory trajectory;
  std::array<bool, 4> known{};  // mass, inertia, com_height, gravity (kPropertySpecs order)
  trajectory.slider = ResolveSlider(ctx, meta, known);
  if (header.Has(kPx) && !known[2]) {
    ctx.Fail(0, "", "slider com_height is not known but needed for the moments of px, py, pz: "
                    "add '# com_height = ...' to the log or pass --com-height");
  }
  if (known[0]) {
    CheckNormalForce(ctx, rows, trajectory.slider);
  } else if (header.Has(kFz)) {
    ctx.report.notes.push_back("fz not checked against m g: mass unknown");
  }
  trajectory.patch_spec = meta.patch.value_or("");
  trajectory.extra_metadata = meta.extra;
  ResolveTruth(ctx, meta, trajectory);
  trajectory.columns = PresentColumns(header);
  FillSamples(ctx, rows, header, trajectory);
  NoteUnknownColumns(ctx);
  return trajectory;
}

// ---------------------------------------------------------------------------------------
// Writer
// ---------------------------------------------------------------------------------------

/// The residual r such that the reader's (moment + r) equals total, when one exists.
double ResidualFor(double total, double moment) {
  double residual = total - moment;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kMaxResidualNudges && moment + residual != total; ++i) {
    residual = std::nextafter(residual, moment + residual < total ? kInf : -kInf);
  }
  return residual;
}

/// Where a row's force is written to act: its push point, else the CM (r = 0).
Eigen::Vector3d WrittenPushPoint(const TrajectorySample& s, double com_height_m) {
  if (s.push_point_world) return *s.push_point_world;
  return {s.state.x, s.state.y, com_height_m};
}

/// The tx, ty, tz to write: total moments, minus r x f when push points are written.
Eigen::Vector3d WrittenMoments(const TrajectorySample& s, bool push_point,
                               double com_height_m) {
  const AppliedWrench& a = s.applied;
  if (!push_point) return {a.tx, a.ty, a.tz};
  const Eigen::Vector3d p = WrittenPushPoint(s, com_height_m);
  const AppliedWrench m = WrenchFromForceAt(a.fx, a.fy, a.fz, p.x() - s.state.x,
                                            p.y() - s.state.y, p.z() - com_height_m);
  return {ResidualFor(a.tx, m.tx), ResidualFor(a.ty, m.ty), ResidualFor(a.tz, m.tz)};
}

/// The groups actually written: the requested ones, plus any whose data would otherwise be
/// lost (non-zero forces or moments), plus poses when push points need them.
LogColumns WrittenColumns(const Trajectory& tr) {
  LogColumns c = tr.columns;
  if (!c.pose && !c.velocity) c.pose = c.velocity = true;
  if (c.push_point) c.pose = true;
  for (const TrajectorySample& s : tr.samples) {
    c.force = c.force || s.applied.fx != 0.0 || s.applied.fy != 0.0;
    c.fz = c.fz || s.applied.fz != 0.0;
    if (!c.moments) {
      c.moments = !WrittenMoments(s, c.push_point, tr.slider.com_height_m).isZero(0.0);
    }
  }
  return c;
}

void CheckMetadataEntry(const Trajectory& tr, const std::string& key, const std::string& value) {
  const bool reserved = Contains(kSliderKeys, key) || (key == "patch" && !tr.patch_spec.empty()) ||
                        (Contains(kTruthKeys, key) && tr.true_friction.has_value());
  if (!IsIdentifier(key) || reserved || value.find('\n') != std::string::npos) {
    throw std::invalid_argument("push log metadata '" + key + "' cannot be written: keys must "
                                "be identifiers not written elsewhere, values one line");
  }
}

void WriteMetadata(const Trajectory& tr, std::ostream& out) {
  const SliderProperties& s = tr.slider;
  out << "# mass = " << FormatNumber(s.mass_kg) << "\n# inertia = "
      << FormatNumber(s.inertia_kgm2) << "\n# com_height = " << FormatNumber(s.com_height_m)
      << "\n# gravity = " << FormatNumber(s.gravity_mps2) << "\n";
  if (!tr.patch_spec.empty()) out << "# patch = " << tr.patch_spec << "\n";
  if (tr.true_friction) {
    const FrictionParameters& f = *tr.true_friction;
    out << "# mu = " << FormatNumber(f.mu) << "\n# e_t = " << FormatNumber(f.e_t)
        << "\n# e_o = " << FormatNumber(f.e_o) << "\n# e_r = " << FormatNumber(f.e_r) << "\n";
  }
  for (const auto& [key, value] : tr.extra_metadata) {
    out << "# " << key << " = " << value << "\n";
  }
}

std::string HeaderLine(const LogColumns& c) {
  std::string h = "t";
  if (c.pose) h += ",x,y,theta";
  if (c.velocity) h += ",vx,vy,wz";
  if (c.force) h += ",fx,fy";
  if (c.fz) h += ",fz";
  if (c.push_point) h += ",px,py,pz";
  if (c.moments) h += ",tx,ty,tz";
  if (c.step_info) h += ",ax,ay,pt,po,pr,sigma,mode";
  return h;
}

void Append(std::string& line, std::initializer_list<double> values) {
  for (double v : values) {
    line += ',';
    line += FormatNumber(v);
  }
}

std::string RowLine(const TrajectorySample& s, const LogColumns& c, double com_height_m) {
  std::string line = FormatNumber(s.t_s);
  const PlanarState& q = s.state;
  if (c.pose) Append(line, {q.x, q.y, q.theta});
  if (c.velocity) Append(line, {q.vx, q.vy, q.wz});
  if (c.force) Append(line, {s.applied.fx, s.applied.fy});
  if (c.fz) Append(line, {s.applied.fz});
  if (c.push_point) {
    const Eigen::Vector3d p = WrittenPushPoint(s, com_height_m);
    Append(line, {p.x(), p.y(), p.z()});
  }
  if (c.moments) {
    const Eigen::Vector3d m = WrittenMoments(s, c.push_point, com_height_m);
    Append(line, {m.x(), m.y(), m.z()});
  }
  if (c.step_info) {
    Append(line, {s.ecp_world.x(), s.ecp_world.y(), s.pt, s.po, s.pr, s.sigma});
    line += ',';
    line += ModeName(s.mode);
  }
  return line;
}

/// Writes without checking the stream; callers check and name their target.
void WriteUnchecked(const Trajectory& tr, std::ostream& out) {
  for (const auto& [key, value] : tr.extra_metadata) CheckMetadataEntry(tr, key, value);
  WriteMetadata(tr, out);
  const LogColumns columns = WrittenColumns(tr);
  out << HeaderLine(columns) << '\n';
  for (const TrajectorySample& s : tr.samples) {
    out << RowLine(s, columns, tr.slider.com_height_m) << '\n';
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Public functions
// ---------------------------------------------------------------------------------------

namespace {
std::string FormatLogError(const std::string& file, int line, const std::string& column,
                           const std::string& what) {
  std::string message = file + ":" + std::to_string(line) + ": ";
  if (!column.empty()) message += "column '" + column + "': ";
  return message + what;
}
}  // namespace

LogError::LogError(const std::string& file, int line, const std::string& column,
                   const std::string& what)
    : std::runtime_error(FormatLogError(file, line, column, what)),
      file_(file),
      line_(line),
      column_(column) {}

Trajectory ReadPushLog(const std::string& path, const LogReadOptions& options,
                       LogReadReport* report) {
  LogReadReport local_report;
  const ReadContext ctx{path, options, report ? *report : local_report};
  std::unique_ptr<io::LineReader> in;
  try {
    in = std::make_unique<io::LineReader>(path);
  } catch (const io::error::base& e) {
    throw LogError(path, 0, "", std::string("cannot read: ") + e.what());
  }
  try {
    return ReadFromLines(ctx, *in);
  } catch (const io::error::base& e) {  // e.g. a line longer than fccp's 16 MiB block
    throw LogError(path, static_cast<int>(in->get_file_line()), "", e.what());
  }
}

void WritePushLog(const Trajectory& trajectory, std::ostream& out) {
  WriteUnchecked(trajectory, out);
  out.flush();
  if (!out) throw std::runtime_error("writing the push log to a stream failed");
}

void WritePushLog(const Trajectory& trajectory, const std::string& path) {
  const std::string tmp = path + ".tmp";
  try {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot open '" + tmp + "' for writing");
    WriteUnchecked(trajectory, out);
    out.close();
    if (!out) throw std::runtime_error("writing '" + tmp + "' failed");
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
      throw std::runtime_error("cannot rename '" + tmp + "' to '" + path +
                               "': " + std::strerror(errno));
    }
  } catch (const std::invalid_argument&) {
    std::remove(tmp.c_str());
    throw;
  } catch (const std::exception& e) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write push log '" + path + "': " + e.what());
  }
}

}  // namespace slideid
