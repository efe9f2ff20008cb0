#pragma once
// The HTML report's inputs gathered from files, and the report written (identify --report,
// validate --report; report/html_report.h renders it). What the result does not carry is
// gathered here: each log read again as the run read it, replayed (identify) or predicted
// (validate), checked before fitting (estimator/log_check.h), and its import report row.

#include <string>
#include <vector>

#include "pipeline/identify_files.h"
#include "prediction/validate.h"
#include "report/report_inputs.h"

namespace slideid {

/// identify's report: `run` is what IdentifyFiles(paths, options) returned. A log that
/// cannot be read again, replayed or checked says so in its place; nothing here throws for
/// that. The command line and the timings are the caller's to add.
ReportInputs GatherIdentifyReport(const std::vector<std::string>& paths,
                                  const FileIdentifyOptions& options,
                                  const FileIdentifyResult& run);

/// identify's report of logs already in memory (the Python module's), named by their
/// `source` as IdentifyReadLogs names them; `run` what IdentifyReadLogs returned.
ReportInputs GatherIdentifyReportOfLogs(const std::vector<Trajectory>& logs,
                                        const FileIdentifyOptions& options,
                                        const FileIdentifyResult& run);

/// validate's report: `logs` as validated (their `source` the paths), `result` what
/// Validate(logs, options) returned. Each log is predicted by its fold's friction.
ReportInputs GatherValidateReport(const std::vector<Trajectory>& logs,
                                  const ValidationOptions& options, const ValidationResult& result);

/// Renders `inputs` and writes the page to `path` atomically (io/atomic_file.h); throws
/// FileWriteError.
void WriteHtmlReport(const ReportInputs& inputs, const std::string& path);

/// The command line as one string a shell would read back: arguments with characters a
/// shell treats specially are single-quoted.
std::string QuotedCommandLine(int argc, const char* const* argv);

}  // namespace slideid
