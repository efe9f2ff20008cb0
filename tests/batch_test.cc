// Batch identification (pipeline/batch.h, identify --batch): one JSON line per log, as each
// finishes; failed logs give a line with their error; shards split the sorted list.

#include "pipeline/batch.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "io/push_log.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using Json = nlohmann::json;

std::string Dir() {
  static const std::string dir = [] {
    std::string pattern = ::testing::TempDir() + "slideid_batch_XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    return pattern;
  }();
  return dir;
}

// Three good logs (simulated, with their truth) and one that is not a push log.
std::vector<std::string> Logs() {
  static const std::vector<std::string> files = [] {
    std::vector<std::string> f;
    const Scene scenes[] = {testing::PushedSlider(), testing::FreeSlideWithSpin(),
                            testing::TiltingPush()};
    for (int k = 0; k < 3; ++k) {
      f.push_back(Dir() + "/log_" + std::to_string(k) + ".csv");
      WritePushLog(testing::SimulateOrFail(scenes[k]), f.back());
    }
    f.push_back(Dir() + "/log_9_bad.csv");
    std::ofstream(f.back())
        << "# mass = 1\n# inertia = 0.01\n# com_height = 0\nt,x,y,theta\n0,0,0,0\n0.01,abc,0,0\n";
    return f;
  }();
  return files;
}

std::vector<Json> Lines(const std::string& text) {
  std::vector<Json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(Json::parse(line));
  return lines;
}

TEST(Batch, WritesOneLinePerLogWithTheIdentifyKeysOrTheError) {
  std::ostringstream out;
  BatchOptions options;
  options.jobs = 2;
  const BatchSummary s = RunBatch(Logs(), options, out);
  EXPECT_EQ(s.total, 4);
  EXPECT_EQ(s.ok, 3);
  EXPECT_EQ(s.failed, 1);
  const std::vector<Json> lines = Lines(out.str());
  ASSERT_EQ(lines.size(), 4u);
  std::set<std::string> seen;
  for (const Json& line : lines) {
    const std::string file = line.at("file");
    seen.insert(file);
    if (file.find("bad") != std::string::npos) {
      EXPECT_FALSE(line.at("ok").get<bool>());
      EXPECT_NE(line.at("error").get<std::string>().find(file + ":6"), std::string::npos)
          << line.at("error");  // the reader's message: file and line
    } else {
      EXPECT_TRUE(line.at("ok").get<bool>());
      EXPECT_EQ(line.at("method"), "trajectory");
      EXPECT_TRUE(line.at("e_t_mu").at("identifiable").get<bool>()) << file;
      EXPECT_TRUE(line.at("warnings").is_array()) << file;
    }
  }
  EXPECT_EQ(seen.size(), 4u);
}

TEST(Batch, FitsThatFailOrIdentifyNothingGiveFailedLinesWithTheirResult) {
  // A log at rest determines nothing (exit code 1 for one file), and a fit cut short by
  // its iteration limit does not converge (exit code 3): both fail, with the result. (The
  // noise-free logs above converge at once from their seeds; the bundled noisy one does not.)
  Scene rest = testing::BaseScene();
  rest.duration_s = 0.3;
  const std::string at_rest = Dir() + "/at_rest.csv";
  WritePushLog(testing::SimulateOrFail(rest), at_rest);
  BatchOptions options;
  options.identify.identify.trajectory.max_iterations = 1;
  std::ostringstream out;
  const std::string noisy = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";
  const BatchSummary s = RunBatch({at_rest, noisy}, options, out);
  EXPECT_EQ(s.failed, 2);
  EXPECT_EQ(s.rows, 0);
  for (const Json& line : Lines(out.str())) {
    const std::string file = line.at("file");
    EXPECT_FALSE(line.at("ok").get<bool>()) << file;
    const std::string error = line.at("error");
    EXPECT_EQ(error.rfind(file + ": ", 0), 0u) << error;
    const std::string why = file == at_rest ? "too little sliding" : "did not converge";
    EXPECT_NE(error.find(why), std::string::npos) << error;
    EXPECT_FALSE(line.at("result").at("converged").get<bool>()) << file;
    EXPECT_FALSE(line.contains("e_t_mu")) << file;
  }
}

TEST(Batch, TwoJobsGiveTheSameLinesAsOneButForTimes) {
  std::ostringstream one, two;
  BatchOptions options;
  RunBatch(Logs(), options, one);
  options.jobs = 2;
  RunBatch(Logs(), options, two);
  auto by_file = [](const std::string& text) {
    std::map<std::string, Json> m;
    for (Json line : Lines(text)) {
      line.erase("seconds");
      m[line.at("file")] = line;
    }
    return m;
  };
  EXPECT_EQ(by_file(one.str()), by_file(two.str()));
}

TEST(Batch, ShardsSplitTheSortedListWithoutOverlap) {
  const std::vector<std::string> files = {"a", "b", "c", "d", "e"};
  std::vector<std::string> all;
  for (int i = 0; i < 3; ++i) {
    const std::vector<std::string> part = Shard::Parse(std::to_string(i) + "/3").Select(files);
    all.insert(all.end(), part.begin(), part.end());
  }
  std::sort(all.begin(), all.end());
  EXPECT_EQ(all, files);
  EXPECT_EQ(Shard::Parse("1/3").Select(files), (std::vector<std::string>{"b", "e"}));
  for (const char* bad : {"3/3", "-1/2", "1", "a/b", "1/0", "1/2x"}) {
    EXPECT_THROW(Shard::Parse(bad), std::invalid_argument) << bad;
  }
}

/// identify's exit code; `output` gets what it printed on both streams.
int RunIdentify(const std::string& args, std::string* output) {
  const testing::ToolRun r = testing::RunTool("identify", args);
  *output = r.all();
  return r.code;
}

TEST(Batch, ToolExitsOneWhenALogFailedAndWritesEveryLine) {
  Logs();
  std::string output;
  const std::string results = Dir() + "/results.jsonl";
  EXPECT_EQ(RunIdentify("--batch '" + Dir() + "/log_*.csv' --jobs 2 --out " + results, &output), 1)
      << output;
  // Not on a terminal (the test's stderr is a file), the run still ends with one line.
  EXPECT_NE(output.find("identify: 4 logs, 3 identified, 1 failed, "), std::string::npos) << output;
  EXPECT_NE(output.find(" s; results in " + results + " (the failed logs' lines there say why)"),
            std::string::npos)
      << output;
  std::stringstream text;
  text << std::ifstream(results).rdbuf();
  EXPECT_EQ(Lines(text.str()).size(), 4u);
  // Shard 0/2 of the sorted list: log_0 and log_2, both good.
  EXPECT_EQ(RunIdentify("--batch '" + Dir() + "/log_*.csv' --shard 0/2 --out " + results, &output),
            0)
      << output;
  EXPECT_NE(output.find("identify: 2 logs, 2 identified, 0 failed, "), std::string::npos) << output;
}

// A pipe given as the batch (`--batch <(cat log.csv)`) is read once, by the log reader: its
// hash for resuming was taken first, which emptied it ("no header line"). It has no hash:
// on resume its line is fitted again, as an unreadable file's is.
TEST(Batch, APipeIsReadOnceByTheLogReader) {
  const char* bin = std::getenv("SLIDEID_BIN_DIR");
  const std::string results = Dir() + "/piped.jsonl";
  const std::string command = "bash -c '" + std::string(bin ? bin : "build/bin") +
                              "/identify --batch <(cat " + Logs()[0] + ") --out " + results +
                              "' > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 0);
  std::stringstream text;
  text << std::ifstream(results).rdbuf();
  const std::vector<Json> lines = Lines(text.str());
  ASSERT_EQ(lines.size(), 1u) << text.str();
  EXPECT_TRUE(lines[0]["ok"].get<bool>()) << text.str();
  EXPECT_TRUE(lines[0]["e_t_mu"].is_object()) << text.str();
}

TEST(Batch, ToolUsageErrorsNameTheOption) {
  std::string output;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--batch " + Dir() + " --out x.jsonl --log y.csv", "--log does not go with --batch"},
      {"--batch " + Dir(), "--batch needs --out"},
      {"--batch " + Dir() + " --out x.jsonl --jobs 0", "--jobs"},
      {"--batch " + Dir() + " --out x.jsonl --shard 2/2", "--shard"},
      {"--batch /nonexistent/dir --out x.jsonl", "--batch"},
      {"--log a.csv --jobs 2", "--jobs needs --batch"},
  };
  for (const auto& [args, fragment] : cases) {
    EXPECT_EQ(RunIdentify(args, &output), 2) << args << ": " << output;
    EXPECT_NE(output.find(fragment), std::string::npos) << args << ": " << output;
  }
}

}  // namespace
}  // namespace slideid
