#include "io/pusher_path_csv.h"

// fccp copies the file name with strncpy, which GCC warns of (-Wstringop-truncation) where
// this reader inlines it; the copy is bounded and terminated, so the warning is fccp's noise.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstringop-truncation"
#include <libfccp/csv.h>
#pragma GCC diagnostic pop

#include <cmath>
#include <stdexcept>
#include <vector>

#include "forward_model/number_format.h"
#include "io/text_lines.h"

namespace slideid {
namespace {

std::string Where(const std::string& path, unsigned line, const char* column) {
  return path + ":" + std::to_string(line) + ": column '" + column + "': ";
}

double Number(const char* cell, const std::string& where) {
  const std::string text = cell ? cell : "";
  const auto value = text::ParseFiniteNumber(text);
  if (!value) throw std::runtime_error(where + "'" + text + "' is not a finite number");
  return *value;
}

}  // namespace

PusherPath ReadPusherPathCsv(const std::string& path) {
  using Reader = io::CSVReader<3, io::trim_chars<' ', '\t'>, io::double_quote_escape<',', '"'>,
                               io::throw_on_overflow, io::single_and_empty_line_comment<'#'>>;
  std::vector<double> times;
  std::vector<Eigen::Vector2d> points;
  try {
    Reader reader(path);
    reader.read_header(io::ignore_extra_column, "t", "x", "y");
    char *t = nullptr, *x = nullptr, *y = nullptr;
    while (reader.read_row(t, x, y)) {
      const unsigned line = reader.get_file_line();
      const double time = Number(t, Where(path, line, "t"));
      if (!times.empty() && !(time > times.back())) {
        throw std::runtime_error(Where(path, line, "t") + "t = " + ShortNumber(time) +
                                 " s is not after the previous row's " + ShortNumber(times.back()) +
                                 " s");
      }
      times.push_back(time);
      points.emplace_back(Number(x, Where(path, line, "x")), Number(y, Where(path, line, "y")));
    }
  } catch (const io::error::base& e) {
    throw std::runtime_error(std::string("pusher path: ") + e.what());
  }
  if (times.empty()) throw std::runtime_error(path + ": the pusher path has no rows");
  return PusherPath(times, points);
}

}  // namespace slideid
