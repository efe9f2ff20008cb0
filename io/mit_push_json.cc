#include "io/mit_push_json.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>

#include "forward_model/number_format.h"
#include "io/atomic_file.h"

namespace slideid {
namespace {

using nlohmann::json;

/// The streams in file order of the format, with their row meaning for messages.
struct StreamField {
  const char* key;
  std::vector<MitStreamRow> MitPushRecording::*rows;
};
constexpr std::array<StreamField, 3> kStreams = {{
    {"object_pose", &MitPushRecording::object_pose},
    {"tip_pose", &MitPushRecording::tip_pose},
    {"ft_wrench", &MitPushRecording::ft_wrench},
}};

std::string FormatMessage(const std::string& file, const std::string& json_path, int line,
                          int column, const std::string& what) {
  if (!json_path.empty()) return file + ": " + json_path + ": " + what;
  if (line > 0)
    return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + what;
  return file + ": " + what;
}

/// JSON type names as a user reads them ("string", "object", ...).
std::string TypeName(const json& value) {
  if (value.is_number()) return "number";
  return value.type_name();
}

/// Line and column (1-based) of the byte at 1-based index `byte` of `text`: where
/// nlohmann-json stopped reading. Past the end (a truncated file) is the end of the text.
std::pair<int, int> LineColumn(std::string_view text, std::size_t byte) {
  const std::size_t end = std::min(byte == 0 ? 0 : byte - 1, text.size());
  const std::string_view before = text.substr(0, end);
  const int line = 1 + static_cast<int>(std::count(before.begin(), before.end(), '\n'));
  const std::size_t last_newline = before.rfind('\n');
  const std::size_t column0 = last_newline == std::string_view::npos ? end : end - last_newline - 1;
  return {line, static_cast<int>(column0) + 1};
}

/// nlohmann-json reports the last byte it read (1-based): the end of the offending token.
/// Messages point at its first byte, where a reader looks for it.
std::size_t TokenStart(std::string_view text, std::size_t byte) {
  auto in_token = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.';
  };
  if (byte == 0 || byte > text.size() || !in_token(text[byte - 1])) return byte;
  while (byte > 1 && in_token(text[byte - 2])) --byte;
  return byte;
}

/// nlohmann's message without its "[json.exception...] parse error at ...: " prefix.
std::string SyntaxMessage(const std::string& what) {
  const std::size_t at = what.find("parse error");
  if (at == std::string::npos) return what;
  const std::size_t colon = what.find(": ", at);
  return colon == std::string::npos ? what : what.substr(colon + 2);
}

json ParseText(std::string_view text, const std::string& source) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) {
    throw MitPushError(source, "", 0, 0,
                       "empty file (expected a JSON object with the streams "
                       "object_pose, tip_pose and ft_wrench)");
  }
  try {
    return json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    const auto [line, column] = LineColumn(text, TokenStart(text, e.byte));
    const bool truncated = e.byte > text.size();
    throw MitPushError(source, "", line, column,
                       std::string("invalid JSON") + (truncated ? " (truncated file?)" : "") +
                           ": " + SyntaxMessage(e.what()));
  } catch (const json::exception& e) {  // e.g. a number beyond the range of a double
    throw MitPushError(source, "", 0, 0, std::string("invalid JSON: ") + SyntaxMessage(e.what()));
  }
}

MitStreamRow ParseRow(const json& row, const std::string& source, const std::string& path) {
  if (!row.is_array()) {
    throw MitPushError(source, path, 0, 0,
                       "not a row (expected an array of 4 numbers, found " + TypeName(row) + ")");
  }
  if (row.size() != 4) {
    throw MitPushError(
        source, path, 0, 0,
        "row of " + std::to_string(row.size()) + " values (expected 4: t and three values)");
  }
  MitStreamRow out{};
  for (std::size_t k = 0; k < 4; ++k) {
    const json& cell = row[k];
    const std::string cell_path = path + "[" + std::to_string(k) + "]";
    if (!cell.is_number()) {
      throw MitPushError(source, cell_path, 0, 0, "not a number (found " + TypeName(cell) + ")");
    }
    out[k] = cell.get<double>();
    if (!std::isfinite(out[k])) throw MitPushError(source, cell_path, 0, 0, "not a finite number");
  }
  return out;
}

std::vector<MitStreamRow> ParseStream(const json& document, const char* key,
                                      const std::string& source) {
  const std::string path = std::string("$.") + key;
  const auto it = document.find(key);
  if (it == document.end()) {
    throw MitPushError(source, path, 0, 0,
                       "missing stream (the file needs object_pose, "
                       "tip_pose and ft_wrench)");
  }
  if (!it->is_array()) {
    throw MitPushError(source, path, 0, 0, "not an array of rows (found " + TypeName(*it) + ")");
  }
  if (it->empty()) throw MitPushError(source, path, 0, 0, "empty stream (no rows)");
  std::vector<MitStreamRow> rows;
  rows.reserve(it->size());
  for (std::size_t i = 0; i < it->size(); ++i) {
    rows.push_back(ParseRow((*it)[i], source, path + "[" + std::to_string(i) + "]"));
  }
  return rows;
}

/// The value of `key=` in a file name: the text up to the next '_' (or the end).
std::optional<std::string> Field(const std::string& name, const std::string& key) {
  const std::string tag = key + "=";
  std::size_t at = 0;
  while ((at = name.find(tag, at)) != std::string::npos) {
    if (at == 0 || name[at - 1] == '_') {
      const std::size_t begin = at + tag.size();
      const std::size_t end = name.find('_', begin);
      return name.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    }
    at += tag.size();
  }
  return std::nullopt;
}

std::optional<double> NumberField(const std::string& name, const std::string& key) {
  const std::optional<std::string> text = Field(name, key);
  if (!text || text->empty()) return std::nullopt;
  double value = 0.0;
  const char* begin = text->data();
  const char* end = begin + text->size();
  const auto result = std::from_chars(begin, end, value);
  if (result.ec != std::errc() || result.ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace

MitPushError::MitPushError(const std::string& file, const std::string& json_path, int line,
                           int column, const std::string& what)
    : std::runtime_error(FormatMessage(file, json_path, line, column, what)),
      file_(file),
      json_path_(json_path),
      line_(line),
      column_(column) {}

MitPushRecording ParseMitPushJson(std::string_view text, const std::string& source) {
  const json document = ParseText(text, source);
  if (!document.is_object()) {
    throw MitPushError(source, "$", 0, 0,
                       "not a JSON object (found " + TypeName(document) +
                           "; expected the streams object_pose, tip_pose and ft_wrench)");
  }
  MitPushRecording recording;
  for (const StreamField& stream : kStreams) {
    recording.*stream.rows = ParseStream(document, stream.key, source);
  }
  return recording;
}

MitPushRecording ReadMitPushJson(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MitPushError(path, "", 0, 0, std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw MitPushError(path, "", 0, 0, "read error");
  return ParseMitPushJson(text.str(), path);
}

std::string FormatMitPushJson(const MitPushRecording& recording) {
  std::string out = "{";
  for (std::size_t s = 0; s < kStreams.size(); ++s) {
    out += s == 0 ? "\n" : ",\n";
    out += "  \"" + std::string(kStreams[s].key) + "\": [";
    const std::vector<MitStreamRow>& rows = recording.*kStreams[s].rows;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      out += i == 0 ? "\n    [" : ",\n    [";
      for (std::size_t k = 0; k < 4; ++k) out += (k ? ", " : "") + ShortNumber(rows[i][k]);
      out += "]";
    }
    out += rows.empty() ? "]" : "\n  ]";
  }
  out += "\n}\n";
  return out;
}

void WriteMitPushJson(const MitPushRecording& recording, const std::string& path) {
  WriteFileAtomically(path, "MIT push file", FormatMitPushJson(recording));
}

MitPushFileName ParseMitPushFileName(const std::string& path) {
  std::string name =
      path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
  if (name.size() > 5 && name.compare(name.size() - 5, 5, ".json") == 0) {
    name.resize(name.size() - 5);
  }
  MitPushFileName out;
  out.surface = Field(name, "surface").value_or("");
  out.shape = Field(name, "shape").value_or("");
  out.acceleration = NumberField(name, "a");
  out.velocity_mm_s = NumberField(name, "v");
  out.side = NumberField(name, "i");
  out.position = NumberField(name, "s");
  out.angle_rad = NumberField(name, "t");
  return out;
}

StreamCleanup SortAndDeduplicate(std::vector<MitStreamRow>* rows) {
  StreamCleanup c;
  c.rows_in = static_cast<int>(rows->size());
  for (std::size_t i = 1; i < rows->size(); ++i) {
    if ((*rows)[i][0] < (*rows)[i - 1][0]) ++c.backward_steps;
  }
  std::stable_sort(rows->begin(), rows->end(),
                   [](const MitStreamRow& a, const MitStreamRow& b) { return a[0] < b[0]; });
  std::vector<MitStreamRow> kept;
  kept.reserve(rows->size());
  for (const MitStreamRow& row : *rows) {
    if (!kept.empty() && kept.back()[0] == row[0]) {
      ++c.duplicates_dropped;
      if (kept.back() != row) ++c.conflicting_duplicates;
      continue;
    }
    kept.push_back(row);
  }
  *rows = std::move(kept);
  return c;
}

}  // namespace slideid
