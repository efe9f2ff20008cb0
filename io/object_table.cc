#include "io/object_table.h"

#include <libfccp/csv.h>

#include <charconv>
#include <cmath>
#include <string>

#include "forward_model/contact_patch.h"
#include "io/cm_offset.h"

namespace slideid {
namespace {

std::string Where(const std::string& path, unsigned line, const std::string& column) {
  return path + ":" + std::to_string(line) + ": column '" + column + "': ";
}

/// A finite number >= 0 (> 0 when `positive`), or an error naming where it is.
double Number(const char* cell, bool positive, const std::string& where) {
  const std::string text = cell ? cell : "";
  double value = 0.0;
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto result = std::from_chars(begin, end, value);
  if (text.empty() || result.ec != std::errc() || result.ptr != end || !std::isfinite(value)) {
    throw std::runtime_error(where + "'" + text + "' is not a finite number");
  }
  if (value < 0.0 || (positive && value == 0.0)) {
    throw std::runtime_error(where + "'" + text + "' must be " + (positive ? "> 0" : ">= 0"));
  }
  return value;
}

}  // namespace

ObjectTable ReadObjectTable(const std::string& path) {
  using Reader = io::CSVReader<7, io::trim_chars<' ', '\t'>, io::double_quote_escape<',', '"'>,
                               io::throw_on_overflow, io::single_and_empty_line_comment<'#'>>;
  ObjectTable table;
  try {
    Reader reader(path);
    reader.read_header(io::ignore_extra_column | io::ignore_missing_column, "name", "mass",
                       "inertia", "com_height", "patch", "cm_offset", "source");
    for (const char* required : {"name", "mass", "inertia", "com_height"}) {
      if (!reader.has_column(required)) {
        throw std::runtime_error(
            path + ": missing column '" + required +
            "' (need name, mass, inertia, com_height; optional patch, cm_offset, source)");
      }
    }
    char *name = nullptr, *mass = nullptr, *inertia = nullptr, *com = nullptr;
    char *patch = nullptr, *cm_offset = nullptr, *source = nullptr;
    while (reader.read_row(name, mass, inertia, com, patch, cm_offset, source)) {
      const unsigned line = reader.get_file_line();
      const std::string key = name ? name : "";
      if (key.empty()) throw std::runtime_error(Where(path, line, "name") + "empty object name");
      ObjectProperties p;
      p.mass_kg = Number(mass, true, Where(path, line, "mass"));
      p.inertia_kgm2 = Number(inertia, true, Where(path, line, "inertia"));
      p.com_height_m = Number(com, false, Where(path, line, "com_height"));
      if (patch && *patch) {
        try {
          p.patch_spec = ContactPatch::Parse(patch).Spec();
        } catch (const std::invalid_argument& e) {
          throw std::runtime_error(Where(path, line, "patch") + e.what());
        }
      }
      if (cm_offset && *cm_offset) {
        const std::optional<Eigen::Vector2d> offset = ParseCmOffset(cm_offset);
        if (!offset) {
          throw std::runtime_error(Where(path, line, "cm_offset") + "'" + cm_offset +
                                   "' is not two numbers DX DY (m)");
        }
        p.cm_offset_m = *offset;
      }
      if (source) p.source = source;
      if (!table.emplace(key, p).second) {
        throw std::runtime_error(Where(path, line, "name") + "object '" + key + "' given twice");
      }
    }
  } catch (const io::error::base& e) {
    throw std::runtime_error(std::string("object table: ") + e.what());
  }
  if (table.empty()) throw std::runtime_error(path + ": no objects in the table");
  return table;
}

}  // namespace slideid
