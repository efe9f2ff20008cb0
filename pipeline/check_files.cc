#include "pipeline/check_files.h"

#include <filesystem>
#include <stdexcept>

namespace slideid {
namespace {

void CheckOptions(const FileIdentifyOptions& options) {
  std::string why;
  if (!options.identify.IsValid(&why)) throw std::invalid_argument(why);
  if (options.identify.method != EstimatorMethod::kTrajectory) {
    throw std::invalid_argument(
        std::string("--check forecasts the trajectory fit; it does not go with --method ") +
        ToString(options.identify.method));
  }
}

}  // namespace

std::vector<FileCheck> CheckFiles(const std::vector<std::string>& paths,
                                  const FileIdentifyOptions& options) {
  CheckOptions(options);
  std::vector<FileCheck> out;
  for (const std::string& path : paths) {
    FileCheck f;
    f.path = path;
    try {
      LogReadReport report;
      Trajectory log = ReadPushLog(path, options.read, &report);
      log.source = std::filesystem::path(path).filename().string();
      f.warnings = report.warnings;
      f.check = CheckLog(log, options.identify);
    } catch (const std::exception& e) {
      f.error = e.what();
    }
    out.push_back(std::move(f));
  }
  return out;
}

std::vector<FileCheck> CheckReadLogs(const std::vector<Trajectory>& logs,
                                     const FileIdentifyOptions& options) {
  CheckOptions(options);
  std::vector<FileCheck> out;
  for (size_t k = 0; k < logs.size(); ++k) {
    FileCheck f;
    f.path = logs[k].source.empty() ? "log " + std::to_string(k + 1) : logs[k].source;
    f.check = CheckLog(logs[k], options.identify);
    if (f.check->name.empty()) f.check->name = f.path;
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace slideid
