// A push log as columns (what the Python module's arrays are) and logs identified in memory
// (what its identify does with Log objects): the same as the file and the file's fit.

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "forward_model/simulator.h"
#include "io/push_log.h"
#include "io/result_json.h"
#include "pipeline/identify_files.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

std::string Text(const Trajectory& log) {
  std::ostringstream out;
  WritePushLog(log, out);
  return out.str();
}

/// The metadata lines of a written log, as key-value pairs.
std::vector<std::pair<std::string, std::string>> Metadata(const std::string& text) {
  std::vector<std::pair<std::string, std::string>> metadata;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line) && line.rfind("# ", 0) == 0;) {
    const auto eq = line.find(" = ");
    metadata.emplace_back(line.substr(2, eq - 2), line.substr(eq + 3));
  }
  return metadata;
}

Trajectory PushedLog() {
  Trajectory log = Simulate(testing::TiltingPush()).trajectory;
  log.measured.push_point = true;
  log.measured.fz = true;
  log.source = "pushed.csv";
  return log;
}

TEST(LogColumns, ColumnsReadBackIntoTheLogTheFileHolds) {
  const Trajectory log = PushedLog();
  const PushLogColumns columns = ColumnsOf(log);
  ASSERT_EQ(columns.names.front(), "t");
  ASSERT_EQ(columns.mode.size(), log.samples.size());
  for (const auto& values : columns.values) ASSERT_EQ(values.size(), log.samples.size());
  const std::string text = Text(log);
  const Trajectory back = ParsePushLogColumns(columns, Metadata(text), "pushed.csv").log;
  EXPECT_EQ(Text(back), text);  // every value, bit for bit
}

TEST(LogColumns, ErrorsNameTheLineOfTheRowAndTheColumn) {
  PushLogColumns columns;
  columns.names = {"t", "vx", "vy", "wz"};
  columns.values = {{0, 0.01, 0.02}, {1, 1, 1}, {0, 0, 0}, {0, 0, 0}};
  const std::vector<std::pair<std::string, std::string>> metadata = {
      {"mass", "1"}, {"inertia", "0.001"}, {"com_height", "0"}};
  EXPECT_NO_THROW(ParsePushLogColumns(columns, metadata, "arrays"));
  // Metadata on lines 1 to 3, the header on line 4, row 1 on line 6.
  columns.values[1][1] = std::nan("");
  try {
    ParsePushLogColumns(columns, metadata, "arrays");
    ADD_FAILURE() << "no error";
  } catch (const LogError& e) {
    EXPECT_EQ(e.line(), 6);
    EXPECT_EQ(e.column(), "vx");
  }
  columns.values[1] = {1, 1};
  try {
    ParsePushLogColumns(columns, metadata, "arrays");
    ADD_FAILURE() << "no error";
  } catch (const LogError& e) {
    EXPECT_EQ(e.line(), 4);
    EXPECT_EQ(e.column(), "vx");
    EXPECT_NE(std::string(e.what()).find("has 2 values, 't' 3"), std::string::npos) << e.what();
  }
  columns.values[1] = {1, 1, 1};
  columns.names[1] = "v,x";
  EXPECT_THROW(ParsePushLogColumns(columns, metadata, "arrays"), LogError);
  columns.names[1] = "vx";
  EXPECT_THROW(ParsePushLogColumns(columns, {{"mass", "1\n2"}}, "arrays"), LogError);
}

TEST(IdentifyReadLogs, EqualsIdentifyFilesOnTheSameLogs) {
  const std::string path = ::testing::TempDir() + "/log_columns_pushed.csv";
  WritePushLog(PushedLog(), path);
  FileIdentifyOptions options;
  EstimateResult from_file = IdentifyFiles({path, path}, options).result;
  Trajectory read = ReadPushLog(path);
  read.source = "log_columns_pushed.csv";
  EstimateResult in_memory = IdentifyReadLogs({read, read}, options).result;
  from_file.seconds = in_memory.seconds = 0;
  EXPECT_EQ(FormatJson(in_memory), FormatJson(from_file));
  ASSERT_EQ(in_memory.logs.size(), 2u);

  options.identify.method = EstimatorMethod::kQuasiStatic;
  EXPECT_THROW(IdentifyReadLogs({read}, options), std::invalid_argument);
  EXPECT_THROW(IdentifyReadLogs({}, FileIdentifyOptions{}), FileError);
}

}  // namespace
}  // namespace slideid
