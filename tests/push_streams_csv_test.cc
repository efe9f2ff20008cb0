// A push as one CSV file per stream (io/push_streams_csv.h, `import-log --format streams`)
// on synthetic pushes made by the simulator (datasets/mit_push_synth.h), written by our own
// writer: the mapping's text is parsed with clear errors; times in each unit read back the
// same doubles; a push with each defect the MIT tests inject imports to the same log as the
// MIT JSON of the same push (byte for byte with seconds, yaw and world axes; to a few ulps
// with a quaternion or a sensor frame to turn); and bad files fail naming the file, the line
// and the column.

#include "io/push_streams_csv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "datasets/mit_push_synth.h"
#include "io/mit_push_files.h"
#include "io/mit_push_import.h"
#include "io/mit_push_json.h"
#include "pipeline/import_files.h"
#include "tests/estimator_test_support.h"
#include "tests/import_test_support.h"

namespace slideid {
namespace {

using testing::DefectiveSpec;
using testing::ExpectError;
using testing::ExpectSameImport;
using testing::NewDir;
using testing::Options;
using testing::Rect1;
using testing::WithoutSource;

// A yaw through a quaternion (half-angle sine and cosine, then atan2), or a force turned into
// a sensor frame and back: a few ulps of values of order 1.
constexpr double kTurnedValueTol = 1e-13;

/// The three files in `dir`, mapped by the given texts.
PushStreamsCsv Files(const std::string& dir, const std::string& pose, const std::string& tip,
                     const std::string& force) {
  PushStreamsCsv f;
  f.pose = ParseStreamMapping(PushStream::kPose, "--pose", dir + "/" + pose);
  f.tip = ParseStreamMapping(PushStream::kTip, "--tip", dir + "/" + tip);
  f.force = ParseStreamMapping(PushStream::kForce, "--force", dir + "/" + force);
  return f;
}

TEST(PushStreamsMapping, ReadsKeysColumnsUnitsAndFrames) {
  const StreamCsvMapping p =
      ParseStreamMapping(PushStream::kPose, "--pose", "dir/pose.csv:t=stamp,x=px,y=py,theta=yaw");
  EXPECT_EQ(p.path, "dir/pose.csv");
  EXPECT_EQ(p.columns.at("t"), "stamp");
  EXPECT_EQ(p.columns.at("theta"), "yaw");
  EXPECT_EQ(p.time_digits, 0);
  const StreamCsvMapping q =
      ParseStreamMapping(PushStream::kPose, "--pose", "p.csv:t=time,unit=ns,qx=a,qy=b,qz=c,qw=d");
  EXPECT_TRUE(q.Quaternion());
  EXPECT_EQ(q.time_digits, 9);
  EXPECT_EQ(q.columns.count("theta"), 0u);
  EXPECT_EQ(q.columns.at("x"), "x");  // unmapped keys: columns of their own name
  const StreamCsvMapping f =
      ParseStreamMapping(PushStream::kForce, "--force", "ft.csv:t,fx,fy,frame=sensor,yaw=0.3");
  EXPECT_TRUE(f.sensor_frame);
  EXPECT_EQ(*f.sensor_yaw_rad, 0.3);
  EXPECT_EQ(f.columns.at("fx"), "fx");
  const StreamCsvMapping g =
      ParseStreamMapping(PushStream::kForce, "--force", "ft.csv:frame=sensor,yaw=tip,unit=ms");
  EXPECT_TRUE(g.sensor_frame);
  EXPECT_FALSE(g.sensor_yaw_rad.has_value());
  EXPECT_EQ(g.time_digits, 3);
  const StreamCsvMapping t = ParseStreamMapping(PushStream::kTip, "--tip", "tip.csv");
  EXPECT_EQ(t.columns.count("theta"), 0u);  // the tip's orientation is optional
}

TEST(PushStreamsMapping, BadMappingsAreNamedWithTheOption) {
  auto bad = [](PushStream s, const char* option, const std::string& text, const std::string& m) {
    ExpectError<std::exception>([&] { ParseStreamMapping(s, option, text); },
                                {std::string(option) + ": " + m});
  };
  bad(PushStream::kPose, "--pose", "p.csv:t=stamp,thta=yaw", "unknown key 'thta' (keys: t, x, y");
  bad(PushStream::kPose, "--pose", "p.csv:unit=min", "unknown time unit 'min' in unit=min");
  bad(PushStream::kTip, "--tip", "p.csv:fx=a", "unknown key 'fx'");
  bad(PushStream::kPose, "--pose", "p.csv:qx=a,qy=b", "a quaternion needs all of qx, qy, qz");
  bad(PushStream::kPose, "--pose", "p.csv:theta=h,qx=a,qy=b,qz=c,qw=d",
      "give theta or qx, qy, qz, qw, not both");
  bad(PushStream::kPose, "--pose", "p.csv:t=a,t=b", "key 't' given twice");
  bad(PushStream::kPose, "--pose", "p.csv:x=px,y=px", "keys 'x' and 'y' both name column 'px'");
  bad(PushStream::kPose, "--pose", "p.csv:theta=x", "keys 'theta' and 'x' both name column 'x'");
  bad(PushStream::kPose, "--pose", ":t=a", "no file given");
  bad(PushStream::kPose, "--pose", "p.csv:t=", "key 't' has no value");
  bad(PushStream::kForce, "--force", "f.csv:frame=sensor", "frame=sensor needs yaw=RAD");
  bad(PushStream::kForce, "--force", "f.csv:frame=robot", "unknown frame 'robot'");
  bad(PushStream::kForce, "--force", "f.csv:yaw=0.3", "yaw= applies to frame=sensor only");
  bad(PushStream::kForce, "--force", "f.csv:frame=sensor,yaw=west", "yaw=west is neither");
}

TEST(PushStreamsCsv, TimesInEachUnitReadBackTheSameDoubles) {
  const MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  for (const char* unit : {"s", "ms", "us", "ns"}) {
    SCOPED_TRACE(unit);
    PushStreamsCsv f = Files("d", std::string("p.csv:t=stamp,unit=") + unit, "t.csv:theta",
                             std::string("f.csv:t=time,tz,unit=") + unit);
    const std::string pose = FormatPushStreamCsv(rec, f.pose);
    const std::string force = FormatPushStreamCsv(rec, f.force);
    const PushStreamsRead r = ParsePushStreamsCsv(f, pose, FormatPushStreamCsv(rec, f.tip), force);
    ASSERT_EQ(r.recording.object_pose.size(), rec.object_pose.size());
    for (std::size_t i = 0; i < rec.object_pose.size(); ++i) {
      ASSERT_EQ(r.recording.object_pose[i], rec.object_pose[i]) << i;
    }
    for (std::size_t i = 0; i < rec.ft_wrench.size(); ++i) {
      ASSERT_EQ(r.recording.ft_wrench[i], rec.ft_wrench[i]) << i;
    }
    EXPECT_NE(r.notes[0].find(std::string("times in ") + unit), std::string::npos) << r.notes[0];
  }
  // By hand: 1476728847123.25 ms and 1476728847123250000 ns are 1476728847.12325 s.
  PushStreamsCsv f = Files("d", "p.csv:unit=ms", "t.csv:unit=ns", "f.csv:unit=us");
  const PushStreamsRead r =
      ParsePushStreamsCsv(f, "t,x,y,theta\n1476728847123.25,0,0,0\n",
                          "t,x,y\n1476728847123250000,0,0\n", "t,fx,fy\n1.47672884712325e15,0,0\n");
  EXPECT_EQ(r.recording.object_pose[0][0], 1476728847.12325);
  EXPECT_EQ(r.recording.tip_pose[0][0], 1476728847.12325);
  EXPECT_EQ(r.recording.ft_wrench[0][0], 1476728847.12325);
}

TEST(PushStreamsCsv, QuaternionsAndSensorFramesAreTurnedBack) {
  MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  for (MitStreamRow& r : rec.tip_pose) r[3] = 0.4 + 3.0 * std::sin(r[0] - 1476728847.0);  // turns
  for (const char* force : {"f.csv:tz,frame=sensor,yaw=0.3", "f.csv:tz,frame=sensor,yaw=tip"}) {
    SCOPED_TRACE(force);
    PushStreamsCsv f = Files("d", "p.csv:qx=a,qy=b,qz=c,qw=d", "t.csv:theta=yaw", force);
    const PushStreamsRead r =
        ParsePushStreamsCsv(f, FormatPushStreamCsv(rec, f.pose), FormatPushStreamCsv(rec, f.tip),
                            FormatPushStreamCsv(rec, f.force));
    for (std::size_t i = 0; i < rec.object_pose.size(); ++i) {
      const double d = r.recording.object_pose[i][3] - rec.object_pose[i][3];
      ASSERT_NEAR(std::remainder(d, 2 * 3.141592653589793), 0.0, kTurnedValueTol) << i;
    }
    for (std::size_t i = 0; i < rec.ft_wrench.size(); ++i) {
      ASSERT_NEAR(r.recording.ft_wrench[i][1], rec.ft_wrench[i][1], kTurnedValueTol) << i;
      ASSERT_NEAR(r.recording.ft_wrench[i][2], rec.ft_wrench[i][2], kTurnedValueTol) << i;
    }
  }
  // The file itself holds the sensor's reading: at yaw 0.3 a world force (1, 0) reads as
  // (cos 0.3, -sin 0.3).
  PushStreamsCsv f = Files("d", "p.csv", "t.csv", "f.csv:frame=sensor,yaw=0.3");
  const PushStreamsRead r = ParsePushStreamsCsv(f, "t,x,y,theta\n0,0,0,0\n", "t,x,y\n0,0,0\n",
                                                "t,fx,fy\n0,0.955336489125606,-0.29552020666134\n");
  EXPECT_NEAR(r.recording.ft_wrench[0][1], 1.0, kTurnedValueTol);
  EXPECT_NEAR(r.recording.ft_wrench[0][2], 0.0, kTurnedValueTol);
}

TEST(PushStreamsCsv, TheDefectivePushImportsToTheSameLogAsTheJson) {
  const std::string dir = NewDir("streams_same");
  std::filesystem::create_directories(dir + "/json");
  std::filesystem::create_directories(dir + "/csv");
  const MitPushRecording rec = MakeMitPushRecording(DefectiveSpec()).recording;
  WriteMitPushJson(rec, dir + "/push.json");
  MitImportOptions options;
  options.tip_radius_m = MitSynthSpec{}.tip_radius_m;
  std::set<std::string> used_json, used_csv;
  const RecordingReader json = [](const std::string& path) {
    RecordingRead r;
    r.recording = ReadMitPushJson(path);
    return r;
  };
  const MitImportReport a =
      ImportRecordingFile(dir + "/push.json", json, Rect1(), options, dir + "/json", &used_json);
  ASSERT_EQ(a.verdict, ImportVerdict::kAccepted) << a.reason;
  // Seconds, yaw and world axes: the same doubles, the same log byte for byte (but its
  // source line); the columns named otherwise, and in another order, than the MIT streams.
  const PushStreamsCsv plain =
      Files(dir, "push.csv:t=stamp,x=px,y=py,theta=yaw", "tip.csv:t=time,theta=heading",
            "ft.csv:t=time,fx=force_x,fy=force_y,tz=torque_z");
  WritePushStreamsCsv(rec, plain);
  const MitImportReport b = ImportRecordingFile(dir + "/push.csv", PushStreamsReader(plain),
                                                Rect1(), options, dir + "/csv", &used_csv);
  ASSERT_EQ(b.verdict, ImportVerdict::kAccepted) << b.reason;
  EXPECT_EQ(WithoutSource(testing::ReadText(a.output)), WithoutSource(testing::ReadText(b.output)));
  EXPECT_NE(b.notes[0].find("streams: pose " + dir + "/push.csv"), std::string::npos) << b.notes[0];
  // Milliseconds, nanoseconds, a quaternion, a sensor frame: the same log to a few ulps.
  const MitImportResult expected = ImportMitPush(rec, "push", Options(DefectiveSpec()));
  for (const char* force :
       {"ft.csv:tz,unit=us,frame=sensor,yaw=-2.5", "ft.csv:tz,unit=ns,frame=sensor,yaw=tip"}) {
    SCOPED_TRACE(force);
    const PushStreamsCsv turned =
        Files(dir, "push.csv:unit=ms,qx=qx,qy=qy,qz=qz,qw=qw", "tip.csv:unit=ns,theta", force);
    WritePushStreamsCsv(rec, turned);
    const PushStreamsRead read = ReadPushStreamsCsv(turned);
    ExpectSameImport(expected, ImportMitPush(read.recording, "push", Options(DefectiveSpec())));
  }
}

TEST(PushStreamsCsv, AFileTheJsonImportRejectsIsRejectedForTheSameReason) {
  for (int defect = 0; defect < 3; ++defect) {
    MitSynthSpec spec;
    if (defect == 0) spec.defects.dead_force = true;
    if (defect == 1) spec.defects.saturation_n = 2.0;
    if (defect == 2) spec.defects.tip_clearance_m = 0.02;
    const MitPushRecording rec = MakeMitPushRecording(spec).recording;
    const MitImportResult json = ImportMitPush(rec, "push", Options(spec));
    ASSERT_EQ(json.report.verdict, ImportVerdict::kRejected) << defect;
    PushStreamsCsv f = Files("d", "p.csv", "t.csv:theta", "f.csv:tz");
    const PushStreamsRead r =
        ParsePushStreamsCsv(f, FormatPushStreamCsv(rec, f.pose), FormatPushStreamCsv(rec, f.tip),
                            FormatPushStreamCsv(rec, f.force));
    const MitImportResult csv = ImportMitPush(r.recording, "push", Options(spec));
    EXPECT_EQ(csv.report.verdict, ImportVerdict::kRejected);
    EXPECT_EQ(csv.report.reason, json.report.reason);
  }
}

TEST(PushStreamsBadInput, EachBadFileIsNamedWithItsLineAndColumn) {
  const PushStreamsCsv f = Files("d", "p.csv:t=stamp,x=px,y=py,theta=yaw", "t.csv", "f.csv");
  const std::string tip = "t,x,y\n1,0,0\n2,0,0\n", force = "t,fx,fy\n1,0,0\n2,0,0\n";
  auto pose = [&](const std::string& text, std::initializer_list<std::string> parts) {
    ExpectError<std::exception>([&] { ParsePushStreamsCsv(f, text, tip, force); }, parts);
  };
  pose("stamp,px,py,thta\n1,0,0,0\n",
       {"d/p.csv:1: column 'yaw': not in the header (--pose maps theta to it; the header's "
        "columns: stamp, px, py, thta)"});
  pose("# a comment\nstamp,px,py,yaw\n1,0,0,0\n2,0,abc,0\n",
       {"d/p.csv:4: column 'py': not a finite number: 'abc'"});
  pose("stamp,px,py,yaw\n1,0,0\n", {"d/p.csv:2: column 'yaw': missing: the row has 3 cells"});
  pose("stamp,px,py,yaw\n", {"d/p.csv: no rows (a header and no data)"});
  pose("", {"d/p.csv: empty file"});
  pose("stamp,px,py,yaw\nnan,0,0,0\n", {"d/p.csv:2: column 'stamp': not a finite number: 'nan'"});
  pose("stamp,px,px,yaw\n1,0,0,0\n", {"d/p.csv:1: column 'px': appears twice in the header"});
  const PushStreamsCsv q = Files("d", "p.csv:qx=a,qy=b,qz=c,qw=d", "t.csv", "f.csv");
  ExpectError<std::exception>(
      [&] { ParsePushStreamsCsv(q, "t,x,y,a,b,c,d\n1,0,0,0,0,0,0\n", tip, force); },
      {"d/p.csv:2: column 'd': the quaternion is zero"});
  const PushStreamsCsv tipyaw = Files("d", "p.csv", "t.csv", "f.csv:frame=sensor,yaw=tip");
  ExpectError<std::exception>(
      [&] { ParsePushStreamsCsv(tipyaw, "t,x,y,theta\n1,0,0,0\n", tip, force); },
      {"--force yaw=tip needs the tip's orientation"});
  const std::string dir = NewDir("streams_missing");
  const PushStreamsCsv missing = Files(dir, "p.csv", "t.csv", "f.csv");
  ExpectError<std::exception>([&] { ReadPushStreamsCsv(missing); }, {dir + "/p.csv"});
}

TEST(PushStreamsBadInput, ClocksThatNeverOverlapRejectTheFileNamingTheFiles) {
  MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  for (MitStreamRow& r : rec.ft_wrench) r[0] -= 1476728000.0;  // the sensor's own clock
  const std::string dir = NewDir("streams_clock");
  const PushStreamsCsv f = Files(dir, "push.csv", "tip.csv", "ft.csv");
  WritePushStreamsCsv(rec, f);
  std::set<std::string> used;
  const MitImportReport r =
      ImportRecordingFile(dir + "/push.csv", PushStreamsReader(f), Rect1(), {}, dir, &used);
  EXPECT_EQ(r.verdict, ImportVerdict::kRejected);
  EXPECT_NE(r.reason.find("the clocks never overlap: the pose file " + dir +
                          "/push.csv spans 1476728847"),
            std::string::npos)
      << r.reason;
  EXPECT_NE(r.reason.find("and the force file " + dir + "/ft.csv 847.0"), std::string::npos)
      << r.reason;
}

TEST(ImportLogTool, ReadsStreamsAndNamesBadMappings) {
  const std::string in = NewDir("streams_tool_in"), out = NewDir("streams_tool_out");
  const MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  const PushStreamsCsv f =
      Files(in, "shape=rect1_push.csv:t=stamp,unit=ms", "tip.csv", "ft.csv:frame=sensor,yaw=0.3");
  WritePushStreamsCsv(rec, f);
  const std::string objects = " --objects " + std::string(SLIDEID_SOURCE_DIR) +
                              "/datasets/mit_objects.csv --mass 0.835 --inertia 0.00112725";
  const testing::ToolRun run = testing::RunTool(
      "import-log", "--format streams --pose " + in + "/shape=rect1_push.csv:t=stamp,unit=ms" +
                        " --tip " + in + "/tip.csv --force " + in + "/ft.csv:frame=sensor,yaw=0.3" +
                        objects + " --out " + out);
  EXPECT_EQ(run.code, 0) << run.all();
  EXPECT_NE(run.all().find("accepted " + out + "/shape=rect1_push.csv"), std::string::npos)
      << run.all();
  const testing::ToolRun unit = testing::RunTool(
      "import-log", "--format streams --pose " + in + "/p.csv:t=stamp,unit=min --tip " + in +
                        "/tip.csv --force " + in + "/ft.csv" + objects + " --out " + out);
  EXPECT_EQ(unit.code, 2) << unit.all();
  EXPECT_NE(unit.all().find("--pose: unknown time unit 'min' in unit=min (s, ms, us or ns)"),
            std::string::npos)
      << unit.all();
  const testing::ToolRun key = testing::RunTool(
      "import-log", "--format streams --pose " + in + "/p.csv:thta=yaw --tip " + in +
                        "/tip.csv --force " + in + "/ft.csv" + objects + " --out " + out);
  EXPECT_EQ(key.code, 2) << key.all();
  EXPECT_NE(key.all().find("--pose: unknown key 'thta'"), std::string::npos) << key.all();
  const testing::ToolRun column = testing::RunTool(
      "import-log", "--format streams --pose " + in + "/shape=rect1_push.csv:t=time,unit=ms" +
                        " --tip " + in + "/tip.csv --force " + in + "/ft.csv" + objects +
                        " --out " + out);
  EXPECT_EQ(column.code, 1) << column.all();
  EXPECT_NE(column.all().find("unreadable: " + in +
                              "/shape=rect1_push.csv:1: column 'time': "
                              "not in the header"),
            std::string::npos)
      << column.all();
  const testing::ToolRun missing =
      testing::RunTool("import-log", "--format streams --pose " + in + "/p.csv --force " + in +
                                         "/ft.csv" + objects + " --out " + out);
  EXPECT_EQ(missing.code, 2) << missing.all();
  EXPECT_NE(missing.all().find("--format streams needs --tip"), std::string::npos) << missing.all();
}

}  // namespace
}  // namespace slideid
