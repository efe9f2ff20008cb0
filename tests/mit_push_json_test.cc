// The MIT push-dataset JSON reader (io/mit_push_json.h): round trip, every kind of bad file
// named by its JSON path or line and column, file names, sorting and repeated times. The
// files are synthetic (datasets/mit_push_synth.h), never the third-party ones.

#include "io/mit_push_json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "datasets/mit_push_synth.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

/// A small valid file, one row per line (line 1 is "{").
std::string SmallFile() {
  MitPushRecording r;
  r.object_pose = {{1476728847.5, 0.3, -0.03, -1.78}, {1476728847.505, 0.301, -0.03, -1.77}};
  r.tip_pose = {{1476728847.5, 0.35, -0.09, 0.0}};
  r.ft_wrench = {{1476728847.5, -1.5, -0.5, 0.004}};
  return FormatMitPushJson(r);
}

/// The error ParseMitPushJson throws for `text`.
MitPushError ErrorFor(const std::string& text) {
  try {
    ParseMitPushJson(text, "push.json");
  } catch (const MitPushError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for: " << text;
  return MitPushError("", "", 0, 0, "");
}

void Replace(std::string* text, const std::string& from, const std::string& to) {
  const std::size_t at = text->find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text->replace(at, from.size(), to);
}

TEST(MitPushJson, SyntheticRecordingRoundTripsExactly) {
  const MitPushRecording r = MakeMitPushRecording(MitSynthSpec{}).recording;
  const MitPushRecording back = ParseMitPushJson(FormatMitPushJson(r), "synthetic.json");
  EXPECT_EQ(back.object_pose, r.object_pose);
  EXPECT_EQ(back.tip_pose, r.tip_pose);
  EXPECT_EQ(back.ft_wrench, r.ft_wrench);
  const std::string path = testing::TempPath("roundtrip.json");
  WriteMitPushJson(r, path);
  EXPECT_EQ(ReadMitPushJson(path).ft_wrench, r.ft_wrench);
}

TEST(MitPushJson, ReadsTheRealLayoutWithIndentationIntegersAndExtraKeys) {
  const std::string text =
      "{\n    \"tip_pose\": [\n        [\n            1476728847, \n            0.35, \n"
      "            -0.09, \n            0\n        ]\n    ], \n    \"ft_wrench\": [[1476728847.1, "
      "-1.5, -0.5, 1e-3]], \"comment\": \"ignored\",\n    \"object_pose\": [[1476728847.2, 0.3, "
      "-0.03, -1.78]]\n}";
  const MitPushRecording r = ParseMitPushJson(text, "layout.json");
  ASSERT_EQ(r.tip_pose.size(), 1u);
  EXPECT_EQ(r.tip_pose[0][0], 1476728847.0);
  EXPECT_EQ(r.ft_wrench[0][3], 1e-3);
}

TEST(MitPushJson, MissingStreamIsNamedByItsPath) {
  std::string text = SmallFile();
  Replace(&text, "\"tip_pose\"", "\"tip_pos\"");
  const MitPushError e = ErrorFor(text);
  EXPECT_EQ(e.json_path(), "$.tip_pose");
  EXPECT_NE(std::string(e.what()).find("push.json: $.tip_pose: missing stream"), std::string::npos)
      << e.what();
}

TEST(MitPushJson, NonNumericValueIsNamedByRowAndColumn) {
  std::string text = SmallFile();
  Replace(&text, "-1.77]", "\"-1.77\"]");
  const MitPushError e = ErrorFor(text);
  EXPECT_EQ(e.json_path(), "$.object_pose[1][3]");
  EXPECT_NE(std::string(e.what()).find("not a number (found string)"), std::string::npos)
      << e.what();
  text = SmallFile();
  Replace(&text, "-0.09", "null");
  EXPECT_EQ(ErrorFor(text).json_path(), "$.tip_pose[0][2]");
}

TEST(MitPushJson, RowOfTheWrongLengthOrTypeIsNamed) {
  std::string text = SmallFile();
  Replace(&text, "-0.5, 0.004]", "-0.5]");
  MitPushError e = ErrorFor(text);
  EXPECT_EQ(e.json_path(), "$.ft_wrench[0]");
  EXPECT_NE(std::string(e.what()).find("row of 3 values (expected 4"), std::string::npos)
      << e.what();
  text = SmallFile();
  Replace(&text, "[1476728847.5, 0.35, -0.09, 0]", "{\"t\": 1}");
  e = ErrorFor(text);
  EXPECT_EQ(e.json_path(), "$.tip_pose[0]");
  EXPECT_NE(std::string(e.what()).find("found object"), std::string::npos) << e.what();
}

TEST(MitPushJson, EmptyFileEmptyStreamAndNonObjectAreErrors) {
  EXPECT_NE(std::string(ErrorFor("").what()).find("push.json: empty file"), std::string::npos);
  EXPECT_NE(std::string(ErrorFor(" \n\t\n").what()).find("empty file"), std::string::npos);
  std::string text = SmallFile();
  Replace(&text, "[\n    [1476728847.5, -1.5, -0.5, 0.004]\n  ]", "[]");
  EXPECT_EQ(ErrorFor(text).json_path(), "$.ft_wrench");
  EXPECT_EQ(ErrorFor("[1, 2, 3]").json_path(), "$");
  EXPECT_EQ(ErrorFor("{\"object_pose\": 7, \"tip_pose\": [], \"ft_wrench\": []}").json_path(),
            "$.object_pose");
}

TEST(MitPushJson, TruncatedFileGivesTheLineAndColumnWhereItEnds) {
  const std::string full = SmallFile();
  const std::size_t cut = full.find("-0.03, -1.77");  // line 4
  const MitPushError e = ErrorFor(full.substr(0, cut));
  EXPECT_TRUE(e.json_path().empty());
  EXPECT_EQ(e.line(), 4);
  EXPECT_EQ(e.column(), static_cast<int>(cut - full.rfind('\n', cut)));  // one past the end
  EXPECT_NE(std::string(e.what()).find("push.json:4:"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
}

TEST(MitPushJson, SyntaxErrorGivesItsLineAndColumn) {
  std::string text = SmallFile();  // line 3: "    [1476728847.5, 0.3, -0.03, -1.78],"
  Replace(&text, "0.3, -0.03, -1.78", "0.3 -0.03, -1.78");
  const MitPushError e = ErrorFor(text);
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.column(), 24);  // the '-' after "0.3 "
  EXPECT_NE(std::string(e.what()).find("push.json:3:24: invalid JSON"), std::string::npos)
      << e.what();
}

TEST(MitPushJson, OutOfRangeNumberAndUnreadableFileAreErrors) {
  std::string text = SmallFile();
  Replace(&text, "-1.78", "1e999");
  EXPECT_NE(std::string(ErrorFor(text).what()).find("push.json"), std::string::npos);
  try {
    ReadMitPushJson(testing::TempPath("no_such_file.json"));
    ADD_FAILURE() << "no error";
  } catch (const MitPushError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos) << e.what();
  }
}

TEST(MitPushJson, FileNameGivesTheObjectAndThePush) {
  const MitPushFileName n = ParseMitPushFileName(
      "data/01_train/motion_surface=plywood_shape=rect1_a=0_v=100_i=1.000_s=0.300_t=-1.396.json");
  EXPECT_EQ(n.surface, "plywood");
  EXPECT_EQ(n.shape, "rect1");
  EXPECT_EQ(n.acceleration, 0.0);
  EXPECT_EQ(n.velocity_mm_s, 100.0);
  EXPECT_EQ(n.side, 1.0);
  EXPECT_EQ(n.position, 0.3);
  EXPECT_EQ(n.angle_rad, -1.396);
  const MitPushFileName other = ParseMitPushFileName("/tmp/my_push.json");
  EXPECT_TRUE(other.shape.empty());
  EXPECT_FALSE(other.velocity_mm_s.has_value());
}

TEST(MitPushJson, SortingCountsBackwardStepsAndDropsRepeatedTimes) {
  std::vector<MitStreamRow> rows = {{3, 0, 0, 0}, {1, 1, 0, 0}, {2, 2, 0, 0},
                                    {2, 2, 0, 0}, {2, 9, 0, 0}, {0, 3, 0, 0}};
  const StreamCleanup c = SortAndDeduplicate(&rows);
  EXPECT_EQ(c.rows_in, 6);
  EXPECT_EQ(c.backward_steps, 2);  // 3 -> 1 and 2 -> 0
  EXPECT_EQ(c.duplicates_dropped, 2);
  EXPECT_EQ(c.conflicting_duplicates, 1);  // {2, 9}: the first row of a time is kept
  ASSERT_EQ(rows.size(), 4u);
  for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i][0], static_cast<double>(i));
  EXPECT_EQ(rows[2][1], 2.0);
}

}  // namespace
}  // namespace slideid
