#include "io/import_report_row.h"

#include <filesystem>
#include <fstream>

namespace slideid {
namespace {

// Splits one CSV line into cells (RFC 4180 quoting; no line breaks inside cells, which the
// import report never writes).
std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quoted) {
      if (ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else if (ch == '"') {
        quoted = false;
      } else {
        cells.back() += ch;
      }
    } else if (ch == '"') {
      quoted = true;
    } else if (ch == ',') {
      cells.emplace_back();
    } else if (ch != '\r') {
      cells.back() += ch;
    }
  }
  return cells;
}

}  // namespace

std::string ImportReportBeside(const std::string& log_path) {
  return (std::filesystem::path(log_path).parent_path() / "import_report.csv").string();
}

std::vector<std::pair<std::string, std::string>> FindImportReportRow(
    const std::string& report_path, const std::string& log_file_name) {
  std::ifstream in(report_path);
  std::string line;
  if (!in || !std::getline(in, line)) return {};
  const std::vector<std::string> header = SplitCsvLine(line);
  size_t output = header.size();
  for (size_t k = 0; k < header.size(); ++k) {
    if (header[k] == "output") output = k;
  }
  if (output == header.size()) return {};
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = SplitCsvLine(line);
    if (output >= cells.size() || cells[output].empty() ||
        std::filesystem::path(cells[output]).filename().string() != log_file_name) {
      continue;
    }
    std::vector<std::pair<std::string, std::string>> row;
    for (size_t k = 0; k < header.size(); ++k) {
      row.emplace_back(header[k], k < cells.size() ? cells[k] : "");
    }
    return row;
  }
  return {};
}

}  // namespace slideid
