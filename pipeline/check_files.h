#pragma once
// The check before fitting (estimator/log_check.h) of files: what `identify --check` and
// slideid.check do. Each file is read as identify reads it and checked on its own; a file
// that cannot be read gives its error and does not stop the others.

#include <optional>
#include <string>
#include <vector>

#include "estimator/log_check.h"
#include "pipeline/identify_files.h"

namespace slideid {

/// One file's check, or why it could not be read.
struct FileCheck {
  std::string path;
  std::optional<LogCheck> check;      ///< empty when the file could not be read
  std::string error;                  ///< why not (naming the file and the place)
  std::vector<std::string> warnings;  ///< what the reader noticed, each naming the file
  /// Whether the check expects the fit of this file to identify something.
  bool Usable() const { return check && check->AnyIdentifiable(); }
};

/// Reads and checks every file with `options` (the trajectory fit's; the read options
/// apply). Throws std::invalid_argument for invalid options or another method.
std::vector<FileCheck> CheckFiles(const std::vector<std::string>& paths,
                                  const FileIdentifyOptions& options);

/// The check of logs already in memory (the Python module's), named by their `source`.
std::vector<FileCheck> CheckReadLogs(const std::vector<Trajectory>& logs,
                                     const FileIdentifyOptions& options);

}  // namespace slideid
