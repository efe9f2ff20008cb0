#pragma once
// A log's row of the import report import-log writes beside its logs (DIR/import_report.csv,
// io/mit_push_report.h; its columns in docs/real-data.md), for the HTML report.

#include <string>
#include <utility>
#include <vector>

namespace slideid {

/// The import report that would sit beside `log_path`: DIR/import_report.csv.
std::string ImportReportBeside(const std::string& log_path);

/// The row of the import report at `report_path` whose `output` cell names the file
/// `log_file_name` (compared by file name), as (column, cell) pairs in the header's order;
/// empty when the report does not exist, cannot be read, or has no such row. Cells are
/// unquoted (RFC 4180: "" is a quote).
std::vector<std::pair<std::string, std::string>> FindImportReportRow(
    const std::string& report_path, const std::string& log_file_name);

}  // namespace slideid
