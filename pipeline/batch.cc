#include "pipeline/batch.h"

#include <atomic>
#include <chrono>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <ostream>
#include <set>
#include <stdexcept>
#include <thread>

#include "io/atomic_file.h"
#include "io/file_hash.h"
#include "io/result_json.h"

namespace slideid {
namespace {

/// Why the identification of one file must not be used ("" when it may), naming the file,
/// as the identify tool's error for it would.
std::string FileFailure(const std::string& file, const EstimateResult& result) {
  if (const std::string nothing = NothingIdentified(result); !nothing.empty()) {
    return file + ": " + nothing;
  }
  const std::string failure = NumericalFailure(result);
  return failure.empty() ? "" : file + ": " + failure;
}

/// The SHA-256 that identifies `file` on resume, or "" where it cannot be taken (a line
/// without one is fitted again on resume). Only a regular file is hashed: a pipe
/// (--batch <(cat log.csv)) can be read only once, and that is the log reader's (hashing
/// it first left the reader an empty pipe: "no header line").
std::string ResumeHash(const std::string& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) return "";
  try {
    return Sha256OfFile(file);
  } catch (const std::exception&) {
    return "";  // unreadable: the fit says why
  }
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
  return RunBatch(
      files, options,
      [&](const std::string& line) {
        out << line << '\n';
        out.flush();
        if (!out) throw std::runtime_error("cannot write the results");
      },
      progress);
}

BatchSummary RunBatch(const std::vector<std::string>& files, const BatchOptions& options,
                      const std::function<void(const std::string& line)>& write_line,
                      const std::function<void(const BatchProgress&)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  BatchSummary summary;
  summary.total = static_cast<int>(files.size());
  std::atomic<size_t> next{0};
  std::mutex write;  // guards write_line, summary, progress and write_error
  std::exception_ptr write_error;
  std::atomic<bool> halt{false};  // a write failed: start no further log
  auto stopped = [&] { return halt || (options.stop != nullptr && *options.stop); };
  auto work = [&] {
    for (size_t k = 0; !stopped() && (k = next++) < files.size();) {
      std::string line;
      long long rows = 0;
      bool ok = false;
      // The hash of what is about to be read: a change after this is fitted again on resume.
      const std::string sha256 = ResumeHash(files[k]);
      try {
        const FileIdentifyResult r = IdentifyFiles({files[k]}, options.identify);
        const std::string error = FileFailure(files[k], r.result);
        line = FormatBatchLine(files[k], &r.result, error, r.warnings, sha256);
        ok = error.empty();
        if (ok) rows = RowsFitted(r.result);
      } catch (const std::exception& e) {
        line = FormatBatchLine(files[k], nullptr, e.what(), {}, sha256);
      }
      std::lock_guard<std::mutex> lock(write);
      if (halt) return;
      try {
        write_line(line);
      } catch (...) {
        write_error = std::current_exception();
        halt = true;
        return;
      }
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
  if (write_error) std::rethrow_exception(write_error);
  summary.interrupted = summary.ok + summary.failed < summary.total;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

BatchResults ReadBatchResults(const std::string& path, const std::vector<std::string>& files) {
  BatchResults results;
  std::ifstream in(path, std::ios::binary);
  if (!in) return results;  // no results yet
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error(path + ": cannot read the results to resume");
  const std::set<std::string> batch(files.begin(), files.end());
  std::map<std::string, std::string> hashes;  // of the batch's files with a line, as now
  std::set<std::string> seen;
  auto drop = [&](size_t line_number, const std::string& why) {
    results.warnings.push_back(path + ":" + std::to_string(line_number) + ": " + why);
    results.dropped = true;
  };
  size_t start = 0;
  for (size_t number = 1; start < text.size(); ++number) {
    const size_t end = text.find('\n', start);
    if (end == std::string::npos) {
      drop(number, "a torn last line (" + std::to_string(text.size() - start) +
                       " bytes without a line break, from an interrupted run) dropped");
      break;
    }
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    const std::optional<BatchLineKey> key = ParseBatchLineKey(line);
    if (!key) {
      drop(number, "not a batch result (no JSON object with \"file\" and \"ok\"); dropped");
      continue;
    }
    if (!seen.insert(key->file).second) {
      drop(number, "a second line for " + key->file + "; dropped");
      continue;
    }
    if (batch.count(key->file)) {
      if (!hashes.count(key->file)) hashes[key->file] = ResumeHash(key->file);
      if (key->sha256.empty() || key->sha256 != hashes[key->file]) {
        seen.erase(key->file);
        drop(number, key->file +
                         (key->sha256.empty() ? " could not be read then"
                                              : " has changed since (SHA-256)") +
                         ": its line dropped, the log is fitted again");
        continue;
      }
    }
    results.lines.push_back(line);
    results.keys.push_back(*key);
  }
  return results;
}

BatchSummary RunBatchToFile(const std::vector<std::string>& files, const BatchOptions& options,
                            const std::string& path, const BatchFileOptions& file_options,
                            std::vector<std::string>* warnings,
                            const std::function<void(const BatchProgress&)>& progress) {
  std::vector<std::string> todo = files;
  int skipped_ok = 0, skipped_failed = 0;
  if (file_options.resume) {
    const BatchResults before = ReadBatchResults(path, files);
    if (warnings) warnings->insert(warnings->end(), before.warnings.begin(), before.warnings.end());
    if (before.dropped) {
      WriteFileAtomically(path, "the results", [&](std::ostream& out) {
        for (const std::string& line : before.lines) out << line << '\n';
      });
    }
    std::map<std::string, bool> done;
    for (const BatchLineKey& key : before.keys) done[key.file] = key.ok;
    todo.clear();
    for (const std::string& file : files) {
      const auto it = done.find(file);
      if (it == done.end()) {
        todo.push_back(file);
      } else {
        (it->second ? skipped_ok : skipped_failed)++;
      }
    }
  }
  JsonLinesOptions journal_options;
  journal_options.truncate = !file_options.resume;
  journal_options.fsync_interval_s = file_options.fsync_interval_s;
  JsonLinesFile journal(path, journal_options);
  BatchSummary summary = RunBatch(
      todo, options, [&](const std::string& line) { journal.Append(line); }, progress);
  journal.Sync();
  summary.skipped = skipped_ok + skipped_failed;
  summary.ok += skipped_ok;
  summary.failed += skipped_failed;
  summary.total += summary.skipped;
  return summary;
}

}  // namespace slideid
