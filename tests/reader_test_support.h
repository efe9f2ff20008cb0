#pragma once
// What the tests of the log readers share (tests/push_log_test.cc,
// tests/wrench_twist_csv_test.cc, tests/zhou_tripod_test.cc): that a LogError names the file,
// the line and the column, and that a reader's file and memory forms agree on every file of a
// fuzzing seed corpus.

#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <string>

#include "io/push_log.h"
#include "tests/estimator_test_support.h"

namespace slideid::testing {

/// `e` names `path` and `line`: "file:line:", or "file: " for the file as a whole (line 0),
/// never "file:0:"; and e.line() is `line`.
inline void ExpectNamesFileAndLine(const LogError& e, const std::string& path, int line) {
  const std::string what = e.what();
  EXPECT_NE(what.find(path + (line > 0 ? ":" + std::to_string(line) + ":" : std::string(": "))),
            std::string::npos)
      << what;
  EXPECT_EQ(what.find(":0:"), std::string::npos) << what;
  EXPECT_EQ(e.line(), line) << what;
}

/// `e` names `path` and `line` as ExpectNamesFileAndLine checks, e.column() is `column` ("":
/// none) and its message contains `words`.
inline void ExpectNamesFileLineColumn(const LogError& e, const std::string& path, int line,
                                      const std::string& column, const std::string& words) {
  const std::string what = e.what();
  ExpectNamesFileAndLine(e, path, line);
  EXPECT_EQ(e.column(), column) << what;
  EXPECT_NE(what.find(words), std::string::npos) << what;
}

/// How many files of a seed corpus were read, and how many of them were accepted.
struct CorpusReads {
  int files = 0, accepted = 0;
};

/// Reads every file of the seed corpus fuzz/corpus/`corpus` with `read_file(path)` and with
/// `read_memory(text, path)` (each returns how many records it read, or throws LogError):
/// both must give the same records or the same error, and exactly the seeds named bad_ fail.
template <typename ReadFile, typename ReadMemory>
CorpusReads ExpectFileAndMemoryReadersAgree(const std::string& corpus, ReadFile read_file,
                                            ReadMemory read_memory) {
  CorpusReads reads;
  const std::string dir = std::string(SLIDEID_SOURCE_DIR) + "/fuzz/corpus/" + corpus;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string path = entry.path().string();
    const std::string text = ReadText(path);
    std::string file_error, memory_error;
    std::size_t file_records = 0, memory_records = 0;
    try {
      file_records = read_file(path);
    } catch (const LogError& e) {
      file_error = e.what();
    }
    try {
      memory_records = read_memory(text, path);
    } catch (const LogError& e) {
      memory_error = e.what();
    }
    EXPECT_EQ(file_error, memory_error) << path;
    EXPECT_EQ(file_records, memory_records) << path;
    const bool bad = entry.path().filename().string().rfind("bad_", 0) == 0;
    EXPECT_EQ(!file_error.empty(), bad) << path << ": " << file_error;
    ++reads.files;
    reads.accepted += file_error.empty();
  }
  return reads;
}

}  // namespace slideid::testing
