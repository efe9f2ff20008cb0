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

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out + "\"";
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

std::string BatchLine(const std::string& file, const FileIdentifyResult* result,
                      const std::string& error) {
  std::string line = "{\"file\": " + JsonString(file);
  if (!result) return line + ", \"ok\": false, \"error\": " + JsonString(error) + "}";
  const std::string json = FormatJson(result->result);  // "{...}"
  return line + ", \"ok\": true, " + json.substr(1);
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
        if (r.result.status == TerminationStatus::kTooLittleExcitation) {
          line = BatchLine(files[k], nullptr, r.result.message);
        } else {
          line = BatchLine(files[k], &r, "");
          ok = true;
          for (const LogResult& log : r.result.logs) rows += log.rows;
          if (r.result.logs.empty()) rows = r.result.steps_total + 1;
        }
      } catch (const std::exception& e) {
        line = BatchLine(files[k], nullptr, e.what());
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
