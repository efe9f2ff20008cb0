#include "io/wrench_twist_csv.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "forward_model/number_format.h"
#include "io/atomic_file.h"

namespace slideid {
namespace {

constexpr double kDefaultGravity_mps2 = 9.81;  // as push logs (log-format.md)
/// Largest push number or sample count a row may hold; far above any experiment.
constexpr long long kMaxRowCount = 1000000000;

// ---------------------------------------------------------------------------------------
// Columns
// ---------------------------------------------------------------------------------------

enum Col : int {
  kPush,
  kFx,
  kFy,
  kFz,
  kMz,
  kVx,
  kVy,
  kWz,
  kDuration,
  kDx,
  kDy,
  kDtheta,
  kContactX,
  kContactY,
  kPeakForce,
  kSamples,
  kNumCols
};
constexpr std::array<const char*, kNumCols> kColumnNames = {
    "push",     "fx", "fy", "fz",     "mz",        "vx",        "vy",         "wz",
    "duration", "dx", "dy", "dtheta", "contact_x", "contact_y", "peak_force", "samples"};
constexpr std::array<Col, 6> kRequired = {kFx, kFy, kMz, kVx, kVy, kWz};

/// Columns whose cells may be empty (unknown).
bool MayBeEmpty(int c) { return c == kPush || c >= kDuration; }
/// Columns holding whole numbers.
bool IsCount(int c) { return c == kPush || c == kSamples; }

struct Header {
  int line = 0;
  int num_fields = 0;
  std::array<int, kNumCols> field;
  Header() { field.fill(-1); }
  bool Has(int c) const { return field[c] >= 0; }
};

constexpr std::array<const char*, 4> kSliderKeys = {"mass", "gravity", "inertia", "com_height"};
constexpr std::array<const char*, 4> kTruthKeys = {"mu", "e_t", "e_o", "e_r"};
constexpr std::array<const char*, 2> kTextKeys = {"supports", "source"};

template <std::size_t N>
bool Contains(const std::array<const char*, N>& keys, std::string_view key) {
  for (const char* k : keys) {
    if (key == k) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------
// Reader
// ---------------------------------------------------------------------------------------

struct Metadata {
  std::map<std::string, std::pair<double, int>> numbers;  // key -> (value, line)
  std::map<std::string, std::string> texts;
  std::vector<std::pair<std::string, std::string>> extra;
};

class Reader {
 public:
  Reader(TextLines& in, const SliderOverrides& overrides, WrenchTwistReadReport& report)
      : in_(in), overrides_(overrides), report_(report) {}

  WrenchTwistData Read() {
    Metadata meta;
    const std::string header_text = Preamble(meta);
    const Header header = ParseHeader(header_text);
    WrenchTwistData data;
    ResolveMetadata(meta, data);
    ReadRows(header, data);
    return data;
  }

 private:
  [[noreturn]] void Fail(int line, const std::string& column, const std::string& what) const {
    throw LogError(in_.name(), line, column, what);
  }

  void CommentLine(std::string_view line, int line_no, Metadata& meta) {
    line.remove_prefix(1);  // '#'
    const auto eq = line.find('=');
    if (eq == std::string_view::npos) return;
    const std::string key(text::Trim(line.substr(0, eq)));
    if (!text::IsIdentifier(key)) return;  // prose that happens to contain '='
    const std::string value(text::Trim(line.substr(eq + 1)));
    const bool seen = meta.numbers.count(key) || meta.texts.count(key);
    if (seen) Fail(line_no, "", "metadata '" + key + "' given twice");
    if (Contains(kSliderKeys, key) || Contains(kTruthKeys, key)) {
      const auto number = text::ParseFiniteNumber(value);
      if (!number) {
        Fail(line_no, "",
             "metadata '" + key + "': '" + text::Excerpt(value) + "' is not a finite number");
      }
      meta.numbers[key] = {*number, line_no};
    } else if (Contains(kTextKeys, key)) {
      meta.texts[key] = value;
    } else {
      meta.extra.emplace_back(key, value);
    }
  }

  std::string Preamble(Metadata& meta) {
    while (const auto raw = in_.Next()) {
      const std::string_view line = text::Trim(*raw);
      const int line_no = in_.LineNumber();
      if (line.empty()) continue;
      if (line.front() == '#') {
        CommentLine(line, line_no, meta);
        continue;
      }
      header_line_ = line_no;
      return std::string(line);
    }
    Fail(0, "",
         in_.Empty() ? "the file is empty: expected metadata comments and a header line"
                     : "no header line: the file holds only comments");
  }

  Header ParseHeader(const std::string& header_text) {
    Header h;
    h.line = header_line_;
    std::vector<std::string_view> names;
    text::SplitCells(header_text, names);
    h.num_fields = static_cast<int>(names.size());
    for (int i = 0; i < h.num_fields; ++i) {
      const std::string name(names[i]);
      int col = -1;
      for (int c = 0; c < kNumCols; ++c) {
        if (name == kColumnNames[c]) col = c;
      }
      if (col < 0) {
        if (text::ParseFiniteNumber(name)) {
          Fail(h.line, "",
               "the first line that is not a comment must be the header (column "
               "names); found a number, '" +
                   text::Excerpt(name) + "'");
        }
        unknown_.push_back(name.empty() ? "(empty)" : name);
        continue;
      }
      if (h.Has(col)) Fail(h.line, name, "column given twice");
      h.field[col] = i;
    }
    for (Col c : kRequired) {
      if (!h.Has(c)) {
        Fail(h.line, kColumnNames[c],
             "missing: a wrench-twist file needs fx, fy, mz, vx, vy, wz "
             "(column names are lower case)");
      }
    }
    if (!unknown_.empty()) {
      std::string note = "unknown columns ignored:";
      for (const auto& n : unknown_) note += " " + n;
      report_.notes.push_back(note);
    }
    return h;
  }

  /// A slider property from the override, else the metadata; nullopt when neither.
  std::optional<double> Property(const Metadata& meta, const char* key,
                                 const std::optional<double>& override_value, bool zero_allowed) {
    const auto it = meta.numbers.find(key);
    if (!override_value && it == meta.numbers.end()) return std::nullopt;
    const double value = override_value ? *override_value : it->second.first;
    const int line = override_value ? 0 : it->second.second;
    const bool ok = std::isfinite(value) && (zero_allowed ? value >= 0.0 : value > 0.0);
    if (!ok) {
      Fail(line, "",
           std::string(key) + " = " + ShortNumber(value) +
               (override_value ? " (from the options)" : " (metadata)") +
               (zero_allowed ? " must be >= 0" : " must be > 0"));
    }
    return value;
  }

  void ResolveMetadata(const Metadata& meta, WrenchTwistData& data) {
    const auto mass = Property(meta, "mass", overrides_.mass_kg, false);
    if (!mass) {
      Fail(0, "",
           "slider mass is not known: add '# mass = ...' to the file or pass --mass (the "
           "normal force m g - fz scales the friction wrench)");
    }
    data.mass_kg = *mass;
    data.gravity_mps2 =
        Property(meta, "gravity", overrides_.gravity_mps2, false).value_or(kDefaultGravity_mps2);
    if (!std::isfinite(data.WeightN())) {
      Fail(0, "",
           "the weight m g overflows: mass = " + ShortNumber(data.mass_kg) +
               " kg, gravity = " + ShortNumber(data.gravity_mps2) + " m/s^2");
    }
    data.inertia_kgm2 = Property(meta, "inertia", overrides_.inertia_kgm2, false);
    data.com_height_m = Property(meta, "com_height", overrides_.com_height_m, true);
    if (const auto it = meta.texts.find("supports"); it != meta.texts.end()) {
      data.supports = it->second;
    }
    if (const auto it = meta.texts.find("source"); it != meta.texts.end()) data.source = it->second;
    std::size_t truth_keys = 0;
    for (const char* key : kTruthKeys) truth_keys += meta.numbers.count(key);
    if (truth_keys == kTruthKeys.size()) {
      data.true_friction =
          FrictionParameters{meta.numbers.at("mu").first, meta.numbers.at("e_t").first,
                             meta.numbers.at("e_o").first, meta.numbers.at("e_r").first};
    } else {
      for (const char* key : kTruthKeys) {
        const auto it = meta.numbers.find(key);
        if (it != meta.numbers.end()) {
          data.extra_metadata.emplace_back(key, ShortNumber(it->second.first));
        }
      }
      if (truth_keys > 0) {
        report_.notes.push_back(
            "partial true friction (needs mu, e_t, e_o, e_r) kept as extra "
            "metadata");
      }
    }
    data.extra_metadata.insert(data.extra_metadata.end(), meta.extra.begin(), meta.extra.end());
  }

  /// Parses the cells of one row into `v` (NaN for empty optional cells).
  void ParseCells(const Header& h, int line_no, std::array<double, kNumCols>& v) {
    if (static_cast<int>(cells_.size()) != h.num_fields) {
      Fail(line_no, "",
           "expected " + std::to_string(h.num_fields) + " fields as in the header on line " +
               std::to_string(h.line) + ", found " + std::to_string(cells_.size()));
    }
    v.fill(std::numeric_limits<double>::quiet_NaN());
    v[kFz] = 0.0;
    for (int c = 0; c < kNumCols; ++c) {
      if (!h.Has(c)) continue;
      const std::string_view cell = cells_[h.field[c]];
      if (cell.empty() && MayBeEmpty(c)) continue;
      if (IsCount(c)) {
        const auto n = text::ParseCount(cell, kMaxRowCount);
        if (!n) {
          Fail(line_no, kColumnNames[c],
               "'" + text::Excerpt(cell) +
                   "' is not a whole number "
                   "from 0 to " +
                   std::to_string(kMaxRowCount));
        }
        v[c] = static_cast<double>(*n);
        continue;
      }
      const auto x = text::ParseFiniteNumber(cell);
      if (!x) {
        Fail(line_no, kColumnNames[c],
             cell.empty() ? "empty; a number is required"
                          : "'" + text::Excerpt(cell) + "' is not a finite number");
      }
      v[c] = *x;
    }
  }

  /// The physical checks of one row: a wrench and a twist that say something, N > 0.
  void CheckRow(const WrenchTwistRow& r, double weight_n, int line_no) {
    const WrenchTwistPair& p = r.pair;
    if (p.fx == 0.0 && p.fy == 0.0 && p.mz == 0.0) {
      Fail(line_no, "fx",
           "the applied wrench (fx, fy, mz) is zero: a sliding push needs a force "
           "or a moment (a push without contact, or a dead force sensor?)");
    }
    if (p.vx == 0.0 && p.vy == 0.0 && p.wz == 0.0) {
      Fail(line_no, "vx",
           "the twist (vx, vy, wz) is zero: the slider did not move in this push, "
           "so it says nothing about the direction of sliding");
    }
    if (!(weight_n - p.fz > 0.0)) {
      Fail(line_no, "fz",
           "the vertical force lifts the slider: fz = " + ShortNumber(p.fz) +
               " N is not below m g = " + ShortNumber(weight_n) + " N");
    }
    if (!std::isnan(r.duration_s) && !(r.duration_s > 0.0)) {
      Fail(line_no, "duration", "duration = " + ShortNumber(r.duration_s) + " s must be > 0");
    }
  }

  void ReadRows(const Header& h, WrenchTwistData& data) {
    std::array<double, kNumCols> v;
    while (const auto raw = in_.Next()) {
      const std::string_view line = text::Trim(*raw);
      if (line.empty() || line.front() == '#') continue;
      const int line_no = in_.LineNumber();
      text::SplitCells(line, cells_);
      ParseCells(h, line_no, v);
      WrenchTwistRow r;
      r.push = std::isnan(v[kPush]) ? 0 : static_cast<int>(v[kPush]);
      r.pair = {v[kFx], v[kFy], v[kFz], v[kMz], v[kVx], v[kVy], v[kWz]};
      r.duration_s = v[kDuration];
      r.dx_m = v[kDx];
      r.dy_m = v[kDy];
      r.dtheta_rad = v[kDtheta];
      r.contact_x_m = v[kContactX];
      r.contact_y_m = v[kContactY];
      r.peak_force_n = v[kPeakForce];
      r.samples = std::isnan(v[kSamples]) ? 0 : static_cast<int>(v[kSamples]);
      r.line = line_no;
      CheckRow(r, data.WeightN(), line_no);
      data.rows.push_back(r);
    }
    if (data.rows.empty()) Fail(h.line, "", "the header is not followed by any data row");
  }

  TextLines& in_;
  const SliderOverrides& overrides_;
  WrenchTwistReadReport& report_;
  int header_line_ = 0;
  std::vector<std::string> unknown_;
  std::vector<std::string_view> cells_;
};

// ---------------------------------------------------------------------------------------
// Writer
// ---------------------------------------------------------------------------------------

std::string Cell(double value) { return std::isnan(value) ? "" : ShortNumber(value); }

void CheckWritable(const WrenchTwistData& data) {
  if (!(std::isfinite(data.mass_kg) && data.mass_kg > 0.0) ||
      !(std::isfinite(data.gravity_mps2) && data.gravity_mps2 > 0.0)) {
    throw std::invalid_argument("wrench-twist data: mass and gravity must be finite and > 0");
  }
  auto one_line = [](const std::string& key, const std::string& value) {
    if (value.find_first_of("\r\n") != std::string::npos) {
      throw std::invalid_argument("wrench-twist metadata '" + key + "' must be one line");
    }
  };
  one_line("supports", data.supports);
  one_line("source", data.source);
  for (const auto& [key, value] : data.extra_metadata) {
    const bool reserved = Contains(kSliderKeys, key) || Contains(kTextKeys, key) ||
                          (Contains(kTruthKeys, key) && data.true_friction.has_value());
    if (!text::IsIdentifier(key) || reserved) {
      throw std::invalid_argument("wrench-twist metadata '" + key +
                                  "' cannot be written: keys "
                                  "must be identifiers not written elsewhere");
    }
    one_line(key, value);
  }
  for (std::size_t i = 0; i < data.rows.size(); ++i) {
    const WrenchTwistPair& p = data.rows[i].pair;
    const double required[] = {p.fx, p.fy, p.fz, p.mz, p.vx, p.vy, p.wz};
    for (double x : required) {
      if (!std::isfinite(x)) {
        throw std::invalid_argument("wrench-twist row " + std::to_string(i + 1) + " (push " +
                                    std::to_string(data.rows[i].push) +
                                    "): the wrench and twist must be finite");
      }
    }
  }
}

void WriteUnchecked(const WrenchTwistData& data, std::ostream& out) {
  out << "# slideid wrench-twist pairs: one push per row; SI units; frame origin at the CM "
         "(docs/real-data.md)\n";
  out << "# mass = " << ShortNumber(data.mass_kg)
      << "\n# gravity = " << ShortNumber(data.gravity_mps2) << "\n";
  if (data.inertia_kgm2) out << "# inertia = " << ShortNumber(*data.inertia_kgm2) << "\n";
  if (data.com_height_m) out << "# com_height = " << ShortNumber(*data.com_height_m) << "\n";
  if (!data.supports.empty()) out << "# supports = " << data.supports << "\n";
  if (!data.source.empty()) out << "# source = " << data.source << "\n";
  if (data.true_friction) {
    const FrictionParameters& f = *data.true_friction;
    out << "# mu = " << ShortNumber(f.mu) << "\n# e_t = " << ShortNumber(f.e_t)
        << "\n# e_o = " << ShortNumber(f.e_o) << "\n# e_r = " << ShortNumber(f.e_r) << "\n";
  }
  for (const auto& [key, value] : data.extra_metadata) out << "# " << key << " = " << value << "\n";
  for (int c = 0; c < kNumCols; ++c) out << (c ? "," : "") << kColumnNames[c];
  out << "\n";
  for (const WrenchTwistRow& r : data.rows) {
    const WrenchTwistPair& p = r.pair;
    out << r.push;
    for (double x : {p.fx, p.fy, p.fz, p.mz, p.vx, p.vy, p.wz}) out << ',' << ShortNumber(x);
    for (double x : {r.duration_s, r.dx_m, r.dy_m, r.dtheta_rad, r.contact_x_m, r.contact_y_m,
                     r.peak_force_n}) {
      out << ',' << Cell(x);
    }
    out << ',';
    if (r.samples > 0) out << r.samples;
    out << "\n";
  }
}

}  // namespace

WrenchTwistData ReadWrenchTwistCsv(const std::string& path, const SliderOverrides& overrides,
                                   WrenchTwistReadReport* report) {
  WrenchTwistReadReport local;
  const std::unique_ptr<TextLines> lines = TextLines::OpenFile(path);
  WrenchTwistData data = Reader(*lines, overrides, report ? *report : local).Read();
  if (!lines->Empty() && !lines->EndsWithLineBreak()) {
    (report ? *report : local)
        .notes.push_back("the last line has no line break: check that the file was not cut short");
  }
  return data;
}

WrenchTwistData ParseWrenchTwistCsv(std::string_view text, const std::string& source,
                                    const SliderOverrides& overrides,
                                    WrenchTwistReadReport* report) {
  WrenchTwistReadReport local;
  const std::unique_ptr<TextLines> lines = TextLines::FromMemory(text, source);
  return Reader(*lines, overrides, report ? *report : local).Read();
}

void WriteWrenchTwistCsv(const WrenchTwistData& data, std::ostream& out) {
  CheckWritable(data);
  WriteUnchecked(data, out);
  out.flush();
  if (!out) throw std::runtime_error("writing the wrench-twist pairs to a stream failed");
}

void WriteWrenchTwistCsv(const WrenchTwistData& data, const std::string& path) {
  CheckWritable(data);
  WriteFileAtomically(path, "wrench-twist pairs",
                      [&](std::ostream& out) { WriteUnchecked(data, out); });
}

}  // namespace slideid
