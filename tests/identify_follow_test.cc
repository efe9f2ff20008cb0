// identify --follow end to end: a log piped in as a logger writes it gives one JSON line per
// --every rows, the same estimates as the online identifier on the file, bad rows name their
// line, and a reader that goes away (a closed pipe) ends the run cleanly.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "datasets/coverage_conditions.h"
#include "estimator/online_identifier.h"
#include "fixtures/pushed_square.h"
#include "forward_model/constants.h"
#include "io/push_log.h"

namespace slideid {
namespace {

struct ShellRun {
  int exit_code = -1;
  std::string out, err;
};

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// `shell` run by bash with $IDENTIFY set; its stdout and stderr.
ShellRun Shell(const std::string& shell) {
  const char* bin = std::getenv("SLIDEID_BIN_DIR");
  const std::string stem = ::testing::TempDir() + "/follow_" + std::to_string(getpid());
  const std::string script = stem + ".sh";
  std::ofstream(script) << "IDENTIFY=" << (bin ? bin : "build/bin") << "/identify\n"
                        << shell << "\n";
  const std::string cmd = "bash " + script + " > " + stem + ".out 2> " + stem + ".err";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, Slurp(stem + ".out"), Slurp(stem + ".err")};
}

std::vector<nlohmann::json> Lines(const std::string& text) {
  std::vector<nlohmann::json> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(nlohmann::json::parse(line));
  return out;
}

std::string LogFile() {
  static const std::string path = [] {
    const std::string p = ::testing::TempDir() + "/follow_log_" + std::to_string(getpid()) + ".csv";
    WritePushLog(MakeCoverageLog(FindCoverageCondition("short-300"), 3).log, p);
    return p;
  }();
  return path;
}

// simulate writes its log to standard output as it would to a file (a stream is written in
// place, and its summary then goes to standard error), so the two tools pipe together.
TEST(IdentifyFollow, ReadsWhatSimulateWritesToStandardOutput) {
  const std::string scene = std::string(SLIDEID_SOURCE_DIR) + "/datasets/scenes/default_push.ini";
  const ShellRun run = Shell("set -o pipefail; ${IDENTIFY%/identify}/simulate --scene " + scene +
                             " --out /dev/stdout | $IDENTIFY --follow --every 200");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<nlohmann::json> lines = Lines(run.out);
  ASSERT_EQ(lines.size(), 4u) << run.out;  // 601 rows: after 200, 400, 600 and the last
  EXPECT_EQ(lines.back()["row"], 600);
  EXPECT_EQ(lines.back()["e_t_mu"]["verdict"], "ok") << lines.back().dump();
  EXPECT_NE(run.err.find("wrote       /dev/stdout"), std::string::npos) << run.err;
}

// A stream that ends between two lines still gives its last row's estimate, the final one.
TEST(IdentifyFollow, PrintsTheLastRowsEstimateWhereTheStreamEndsBetweenLines) {
  const ShellRun run = Shell("cat " + LogFile() + " | $IDENTIFY --follow --every 200");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<nlohmann::json> lines = Lines(run.out);
  ASSERT_EQ(lines.size(), 2u) << run.out;  // 300 rows
  EXPECT_EQ(lines[0]["row"], 199);
  EXPECT_EQ(lines[1]["row"], 299);
  const ShellRun every = Shell("cat " + LogFile() + " | $IDENTIFY --follow --every 1 | tail -n 1");
  EXPECT_EQ(nlohmann::json::parse(every.out), lines[1]);  // the same update, the same line
}

TEST(IdentifyFollow, PrintsALinePerEveryNRowsWithTheOnlineIdentifiersEstimates) {
  const ShellRun run = Shell("cat " + LogFile() + " | $IDENTIFY --follow --every 50");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<nlohmann::json> lines = Lines(run.out);
  ASSERT_EQ(lines.size(), 6u) << run.out;  // 300 rows
  for (size_t k = 0; k < lines.size(); ++k) EXPECT_EQ(lines[k]["row"], 50 * k + 49);
  // The same estimates as the identifier fed the rows of the file as the reader reads them.
  const Trajectory log = ReadPushLog(LogFile());
  OnlineIdentifier id(log);
  for (const TrajectorySample& row : log.samples) id.Update(row);
  const nlohmann::json& last = lines.back();
  EXPECT_TRUE(last["started"].get<bool>());
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = id.result().parameters[i];
    ASSERT_TRUE(p.identifiable);
    EXPECT_EQ(last[ParameterName(i)]["value"].get<double>(), p.value) << ParameterName(i);
    EXPECT_EQ(last[ParameterName(i)]["ci95"][0].get<double>(), p.ci95_lo) << ParameterName(i);
    // The quantile the interval took (t for a factor read from few degrees of freedom).
    EXPECT_EQ(last[ParameterName(i)]["interval_quantile"].get<double>(), p.interval_quantile)
        << ParameterName(i);
    EXPECT_EQ(last[ParameterName(i)]["verdict"], "ok");
  }
}

// A motion-capture dropout in the stream (rows with NaN poses): an error naming its line
// that says what to do, or with --missing-as-gaps the rows dropped and the motion started
// afresh after each dropout. The same estimates as the identifier fed the file read with
// the same option (each row after a dropout starting a run).
TEST(IdentifyFollow, DropoutsAreAnErrorOrGapsWhenAskedFor) {
  std::istringstream in(Slurp(LogFile()));
  std::string text, line;
  int data_row = -1;
  while (std::getline(in, line)) {
    if (data_row >= 0) ++data_row;
    if (data_row < 0 && !line.empty() && line[0] != '#') data_row = 0;  // the header
    if (data_row == 100 || data_row == 101 || data_row == 200) {
      std::vector<std::string> cells;
      std::istringstream row(line);
      for (std::string c; std::getline(row, c, ',');) cells.push_back(c);
      cells[1] = cells[2] = cells[3] = "nan";  // x, y, theta
      line = cells[0];
      for (size_t c = 1; c < cells.size(); ++c) line += "," + cells[c];
    }
    text += line + "\n";
  }
  const std::string path = ::testing::TempDir() + "/dropouts_" + std::to_string(getpid()) + ".csv";
  std::ofstream(path) << text;
  const ShellRun failed = Shell("cat " + path + " | $IDENTIFY --follow --every 300");
  EXPECT_EQ(failed.exit_code, 1) << failed.err;
  EXPECT_NE(failed.err.find("--missing-as-gaps"), std::string::npos) << failed.err;
  const ShellRun run =
      Shell("cat " + path + " | $IDENTIFY --follow --every 300 --missing-as-gaps --verbose");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("3 dropped (a missing cell)"), std::string::npos) << run.err;
  const std::vector<nlohmann::json> lines = Lines(run.out);
  ASSERT_FALSE(lines.empty());
  LogReadOptions gaps;
  gaps.missing_as_gaps = true;
  const Trajectory log = ReadPushLog(path, gaps);
  ASSERT_EQ(log.samples.size(), 297u);
  OnlineIdentifier id(log);
  for (const TrajectorySample& row : log.samples) id.Update(row);
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = id.result().parameters[i];
    ASSERT_TRUE(p.identifiable) << ParameterName(i);
    EXPECT_EQ(lines.back()[ParameterName(i)]["value"].get<double>(), p.value) << ParameterName(i);
  }
}

// --batch-check N: the identifier's batch check from N rows (0: none); each line counts the
// checks and the takeovers.
TEST(IdentifyFollow, BatchCheckOptionSetsTheIdentifiersCheck) {
  for (int rows : {0, 100}) {
    const ShellRun run =
        Shell("cat " + LogFile() + " | $IDENTIFY --follow --every 300 --batch-check " +
              std::to_string(rows));
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const std::vector<nlohmann::json> lines = Lines(run.out);
    ASSERT_EQ(lines.size(), 1u) << run.out;
    EXPECT_EQ(lines[0]["batch_checks"], rows == 0 ? 0 : 2);  // 300 rows: at 100 and 200
    OnlineOptions options;
    options.batch_check_first_rows = rows;
    const Trajectory log = ReadPushLog(LogFile());
    OnlineIdentifier id(log, options);
    for (const TrajectorySample& row : log.samples) id.Update(row);
    EXPECT_EQ(lines[0]["batch_takeovers"], id.result().batch_takeovers);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(lines[0][ParameterName(i)]["value"].get<double>(), id.result().parameters[i].value)
          << ParameterName(i) << " with --batch-check " << rows;
    }
  }
}

// A log with the tip's path: each line carries mu_pusher, the identifier's.
TEST(IdentifyFollow, ReportsMuPusherWhereTheLogHasTheTip) {
  testing::SquarePush push;
  push.angle_rad = 60 * kPi / 180;  // the tip slides along the edge
  push.mu_pusher = 0.3;
  push.offset_m = -0.02;
  push.distance_m = 0.06;
  const std::string path =
      ::testing::TempDir() + "/follow_tip_" + std::to_string(getpid()) + ".csv";
  WritePushLog(testing::NoisyPushLog(testing::PushedSquareScene(push), 3), path);
  const ShellRun run = Shell("cat " + path + " | $IDENTIFY --follow --every 20");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<nlohmann::json> lines = Lines(run.out);
  ASSERT_FALSE(lines.empty());
  const Trajectory log = ReadPushLog(path);
  OnlineIdentifier id(log);
  for (const TrajectorySample& row : log.samples) id.Update(row);
  ASSERT_TRUE(id.result().mu_pusher.identifiable) << id.result().mu_pusher.reason;
  const nlohmann::json& mu = lines.back()["mu_pusher"];
  ASSERT_TRUE(mu.is_object()) << lines.back();
  if (static_cast<int>(lines.back()["row"]) == id.result().rows - 1) {
    EXPECT_EQ(mu["value"].get<double>(), id.result().mu_pusher.value);
    EXPECT_EQ(mu["ci95"][1].get<double>(), id.result().mu_pusher.ci95_hi);
  }
  EXPECT_NEAR(mu["value"].get<double>(), 0.3, 0.015);
  EXPECT_EQ(mu["verdict"], "ok");
  // Row 19: the tip has slid in a few rows only (suspect: its interval rests on 2 batches).
  EXPECT_NE(lines.front()["mu_pusher"]["verdict"], "ok");
}

TEST(IdentifyFollow, EndsCleanlyWhenTheReaderGoesAway) {
  // head takes one line and closes the pipe; identify's next writes fail (EPIPE): it
  // stops reading and exits 0, as a logger's consumer expects.
  const ShellRun run = Shell("set -o pipefail; cat " + LogFile() +
                             " | $IDENTIFY --follow | head -n 1; echo \"status ${PIPESTATUS[1]}\"");
  EXPECT_NE(run.out.find("status 0"), std::string::npos) << run.out << run.err;
  EXPECT_EQ(run.out.find("status 141"), std::string::npos) << "killed by SIGPIPE";
  EXPECT_EQ(Lines(run.out.substr(0, run.out.find('\n') + 1)).size(), 1u);
}

TEST(IdentifyFollow, ABadRowNamesItsLineOfTheStream) {
  // The log's metadata and header, two rows, then a row with a word for x.
  const ShellRun run = Shell("{ grep -v '^[0-9-]' " + LogFile() + "; grep '^[0-9-]' " + LogFile() +
                             " | head -n 2; echo '0.5,oops,0,0,0,0,0,0,0'; } | $IDENTIFY --follow");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  const std::string header = Slurp(LogFile());
  int metadata_lines = 0;
  for (std::istringstream in(header); !in.eof();) {
    std::string line;
    std::getline(in, line);
    if (!line.empty() && (line[0] == '#' || !std::isdigit(static_cast<unsigned char>(line[0])))) {
      ++metadata_lines;
    } else {
      break;
    }
  }
  const std::string where = "<stdin>:" + std::to_string(metadata_lines + 3);
  EXPECT_NE(run.err.find(where), std::string::npos) << run.err << " (expected " << where << ")";
}

// A byte-order mark before the metadata is skipped, as a file's reader skips it (it made the
// first metadata line the header); a stream that ends after its header is an error, as a
// file that does (it exited 0 having printed nothing).
TEST(IdentifyFollow, AByteOrderMarkIsSkippedAndAHeaderWithoutRowsIsAnError) {
  const ShellRun plain = Shell("cat " + LogFile() + " | $IDENTIFY --follow --every 300");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const ShellRun bom = Shell("{ printf '\\357\\273\\277'; cat " + LogFile() +
                             "; } | $IDENTIFY --follow --every 300");
  ASSERT_EQ(bom.exit_code, 0) << bom.err;
  EXPECT_EQ(bom.out, plain.out);
  const ShellRun header_only = Shell("grep -v '^[0-9-]' " + LogFile() + " | $IDENTIFY --follow");
  EXPECT_EQ(header_only.exit_code, 1) << header_only.err;
  EXPECT_NE(header_only.err.find("the header is not followed by any data row"), std::string::npos)
      << header_only.err;
  EXPECT_EQ(header_only.out, "");
}

// A heading of 1e17 rad (a unit error) leaves every row's theta the same: the file's reader
// warns of it and the fit identifies nothing. The stream's reader warns as the file's does,
// at the same line, once, and no answer after it is ok (c came out "ok" before).
TEST(IdentifyFollow, WarnsAsTheFilesReaderDoesAndDoubtsTheAnswersAfter) {
  Trajectory log = ReadPushLog(LogFile());
  for (TrajectorySample& s : log.samples) s.state.theta += 1e17;
  const std::string path =
      ::testing::TempDir() + "/follow_theta_" + std::to_string(getpid()) + ".csv";
  WritePushLog(log, path);
  LogReadReport file_report;
  ReadPushLog(path, {}, &file_report);
  ASSERT_EQ(file_report.warnings.size(), 1u);
  const std::string file_warning = file_report.warnings[0];  // "path:27: column 'theta': ..."
  const std::string at = file_warning.substr(path.size(), file_warning.find(" rad ") - path.size());

  const ShellRun run = Shell("$IDENTIFY --follow --every 100 < " + path);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const size_t warned = run.err.find("identify: warning: <stdin>" + at + " rad is beyond");
  EXPECT_NE(warned, std::string::npos) << run.err << " (expected <stdin>" << at << ")";
  EXPECT_EQ(run.err.find("identify: warning", warned + 1), std::string::npos)
      << "once: " << run.err;
  const std::vector<nlohmann::json> lines = Lines(run.out);
  ASSERT_FALSE(lines.empty());
  for (const nlohmann::json& line : lines) {
    for (int i = 0; i < 3; ++i) {
      const nlohmann::json& p = line[ParameterName(i)];
      EXPECT_NE(p["verdict"], "ok") << line.dump();
      if (p["verdict"] == "suspect") {
        EXPECT_NE(p["reason"].get<std::string>().find("theta"), std::string::npos) << p.dump();
      }
    }
  }
}

// `command` exits with `exit_code`, saying `text` on standard error.
void ExpectFailure(const std::string& command, int exit_code, const std::string& text) {
  const ShellRun run = Shell(command);
  EXPECT_EQ(run.exit_code, exit_code) << command;
  EXPECT_NE(run.err.find(text), std::string::npos) << command << ": " << run.err;
}

TEST(IdentifyFollow, RejectsOptionsThatDoNotGoWithIt) {
  ExpectFailure("$IDENTIFY --follow --log x.csv < /dev/null", 2, "--log does not go with --follow");
  ExpectFailure("$IDENTIFY --follow --every 0 < /dev/null", 2, "--every");
  ExpectFailure("$IDENTIFY --follow --batch-check -1 < /dev/null", 2, "--batch-check");
  ExpectFailure("$IDENTIFY --log x.csv --batch-check 64", 2, "--batch-check needs --follow");
  ExpectFailure("$IDENTIFY --follow < /dev/null", 1, "no header line");
}

}  // namespace
}  // namespace slideid
