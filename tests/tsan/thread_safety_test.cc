// Thread safety (issue 22): 8 threads identifying the same logs at once give results
// identical, bit for bit, to one thread's, and a batch on 4 jobs the same lines as on one;
// the online identifier's batch check runs on a thread of its own (issue 21).
// Built on its own (not in slideid_tests) so that the ThreadSanitizer job
// (scripts/tsan.sh) compiles only what it needs; any data race it reports fails the test.
// python/tests/test_concurrency.py runs the same with Python threads and processes.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "estimator/online_identifier.h"
#include "io/dataset_files.h"
#include "io/push_log.h"
#include "io/result_json.h"
#include "pipeline/batch.h"
#include "pipeline/identify_files.h"

namespace slideid {
namespace {

constexpr int kThreads = 8;
constexpr int kLogs = 6;  // few: ThreadSanitizer runs the fits 5 to 15 times slower

/// Short synthetic logs, written once.
const std::vector<std::string>& Logs() {
  static const std::vector<std::string> files = [] {
    std::string dir = ::testing::TempDir() + "slideid_threads_XXXXXX";
    if (mkdtemp(dir.data()) == nullptr) std::abort();
    DatasetSpec spec;
    spec.count = kLogs;
    spec.seed = 22;
    spec.program.count = 2;
    MakeDataset(spec, dir);
    return ExpandFiles(dir);
  }();
  return files;
}

/// Each method's options: the trajectory fit (Ceres, shooting segments, the step solver)
/// with a small iteration cap, and the equation-error fit.
std::vector<FileIdentifyOptions> Methods() {
  FileIdentifyOptions trajectory;
  trajectory.identify.trajectory.max_iterations = 10;
  FileIdentifyOptions equation_error;
  equation_error.identify.method = EstimatorMethod::kEquationError;
  return {trajectory, equation_error};
}

/// The result of every log with every method, as exact JSON text without the run time.
std::vector<std::string> Fit(const std::vector<std::string>& files, int shift) {
  std::vector<std::string> out;
  for (const FileIdentifyOptions& options : Methods()) {
    for (size_t k = 0; k < files.size(); ++k) {
      FileIdentifyResult r = IdentifyFiles({files[(k + shift) % files.size()]}, options);
      r.result.seconds = 0;
      out.push_back(FormatJson(r.result));
    }
  }
  return out;
}

TEST(ThreadSafety, EightThreadsGiveOneThreadsResultsBitForBit) {
  const std::vector<std::string> one = Fit(Logs(), 0);
  std::vector<std::vector<std::string>> runs(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] { runs[t] = Fit(Logs(), t); });
  }
  for (std::thread& thread : threads) thread.join();
  const size_t n = Logs().size();
  for (int t = 0; t < kThreads; ++t) {
    ASSERT_EQ(runs[t].size(), one.size());
    for (size_t m = 0; m < one.size() / n; ++m) {
      for (size_t k = 0; k < n; ++k) {
        EXPECT_EQ(runs[t][m * n + k], one[m * n + (k + t) % n]) << "thread " << t << " log " << k;
      }
    }
  }
}

TEST(ThreadSafety, BatchOnFourJobsWritesOneJobsLines) {
  auto lines = [](int jobs) {
    BatchOptions options;
    options.jobs = jobs;
    options.identify.identify.trajectory.max_iterations = 10;
    std::map<std::string, std::string> by_file;
    RunBatch(Logs(), options, [&](const std::string& line) {
      // The run time is the only field that may differ: cut it out of the text.
      const size_t at = line.find("\"seconds\": ");
      const size_t end = line.find_first_of(",}", at);
      by_file[line.substr(10, line.find('"', 10) - 10)] = line.substr(0, at) + line.substr(end);
    });
    return by_file;
  };
  EXPECT_EQ(lines(4), lines(1));
}

// The online identifier's batch check on a thread of its own (OnlineOptions::
// batch_check_thread): the fit reads its copy of the rows while the filter goes on.
TEST(ThreadSafety, OnlineBatchCheckOnItsOwnThreadSharesNothing) {
  const Trajectory log = ReadPushLog(Logs()[0]);
  OnlineOptions options;
  options.batch_check_thread = true;
  options.batch_check_first_rows = 32;
  OnlineIdentifier online(log, options);
  for (const TrajectorySample& row : log.samples) online.Update(row);
  const OnlineResult& r = online.WaitForBatchCheck();
  EXPECT_GE(r.batch_checks, 1);
  EXPECT_EQ(r.rows, static_cast<int>(log.samples.size()));
}

}  // namespace
}  // namespace slideid
