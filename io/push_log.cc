#include "io/push_log.h"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <ostream>
#include <string_view>
#include <system_error>
#include <tuple>

#include "estimator/robust_statistics.h"
#include "forward_model/constants.h"
#include "forward_model/contact_patch.h"
#include "forward_model/number_format.h"
#include "io/atomic_file.h"
#include "io/cm_offset.h"
#include "io/force_work.h"
#include "io/row_times.h"
#include "io/text_lines.h"

namespace slideid {

namespace {

/// A log's column groups: one per kind of quantity a Trajectory can carry (log-format.md).
using LogColumns = Measurements;

constexpr double kTwoPi = 2.0 * kPi;
constexpr double kDefaultGravity = 9.81;  // log-format.md: gravity defaults to 9.81 m/s^2
// Writer: the residual moment is nudged by at most this many ulps so that the reader's sum
// (r x f) + residual reproduces the total bit for bit; 4 covers every rounding case that
// can be repaired at all (the plain difference is off by at most one or two ulps).
constexpr int kMaxResidualNudges = 4;

// Reader: an interval longer than this many times the median interval is reported as a
// warning (dropped samples); LogReadOptions::max_gap_ratio makes longer ones errors.
constexpr double kWarnGapRatio = 3.0;
// Reader: a median interval between rows longer than this [s] (slower than 1 Hz) is warned
// of: times in milliseconds read as seconds make every motion a thousand times slower, which
// the fit then calls too little sliding. Pushing logs here run at 30 Hz to 1 kHz.
constexpr double kSlowestPlausibleInterval_s = 1.0;
// Reader: magnitudes no pushing experiment reaches. A value beyond one is read, but warned
// about: a unit error (mm for m, g for kg, g cm^2 for kg m^2) is far likelier.
constexpr double kAbsurdPosition_m = 1e3;  // x, y, px, py, pz
constexpr double kAbsurdSpeed_mps = 1e2;   // vx, vy, given or from poses
constexpr double kAbsurdSpin_radps = 1e3;  // wz: 160 turns a second
// theta, unwrapped: 160,000 turns. Far beyond it a double cannot resolve a step's turn (at
// 1e17 rad its spacing is 16 rad: every row the same heading), and the fits went on as if
// the slider never turned.
constexpr double kAbsurdHeading_rad = 1e6;
constexpr double kAbsurdForce_n = 1e5;    // fx, fy, fz
constexpr double kAbsurdMoment_Nm = 1e5;  // tx, ty, tz
constexpr double kAbsurdMass_kg = 1e4;
constexpr double kAbsurdComHeight_m = 1e2;
// Theta in degrees (WarnThetaInDegrees): a jump between rows of 300-420 is a wrap at +-180
// degrees (a wrap in radians is 2 pi); a spin beyond 60 rad/s in a tenth of the turning
// intervals is degrees per second.
constexpr double kDegreeWrapLo = 300.0, kDegreeWrapHi = 420.0;
constexpr double kDegreesSpin_radps = 60.0;
constexpr double kDegreesSpinFraction = 0.1;
constexpr double kMinGyration_m = 1e-4;  // radius of gyration sqrt(I/m)
constexpr double kMaxGyration_m = 1e2;
constexpr double kMinGravity_mps2 = 0.1;
constexpr double kMaxGravity_mps2 = 1e2;  // 981 would be cm/s^2

// ---------------------------------------------------------------------------------------
// Columns
// ---------------------------------------------------------------------------------------

/// The numeric columns the reader knows; `mode` is the only text column.
enum Col : int {
  kT,
  kX,
  kY,
  kTheta,
  kVx,
  kVy,
  kWz,
  kFx,
  kFy,
  kFz,
  kTx,
  kTy,
  kTz,
  kPx,
  kPy,
  kPz,
  kAx,
  kAy,
  kPt,
  kPo,
  kPr,
  kSigma,
  kTipX,
  kTipY,
  kNumNumeric
};
constexpr std::array<const char*, kNumNumeric> kColumnNames = {
    "t",  "x",  "y",  "theta", "vx", "vy", "wz", "fx", "fy", "fz",    "tx",    "ty",
    "tz", "px", "py", "pz",    "ax", "ay", "pt", "po", "pr", "sigma", "tip_x", "tip_y"};
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
  int patch_line = 0;
  std::optional<std::pair<double, int>> tip_radius;  // (value, line)
  /// The CM in the frame whose pose the log gives [m, body axes], and its line.
  std::optional<std::pair<Eigen::Vector2d, int>> cm_offset;
  std::vector<std::pair<std::string, std::string>> extra;
};

constexpr std::array<const char*, 4> kSliderKeys = {"mass", "inertia", "com_height", "gravity"};
constexpr std::array<const char*, 4> kTruthKeys = {"mu", "e_t", "e_o", "e_r"};

// ---------------------------------------------------------------------------------------
// Text helpers
// ---------------------------------------------------------------------------------------

using text::IsIdentifier;
using text::ParseFiniteNumber;
using text::SplitCells;
using text::Trim;

/// Three significant digits, for ratios in messages.
std::string RoundedNumber(double value) { return Printf("%.3g", value); }

const char* ModeName(SampleMode mode) {
  switch (mode) {
    case SampleMode::kStart:
      return "start";
    case SampleMode::kSlide:
      return "slide";
    case SampleMode::kStick:
      return "stick";
  }
  return "slide";
}

/// A row's mode as written: the first row is always `start`.
const char* WrittenMode(const Trajectory& tr, const TrajectorySample& s) {
  return ModeName(&s == &tr.samples.front() ? SampleMode::kStart : s.mode);
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
  /// Lines of the text that may hold a data row (RowLineCounter), an upper bound on the
  /// rows that the samples are reserved for; 0 when unknown.
  std::size_t row_lines = 0;

  [[noreturn]] void Fail(int line, const std::string& column, const std::string& what) const {
    throw LogError(path, line, column, what);
  }
};

/// Counts the lines of a text, fed in pieces, that are neither blank nor `#` comments: the
/// header and every data row. Reserving the samples for that many spares a 1e6-row log the
/// vector's growth (at the last doubling, the old and the new buffer: 1.5 times the rows).
class RowLineCounter {
 public:
  void Feed(std::string_view text) {
    for (const char c : text) {
      if (c == '\n') {
        at_start_ = true;
      } else if (at_start_ && c != ' ' && c != '\t' && c != '\r') {
        at_start_ = false;
        if (c != '#') ++count_;
      }
    }
  }
  std::size_t count() const { return count_; }

 private:
  bool at_start_ = true;  // nothing but blanks so far on this line
  std::size_t count_ = 0;
};

/// RowLineCounter over a file; 0 when it cannot be read (the reader then says why) or is
/// not a regular file. A pipe (--log <(zcat log.csv.gz), /dev/stdin, a named FIFO) must not
/// be opened a second time: this pass took the rows beyond the reader's first 32 MiB from
/// it (a 61 MB log read from <(cat) failed half-way, or could lose rows), and on a FIFO whose
/// writer had finished it waited for ever.
std::size_t CountRowLines(const std::string& path) {
  struct stat status;
  if (::stat(path.c_str(), &status) != 0 || !S_ISREG(status.st_mode)) return 0;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return 0;
  RowLineCounter counter;
  std::vector<char> buffer(1 << 20);
  std::size_t got = 0;
  while ((got = std::fread(buffer.data(), 1, buffer.size(), file)) > 0) {
    counter.Feed(std::string_view(buffer.data(), got));
  }
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  return failed ? 0 : counter.count();
}

/// Adds one `# ...` comment line to the metadata when it has the `key = value` form.
void ParseCommentLine(const ReadContext& ctx, std::string_view line, int line_no, Metadata& meta) {
  line.remove_prefix(1);  // '#'
  const auto eq = line.find('=');
  if (eq == std::string_view::npos) return;
  const std::string key(Trim(line.substr(0, eq)));
  if (!IsIdentifier(key)) return;  // prose that happens to contain '='
  const std::string value(Trim(line.substr(eq + 1)));
  if (key == "patch") {
    if (meta.patch) ctx.Fail(line_no, "", "metadata 'patch' given twice");
    meta.patch = value;
    meta.patch_line = line_no;
  } else if (key == "tip_radius") {
    if (meta.tip_radius) ctx.Fail(line_no, "", "metadata 'tip_radius' given twice");
    const auto number = ParseFiniteNumber(value);
    if (!number || *number < 0) {
      ctx.Fail(line_no, "", "metadata 'tip_radius': '" + value + "' is not a number >= 0 (m)");
    }
    meta.tip_radius = std::make_pair(*number, line_no);
  } else if (key == "cm_offset") {
    if (meta.cm_offset) ctx.Fail(line_no, "", "metadata 'cm_offset' given twice");
    const std::optional<Eigen::Vector2d> offset = ParseCmOffset(value);
    if (!offset) {
      ctx.Fail(line_no, "",
               "metadata 'cm_offset': '" + value +
                   "' is not two numbers DX DY (m: the CM in the frame of the logged pose)");
    }
    meta.cm_offset = std::make_pair(*offset, line_no);
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
std::string ReadPreamble(const ReadContext& ctx, TextLines& in, Metadata& meta, int& header_line) {
  while (const auto raw = in.Next()) {
    const std::string_view line = Trim(*raw);
    const int line_no = in.LineNumber();
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

void RequireGroup(const ReadContext& ctx, const Header& h, Col a, Col b, Col c, const char* group) {
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
    ctx.Fail(h.line, "",
             "neither the pose columns (x, y, theta) nor the velocity columns "
             "(vx, vy, wz) are present");
  }
  if (h.Has(kPx) && !h.Has(kX)) {
    ctx.Fail(h.line, "px", "push points need the pose columns x, y, theta to form r");
  }
  if (h.Has(kTipX) != h.Has(kTipY)) {
    ctx.Fail(h.line, h.Has(kTipX) ? "tip_y" : "tip_x",
             "missing: the pusher tip group needs both tip_x and tip_y");
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
  std::vector<std::string_view> names;
  SplitCells(text, names);
  h.num_fields = static_cast<int>(names.size());
  if (h.num_fields == 1) {
    for (const char separator : {';', '\t', ' ', '|'}) {
      if (text.find(separator) != std::string::npos) {
        ctx.Fail(
            line, "",
            "the header '" + text +
                "' has one field: fields must be separated "
                "by commas (this line seems to use " +
                (separator == '\t' ? std::string("tabs") : "'" + std::string(1, separator) + "'") +
                ")");
      }
    }
  }
  std::map<std::string, int> seen;
  for (int i = 0; i < h.num_fields; ++i) {
    const std::string name(names[i]);
    if (ParseFiniteNumber(name)) {
      ctx.Fail(line, "",
               "no header: the first non-comment line holds numbers ('" + text +
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

/// Why `cell` is not a finite number, or nullptr when `value` now holds it. Locale
/// independent (std::from_chars); "nan", "inf", "1.2abc", "" and 1e999 are all rejected.
const char* ParseCell(std::string_view cell, double* value) {
  if (cell.empty()) return "is empty: every cell of a known column needs a number";
  std::string_view s = cell;
  if (s.front() == '+') s.remove_prefix(1);  // from_chars rejects '+'
  if (s.empty() || s.front() == '+') return "is not a number";
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), *value);
  if (ec == std::errc::result_out_of_range) return "is out of the range of a double";
  if (ec != std::errc() || end != s.data() + s.size()) return "is not a number";
  if (!std::isfinite(*value)) return "is not a finite number (NaN and Inf are not allowed)";
  return nullptr;
}

/// Counts the rows whose value in one column is absurd for a pushing experiment.
struct MagnitudeTally {
  int count = 0;
  int first_line = 0;
  double first_value = 0.0;

  void Add(double value, int line) {
    if (count++ == 0) {
      first_line = line;
      first_value = value;
    }
  }
};

/// |value| beyond which a column is absurd (0: not checked), and its unit, for warnings.
struct AbsurdLimit {
  double limit;
  const char* unit;
};

constexpr std::array<AbsurdLimit, kNumNumeric> MakeAbsurdLimits() {
  std::array<AbsurdLimit, kNumNumeric> l{};
  for (auto& x : l) x = {0.0, ""};
  for (Col c : {kX, kY, kPx, kPy, kPz, kTipX, kTipY}) l[c] = {kAbsurdPosition_m, "m"};
  for (Col c : {kVx, kVy}) l[c] = {kAbsurdSpeed_mps, "m/s"};
  l[kWz] = {kAbsurdSpin_radps, "rad/s"};
  l[kTheta] = {kAbsurdHeading_rad, "rad"};
  for (Col c : {kFx, kFy, kFz}) l[c] = {kAbsurdForce_n, "N"};
  for (Col c : {kTx, kTy, kTz}) l[c] = {kAbsurdMoment_Nm, "N m"};
  return l;
}
constexpr std::array<AbsurdLimit, kNumNumeric> kAbsurdLimits = MakeAbsurdLimits();

/// Adds a warning for each tallied column: its first absurd row and how many there are.
void WarnAbsurd(const ReadContext& ctx, const std::array<MagnitudeTally, kNumNumeric>& tally,
                const char* how) {
  for (int c = 0; c < kNumNumeric; ++c) {
    const MagnitudeTally& t = tally[c];
    if (t.count == 0) continue;
    const AbsurdLimit& l = kAbsurdLimits[c];
    ctx.report.warnings.push_back(text::Located(
        ctx.path, t.first_line, kColumnNames[c],
        std::string(how) + ShortNumber(t.first_value) + " " + l.unit + " is beyond " +
            ShortNumber(l.limit) + " " + l.unit +
            ", absurd for a pushing experiment (a unit error?)" +
            (t.count > 1 ? "; " + std::to_string(t.count) + " rows like it" : std::string())));
  }
}

/// Whether a cell says the value is missing: empty or NaN, as loggers write a dropout.
bool IsMissing(std::string_view cell) {
  if (!cell.empty() && (cell.front() == '-' || cell.front() == '+')) cell.remove_prefix(1);
  return cell.empty() || ((cell.size() == 3) && (cell[0] == 'n' || cell[0] == 'N') &&
                          (cell[1] == 'a' || cell[1] == 'A') && (cell[2] == 'n' || cell[2] == 'N'));
}

/// Parses one data line into `row`; `cells` is scratch space reused across rows. False for
/// a row with a missing cell that LogReadOptions::missing_as_gaps lets the reader drop.
bool ParseRow(const ReadContext& ctx, const Header& h, std::string_view line, int line_no,
              std::vector<std::string_view>& cells, RawRow& row) {
  SplitCells(line, cells);
  if (static_cast<int>(cells.size()) != h.num_fields) {
    ctx.Fail(line_no, "",
             "expected " + std::to_string(h.num_fields) + " fields as in the header on line " +
                 std::to_string(h.line) + ", found " + std::to_string(cells.size()));
  }
  row.line = line_no;
  for (int c = 0; c < kNumNumeric; ++c) {
    if (!h.Has(static_cast<Col>(c))) continue;
    const std::string_view cell = cells[h.field[c]];
    if (const char* why = ParseCell(cell, &row.v[c])) {
      const bool missing = IsMissing(cell);
      if (missing && ctx.options.missing_as_gaps) return false;
      ctx.Fail(line_no, kColumnNames[c],
               "'" + std::string(cell) + "' " + why +
                   (missing ? "; a dropout? --missing-as-gaps drops such rows and starts a new "
                              "run after them"
                            : ""));
    }
  }
  if (h.mode_field >= 0) {
    const std::string_view cell = cells[h.mode_field];
    row.mode = ParseMode(cell);
    if (!row.mode) {
      ctx.Fail(line_no, kModeColumn, "'" + std::string(cell) + "' is not start, slide or stick");
    }
  }
  return true;
}

/// Shifts `theta` by a multiple of 2 pi so that theta - prev lies in (-pi, pi]; a value
/// needing no shift keeps its bits. Returns false when the difference overflows.
bool UnwrapAgainst(double prev, double& theta, bool& shifted) {
  const double raw = theta;
  double k = std::round((prev - raw) / kTwoPi);
  if (!std::isfinite(k)) return false;
  // Rounding of the quotient can leave the difference just outside (-pi, pi].
  for (int i = 0; i < 2; ++i) {
    const double diff = raw + k * kTwoPi - prev;
    if (diff > kPi)
      k -= 1.0;
    else if (diff <= -kPi)
      k += 1.0;
  }
  shifted = k != 0.0;
  if (shifted) theta = raw + k * kTwoPi;
  return true;
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

/// Whether the header has any of the step columns (ax, ay, pt, po, pr, sigma).
bool HasStepColumns(const Header& h) {
  return h.Has(kAx) || h.Has(kAy) || h.HasAny(kPt, kPo, kPr) || h.Has(kSigma);
}

StepRecord RowStep(const RawRow& row) {
  const auto& v = row.v;
  return {v[kPt], v[kPo], v[kPr], v[kSigma], Eigen::Vector2d(v[kAx], v[kAy])};
}

TrajectorySample RowSample(const RawRow& row, const Header& h, double com_height_m, bool first) {
  const auto& v = row.v;
  TrajectorySample s;
  s.t_s = v[kT];
  s.state = PlanarState{v[kX], v[kY], v[kTheta], v[kVx], v[kVy], v[kWz]};
  s.applied = RowWrench(row, h.Has(kPx), com_height_m);
  if (h.Has(kPx)) s.push_point_world = Eigen::Vector3d(v[kPx], v[kPy], v[kPz]);
  if (h.Has(kTipX)) s.tip_world = Eigen::Vector2d(v[kTipX], v[kTipY]);
  s.mode = row.mode ? *row.mode : (first ? SampleMode::kStart : SampleMode::kSlide);
  return s;
}

bool IsFinite(const AppliedWrench& w) {
  return std::isfinite(w.fx) && std::isfinite(w.fy) && std::isfinite(w.fz) && std::isfinite(w.tx) &&
         std::isfinite(w.ty) && std::isfinite(w.tz);
}

/// Moves a row's pose (and velocity, where logged) from the tracked frame to the CM, which
/// sits at `offset` in that frame: p_cm = p + R(theta) offset, v_cm = v + w x (R(theta)
/// offset). Before the moments r x f are taken about it.
void MoveToCm(const Header& h, const Eigen::Vector2d& offset, RawRow& row) {
  auto& v = row.v;
  const Eigen::Vector2d r = CmOffsetInWorld(offset, v[kTheta]);
  v[kX] += r.x();
  v[kY] += r.y();
  if (h.Has(kVx)) {
    v[kVx] -= v[kWz] * r.y();
    v[kVy] += v[kWz] * r.x();
  }
}

/// Reads the data rows one at a time into trajectory.samples (the line of each in `lines`),
/// checking each as it comes: strictly increasing t, a positive normal force m g - fz
/// (log-format.md: fz reduces it) when the mass is known, finite moments, theta unwrapped;
/// with `cm_offset`, each pose moved to the CM (MoveToCm).
void ReadSamples(const ReadContext& ctx, TextLines& in, const Header& h, Trajectory& trajectory,
                 std::vector<int>& lines, bool mass_known,
                 const std::optional<Eigen::Vector2d>& cm_offset) {
  const double weight = trajectory.slider.mass_kg * trajectory.slider.gravity_mps2;
  const double com_height = trajectory.slider.com_height_m;
  std::vector<std::string_view> cells;
  std::array<MagnitudeTally, kNumNumeric> tally;
  RawRow row;
  const bool steps = HasStepColumns(h);
  if (ctx.row_lines > 0) {
    trajectory.samples.reserve(ctx.row_lines);
    if (steps) trajectory.steps.reserve(ctx.row_lines);
    lines.reserve(ctx.row_lines);
  }
  double prev_t = 0.0, prev_theta = 0.0, prev_raw_theta = 0.0;
  int prev_line = 0, unwrapped = 0;
  int degree_wraps = 0, first_degree_wrap = 0;  // jumps of about 360: a wrap at +-180 degrees
  int dropped = 0, first_dropped = 0;           // rows with a missing cell (missing_as_gaps)
  bool gap_before = false;                      // a row was dropped since the last one kept
  while (const auto raw = in.Next()) {
    const std::string_view line = Trim(*raw);
    // fccp's comment policy would skip '#' lines anywhere; only those before the header
    // are metadata, later ones are plain comments.
    if (line.empty() || line.front() == '#') continue;
    const int line_no = in.LineNumber();
    if (!ParseRow(ctx, h, line, line_no, cells, row)) {
      if (dropped++ == 0) first_dropped = line_no;
      gap_before = true;
      continue;
    }
    const bool first = lines.empty();
    if (!first && !(row.v[kT] > prev_t)) {
      ctx.Fail(line_no, "t",
               "t = " + ShortNumber(row.v[kT]) + " is not greater than t = " + ShortNumber(prev_t) +
                   " on line " + std::to_string(prev_line));
    }
    if (mass_known && !(weight - row.v[kFz] > 0.0)) {
      ctx.Fail(line_no, "fz",
               "vertical force lifts the slider: fz = " + ShortNumber(row.v[kFz]) +
                   " N is not below m g = " + ShortNumber(weight) + " N");
    }
    if (!first && h.Has(kTheta)) {
      const double jump = std::abs(row.v[kTheta] - prev_raw_theta);
      if (jump > kDegreeWrapLo && jump < kDegreeWrapHi && ++degree_wraps == 1) {
        first_degree_wrap = line_no;
      }
    }
    const double raw_theta = row.v[kTheta];
    if (!first && h.Has(kTheta)) {
      bool shifted = false;
      if (!UnwrapAgainst(prev_theta, row.v[kTheta], shifted)) {
        ctx.Fail(line_no, "theta",
                 "theta = " + ShortNumber(row.v[kTheta]) + " cannot be unwrapped against " +
                     ShortNumber(prev_theta) + ": the difference overflows");
      }
      unwrapped += shifted;
    }
    for (int c = 0; c < kNumNumeric; ++c) {
      if (kAbsurdLimits[c].limit > 0 && h.Has(static_cast<Col>(c)) &&
          std::abs(row.v[c]) > kAbsurdLimits[c].limit) {
        tally[c].Add(row.v[c], line_no);
      }
    }
    if (cm_offset) MoveToCm(h, *cm_offset, row);
    trajectory.samples.push_back(RowSample(row, h, com_height, first));
    if (gap_before) trajectory.samples.back().mode = SampleMode::kStart;
    gap_before = false;
    if (steps) trajectory.steps.push_back(RowStep(row));
    if (!IsFinite(trajectory.samples.back().applied)) {
      ctx.Fail(line_no, h.Has(kPx) ? "px" : "tx",
               "the applied moment (r x f at the push point, plus tx, ty, tz) overflows");
    }
    lines.push_back(line_no);
    prev_t = row.v[kT];
    prev_theta = row.v[kTheta];
    prev_raw_theta = raw_theta;
    prev_line = line_no;
  }
  if (degree_wraps > 0) {
    ctx.report.warnings.push_back(text::Located(
        ctx.path, first_degree_wrap, "theta",
        "theta looks like degrees: it jumps by about 360 between rows (a wrap at +-180 "
        "degrees; " +
            std::to_string(degree_wraps) + " such jumps): give theta in radians"));
  }
  if (dropped > 0) {
    ctx.report.notes.push_back(
        Printf("%d rows with a missing cell dropped (--missing-as-gaps), the first on line %d; "
               "the row after each dropout starts a new run",
               dropped, first_dropped));
  }
  if (lines.empty() && !(dropped > 0 && ctx.options.allow_no_rows)) {
    ctx.Fail(h.line, "",
             dropped > 0 ? "every data row has a missing cell (dropped: --missing-as-gaps)"
                         : "the header is not followed by any data row");
  }
  if (unwrapped > 0) {
    ctx.report.notes.push_back("theta unwrapped: " + std::to_string(unwrapped) +
                               " rows shifted by multiples of 2 pi");
  }
  WarnAbsurd(ctx, tally, "");
}

/// Theta in degrees, unwrapped or not, turns the slider tens of times faster than it turns:
/// 1 rad/s becomes 57 "rad/s". Beyond kDegreesSpin_radps (nearly 10 turns a second) in at
/// least kDegreesSpinFraction of the intervals in which it turns, no pushed or thrown
/// object on a table spins (a disk thrown hard: 20-30 rad/s), and the log is warned of.
void WarnThetaInDegrees(const ReadContext& ctx, const Trajectory& tr,
                        const std::vector<int>& lines) {
  if (!tr.measured.pose) return;
  int turning = 0, fast = 0, first_fast = 0;
  for (size_t u = 1; u < tr.samples.size(); ++u) {
    if (StartsRun(tr, u)) continue;  // the turn over a gap is not a rate
    const double dt = tr.samples[u].t_s - tr.samples[u - 1].t_s;
    const double spin = std::abs(tr.samples[u].state.theta - tr.samples[u - 1].state.theta) / dt;
    if (!(spin > 0)) continue;
    ++turning;
    if (spin > kDegreesSpin_radps && ++fast == 1) first_fast = lines[u];
  }
  if (turning == 0 || fast < kDegreesSpinFraction * turning) return;
  ctx.report.warnings.push_back(text::Located(
      ctx.path, first_fast, "theta",
      "theta looks like degrees: it turns faster than " + ShortNumber(kDegreesSpin_radps) +
          " rad/s in " + std::to_string(fast) + " of the " + std::to_string(turning) +
          " intervals in which it turns, which no pushed or thrown object does: give theta "
          "in radians"));
}

/// Logged velocities against the poses' backward differences (docs/log-format.md: what the
/// model means by a row's velocity), per channel. A velocity sampled at t differs from the
/// interval's mean velocity by at most its change over the interval where the motion is
/// monotone, so an interval disagrees where |v - (q - q_prev) / dt| exceeds |v - v_prev|
/// plus kVelocityNoiseSigmas times the noise of both (each from the median absolute change
/// of its own series: white noise's changes have sqrt(3) and sqrt(2) times its spread).
/// More than kVelocityDisagreeFraction of the intervals disagreeing is a unit, sign or frame
/// error (mm/s, the body frame), not noise or an impact: warned of at its first row.
constexpr double kVelocityNoiseSigmas = 4;
constexpr double kVelocityDisagreeFraction = 0.1;

/// The spread of white noise whose changes (`changes`, absolute) are `change_factor`
/// (sqrt(3) or sqrt(2)) times as wide as it: from their median (the MAD's scale).
double NoiseOfChanges(std::vector<double> changes, double change_factor) {
  return changes.empty() ? 0.0 : kMadToSigma * Median(std::move(changes)) / change_factor;
}

/// One velocity column against the poses' differences: how many intervals disagree, and the
/// first.
struct VelocityDisagreement {
  std::size_t count = 0, first = 0;
  double gap = 0, tolerance = 0;  ///< at the first
};

/// `v` of the logged states against `from_poses` over the intervals ending at `rows`.
VelocityDisagreement CompareVelocity(const Trajectory& tr, const std::vector<std::size_t>& rows,
                                     const std::vector<PlanarState>& from_poses,
                                     double PlanarState::*v) {
  const auto logged = [&](std::size_t u) { return tr.samples[u].state.*v; };
  std::vector<double> change_d, change_v;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    const std::size_t u = rows[k];
    if (rows[k - 1] + 1 != u) continue;  // a change within one run only
    change_d.push_back(std::abs(from_poses[u].*v - from_poses[u - 1].*v));
    change_v.push_back(std::abs(logged(u) - logged(u - 1)));
  }
  const double noise = kVelocityNoiseSigmas * (NoiseOfChanges(change_d, std::sqrt(3.0)) +
                                               NoiseOfChanges(change_v, std::sqrt(2.0)));
  VelocityDisagreement d;
  for (std::size_t u : rows) {
    const double gap = std::abs(logged(u) - from_poses[u].*v);
    const double tolerance = std::abs(logged(u) - logged(u - 1)) + noise +
                             1e-9 * (std::abs(logged(u)) + std::abs(from_poses[u].*v)) + 1e-12;
    if (!(gap > tolerance) || d.count++ > 0) continue;
    d.first = u;
    d.gap = gap;
    d.tolerance = tolerance;
  }
  return d;
}

void WarnVelocitiesAgainstPoses(const ReadContext& ctx, const Trajectory& tr,
                                const std::vector<int>& lines) {
  std::vector<std::size_t> rows;  // intervals: rows whose previous row is in their run
  for (std::size_t u = 1; u < tr.samples.size(); ++u) {
    if (!StartsRun(tr, u)) rows.push_back(u);
  }
  if (rows.size() < 3) return;
  std::vector<PlanarState> from_poses(tr.samples.size());
  for (std::size_t u : rows) from_poses[u] = StateWithPoseVelocity(tr, u);
  const std::array<std::tuple<Col, Col, double PlanarState::*>, 3> channels = {
      {{kVx, kX, &PlanarState::vx}, {kVy, kY, &PlanarState::vy}, {kWz, kTheta, &PlanarState::wz}}};
  for (const auto& [column, pose, v] : channels) {
    const VelocityDisagreement d = CompareVelocity(tr, rows, from_poses, v);
    if (d.count <= kVelocityDisagreeFraction * rows.size()) continue;
    const std::string name = kColumnNames[column], unit = kAbsurdLimits[column].unit;
    ctx.report.warnings.push_back(text::Located(
        ctx.path, lines[d.first], name,
        "the logged velocity disagrees with the poses' differences (" +
            std::string(kColumnNames[pose]) + " - previous) / (t - previous) in " +
            std::to_string(d.count) + " of " + std::to_string(rows.size()) +
            " intervals, first here by " + Printf("%.3g", d.gap) + " " + unit + " (tolerance " +
            Printf("%.3g", d.tolerance) + " " + unit + ": the change of " + name +
            " over the interval plus " + ShortNumber(kVelocityNoiseSigmas) +
            " times the noise of both); a unit, sign or frame error? The fits use the logged "
            "velocities"));
  }
}

/// Time gaps (docs/robustness.md): the model holds a row's force over the interval to the
/// next row and takes one backward-Euler step across it, so an interval many times the
/// median one is a hole in the log, not a sample. Above options.max_gap_ratio medians it is
/// an error; above kWarnGapRatio medians, a warning. A hole the log declares, by `start` on
/// the row after it, is no interval: no step is taken across it.
void CheckTimeGaps(const ReadContext& ctx, const Trajectory& tr, const std::vector<int>& lines) {
  std::vector<double> dt;  // dt[i]: the interval ending at row end[i]
  std::vector<std::size_t> end;
  for (std::size_t u = 1; u < tr.samples.size(); ++u) {
    if (StartsRun(tr, u)) continue;
    dt.push_back(tr.samples[u].t_s - tr.samples[u - 1].t_s);
    end.push_back(u);
  }
  if (dt.size() < 2) return;  // one interval: nothing to compare it with
  std::vector<double> sorted = dt;
  // The lower median: with two intervals, the shorter one is the reference.
  const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>((sorted.size() - 1) / 2);
  std::nth_element(sorted.begin(), mid, sorted.end());
  const double median = *mid;
  if (median > kSlowestPlausibleInterval_s) {
    ctx.report.warnings.push_back(text::Located(
        ctx.path, lines[end[0]], "t",
        "the median interval between rows is " + ShortNumber(median) + " s (" +
            ShortNumber(1.0 / median) +
            " Hz), slow for a pushing experiment: t in milliseconds or microseconds? (t is in "
            "seconds)"));
  }
  const double max_ratio = ctx.options.max_gap_ratio;
  int long_count = 0;
  std::size_t longest = 0;
  for (std::size_t i = 0; i < dt.size(); ++i) {
    const double ratio = dt[i] / median;
    const std::size_t u = end[i];
    if (max_ratio > 0 && !(ratio <= max_ratio)) {
      ctx.Fail(lines[u], "t",
               "t jumps by " + ShortNumber(dt[i]) +
                   " s from t = " + ShortNumber(tr.samples[u - 1].t_s) + " (line " +
                   std::to_string(lines[u - 1]) + "), " + RoundedNumber(ratio) +
                   " times the median interval " + ShortNumber(median) +
                   " s: the model holds the force across an interval "
                   "and cannot represent the motion missing from it; mark the row after the "
                   "gap 'start' in a mode column, or allow it with --max-gap-ratio (now " +
                   ShortNumber(max_ratio) + ")");
    }
    if (ratio > kWarnGapRatio) {
      if (long_count == 0 || dt[i] > dt[longest]) longest = i;
      ++long_count;
    }
  }
  if (long_count > 0) {
    ctx.report.warnings.push_back(text::Located(
        ctx.path, lines[end[longest]], "t",
        std::to_string(long_count) + " intervals longer than " + ShortNumber(kWarnGapRatio) +
            " times the median " + ShortNumber(median) + " s (dropped samples?); the longest, " +
            ShortNumber(dt[longest]) + " s, ends here"));
  }
}

/// Row times that jitter around a regular sampling (io/row_times.h): put on a regular grid
/// with LogReadOptions::regular_times, warned of otherwise. Before velocities come from the
/// poses, which divide by the intervals.
void CheckRowTimes(const ReadContext& ctx, Trajectory& tr, const std::vector<int>& lines) {
  const RowTimesSpread s = MeasureRowTimes(tr);
  if (ctx.options.regular_times) {
    PutRowsOnRegularTimes(&tr);
    ctx.report.notes.push_back(Printf(
        "rows put on a regular grid per run (--regular-times): their intervals varied %.3g%% "
        "around %.4g s",
        100 * s.spread, s.median_interval_s));
    return;
  }
  if (!TimesLookStampedOnArrival(s)) return;
  ctx.report.warnings.push_back(text::Located(
      ctx.path, lines.size() > 1 ? lines[1] : lines[0], "t",
      Printf("the intervals between rows vary %.0f%% around %.4g s, while the poses move as if "
             "sampled regularly (over %d moving rows their steps follow the intervals by a "
             "factor %.2f, where rows sampled at their times give about 1): the times look "
             "stamped on arrival, and the fits, which take them as exact, are biased by them; "
             "--regular-times puts each run's rows on a regular grid",
             100 * s.spread, s.median_interval_s, s.moving_rows, s.step_slope)));
}

/// A force that does not push the object the way it moves (io/force_work.h): its sign or
/// its frame is likely wrong. The fits use it as logged.
/// Returns whether it warned.
bool WarnForceAgainstMotion(const ReadContext& ctx, const ForceWork& w) {
  if (w.rows < kMinForceWorkRows) return false;
  const double share = double(w.positive) / w.rows;
  if (share >= kForceWorkMinPositiveShare) return false;
  const double in_object_frame = double(w.positive_in_object_frame) / w.rows;
  // Under kForceWorkMinPositiveShare as logged: which other reading would do the work.
  const std::string why =
      in_object_frame < 0.5
          ? "its sign looks flipped (a sensor's reading of the force on the pusher, the "
            "reaction?): the force on the object is wanted"
      : in_object_frame > 1 - kForceWorkMinPositiveShare
          ? Printf(
                "read in the object's own frame (rotated by theta into world axes) it "
                "would do positive work in %.0f%% of them: world axes are wanted",
                100 * in_object_frame)
          : "a sign or frame error?";
  ctx.report.warnings.push_back(text::Located(
      ctx.path, 0, "",
      Printf("columns 'fx', 'fy': the force does negative work on the object in %d of the %d "
             "rows where it pushes and the contact point moves (a pusher does positive "
             "work): %s. The fits use it as logged",
             w.rows - w.positive, w.rows, why.c_str())));
  return true;
}

/// Called where the force itself does the work it should: a flipped force flips the moment
/// too, and its own warning says so.
void WarnSpinAgainstMoment(const ReadContext& ctx, const SpinWork& w) {
  if (w.rows < kMinForceWorkRows) return;
  if (double(w.positive) / w.rows >= kForceWorkMinPositiveShare) return;
  ctx.report.warnings.push_back(text::Located(
      ctx.path, 0, "theta",
      Printf("the slider turns against the applied moment in %d of the %d rows where a push "
             "off the CM turns it (a push turns it its way): theta measured clockwise, or a "
             "y axis flipped in the poses but not in the push points? theta is wanted "
             "counter-clockwise about z up. The fits use it as logged",
             w.rows - w.positive, w.rows)));
}

/// Rows marked `start` after the first split the log into runs; say so, for a user who did
/// not know the mode column does that.
void NoteRuns(const ReadContext& ctx, const Trajectory& tr) {
  const std::size_t runs = Runs(tr).size();
  if (runs < 2) return;
  ctx.report.notes.push_back(std::to_string(runs - 1) +
                             " rows after the first are marked "
                             "'start': " +
                             std::to_string(runs) +
                             " runs, no step taken "
                             "across the gaps between them");
}

/// Velocities from poses by the kinematic map; they must be finite, and are checked for
/// absurd magnitudes like given ones.
void VelocitiesFromPoses(const ReadContext& ctx, Trajectory& tr, const std::vector<int>& lines) {
  SetVelocitiesFromPoses(&tr);
  ctx.report.velocities_from_poses = true;
  ctx.report.notes.push_back("velocities computed from poses (backward Euler)");
  std::array<MagnitudeTally, kNumNumeric> tally;
  for (std::size_t u = 1; u < tr.samples.size(); ++u) {
    const PlanarState& q = tr.samples[u].state;
    const std::array<std::pair<Col, double>, 3> v = {{{kVx, q.vx}, {kVy, q.vy}, {kWz, q.wz}}};
    for (const auto& [c, value] : v) {
      if (!std::isfinite(value)) {
        const Col pose = c == kVx ? kX : c == kVy ? kY : kTheta;
        ctx.Fail(lines[u], kColumnNames[pose],
                 std::string("the velocity from poses, ") + kColumnNames[c] + " = (" +
                     kColumnNames[pose] + " - previous) / (t - previous), overflows");
      }
      if (std::abs(value) > kAbsurdLimits[c].limit) tally[c].Add(value, lines[u]);
    }
  }
  WarnAbsurd(ctx, tally, "from poses: ");
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
    {"com_height", "--com-height", &SliderOverrides::com_height_m, &SliderProperties::com_height_m,
     true},
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
    ctx.Fail(line, "",
             std::string(spec.key) + " = " + ShortNumber(value) +
                 (override_value ? std::string(" (from ") + spec.option + ")"
                                 : std::string(" (metadata)")) +
                 (spec.zero_allowed ? " must be >= 0" : " must be > 0"));
  }
  slider.*(spec.field) = value;
  return true;
}

/// " (found '# Mass = ...': metadata keys are lower case)" when such a key is there.
std::string MisspeltKeyHint(const Metadata& meta, const std::string& key) {
  for (const auto& [other, value] : meta.extra) {
    if (other.size() == key.size() &&
        std::equal(other.begin(), other.end(), key.begin(), [](char a, char b) {
          return std::tolower(static_cast<unsigned char>(a)) == b;
        })) {
      return " (found '# " + other + " = " + value + "': metadata keys are lower case)";
    }
  }
  return "";
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
      ctx.Fail(0, "",
               std::string("slider ") + spec.key + " is not known: add '# " + spec.key +
                   " = ...' to the log or pass " + spec.option + MisspeltKeyHint(meta, spec.key));
    }
  }
  return slider;
}

/// True friction when all four keys are present; partial truth is kept as extra metadata.
void ResolveTruth(const ReadContext& ctx, const Metadata& meta, PushLogFile& file) {
  std::size_t present = 0;
  for (const char* key : kTruthKeys) present += meta.numbers.count(key);
  if (present == kTruthKeys.size()) {
    file.log.true_friction =
        FrictionParameters{meta.numbers.at("mu").first, meta.numbers.at("e_t").first,
                           meta.numbers.at("e_o").first, meta.numbers.at("e_r").first};
    return;
  }
  for (const char* key : kTruthKeys) {
    const auto it = meta.numbers.find(key);
    if (it != meta.numbers.end()) {
      file.extra_metadata.emplace_back(key, ExactNumber(it->second.first));
    }
  }
  if (present > 0) {
    ctx.report.notes.push_back(
        "partial true friction (needs mu, e_t, e_o, e_r) kept as "
        "extra metadata");
  }
}

// ---------------------------------------------------------------------------------------
// Reader: putting it together
// ---------------------------------------------------------------------------------------

/// Warnings for slider properties no pushing experiment has (a unit error is likelier).
void WarnAbsurdSlider(const ReadContext& ctx, const Metadata& meta, const SliderProperties& s,
                      const std::array<bool, 4>& known) {
  auto where = [&](const char* key) {
    const auto it = meta.numbers.find(key);
    return it == meta.numbers.end() ? 0 : it->second.second;
  };
  auto warn = [&](const char* key, const std::string& what) {
    ctx.report.warnings.push_back(text::Located(ctx.path, where(key), "", what));
  };
  if (known[0] && s.mass_kg > kAbsurdMass_kg) {
    warn("mass", "mass = " + ShortNumber(s.mass_kg) + " kg is beyond " +
                     ShortNumber(kAbsurdMass_kg) + " kg (a unit error?)");
  }
  if (known[0] && known[1]) {
    const double gyration = std::sqrt(s.inertia_kgm2 / s.mass_kg);
    if (!(gyration >= kMinGyration_m && gyration <= kMaxGyration_m)) {
      warn("inertia", "inertia = " + ShortNumber(s.inertia_kgm2) +
                          " kg m^2 gives a radius of "
                          "gyration sqrt(I/m) = " +
                          // A subnormal mass (1e-320 kg) overflows it: no "inf" in a message.
                          (std::isfinite(gyration) ? ShortNumber(gyration) : "over 1e308") +
                          " m, outside [" + ShortNumber(kMinGyration_m) + ", " +
                          ShortNumber(kMaxGyration_m) +
                          "] m (inertia in kg m^2 about the vertical axis through the CM?)");
    }
  }
  if (known[2] && s.com_height_m > kAbsurdComHeight_m) {
    warn("com_height", "com_height = " + ShortNumber(s.com_height_m) + " m is beyond " +
                           ShortNumber(kAbsurdComHeight_m) + " m (a unit error?)");
  }
  if (!(s.gravity_mps2 >= kMinGravity_mps2 && s.gravity_mps2 <= kMaxGravity_mps2)) {
    warn("gravity", "gravity = " + ShortNumber(s.gravity_mps2) + " m/s^2 is outside [" +
                        ShortNumber(kMinGravity_mps2) + ", " + ShortNumber(kMaxGravity_mps2) +
                        "] m/s^2 (a unit error?)");
  }
}

/// The patch metadata, checked: a spec ContactPatch::Parse reads, or empty.
std::optional<ContactPatch> CheckedPatch(const ReadContext& ctx, const Metadata& meta) {
  if (!meta.patch) return std::nullopt;
  try {
    return ContactPatch::Parse(*meta.patch);
  } catch (const std::invalid_argument& e) {
    ctx.Fail(meta.patch_line, "", std::string("metadata 'patch': ") + e.what());
  }
  return std::nullopt;  // Fail throws
}

LogColumns PresentColumns(const Header& h) {
  LogColumns c;
  c.pose = h.Has(kX);
  c.velocity = h.Has(kVx);
  c.force = h.Has(kFx) || h.Has(kFy);
  c.fz = h.Has(kFz);
  c.moments = h.HasAny(kTx, kTy, kTz);
  c.push_point = h.Has(kPx);
  c.tip = h.Has(kTipX);
  c.step_info = HasStepColumns(h);
  c.mode = h.mode_field >= 0;
  return c;
}

void NoteUnknownColumns(const ReadContext& ctx) {
  if (ctx.report.unknown_columns.empty()) return;
  std::string note = "unknown columns ignored:";
  for (const auto& name : ctx.report.unknown_columns) note += " " + name;
  ctx.report.notes.push_back(note);
}

PushLogFile ReadFromLines(const ReadContext& ctx, TextLines& in) {
  Metadata meta;
  int header_line = 0;
  const std::string header_text = ReadPreamble(ctx, in, meta, header_line);
  const Header header = ParseHeader(ctx, header_text, header_line);

  PushLogFile file;
  Trajectory& trajectory = file.log;
  std::array<bool, 4> known{};  // mass, inertia, com_height, gravity (kPropertySpecs order)
  trajectory.slider = ResolveSlider(ctx, meta, known);
  if (header.Has(kPx) && !known[2]) {
    ctx.Fail(0, "",
             "slider com_height is not known but needed for the moments of px, py, pz: "
             "add '# com_height = ...' to the log or pass --com-height");
  }
  WarnAbsurdSlider(ctx, meta, trajectory.slider, known);
  if (!known[0] && header.Has(kFz)) {
    ctx.report.notes.push_back("fz not checked against m g: mass unknown");
  }
  trajectory.patch = CheckedPatch(ctx, meta);
  if (meta.patch) file.patch_spec = *meta.patch;
  if (meta.tip_radius) trajectory.tip_radius_m = meta.tip_radius->first;
  file.extra_metadata = meta.extra;
  ResolveTruth(ctx, meta, file);
  trajectory.measured = PresentColumns(header);

  std::optional<Eigen::Vector2d> cm_offset;
  if (meta.cm_offset) {
    if (!header.Has(kX)) {
      ctx.Fail(meta.cm_offset->second, "",
               "metadata 'cm_offset' needs the pose columns x, y, theta: it moves the logged "
               "pose to the CM");
    }
    cm_offset = meta.cm_offset->first;
    ctx.report.notes.push_back("poses moved to the CM, at (" + ShortNumber(cm_offset->x()) + ", " +
                               ShortNumber(cm_offset->y()) +
                               ") m in the logged pose's frame (cm_offset)");
  }
  std::vector<int> lines;  // the file line of each sample, for messages
  ReadSamples(ctx, in, header, trajectory, lines, known[0], cm_offset);
  CheckTimeGaps(ctx, trajectory, lines);
  NoteRuns(ctx, trajectory);
  CheckRowTimes(ctx, trajectory, lines);
  const PushWork work = MeasurePushWork(trajectory);
  if (!WarnForceAgainstMotion(ctx, work.force)) WarnSpinAgainstMoment(ctx, work.spin);
  WarnThetaInDegrees(ctx, trajectory, lines);
  if (!header.Has(kVx)) {
    VelocitiesFromPoses(ctx, trajectory, lines);
  } else if (header.Has(kX)) {
    WarnVelocitiesAgainstPoses(ctx, trajectory, lines);
  }
  NoteUnknownColumns(ctx);
  return file;
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
Eigen::Vector3d WrittenMoments(const TrajectorySample& s, bool push_point, double com_height_m) {
  const AppliedWrench& a = s.applied;
  if (!push_point) return {a.tx, a.ty, a.tz};
  const Eigen::Vector3d p = WrittenPushPoint(s, com_height_m);
  const AppliedWrench m = WrenchFromForceAt(a.fx, a.fy, a.fz, p.x() - s.state.x, p.y() - s.state.y,
                                            p.z() - com_height_m);
  return {ResidualFor(a.tx, m.tx), ResidualFor(a.ty, m.ty), ResidualFor(a.tz, m.tz)};
}

/// The groups actually written: the requested ones, plus any whose data would otherwise be
/// lost (non-zero forces or moments), plus poses when push points need them.
LogColumns WrittenColumns(const Trajectory& tr) {
  LogColumns c = tr.measured;
  c.mode = c.mode || c.step_info || HasGaps(tr);
  // The tip columns only when every row knows the tip (a log carries no missing values).
  c.tip = c.tip && std::all_of(tr.samples.begin(), tr.samples.end(),
                               [](const TrajectorySample& s) { return s.tip_world.has_value(); });
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
  const bool reserved = Contains(kSliderKeys, key) || (key == "patch" && tr.patch.has_value()) ||
                        (key == "tip_radius" && tr.tip_radius_m.has_value()) ||
                        (Contains(kTruthKeys, key) && tr.true_friction.has_value());
  if (!IsIdentifier(key) || reserved || value.find('\n') != std::string::npos) {
    throw std::invalid_argument("push log metadata '" + key +
                                "' cannot be written: keys must "
                                "be identifiers not written elsewhere, values one line");
  }
}

/// Whether `text` parses to the patch whose Spec() is `spec`.
bool Describes(const std::string& text, const std::string& spec) {
  try {
    return ContactPatch::Parse(text).Spec() == spec;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

/// The file's own patch text while it still describes the patch (a log written back is the
/// log read), else the patch as it now is.
std::string PatchText(const Trajectory& tr, const std::string& patch_spec) {
  if (!tr.patch) return "";
  const std::string spec = tr.patch->Spec();
  return !patch_spec.empty() && Describes(patch_spec, spec) ? patch_spec : spec;
}

/// The writer's view of a PushLogFile, so that a Trajectory alone is written uncopied.
struct FileView {
  const Trajectory& log;
  const std::string& patch_spec;
  const std::vector<std::pair<std::string, std::string>>& extra_metadata;
};

void WriteMetadata(const FileView& file, std::ostream& out) {
  const Trajectory& tr = file.log;
  const SliderProperties& s = tr.slider;
  out << "# mass = " << ExactNumber(s.mass_kg) << "\n# inertia = " << ExactNumber(s.inertia_kgm2)
      << "\n# com_height = " << ExactNumber(s.com_height_m)
      << "\n# gravity = " << ExactNumber(s.gravity_mps2) << "\n";
  if (tr.patch) out << "# patch = " << PatchText(tr, file.patch_spec) << "\n";
  if (tr.tip_radius_m) out << "# tip_radius = " << ExactNumber(*tr.tip_radius_m) << "\n";
  if (tr.true_friction) {
    const FrictionParameters& f = *tr.true_friction;
    out << "# mu = " << ExactNumber(f.mu) << "\n# e_t = " << ExactNumber(f.e_t)
        << "\n# e_o = " << ExactNumber(f.e_o) << "\n# e_r = " << ExactNumber(f.e_r) << "\n";
  }
  for (const auto& [key, value] : file.extra_metadata) {
    out << "# " << key << " = " << value << "\n";
  }
}

/// The numeric columns written, in file order (the mode column, if any, comes last).
std::vector<const char*> WrittenNames(const LogColumns& c) {
  std::vector<const char*> names = {"t"};
  auto add = [&](std::initializer_list<const char*> group) {
    names.insert(names.end(), group.begin(), group.end());
  };
  if (c.pose) add({"x", "y", "theta"});
  if (c.velocity) add({"vx", "vy", "wz"});
  if (c.force) add({"fx", "fy"});
  if (c.fz) add({"fz"});
  if (c.push_point) add({"px", "py", "pz"});
  if (c.moments) add({"tx", "ty", "tz"});
  if (c.tip) add({"tip_x", "tip_y"});
  if (c.step_info) add({"ax", "ay", "pt", "po", "pr", "sigma"});
  return names;
}

std::string HeaderLine(const LogColumns& c) {
  std::string h;
  for (const char* name : WrittenNames(c)) h += (h.empty() ? "" : ",") + std::string(name);
  if (c.mode) h += std::string(",") + kModeColumn;
  return h;
}

/// The numbers of a row, in the order of WrittenNames (`values` is cleared first).
void RowValues(const TrajectorySample& s, const StepRecord& step, const LogColumns& c,
               double com_height_m, std::vector<double>& values) {
  values.clear();
  auto add = [&](std::initializer_list<double> group) {
    values.insert(values.end(), group.begin(), group.end());
  };
  const PlanarState& q = s.state;
  add({s.t_s});
  if (c.pose) add({q.x, q.y, q.theta});
  if (c.velocity) add({q.vx, q.vy, q.wz});
  if (c.force) add({s.applied.fx, s.applied.fy});
  if (c.fz) add({s.applied.fz});
  if (c.push_point) {
    const Eigen::Vector3d p = WrittenPushPoint(s, com_height_m);
    add({p.x(), p.y(), p.z()});
  }
  if (c.moments) {
    const Eigen::Vector3d m = WrittenMoments(s, c.push_point, com_height_m);
    add({m.x(), m.y(), m.z()});
  }
  if (c.tip) add({s.tip_world->x(), s.tip_world->y()});  // WrittenColumns: every row has it
  if (c.step_info) {
    add({step.ecp_world.x(), step.ecp_world.y(), step.pt, step.po, step.pr, step.sigma});
  }
}

/// Writes without checking the stream; callers check and name their target.
void WriteUnchecked(const FileView& file, std::ostream& out) {
  const Trajectory& tr = file.log;
  for (const auto& [key, value] : file.extra_metadata) CheckMetadataEntry(tr, key, value);
  WriteMetadata(file, out);
  const LogColumns columns = WrittenColumns(tr);
  out << HeaderLine(columns) << '\n';
  std::vector<double> values;
  std::string line;
  for (std::size_t u = 0; u < tr.samples.size(); ++u) {
    const TrajectorySample& s = tr.samples[u];
    RowValues(s, StepAt(tr, u), columns, tr.slider.com_height_m, values);
    line.clear();
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i > 0) line += ',';
      line += ExactNumber(values[i]);
    }
    if (columns.mode) line += std::string(",") + WrittenMode(tr, s);
    out << line << '\n';
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Public functions
// ---------------------------------------------------------------------------------------

LogError::LogError(const std::string& file, int line, const std::string& column,
                   const std::string& what)
    : std::runtime_error(text::Located(file, line, column, what)),
      file_(file),
      line_(line),
      column_(column) {}

namespace {

void NoteMissingFinalLineBreak(const ReadContext& ctx, bool empty, bool ends_with_newline) {
  if (!empty && !ends_with_newline) {
    ctx.report.notes.push_back(
        "the last line has no line break: check that the file was not "
        "cut short");
  }
}

}  // namespace

PushLogFile ReadPushLogFile(const std::string& path, const LogReadOptions& options,
                            LogReadReport* report) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw LogError(path, 0, "", "cannot read: it is a directory, not a log file");
  }
  LogReadReport local_report;
  const std::unique_ptr<TextLines> lines = TextLines::OpenFile(path);
  const ReadContext ctx{path, options, report ? *report : local_report, CountRowLines(path)};
  PushLogFile file = ReadFromLines(ctx, *lines);
  NoteMissingFinalLineBreak(ctx, lines->Empty(), lines->EndsWithLineBreak());
  return file;
}

PushLogFile ParsePushLogFile(std::string_view text, const std::string& source,
                             const LogReadOptions& options, LogReadReport* report) {
  LogReadReport local_report;
  RowLineCounter counter;
  counter.Feed(text);
  const ReadContext ctx{source, options, report ? *report : local_report, counter.count()};
  const std::unique_ptr<TextLines> lines = TextLines::FromMemory(text, source);
  PushLogFile file = ReadFromLines(ctx, *lines);
  NoteMissingFinalLineBreak(ctx, lines->Empty(), lines->EndsWithLineBreak());
  return file;
}

Trajectory ReadPushLog(const std::string& path, const LogReadOptions& options,
                       LogReadReport* report) {
  return ReadPushLogFile(path, options, report).log;
}

Trajectory ParsePushLog(std::string_view text, const std::string& source,
                        const LogReadOptions& options, LogReadReport* report) {
  return ParsePushLogFile(text, source, options, report).log;
}

std::string PatchText(const PushLogFile& file) { return PatchText(file.log, file.patch_spec); }

namespace {

const std::string kNoPatchText;
const std::vector<std::pair<std::string, std::string>> kNoMetadata;

void WriteToStream(const FileView& file, std::ostream& out) {
  WriteUnchecked(file, out);
  out.flush();
  if (!out) throw std::runtime_error("writing the push log to a stream failed");
}

void WriteToPath(const FileView& file, const std::string& path) {
  WriteFileAtomically(path, "push log", [&](std::ostream& out) { WriteUnchecked(file, out); });
}

}  // namespace

void WritePushLog(const PushLogFile& file, std::ostream& out) {
  WriteToStream({file.log, file.patch_spec, file.extra_metadata}, out);
}

void WritePushLog(const PushLogFile& file, const std::string& path) {
  WriteToPath({file.log, file.patch_spec, file.extra_metadata}, path);
}

void WritePushLog(const Trajectory& trajectory, std::ostream& out) {
  WriteToStream({trajectory, kNoPatchText, kNoMetadata}, out);
}

void WritePushLog(const Trajectory& trajectory, const std::string& path) {
  WriteToPath({trajectory, kNoPatchText, kNoMetadata}, path);
}

PushLogColumns ColumnsOf(const Trajectory& trajectory) {
  const LogColumns written = WrittenColumns(trajectory);
  PushLogColumns columns;
  for (const char* name : WrittenNames(written)) columns.names.emplace_back(name);
  columns.values.assign(columns.names.size(), {});
  for (auto& column : columns.values) column.reserve(trajectory.samples.size());
  std::vector<double> values;
  for (std::size_t u = 0; u < trajectory.samples.size(); ++u) {
    const TrajectorySample& s = trajectory.samples[u];
    RowValues(s, StepAt(trajectory, u), written, trajectory.slider.com_height_m, values);
    for (std::size_t i = 0; i < values.size(); ++i) columns.values[i].push_back(values[i]);
    if (written.mode) columns.mode.emplace_back(WrittenMode(trajectory, s));
  }
  return columns;
}

namespace {

/// Whether `text` fits in one CSV cell or metadata value of a log (no line break, no
/// comma when `cell`, no NUL).
bool FitsOneLine(std::string_view text, bool cell) {
  return text.find_first_of(cell ? std::string_view("\n\r,\0", 4)
                                 : std::string_view("\n\r\0", 3)) == std::string_view::npos;
}

/// The text of the file that `columns` and `metadata` make (line numbers as documented).
std::string ColumnsText(const PushLogColumns& columns,
                        const std::vector<std::pair<std::string, std::string>>& metadata,
                        const std::string& source) {
  const int header_line = static_cast<int>(metadata.size()) + 1;
  std::string text;
  for (std::size_t i = 0; i < metadata.size(); ++i) {
    const auto& [key, value] = metadata[i];
    if (!IsIdentifier(key) || !FitsOneLine(value, false)) {
      throw LogError(source, static_cast<int>(i) + 1, "",
                     "metadata '" + key + "': keys must be identifiers, values one line");
    }
    text += "# " + key + " = " + value + "\n";
  }
  if (columns.values.size() != columns.names.size()) {
    throw LogError(source, header_line, "", "one column of values per name is needed");
  }
  const bool with_mode = !columns.mode.empty();
  const std::size_t rows = columns.values.empty() ? columns.mode.size() : columns.values[0].size();
  std::string header;
  for (std::size_t c = 0; c < columns.names.size(); ++c) {
    const std::string& name = columns.names[c];
    if (!IsIdentifier(name)) throw LogError(source, header_line, name, "not a column name");
    if (columns.values[c].size() != rows) {
      throw LogError(source, header_line, name,
                     "has " + std::to_string(columns.values[c].size()) + " values, '" +
                         columns.names[0] + "' " + std::to_string(rows));
    }
    header += (c > 0 ? "," : "") + name;
  }
  if (with_mode) {
    if (columns.mode.size() != rows) {
      throw LogError(source, header_line, kModeColumn,
                     "has " + std::to_string(columns.mode.size()) + " values, the others " +
                         std::to_string(rows));
    }
    header += std::string(header.empty() ? "" : ",") + kModeColumn;
  }
  text += header + "\n";
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns.values.size(); ++c) {
      if (c > 0) text += ',';
      text += ShortNumber(columns.values[c][r]);  // "nan", "inf": the reader names them
    }
    if (with_mode) {
      if (!FitsOneLine(columns.mode[r], true)) {
        throw LogError(source, header_line + 1 + static_cast<int>(r), kModeColumn,
                       "is not start, slide or stick");
      }
      text += (columns.values.empty() ? "" : ",") + columns.mode[r];
    }
    text += '\n';
  }
  return text;
}

}  // namespace

PushLogFile ParsePushLogColumns(const PushLogColumns& columns,
                                const std::vector<std::pair<std::string, std::string>>& metadata,
                                const std::string& source, const LogReadOptions& options,
                                LogReadReport* report) {
  return ParsePushLogFile(ColumnsText(columns, metadata, source), source, options, report);
}

}  // namespace slideid
