// Bad input, end to end (issue 6, docs/robustness.md): every malformed or physically
// invalid log, scene and command line gets a clear error naming the file, line and column
// (or the key, or the option) and the documented exit code; nothing crashes or prints NaN,
// and a failed run leaves no output file. Reader details are in push_log_test.cc and
// scene_test.cc; this file adds what they lack and runs the tools.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "forward_model/constants.h"
#include "io/push_log.h"
#include "io/scene_file.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using testing::WriteFile;

constexpr const char* kSliderMeta = "# mass = 0.5\n# inertia = 2e-4\n# com_height = 0.08\n";

/// A fresh directory for this test process's files.
using testing::ReadText;

bool Exists(const std::string& path) { return std::filesystem::exists(path); }

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

using testing::RunTool;
using testing::ToolRun;

ToolRun Identify(const std::string& args) { return RunTool("identify", args); }

/// A log of a pushed slider as `simulate` would write it, in `path`.
std::string PushedLog(const std::string& name) {
  const std::string path = testing::TempDirectory() + "/" + name;
  WritePushLog(testing::SimulateOrFail(testing::PushedSlider()), path);
  return path;
}

/// No number in the output is NaN or Inf (tools print "-" or null instead).
void ExpectNoNaN(const ToolRun& r) {
  static const std::regex kNonFinite("\\b-?(nan|inf|infinity)\\b", std::regex::icase);
  for (const std::string* text : {&r.out, &r.err}) {
    EXPECT_FALSE(std::regex_search(*text, kNonFinite)) << *text;
  }
}

// ---------------------------------------------------------------------------------------
// The log reader (library)
// ---------------------------------------------------------------------------------------

/// The LogError of reading `content` as a file; fails the test if it reads.
LogError ErrorOf(const std::string& name, const std::string& content,
                 const LogReadOptions& options = {}) {
  const std::string path = WriteFile(name, content);
  try {
    ReadPushLog(path, options);
  } catch (const LogError& e) {
    return e;
  }
  ADD_FAILURE() << name << " read without a LogError";
  return LogError(path, -1, "", "none");
}

void ExpectError(const std::string& name, const std::string& content, int line,
                 const std::string& column, const std::string& fragment,
                 const LogReadOptions& options = {}) {
  const LogError e = ErrorOf(name, content, options);
  const std::string what = e.what();
  EXPECT_EQ(e.line(), line) << what;
  EXPECT_EQ(e.column(), column) << what;
  // "file:line: ", or "file: " for the file as a whole (line 0), never "file:0:".
  const std::string at = line > 0 ? ":" + std::to_string(line) + ": " : ": ";
  EXPECT_TRUE(Contains(what, testing::TempDirectory() + "/" + name + at)) << what;
  EXPECT_FALSE(Contains(what, ":0:")) << what;
  EXPECT_TRUE(Contains(what, fragment)) << "wanted '" << fragment << "' in: " << what;
}

// The same text parsed in memory (the splitter beside fccp's file reader): its LogError names
// `line` and says `fragment`.
void ExpectMemoryError(const std::string& text, int line, const std::string& fragment) {
  try {
    ParsePushLog(text, "memory.csv");
    ADD_FAILURE() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_TRUE(Contains(e.what(), fragment)) << "wanted '" << fragment << "' in: " << e.what();
  }
}

TEST(BadLog, CellErrorsSayWhatIsWrongWithTheCell) {
  const std::string h = std::string(kSliderMeta) + "t,x,y,theta\n";
  ExpectError("empty_cell.csv", h + "0,0,,0\n", 5, "y", "is empty");
  ExpectError("text_cell.csv", h + "0,0,abc,0\n", 5, "y", "'abc' is not a number");
  ExpectError("nan_cell.csv", h + "0,0,NaN,0\n", 5, "y", "not a finite number");
  ExpectError("inf_cell.csv", h + "0,0,-inf,0\n", 5, "y", "not a finite number");
  ExpectError("huge_cell.csv", h + "0,0,1e999,0\n", 5, "y", "out of the range of a double");
  ExpectError("decimal_comma.csv", h + "0,0,0,0\n0.1,0,0,0,5\n", 6, "", "expected 4 fields");
}

TEST(BadLog, HeaderProblemsNameTheHeaderLine) {
  ExpectError("semicolons.csv", std::string(kSliderMeta) + "t;x;y;theta\n0;0;0;0\n", 4, "",
              "separated by commas (this line seems to use ';')");
  ExpectError("tabs.csv", std::string(kSliderMeta) + "t\tx\ty\ttheta\n", 4, "", "tabs");
  ExpectError("trailing_comma.csv", std::string(kSliderMeta) + "t,x,y,theta,\n0,0,0,0,\n", 4, "",
              "empty column name in field 5");
  ExpectError("upper_case.csv", std::string(kSliderMeta) + "T,X,Y,THETA\n0,0,0,0\n", 4, "t",
              "lower case");
  ExpectError("duplicate.csv", std::string(kSliderMeta) + "t,vx,vy,wz,vx\n0,0,0,0,0\n", 4, "vx",
              "duplicate column name");
  ExpectError("no_group.csv", std::string(kSliderMeta) + "t,fx,fy\n0,0,0\n", 4, "",
              "neither the pose columns");
}

TEST(BadLog, QuotedCellsAsSpreadsheetsWriteThemAreAccepted) {
  const Trajectory tr = ReadPushLog(
      WriteFile("quoted.csv", std::string(kSliderMeta) + "\"t\",\"x\",\"y\",\"theta\"\n0,0,0,0\n"
                                                         "0.1,\"0.5\",0,0\n"));
  ASSERT_EQ(tr.samples.size(), 2u);
  EXPECT_EQ(tr.samples[1].state.x, 0.5);
}

TEST(BadLog, NulByteIsAnErrorNamingItsLineInFilesAndInMemory) {
  const std::string text = std::string(kSliderMeta) + "t,x,y,theta\n0,0,0,0\n0.1,0,0,0" +
                           std::string(1, '\0') + "junk\n";
  ExpectError("nul.csv", text, 6, "", "NUL byte");
  ExpectMemoryError(text, 6, "NUL byte");
  // A crash can leave a zero-filled tail after the last complete line.
  ExpectError("zero_tail.csv",
              std::string(kSliderMeta) + "t,x,y,theta\n0,0,0,0\n" + std::string(64, '\0'), 6, "",
              "NUL byte");
}

// Old Mac line ends (CR alone) made the whole file one line: the error quoted all of it as
// the value of its first metadata key (93 KB for a 600-row log). A carriage return inside a
// line is now the error itself, in files and in memory alike; CRLF still reads.
TEST(BadLog, CarriageReturnsAloneAreAnErrorNamingTheirLine) {
  std::string text = std::string(kSliderMeta) + "t,x,y,theta\n0,0,0,0\n0.1,0,0,0\n";
  std::replace(text.begin(), text.end(), '\n', '\r');
  ExpectError("cr_only.csv", text, 1, "", "lines must end with LF or CRLF");
  EXPECT_LT(std::string(ErrorOf("cr_only.csv", text).what()).size(), 300u);
  ExpectMemoryError(text, 1, "old Mac line ends");
  // A stray CR in a row, after lines ending in CRLF: named by its line.
  const std::string crlf = std::string(kSliderMeta) + "t,x,y,theta\r\n0,0,0,0\r\n0.1,0\r,0,0\r\n";
  ExpectError("stray_cr.csv", crlf, 6, "", "a carriage return inside the line");
}

// A log read from a pipe (--log <(zcat log.csv.gz), /dev/stdin, a named FIFO) is read once:
// the reader's pass that counts rows to reserve for opened the path a second time and took
// from the pipe whatever the reader had not yet read (its first 32 MiB): a 61 MB log failed
// half-way ("expected 9 fields ..., found 8") and could have lost rows; on a FIFO whose
// writer had finished, the second open waited for ever. 35 MB through a FIFO: every row.
TEST(BadLog, ALogFromAPipeIsReadWholeOnce) {
  const std::string fifo = testing::TempPath("pipe_log.csv");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const int rows = 35000;
  const std::string pad(1000, 'p');  // an unknown column: read past, with a note
  std::thread writer([&] {
    std::ofstream out(fifo);
    out << kSliderMeta << "t,x,y,theta,pad\n";
    for (int u = 0; u < rows; ++u) out << u * 0.01 << ",0,0,0," << pad << "\n";
  });
  std::size_t read = 0;
  try {
    read = ReadPushLog(fifo).samples.size();
  } catch (const LogError& e) {
    ADD_FAILURE() << e.what();
  }
  writer.join();
  EXPECT_EQ(read, static_cast<std::size_t>(rows));
}

// A line of 16 MiB or more (fccp's block) is an error naming that line, in files and in
// memory alike: io/text_lines, which every reader of a text file shares.
TEST(BadLog, OverlongLineIsAnErrorNamingItsLineInFilesAndInMemory) {
  const std::string text = std::string(kSliderMeta) + "t,x,y,theta\n0,0,0,0\n" +
                           std::string(std::size_t{1} << 24, '1') + "\n";
  ExpectError("long_line.csv", text, 6, "", "");
  ExpectMemoryError(text, 6, "longer than");
}

TEST(BadLog, DirectoryIsAnErrorSayingSo) {
  try {
    ReadPushLog(testing::TempDirectory());
    ADD_FAILURE() << "no LogError";
  } catch (const LogError& e) {
    EXPECT_TRUE(Contains(e.what(), testing::TempDirectory() + ": ")) << e.what();
    EXPECT_FALSE(Contains(e.what(), ":0:")) << e.what();  // a file as a whole has no line
    EXPECT_TRUE(Contains(e.what(), "directory")) << e.what();
  }
}

TEST(BadLog, MetadataErrorsNameTheirLine) {
  const std::string rows = "t,x,y,theta\n0,0,0,0\n";
  ExpectError("bad_patch.csv",
              std::string(kSliderMeta) + "# patch = polygon 0 0 1 1 1 0 0 1\n" + rows, 4, "",
              "metadata 'patch'");
  ExpectError("text_mass.csv", "# mass = 0.5 kg\n# inertia = 2e-4\n# com_height = 0\n" + rows, 1,
              "", "'0.5 kg' is not a finite number");
  ExpectError("twice.csv", std::string(kSliderMeta) + "# mass = 1\n" + rows, 4, "", "given twice");
  const LogError e =
      ErrorOf("misspelt.csv", "# Mass = 1\n# inertia = 2e-4\n# com_height = 0\n" + rows);
  EXPECT_TRUE(Contains(e.what(), "--mass")) << e.what();
  EXPECT_TRUE(Contains(e.what(), "found '# Mass = 1'")) << e.what();
}

TEST(BadLog, SliderPropertiesMustBePhysical) {
  const std::string rows = "t,x,y,theta\n0,0,0,0\n";
  ExpectError("no_inertia.csv", "# mass = 1\n# com_height = 0\n" + rows, 0, "", "inertia");
  ExpectError("zero_inertia.csv", "# mass = 1\n# inertia = 0\n# com_height = 0\n" + rows, 2, "",
              "inertia = 0 (metadata) must be > 0");
  ExpectError("negative_mass.csv", "# mass = -1\n# inertia = 1\n# com_height = 0\n" + rows, 1, "",
              "must be > 0");
  ExpectError("negative_height.csv", "# mass = 1\n# inertia = 1\n# com_height = -0.1\n" + rows, 3,
              "", "must be >= 0");
  ExpectError("no_com_height.csv", "# mass = 1\n# inertia = 1\n" + rows, 0, "", "com_height");
}

TEST(BadLog, VerticalForceThatLiftsTheSliderIsAnError) {
  // m g = 0.5 * 9.81 = 4.905 N: fz = 4.905 leaves p_n = 0, fz = 10 makes it negative.
  ExpectError("lift_zero.csv", std::string(kSliderMeta) + "t,x,y,theta,fz\n0,0,0,0,4.905\n", 5,
              "fz", "lifts the slider");
  ExpectError("lift.csv", std::string(kSliderMeta) + "t,x,y,theta,fz\n0,0,0,0,0\n0.1,0,0,0,10\n", 6,
              "fz", "not below m g");
}

TEST(BadLog, TimeMustIncreaseStrictly) {
  const std::string h = std::string(kSliderMeta) + "t,x,y,theta\n";
  ExpectError("t_equal.csv", h + "0,0,0,0\n0,0,0,0\n", 6, "t", "is not greater than t = 0");
  ExpectError("t_back.csv", h + "0.2,0,0,0\n0.1,0,0,0\n", 6, "t", "on line 5");
}

/// Rows at 10 ms with one gap of `gap` seconds after the fifth.
std::string LogWithGap(double gap) {
  std::string text = std::string(kSliderMeta) + "t,x,y,theta\n";
  double t = 0;
  for (int u = 0; u < 10; ++u) {
    std::ostringstream row;
    row << t << "," << 0.001 * u << ",0,0\n";
    text += row.str();
    t += u == 4 ? gap : 0.01;
  }
  return text;
}

TEST(BadLog, GapFarLongerThanTheMedianIntervalIsAnErrorUnlessAllowed) {
  // Header on line 4; the gap follows the fifth row (line 9): the sixth row is on line 10.
  ExpectError("gap.csv", LogWithGap(2.0), 10, "t", "200 times the median interval 0.01 s");
  LogReadOptions allow;
  allow.max_gap_ratio = 0;
  LogReadReport report;
  const Trajectory tr = ReadPushLog(WriteFile("gap_allowed.csv", LogWithGap(2.0)), allow, &report);
  EXPECT_EQ(tr.samples.size(), 10u);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_TRUE(Contains(report.warnings[0], "gap_allowed.csv:10: column 't': 1 intervals longer"))
      << report.warnings[0];
  // A few dropped samples: a warning only.
  report = {};
  ReadPushLog(WriteFile("gap_small.csv", LogWithGap(0.05)), {}, &report);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_TRUE(Contains(report.warnings[0], "longer than 3 times the median"));
  // Regular sampling: nothing.
  report = {};
  ReadPushLog(WriteFile("gap_none.csv", LogWithGap(0.01)), {}, &report);
  EXPECT_TRUE(report.warnings.empty());
}

TEST(BadLog, AbsurdMagnitudesAreReadWithWarningsNamingLineAndColumn) {
  // Millimetres for metres, and a force in mN: every such row is counted.
  LogReadReport report;
  const std::string path = WriteFile("millimetres.csv",
                                     "# mass = 20000\n# inertia = 1e-5\n# com_height = 0.08\n"
                                     "t,x,y,theta,fx,fy\n0,1500,0,0,0,0\n0.01,1510,0,0,2e5,0\n"
                                     "0.02,1520,0,0,0,0\n");
  const Trajectory tr = ReadPushLog(path, {}, &report);
  EXPECT_EQ(tr.samples.size(), 3u);
  const auto has = [&](const std::string& fragment) {
    for (const std::string& w : report.warnings) {
      if (Contains(w, fragment)) return true;
    }
    return false;
  };
  EXPECT_TRUE(has(path + ":5: column 'x': 1500 m is beyond 1000 m"))
      << ::testing::PrintToString(report.warnings);
  EXPECT_TRUE(has("3 rows like it"));
  EXPECT_TRUE(has(path + ":6: column 'fx': 2e+05 N is beyond 1e+05 N"));
  EXPECT_TRUE(has(path + ":1: mass = 20000 kg"));
  EXPECT_TRUE(has(path + ":2: inertia = 1e-05 kg m^2 gives a radius of gyration"));
  EXPECT_TRUE(has(path + ":6: column 'vx': from poses: 1000 m/s is beyond 100 m/s"));
  // A heading offset by 1e17 rad (a broken logger's counter) reads as a slider that never
  // turns (a double's spacing there is 16 rad): warned, as the other absurd magnitudes.
  report = {};
  const std::string heading = WriteFile(
      "huge_heading.csv", std::string(kSliderMeta) + "t,x,y,theta\n0,0,0,1e17\n0.01,0,0,1e17\n");
  ReadPushLog(heading, {}, &report);
  EXPECT_TRUE(has(heading + ":5: column 'theta': 1e+17 rad is beyond 1e+06 rad"))
      << ::testing::PrintToString(report.warnings);
  // A subnormal mass overflows the radius of gyration: said in words, not as "inf".
  report = {};
  const std::string subnormal =
      WriteFile("subnormal_mass.csv",
                "# mass = 1e-320\n# inertia = 1e-3\n# com_height = 0.01\nt,x,y,theta\n0,0,0,0\n");
  ReadPushLog(subnormal, {}, &report);
  EXPECT_TRUE(has(subnormal + ":2: inertia = 0.001 kg m^2 gives a radius of gyration sqrt(I/m) = "
                              "over 1e308 m"))
      << ::testing::PrintToString(report.warnings);
  // Sensible values: no warnings.
  report = {};
  ReadPushLog(WriteFile("sensible.csv", std::string(kSliderMeta) + "t,x,y,theta\n0,0,0,0\n"), {},
              &report);
  EXPECT_TRUE(report.warnings.empty()) << ::testing::PrintToString(report.warnings);
}

// Logged velocities that disagree with the poses' differences (vx in cm/s, wz of the wrong
// sign) are warned of, naming the column and its first row; a simulated log's own velocities,
// noise-free or with motion-capture noise on the poses, are not.
TEST(BadLog, VelocitiesThatDisagreeWithThePosesAreWarnedOf) {
  Trajectory log = testing::SimulateOrFail(testing::PushedSlider());
  ASSERT_TRUE(log.measured.pose && log.measured.velocity);
  Trajectory noisy = log;
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0, 3e-4);
  for (TrajectorySample& s : noisy.samples) s.state.x += noise(random);
  for (const Trajectory* good : {&log, &noisy}) {
    const std::string path = testing::TempDirectory() + "/velocities_ok.csv";
    WritePushLog(*good, path);
    LogReadReport report;
    ReadPushLog(path, {}, &report);
    EXPECT_TRUE(report.warnings.empty()) << ::testing::PrintToString(report.warnings);
  }
  Trajectory bad = log;
  for (TrajectorySample& s : bad.samples) {
    s.state.vx *= 1e2;  // cm/s, within the absurd-magnitude limit
    s.state.wz = -s.state.wz;
  }
  const std::string path = testing::TempDirectory() + "/velocities_bad.csv";
  WritePushLog(bad, path);
  LogReadReport report;
  ReadPushLog(path, {}, &report);
  ASSERT_EQ(report.warnings.size(), 2u) << ::testing::PrintToString(report.warnings);
  const std::regex warned(std::regex_replace(path, std::regex("[.]"), "[.]") +
                          ":[0-9]+: column '(vx|wz)': the logged velocity disagrees with the "
                          "poses' differences .* intervals, first here by .*tolerance.*");
  for (const std::string& w : report.warnings) EXPECT_TRUE(std::regex_match(w, warned)) << w;
}

TEST(BadLog, DerivedValuesThatOverflowAreErrors) {
  ExpectError("theta_overflow.csv",
              std::string(kSliderMeta) + "t,x,y,theta\n0,0,0,1e308\n0.1,0,0,-1e308\n", 6, "theta",
              "cannot be unwrapped");
  ExpectError("moment_overflow.csv",
              std::string(kSliderMeta) + "t,x,y,theta,fx,fy,px,py,pz\n0,0,0,0,1e300,0,0,1e300,0\n",
              5, "px", "overflows");
  ExpectError("speed_overflow.csv",
              std::string(kSliderMeta) + "t,x,y,theta\n0,-1e308,0,0\n1e-300,1e308,0,0\n", 6, "x",
              "overflows");
}

TEST(BadLog, MissingFinalLineBreakIsReadWithANote) {
  LogReadReport report;
  const Trajectory tr =
      ReadPushLog(WriteFile("no_final_newline.csv",
                            std::string(kSliderMeta) + "t,x,y,theta\n0,0,0,0\n0.1,1,2,3"),
                  {}, &report);
  ASSERT_EQ(tr.samples.size(), 2u);
  EXPECT_EQ(tr.samples[1].state.theta, 3.0);
  bool noted = false;
  for (const std::string& n : report.notes) noted = noted || Contains(n, "no line break");
  EXPECT_TRUE(noted) << ::testing::PrintToString(report.notes);
}

/// Everything ReadPushLog and ParsePushLog say about a text, as one string.
std::string Outcome(const std::string& text, bool from_file) {
  const std::string path = testing::TempDirectory() + "/same.csv";
  if (from_file) std::ofstream(path, std::ios::binary) << text;
  LogReadOptions options;
  options.require_slider_properties = false;
  LogReadReport report;
  std::ostringstream out;
  try {
    const Trajectory tr = from_file ? ReadPushLog(path, options, &report)
                                    : ParsePushLog(text, path, options, &report);
    for (const TrajectorySample& s : tr.samples) {
      out << s.t_s << " " << s.state.x << " " << s.state.theta << " " << s.state.vx << " "
          << s.applied.tz << " " << static_cast<int>(s.mode) << "\n";
    }
  } catch (const LogError& e) {
    out << "error: " << e.what() << "\n";
  }
  for (const std::string& w : report.warnings) out << "warning: " << w << "\n";
  for (const std::string& n : report.notes) out << "note: " << n << "\n";
  return out.str();
}

// ParsePushLog splits lines itself (fuzzing it spares fccp's 48 MiB buffer per input); it
// must read every text exactly as ReadPushLog reads the same bytes from a file.
TEST(BadLog, ReadingFromMemoryMatchesReadingTheFile) {
  std::vector<std::string> texts = {"",
                                    "\n",
                                    "\r\n",
                                    "\xEF\xBB\xBF",
                                    "# only a comment",
                                    "t,x,y,theta",
                                    "t,x,y,theta\r\n0,0,0,0\r\n0.1,1,2,3",
                                    "\xEF\xBB\xBFt,x,y,theta\n0,0,0,0\n\n\n",
                                    "t,x,y,theta\n0,0,0,0\r\r\n",
                                    "t,x,y,theta\n0,0,0,0\n\r\n0.1,0,0,0\n"};
  const std::string corpus = std::string(SLIDEID_SOURCE_DIR) + "/fuzz/corpus/log";
  if (std::filesystem::is_directory(corpus)) {
    for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
      texts.push_back(ReadText(entry.path().string()));
    }
  }
  for (const std::string& text : texts) {
    EXPECT_EQ(Outcome(text, false), Outcome(text, true)) << "text: " << text;
  }
}

// ---------------------------------------------------------------------------------------
// identify on bad logs: exit code 1 and a message naming file, line and column
// ---------------------------------------------------------------------------------------

struct BadLogCase {
  const char* name;
  std::string content;
  std::string location;  // "line: column 'c'" after the path, or "line: " alone
};

TEST(IdentifyBadLog, EveryMalformedLogExitsOneNamingFileLineAndColumn) {
  const std::string m = kSliderMeta;          // lines 1-3
  const std::string h = m + "t,x,y,theta\n";  // header on line 4
  const std::vector<BadLogCase> cases = {
      {"empty.csv", "", " "},  // the file as a whole: "file: ", no line
      {"header_only.csv", h, "4: "},
      {"missing_header.csv", m + "0,0,0,0\n0.1,0,0,0\n", "4: "},
      {"no_motion_columns.csv", m + "t,fx,fy\n0,0,0\n", "4: "},
      {"partial_group.csv", m + "t,vx,vy\n0,0,0\n", "4: column 'wz'"},
      {"duplicate.csv", m + "t,x,y,theta,y\n0,0,0,0,0\n", "4: column 'y'"},
      {"non_numeric.csv", h + "0,0,0,0\n0.1,0,zero,0\n", "6: column 'y'"},
      {"nan.csv", h + "0,0,0,0\n0.1,nan,0,0\n", "6: column 'x'"},
      {"inf.csv", h + "0,0,0,0\n0.1,0,0,inf\n", "6: column 'theta'"},
      {"too_few.csv", h + "0,0,0,0\n0.1,0,0\n", "6: "},
      {"too_many.csv", h + "0,0,0,0\n0.1,0,0,0,0\n", "6: "},
      {"t_not_increasing.csv", h + "0,0,0,0\n0.1,0,0,0\n0.1,0,0,0\n", "7: column 't'"},
      {"gap.csv", LogWithGap(5.0), "10: column 't'"},
      {"lift.csv", m + "t,x,y,theta,fz\n0,0,0,0,0\n0.1,0,0,0,5\n", "6: column 'fz'"},
      {"no_mass.csv", "# inertia = 2e-4\n# com_height = 0\nt,x,y,theta\n0,0,0,0\n", " "},
      {"zero_inertia.csv", "# mass = 1\n# inertia = 0\n# com_height = 0\nt,x,y,theta\n0,0,0,0\n",
       "2: "},
      {"negative_com_height.csv",
       "# mass = 1\n# inertia = 1\n# com_height = -1\nt,x,y,theta\n0,0,0,0\n", "3: "},
  };
  for (const BadLogCase& c : cases) {
    const std::string path = WriteFile(c.name, c.content);
    const ToolRun r = Identify("--log " + path);
    EXPECT_EQ(r.code, 1) << c.name << ": " << r.err;
    EXPECT_TRUE(Contains(r.err, "identify: error: " + path + ":" + c.location))
        << c.name << ": wanted '" << path << ":" << c.location << "' in: " << r.err;
    EXPECT_EQ(r.out, "") << c.name;
  }
}

TEST(IdentifyBadLog, CrlfBomAndWrappedThetaGiveTheSameEstimateAsTheCleanLog) {
  Trajectory log = testing::SimulateOrFail(testing::FreeSlideWithSpin());
  const std::string clean = testing::TempDirectory() + "/clean.csv";
  WritePushLog(log, clean);
  // Windows line ends and a BOM, as a spreadsheet saves it.
  std::string text = ReadText(clean), crlf = "\xEF\xBB\xBF";
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const std::string windows = WriteFile("windows.csv", crlf);
  // theta wrapped to (-pi, pi], as a tracker reports it (this log spins through pi).
  for (TrajectorySample& s : log.samples) s.state.theta = std::remainder(s.state.theta, 2 * kPi);
  const std::string wrapped = testing::TempDirectory() + "/wrapped.csv";
  WritePushLog(log, wrapped);
  const ToolRun a = Identify("--log " + clean + " --method equation-error --json");
  const ToolRun b = Identify("--log " + windows + " --method equation-error --json");
  const ToolRun c = Identify("--log " + wrapped + " --method equation-error --json --verbose");
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_EQ(b.code, 0) << b.err;
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(a.out.substr(0, 60), b.out.substr(0, 60));
  EXPECT_TRUE(Contains(c.err, "theta unwrapped")) << c.err;
  EXPECT_EQ(a.out.substr(0, 40), c.out.substr(0, 40)) << a.out << "\n" << c.out;
}

TEST(IdentifyBadLog, AbsurdMagnitudesWarnOnStderrWithoutVerboseAndNeverPrintNaN) {
  // The pushed log in millimetres and millinewtons: read, warned about, never NaN.
  Trajectory log = testing::SimulateOrFail(testing::PushedSlider());
  for (TrajectorySample& s : log.samples) {
    s.state.x = 1e3 * s.state.x + 2000.0;
    s.state.y *= 1e3;
    s.applied.fx *= 1e6;
  }
  const std::string path = testing::TempDirectory() + "/millimetres.csv";
  WritePushLog(log, path);
  for (const char* method : {"closed-form", "equation-error", "trajectory"}) {
    const ToolRun r = Identify("--log " + path + " --method " + method);
    EXPECT_TRUE(Contains(r.err, "identify: warning: " + path + ":")) << r.err;
    EXPECT_TRUE(Contains(r.err, "column 'x': ")) << r.err;
    EXPECT_TRUE(r.code == 0 || r.code == 1 || r.code == 3) << method << ": " << r.code;
    ExpectNoNaN(r);
  }
}

// ---------------------------------------------------------------------------------------
// identify's command line: exit code 2 for usage
// ---------------------------------------------------------------------------------------

TEST(IdentifyOptions, UsageErrorsExitTwoNamingTheOption) {
  const std::string log = PushedLog("options.csv");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--bogus", "--bogus"},
      {"--log", "'--log' is missing"},
      {"--log " + log + " --fit-delay sometimes", "--fit-delay"},
      {"--logs /nonexistent/dir", "--logs"},
      {"--log " + log + " --method closed-form --fit-force-bias",
       "--fit-force-bias does not apply"},
      {log, "'--log' (or '--logs') is required"},
      {"--log " + log + " --mass", "'--mass' is missing"},
      {"--log " + log + " --mass heavy", "--mass"},
      {"--log " + log + " --mass nan", "--mass"},
      {"--log " + log + " --mass -1", "--mass"},
      {"--log " + log + " --inertia 0", "--inertia"},
      {"--log " + log + " --com-height -0.1", "--com-height"},
      {"--log " + log + " --gravity inf", "--gravity"},
      {"--log " + log + " --method magic", "closed-form, equation-error, trajectory"},
      {"--log " + log + " --loss l1", "--loss"},
      {"--log " + log + " --segment 1", "--segment"},
      {"--log " + log + " --substeps 0", "--substeps"},
      {"--log " + log + " --substeps 100000", "--substeps"},
      {"--log " + log + " --threads 0", "--threads"},
      {"--log " + log + " --threads 1000000", "--threads"},
      {"--log " + log + " --max-iterations 0", "iterations"},
      {"--log " + log + " --max-gap-ratio nan", "--max-gap-ratio"},
      // One file pooled twice would count its rows twice (intervals too narrow): named
      // twice, or by another spelling of its path.
      {"--log " + log + " --log " + log, "is the same file as '" + log + "'"},
      {"--log " + log + " --logs " + testing::TempDirectory() + "/./options.csv",
       "is the same file as '" + log + "'"},
      // Options that would change a trajectory fit do not apply to the other methods.
      {"--log " + log + " --method closed-form --segment 10", "--segment does not apply"},
      {"--log " + log + " --method equation-error --substeps 4", "--substeps does not apply"},
      {"--log " + log + " --method closed-form --loss none", "--loss does not apply"},
      {"--log " + log + " --method closed-form --max-iterations 5", "does not apply"},
  };
  for (const auto& [args, fragment] : cases) {
    const ToolRun r = Identify(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_TRUE(Contains(r.err, "identify: usage: ")) << args << ": " << r.err;
    EXPECT_TRUE(Contains(r.err, fragment)) << args << ": wanted '" << fragment << "' in " << r.err;
    EXPECT_EQ(r.out, "") << args;
  }
}

TEST(IdentifyOptions, HelpVersionAndCompatibleOptionsSucceed) {
  const ToolRun help = Identify("--help");
  EXPECT_EQ(help.code, 0);
  EXPECT_TRUE(Contains(help.out, "Exit codes")) << help.out;
  EXPECT_TRUE(Contains(help.out, "--max-iterations")) << help.out;
  const ToolRun version = Identify("--version");
  EXPECT_EQ(version.code, 0);
  EXPECT_TRUE(Contains(version.out, "identify (slideid) ")) << version.out;
  // --json and --verbose together: one JSON object on stdout, notes on stderr.
  const std::string log = PushedLog("json_verbose.csv");
  const ToolRun r = Identify("--log " + log + " --json --verbose --method closed-form --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.front(), '{');
  EXPECT_EQ(r.out.substr(r.out.size() - 2), "}\n");
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1);
  ExpectNoNaN(r);
}

TEST(IdentifyOptions, UnwritableResidualsFileExitsFour) {
  const std::string log = PushedLog("residuals_io.csv");
  const ToolRun r = Identify("--log " + log + " --method closed-form --residuals " +
                             testing::TempDirectory() + "/no_such_dir/residuals.csv");
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_TRUE(Contains(r.err, "no_such_dir/residuals.csv")) << r.err;
}

// ---------------------------------------------------------------------------------------
// Numerical failure: exit code 3, and no output file
// ---------------------------------------------------------------------------------------

/// The pushed log with velocities carrying 2 mm/s and 0.02 rad/s of noise (fixed seed): a
/// fit that needs several iterations. (Velocities differentiated from 0.3 mm poses would
/// swamp the friction impulses: the equation error then declines to fit at all.)
std::string NoisyVelocityLog(const std::string& name) {
  Trajectory log = testing::SimulateOrFail(testing::PushedSlider());
  std::mt19937 rng(6);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (TrajectorySample& s : log.samples) {
    s.state.vx += 2e-3 * noise(rng);
    s.state.vy += 2e-3 * noise(rng);
    s.state.wz += 2e-2 * noise(rng);
  }
  log.measured.step_info = false;
  const std::string path = testing::TempDirectory() + "/" + name;
  WritePushLog(log, path);
  return path;
}

TEST(NumericalFailure, FitCutOffByTheIterationLimitExitsThreeAndWritesNoResiduals) {
  const std::string log = NoisyVelocityLog("noisy.csv");
  const std::string residuals = testing::TempDirectory() + "/residuals_failed.csv";
  const ToolRun failed = Identify("--log " + log + " --method equation-error --max-iterations 1 " +
                                  "--residuals " + residuals);
  EXPECT_EQ(failed.code, 3) << failed.out << failed.err;
  EXPECT_TRUE(Contains(failed.err, "identify: error: " + log +
                                       ": the equation-error fit did "
                                       "not converge"))
      << failed.err;
  EXPECT_FALSE(Exists(residuals));
  EXPECT_FALSE(Exists(residuals + ".tmp"));
  ExpectNoNaN(failed);
  // The same log with the default limit fits, and writes the file.
  const ToolRun ok = Identify("--log " + log + " --method equation-error --residuals " + residuals);
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_TRUE(Exists(residuals));
}

// A log of absurd magnitudes (an inertia of 1e-300 kg m^2: a unit error gone wild) pooled
// with a good one overflows the model at the pooled fit's start: bad input, exit 1, naming
// the log and its numbers. It was exit 1 with "AssessIdentifiability: information matrix is
// not finite" naming no log, then a fit that did not converge (exit 3) naming "2 logs".
TEST(NumericalFailure, PooledLogThatOverflowsTheModelIsBadInputNamingIt) {
  const std::string good = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";
  const std::string text = ReadText(good);
  const std::regex inertia("# inertia = [^\n]*");
  ASSERT_TRUE(std::regex_search(text, inertia)) << text.substr(0, 300);
  const std::string absurd =
      WriteFile("pool_absurd.csv", std::regex_replace(text, inertia, "# inertia = 1e-300"));
  const ToolRun r = Identify("--log " + good + " --log " + absurd);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_TRUE(Contains(r.err, "identify: error: " + absurd +
                                  ": identifies nothing on its own (its fit did not converge)"))
      << r.err;
  EXPECT_TRUE(Contains(r.err,
                       "pool_absurd.csv: the numbers are outside the range the model can "
                       "handle"))
      << r.err;
  EXPECT_TRUE(Contains(r.err, "inertia 1e-300 kg m^2")) << r.err;
  EXPECT_FALSE(Contains(r.err, "AssessIdentifiability")) << r.err;
  // Alone its fit starts, overflows at its end and does not converge (exit 3); its report says why
  // without printing "inf" (its interval "spans a factor inf" did).
  const ToolRun alone = Identify("--log " + absurd);
  EXPECT_EQ(alone.code, 3) << alone.err;
  EXPECT_TRUE(Contains(alone.out, "spans a factor over 1e308")) << alone.out;
  ExpectNoNaN(alone);
}

// Logs whose numbers overflow the model at the fit's start (a gravity of 1e-300, forces
// times 1e12): bad input, exit 1, saying so and naming the log and its numbers, alone or
// pooled with a good log. They were "too little sliding" (exit 1) alone and, pooled, a fit
// that did not converge (exit 3) or again "too little sliding" naming no log.
TEST(IdentifyBadLog, LogWhoseNumbersOverflowTheModelAtTheStartExitsOneNamingIt) {
  const std::string good = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";
  const std::string text = ReadText(good);
  const std::regex gravity("# gravity = [^\n]*");
  ASSERT_TRUE(std::regex_search(text, gravity));
  const std::string tiny_g =
      WriteFile("tiny_gravity.csv", std::regex_replace(text, gravity, "# gravity = 1e-300"));
  Trajectory log = ReadPushLog(good);
  for (TrajectorySample& s : log.samples) {  // the moments of the forces too: fz is 0
    for (double* f : {&s.applied.fx, &s.applied.fy, &s.applied.tx, &s.applied.ty, &s.applied.tz}) {
      *f *= 1e12;
    }
  }
  const std::string huge_f = testing::TempDirectory() + "/huge_forces.csv";
  WritePushLog(log, huge_f);
  for (const auto& [path, number] : {std::pair{tiny_g, "gravity 1e-300 m/s^2"},
                                     std::pair{huge_f, "largest push 6.11964e+12 N"}}) {
    for (const std::string& logs : {"--log " + path, "--log " + good + " --log " + path}) {
      const ToolRun r = Identify(logs);
      EXPECT_EQ(r.code, 1) << logs << ": " << r.err;
      EXPECT_TRUE(Contains(r.err,
                           "the numbers are outside the range the model can handle: its "
                           "simulated motion overflows"))
          << r.err;
      EXPECT_TRUE(Contains(r.err, number)) << r.err;
      if (logs.find(good) != std::string::npos) {  // the log that spoils the pooled fit
        EXPECT_TRUE(Contains(
            r.err, "identify: error: " + path + ": identifies nothing on its own (the numbers"))
            << r.err;
      }
      EXPECT_FALSE(Contains(r.err, "too little sliding")) << r.err;
      ExpectNoNaN(r);
    }
  }
}

// A good log pooled with one whose heading is 1e17 rad (its rows all read the same: it
// identifies nothing, and its residuals swamp the good log's) identified nothing, naming no
// log. Now the broken log fails the run, named with why; with --skip-bad it is skipped, with
// a warning, and the good log's fit is the answer.
TEST(IdentifyBadLog, ALogThatSpoilsAPooledFitIsNamedOrSkipped) {
  const std::string good = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";
  Trajectory log = ReadPushLog(good);
  for (TrajectorySample& s : log.samples) s.state.theta += 1e17;
  log.true_friction.reset();  // the truth column is then the good log's alone
  const std::string broken = testing::TempDirectory() + "/heading_1e17.csv";
  WritePushLog(log, broken);
  const ToolRun r = Identify("--log " + good + " --log " + broken);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_TRUE(Contains(r.err, "identify: error: " + broken + ": identifies nothing on its own"))
      << r.err;
  EXPECT_TRUE(Contains(r.err, "the reader warned: " + broken + ":")) << r.err;
  const ToolRun skipped = Identify("--log " + good + " --log " + broken + " --skip-bad");
  EXPECT_EQ(skipped.code, 0) << skipped.err;
  EXPECT_TRUE(Contains(skipped.err, "identify: warning: " + broken + ": skipped: ")) << skipped.err;
  EXPECT_TRUE(Contains(skipped.out, "heading_1e17.csv: skipped (identifies nothing"))
      << skipped.out;
  const ToolRun alone = Identify("--log " + good);
  ASSERT_EQ(alone.code, 0);
  const std::string table = alone.out.substr(0, alone.out.find("(e_t_mu ="));
  // The good log's own estimates, beside its truth (the skipped log has none).
  EXPECT_TRUE(Contains(skipped.out, table)) << skipped.out;
}

// Ceres' glog lines ("WARNING: Logging before InitGoogleLogging() ...", "E... ]
// Terminating: Residual and Jacobian evaluation failed.") reached stderr where a log's
// numbers overflow the model: every tool now keeps them quiet (estimator/ceres_logging.h),
// identify --verbose excepted.
TEST(IdentifyBadLog, CeresLogsNothingToStderrOnAbsurdLogs) {
  const std::string good = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";
  const std::string dir = testing::TempDirectory() + "/glog_logs";
  std::filesystem::create_directories(dir);
  const std::regex gravity("# gravity = [^\n]*");
  const std::string absurd = WriteFile(
      "glog_logs/tiny_g.csv", std::regex_replace(ReadText(good), gravity, "# gravity = 1e-300"));
  WriteFile("glog_logs/good.csv", ReadText(good));
  const ToolRun runs[] = {Identify("--log " + absurd),
                          Identify("--log " + good + " --log " + absurd),
                          RunTool("validate", "--logs " + dir)};
  for (const ToolRun& r : runs) {
    EXPECT_FALSE(Contains(r.err, "InitGoogleLogging")) << r.err;
    EXPECT_FALSE(Contains(r.err, "Residual and Jacobian evaluation failed")) << r.err;
  }
  const ToolRun verbose = Identify("--log " + absurd + " --verbose");
  EXPECT_TRUE(Contains(verbose.err, "Residual and Jacobian evaluation failed")) << verbose.err;
}

TEST(NumericalFailure, SimulateThatWouldTipExitsThreeAndWritesNoLog) {
  const std::string ini = WriteFile("tipping.ini", R"([slider]
mass = 0.5
inertia = 2e-4
com_height = 0.08
[friction]
mu = 0.6
e_t = 1
e_o = 1
e_r = 0.01
[patch]
shape = rectangle
width = 0.05
length = 0.05
[initial]
vx = 0.7
vy = 0.9
wz = 10
[sim]
dt = 0.01
duration = 0.45
)");
  const std::string out = testing::TempDirectory() + "/tipping.csv";
  const ToolRun r = RunTool("simulate", "--scene " + ini + " --out " + out);
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_TRUE(Contains(r.err, "ECP")) << r.err;
  EXPECT_FALSE(Exists(out));
  EXPECT_FALSE(Exists(out + ".tmp"));
}

// ---------------------------------------------------------------------------------------
// Scenes: ParseScene and the simulate tool (exit code 1, message naming file and key)
// ---------------------------------------------------------------------------------------

const char* const kScene = R"([slider]
mass = 0.5
inertia = 2e-4
com_height = 0.08
[friction]
mu = 0.31
e_t = 1
e_o = 1
e_r = 0.01
[sim]
dt = 0.01
duration = 0.2
)";
const char* const kSquare = "[patch]\nshape = rectangle\nwidth = 0.05\nlength = 0.05\n";

/// The scene with `from` replaced by `to` (once), and `extra` appended.
std::string Edited(const std::string& from, const std::string& to, const std::string& extra = "",
                   const std::string& patch = kSquare) {
  std::string text = std::string(kScene) + patch;
  if (!from.empty()) {
    const auto at = text.find(from);
    if (at == std::string::npos)
      ADD_FAILURE() << from;
    else
      text.replace(at, from.size(), to);
  }
  return text + extra;
}

struct BadSceneCase {
  const char* name;
  std::string text;
  std::string key;       // what the message must name
  std::string fragment;  // and what it must say
};

std::vector<BadSceneCase> BadScenes() {
  return {
      {"unknown_section.ini", Edited("", "", "[sliders]\nmass = 1\n"), "sliders", "unknown"},
      {"unknown_key.ini", Edited("", "", "[initial]\nspeed = 1\n"), "speed", "unknown key"},
      {"misspelt_key.ini", Edited("mu = 0.31", "mu = 0.31\nmuu = 0.3"), "muu", "unknown key"},
      {"missing_mass.ini", Edited("mass = 0.5\n", ""), "mass", "missing"},
      {"missing_dt.ini", Edited("dt = 0.01\n", ""), "dt", "missing"},
      {"missing_patch_size.ini", Edited("", "", "", "[patch]\nshape = disk\n"), "radius",
       "missing"},
      {"text_value.ini", Edited("e_r = 0.01", "e_r = small"), "e_r", "'small'"},
      {"unit_suffix.ini", Edited("mass = 0.5", "mass = 500g"), "mass", "500g"},
      {"nan_value.ini", Edited("mu = 0.31", "mu = nan"), "mu", "finite"},
      {"inf_value.ini", Edited("duration = 0.2", "duration = inf"), "duration", "finite"},
      {"zero_mass.ini", Edited("mass = 0.5", "mass = 0"), "mass", "> 0"},
      {"negative_inertia.ini", Edited("inertia = 2e-4", "inertia = -2e-4"), "inertia", "> 0"},
      {"negative_height.ini", Edited("com_height = 0.08", "com_height = -1"), "com_height", ">= 0"},
      {"zero_dt.ini", Edited("dt = 0.01", "dt = 0"), "dt", "> 0"},
      {"negative_mu.ini", Edited("mu = 0.31", "mu = -0.31"), "mu", "> 0"},
      {"zero_width.ini",
       Edited("", "", "", "[patch]\nshape = rectangle\nwidth = 0\nlength = 0.05\n"), "width", "0"},
      {"zero_radius.ini", Edited("", "", "", "[patch]\nshape = disk\nradius = 0\n"), "radius", "0"},
      {"ring_inner_equal.ini",
       Edited("", "", "", "[patch]\nshape = ring\nradius = 0.1\ninner_radius = 0.1\n"),
       "inner_radius", "outer"},
      {"ring_inner_larger.ini",
       Edited("", "", "", "[patch]\nshape = ring\nradius = 0.05\ninner_radius = 0.1\n"),
       "inner_radius", "outer"},
      {"polygon_zero_area.ini",
       Edited("", "", "", "[patch]\nshape = polygon\nvertices = 0 0 0.1 0 0.2 0\n"), "vertices",
       "zero area"},
      {"polygon_self_intersecting.ini",
       Edited("", "", "", "[patch]\nshape = polygon\nvertices = 0 0 0.1 0.1 0.1 0 0 0.1\n"),
       "vertices", "self-intersecting"},
      {"polygon_odd_count.ini",
       Edited("", "", "", "[patch]\nshape = polygon\nvertices = 0 0 0.1 0 0.1\n"), "vertices", ""},
      {"polygon_clockwise.ini",
       Edited("", "", "", "[patch]\nshape = polygon\nvertices = 0 0 0 0.1 0.1 0.1 0.1 0\n"),
       "vertices", "counter-clockwise"},
  };
}

TEST(BadScene, ParseSceneNamesTheFileAndTheKey) {
  for (const BadSceneCase& c : BadScenes()) {
    try {
      ParseScene(c.text, c.name);
      ADD_FAILURE() << c.name << ": parsed without a SceneError";
    } catch (const SceneError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(std::string(c.name) + ": ", 0), 0u) << c.name << ": " << what;
      EXPECT_TRUE(Contains(what, c.key)) << c.name << ": wanted '" << c.key << "' in " << what;
      EXPECT_TRUE(Contains(what, c.fragment))
          << c.name << ": wanted '" << c.fragment << "' in " << what;
    }
  }
}

TEST(BadScene, SimulateExitsOneNamingTheFileAndTheKeyAndWritesNoLog) {
  for (const BadSceneCase& c : BadScenes()) {
    const std::string ini = WriteFile(c.name, c.text);
    const std::string out = testing::TempDirectory() + "/" + c.name + ".csv";
    const ToolRun r = RunTool("simulate", "--scene " + ini + " --out " + out);
    EXPECT_EQ(r.code, 1) << c.name << ": " << r.err;
    EXPECT_TRUE(Contains(r.err, ini)) << c.name << ": " << r.err;
    EXPECT_TRUE(Contains(r.err, c.key)) << c.name << ": " << r.err;
    EXPECT_FALSE(Exists(out)) << c.name;
  }
}

TEST(BadScene, SimulateUsageErrorsExitTwo) {
  const std::string ini = WriteFile("good.ini", Edited("", ""));
  for (const std::string& args :
       {std::string("--bogus"), std::string("--scene"), "--scene " + ini + " --dt 0",
        "--scene " + ini + " --duration -1", "--scene " + ini + " --dt fast"}) {
    const ToolRun r = RunTool("simulate", args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
  }
  EXPECT_EQ(RunTool("simulate", "--help").code, 0);
  EXPECT_EQ(RunTool("simulate", "--version").code, 0);
  const ToolRun ok = RunTool("simulate", "--scene " + ini);
  EXPECT_EQ(ok.code, 0) << ok.err;
  const ToolRun unwritable = RunTool(
      "simulate", "--scene " + ini + " --out " + testing::TempDirectory() + "/no_such_dir/log.csv");
  EXPECT_EQ(unwritable.code, 4) << unwritable.err;
}

}  // namespace
}  // namespace slideid
