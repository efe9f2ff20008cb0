#pragma once
// import_report.csv of `import-log --format mit-push`: one row per input file, with what
// the import found and did (io/mit_push_import.h, MitImportReport). Columns are documented
// in docs/real-data.md. Unknown values (an offset that could not be estimated, statistics
// of a rejected file) are empty cells.

#include <string>
#include <vector>

#include "io/mit_push_import.h"

namespace slideid {

/// The header line (no newline).
std::string MitImportReportHeader();
/// One row (no newline); text cells with commas or quotes are quoted.
std::string MitImportReportRow(const MitImportReport& report);

/// Writes the header and one row per report to `path`, via a temporary file and a rename.
/// Throws std::runtime_error naming the path if it cannot be written.
void WriteMitImportReport(const std::vector<MitImportReport>& reports, const std::string& path);

}  // namespace slideid
