#include "pipeline/batch.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <ostream>
#include <stdexcept>
#include <thread>

#include "io/result_json.h"

namespace slideid {
namespace {

/// Why the identification of one file must not be used ("" when it may), naming the file,
/// as the identify tool's error for it would.
std::string FileFailure(const std::string& file, const EstimateResult& result) {
  if (result.status == TerminationStatus::kTooLittleExcitation) {
    return file + ": " + result.message;
  }
  const std::string failure = NumericalFailure(result);
  return failure.empty() ? "" : file + ": " + failure;
}

/// The rows of the logs a result fitted.
long long RowsFitted(const EstimateResult& result) {
  if (result.logs.empty()) return result.steps_total + 1;
  long long rows = 0;
  for (const LogResult& log : result.logs) rows += log.rows;
  return rows;
}

}  // namespace

Shard Shard::Parse(const std::string& text) {
  const auto slash = text.find('/');
  Shard s;
  try {
    size_t used_i = 0, used_n = 0;
    if (slash == std::string::npos) throw std::invalid_argument("no /");
    s.index = std::stoi(text.substr(0, slash), &used_i);
    s.count = std::stoi(text.substr(slash + 1), &used_n);
    if (used_i != slash || used_n != text.size() - slash - 1) throw std::invalid_argument("junk");
  } catch (const std::exception&) {
    throw std::invalid_argument("'" + text + "' is not I/N (two whole numbers)");
  }
  if (s.count < 1 || s.index < 0 || s.index >= s.count) {
    throw std::invalid_argument("'" + text + "': need 0 <= I < N");
  }
  return s;
}

std::vector<std::string> Shard::Select(const std::vector<std::string>& sorted_files) const {
  std::vector<std::string> mine;
  for (size_t k = index; k < sorted_files.size(); k += count) mine.push_back(sorted_files[k]);
  return mine;
}

BatchSummary RunBatch(const std::vector<std::string>& files, const BatchOptions& options,
                      std::ostream& out,
                      const std::function<void(const BatchProgress&)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  BatchSummary summary;
  summary.total = static_cast<int>(files.size());
  std::atomic<size_t> next{0};
  std::mutex write;  // guards out, summary and progress
  std::atomic<bool> out_failed{false};
  auto work = [&] {
    for (size_t k = next++; k < files.size() && !out_failed; k = next++) {
      std::string line;
      long long rows = 0;
      bool ok = false;
      try {
        const FileIdentifyResult r = IdentifyFiles({files[k]}, options.identify);
        const std::string error = FileFailure(files[k], r.result);
        line = FormatBatchLine(files[k], &r.result, error, r.warnings);
        ok = error.empty();
        if (ok) rows = RowsFitted(r.result);
      } catch (const std::exception& e) {
        line = FormatBatchLine(files[k], nullptr, e.what(), {});
      }
      std::lock_guard<std::mutex> lock(write);
      out << line << '\n';
      out.flush();
      if (!out) out_failed = true;
      (ok ? summary.ok : summary.failed)++;
      summary.rows += rows;
      if (progress) {
        progress({summary.ok + summary.failed, summary.failed, summary.total,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()});
      }
    }
  };
  const int workers = std::max(1, std::min<int>(options.jobs, static_cast<int>(files.size())));
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (out_failed) throw std::runtime_error("cannot write the results");
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace slideid
