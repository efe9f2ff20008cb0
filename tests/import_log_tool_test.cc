// import-log end to end on synthetic MIT files (a good one, a dead sensor, a truncated
// file, an unknown object): each is imported or reported on its own, the exit code says
// whether all were imported, the imported log identifies; and the object table and the
// import report, the two other files the tool reads and writes.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "datasets/mit_push_synth.h"
#include "io/mit_push_json.h"
#include "io/mit_push_report.h"
#include "io/object_table.h"
#include "io/push_log.h"
#include "io/result_json.h"
#include "io/zhou_tripod_log.h"
#include "io/zhou_tripod_synth.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

using testing::RunTool;
using testing::ToolRun;

std::string NewDir(const std::string& name) {
  std::string dir = ::testing::TempDir() + name + "_XXXXXX";
  if (mkdtemp(dir.data()) == nullptr) std::abort();
  return dir;
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// Cells of one CSV line (RFC 4180 quotes).
std::vector<std::string> Cells(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"') {
      if (quoted && i + 1 < line.size() && line[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else {
        quoted = !quoted;
      }
    } else if (c == ',' && !quoted) {
      cells.emplace_back();
    } else {
      cells.back() += c;
    }
  }
  return cells;
}

std::string Cell(const std::vector<std::string>& header, const std::string& row,
                 const std::string& column) {
  const std::vector<std::string> cells = Cells(row);
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == column) return i < cells.size() ? cells[i] : "";
  }
  ADD_FAILURE() << "no column " << column;
  return "";
}

const char* kGood = "motion_surface=plywood_shape=rect1_a=0_v=100_i=0.000_s=0.300_t=0.000.json";
const char* kDead = "motion_surface=plywood_shape=rect1_a=0_v=100_i=1.000_s=0.500_t=0.349.json";
const char* kCut = "motion_surface=plywood_shape=rect1_a=0_v=100_i=2.000_s=0.100_t=0.698.json";
const char* kHex = "motion_surface=plywood_shape=hex_a=0_v=150_i=1.000_s=0.000_t=-0.349.json";

/// A directory with the four files and an object table that knows rect1 only.
std::string MakeInputs() {
  const std::string dir = NewDir("import_log_in");
  WriteMitPushJson(MakeMitPushRecording(MitSynthSpec{}).recording, dir + "/" + kGood);
  MitSynthSpec dead;
  dead.defects.dead_force = true;
  WriteMitPushJson(MakeMitPushRecording(dead).recording, dir + "/" + kDead);
  const std::string text = FormatMitPushJson(MakeMitPushRecording(MitSynthSpec{}).recording);
  WriteText(dir + "/" + kCut, text.substr(0, text.size() / 2));
  WriteMitPushJson(MakeMitPushRecording(MitSynthSpec{}).recording, dir + "/" + kHex);
  WriteText(dir + "/objects.csv",
            "# test objects\nname,mass,inertia,com_height,patch,source\n"
            "rect1,0.835,0.00112725,0.0065,rectangle 0.09 0.09,\"synthetic, as simulated\"\n");
  return dir;
}

TEST(ImportLogTool, ImportsEachFileOnItsOwnAndReportsEveryOne) {
  const std::string in = MakeInputs(), out = NewDir("import_log_out");
  const ToolRun o =
      RunTool("import-log", "--format mit-push --objects " + in + "/objects.csv --out " + out +
                                " " + in + "/" + kGood + " " + in + "/" + kDead + " " + in + "/" +
                                kCut + " " + in + "/" + kHex);
  EXPECT_EQ(o.code, 1) << o.all();  // some files were not imported
  EXPECT_NE(o.all().find("imported 1 of 4 files"), std::string::npos) << o.all();
  EXPECT_NE(o.all().find("force channel constant (dead sensor?)"), std::string::npos) << o.all();
  EXPECT_NE(o.all().find("unreadable"), std::string::npos) << o.all();
  EXPECT_NE(o.all().find("object 'hex': mass, inertia, com_height, patch unknown"),
            std::string::npos)
      << o.all();

  const std::vector<std::string> report = Lines(out + "/import_report.csv");
  ASSERT_EQ(report.size(), 5u);
  const std::vector<std::string> header = Cells(report[0]);
  for (std::size_t i = 1; i < report.size(); ++i) {
    EXPECT_EQ(Cells(report[i]).size(), header.size()) << report[i];
  }
  EXPECT_EQ(Cell(header, report[1], "verdict"), "accepted");
  EXPECT_EQ(Cell(header, report[1], "force_flipped"), "yes");
  EXPECT_EQ(Cell(header, report[2], "verdict"), "rejected");
  EXPECT_EQ(Cell(header, report[3], "verdict"), "unreadable");
  EXPECT_NE(Cell(header, report[3], "reason").find(std::string(kCut) + ":"), std::string::npos);
  EXPECT_EQ(Cell(header, report[3], "object_pose_rows_in"), "");  // unknown, not 0
  EXPECT_EQ(Cell(header, report[4], "verdict"), "rejected");

  const std::string log_path =
      out + "/" + std::string(kGood).substr(0, std::string(kGood).size() - 5) + ".csv";
  EXPECT_EQ(Cell(header, report[1], "output"), log_path);
  const PushLogFile log = ReadPushLogFile(log_path);
  EXPECT_EQ(log.log.slider.mass_kg, 0.835);
  bool sourced = false;
  for (const auto& [key, value] : log.extra_metadata) {
    sourced |= key == "object_source" && value == "synthetic, as simulated";
  }
  EXPECT_TRUE(sourced);
  const ToolRun fit = RunTool("identify", "--log " + log_path + " --json");
  EXPECT_EQ(fit.code, 0) << fit.all();
}

TEST(ImportLogTool, AllFilesImportedIsExitZeroAndOptionsGiveTheObject) {
  const std::string in = MakeInputs(), out = NewDir("import_log_ok");
  const ToolRun o = RunTool("import-log",
                            "--format mit-push --mass 0.835 --inertia 1.13e-3 "
                            "--com-height 0.0065 --patch 'rectangle 0.09 0.09' --out " +
                                out + " " + in + "/" + kGood + " " + in + "/" + kHex);
  EXPECT_EQ(o.code, 0) << o.all();
  EXPECT_NE(o.all().find("imported 2 of 2 files"), std::string::npos) << o.all();
}

TEST(ImportLogTool, UsageErrorsAreExitTwo) {
  const std::string in = MakeInputs(), out = NewDir("import_log_usage");
  const std::string file = in + "/" + kGood;
  ToolRun o = RunTool("import-log", "--format mit-push --mass 1 --out " + out + " " + file);
  EXPECT_EQ(o.code, 2) << o.all();
  EXPECT_NE(o.all().find("masses are never guessed"), std::string::npos) << o.all();
  // An MIT file read as a tripod log is unreadable there: exit 1, naming the file.
  o = RunTool("import-log", "--format zhou-tripod --out " + out + " " + file);
  EXPECT_EQ(o.code, 1) << o.all();
  EXPECT_NE(o.all().find(file), std::string::npos) << o.all();
  EXPECT_EQ(RunTool("import-log", "--format csv --out " + out + " " + file).code, 2);
  EXPECT_EQ(RunTool("import-log", "--format mit-push " + file).code, 2);
  EXPECT_EQ(RunTool("import-log", "--format mit-push --out " + out).code, 2);
  o = RunTool("import-log", "--format mit-push --objects " + in + "/objects.csv --rate 0 --out " +
                                out + " " + file);
  EXPECT_EQ(o.code, 2) << o.all();
  EXPECT_EQ(RunTool("import-log", "--format mit-push --objects " + in +
                                      "/objects.csv --mass -1 --out " + out + " " + file)
                .code,
            2);
  EXPECT_EQ(RunTool("import-log", "--help").code, 0);
}

TEST(ImportLogTool, UnwritableOutputIsExitFour) {
  const std::string in = MakeInputs();
  const ToolRun o =
      RunTool("import-log", "--format mit-push --objects " + in + "/objects.csv --out " + in +
                                "/objects.csv/sub " + in + "/" + kGood);
  EXPECT_EQ(o.code, 4) << o.all();
}

TEST(ObjectTable, ReadsRowsWithCommentsQuotesAndOptionalColumns) {
  const std::string dir = NewDir("objects");
  WriteText(dir + "/t.csv",
            "# masses: an estimate\ncom_height,name,inertia,mass\n"
            "0.0065,rect1,1.1e-3,0.835\n0,hex,1.5e-3,0.98\n");
  const ObjectTable t = ReadObjectTable(dir + "/t.csv");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t.at("rect1").mass_kg, 0.835);
  EXPECT_EQ(t.at("hex").com_height_m, 0.0);
  EXPECT_TRUE(t.at("hex").patch_spec.empty());
}

TEST(ObjectTable, BadTablesNameTheFileLineAndColumn) {
  const std::string dir = NewDir("objects_bad");
  auto error = [&](const std::string& text) {
    WriteText(dir + "/t.csv", text);
    try {
      ReadObjectTable(dir + "/t.csv");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("name,mass,inertia\nrect1,1,1\n").find("missing column 'com_height'"),
            std::string::npos);
  EXPECT_NE(error("name,mass,inertia,com_height\nrect1,1,1,0\nhex,heavy,1,0\n")
                .find("t.csv:3: column 'mass': 'heavy' is not a finite number"),
            std::string::npos);
  EXPECT_NE(error("name,mass,inertia,com_height\nrect1,0,1,0\n").find("must be > 0"),
            std::string::npos);
  EXPECT_NE(error("name,mass,inertia,com_height,patch\nr,1,1,0,square 1\n").find("column 'patch'"),
            std::string::npos);
  EXPECT_NE(error("name,mass,inertia,com_height\nr,1,1,0\nr,2,1,0\n").find("given twice"),
            std::string::npos);
  EXPECT_NE(error("name,mass,inertia,com_height\n").find("no objects"), std::string::npos);
}

TEST(MitImportReport, RowsHaveEveryColumnAndQuoteTheirText) {
  MitImportReport a;
  a.source = "dir/a,b.json";
  a.verdict = ImportVerdict::kRejected;
  a.reason = "offset drift 0.7 N between before (1, 2) and after";
  a.notes = {"one", "two \"quoted\""};
  const std::vector<std::string> header = Cells(MitImportReportHeader());
  const std::vector<std::string> cells = Cells(MitImportReportRow(a));
  ASSERT_EQ(cells.size(), header.size());
  EXPECT_EQ(Cell(header, MitImportReportRow(a), "source"), a.source);
  EXPECT_EQ(Cell(header, MitImportReportRow(a), "reason"), a.reason);
  EXPECT_EQ(Cell(header, MitImportReportRow(a), "notes"), "one; two \"quoted\"");
  EXPECT_EQ(Cell(header, MitImportReportRow(a), "offset_before_fx_n"), "");  // unknown: empty
}

}  // namespace
}  // namespace slideid

namespace slideid {
namespace {

// import-log --format zhou-tripod on a synthetic tripod log (simulated spring pushes written
// as the rig records them), then identify --method quasi-static on the pairs it writes:
// the truth comes back, and the per-push report names every push.
TEST(ImportLogTool, TripodLogsBecomePairsThatIdentifyFits) {
  const ReducedFriction truth{0.3, 1.0, 0.045};
  const std::string in = NewDir("tripod_in"), out = NewDir("tripod_out");
  const std::string txt = in + "/exp_synthetic.txt";
  WriteZhouTripodLog(TripodLogFromPushes(SimulateSpringPushes(TripodSynthSpec(truth, 12, 5))), txt);
  const ToolRun imported = RunTool("import-log", "--format zhou-tripod --out " + out + " " + txt);
  ASSERT_EQ(imported.code, 0) << imported.all();
  EXPECT_NE(imported.all().find("imported 1 of 1 files"), std::string::npos) << imported.all();
  std::ifstream report(out + "/exp_synthetic_import_report.csv");
  EXPECT_TRUE(report.good());
  const ToolRun fit =
      RunTool("identify", "--method quasi-static --json --log " + out + "/exp_synthetic.csv");
  ASSERT_EQ(fit.code, 0) << fit.all();
  const EstimateResult r = ParseResultJson(fit.out.substr(0, fit.out.find('\n')));
  ASSERT_TRUE(r.parameters[kA].identifiable);
  // The importer's averaging and the spring's own dynamics leave < 1% on synthetic pushes
  // (tests/zhou_tripod_test.cc); 2% leaves room for the CSV round trip.
  EXPECT_NEAR(r.parameters[kA].value / truth.a, 1.0, 0.02);
  ASSERT_TRUE(r.parameters[kC].identifiable);
  EXPECT_NEAR(r.parameters[kC].value / truth.c, 1.0, 0.02);
}

// Two inputs of one name (the ICRA 2016 logs of different configurations share names)
// never map to one output: the second takes its folder's name, each is written, the count
// says so, and identify --logs on the output reads the pairs and not the reports.
TEST(ImportLogTool, TripodFilesOfOneNameInTwoFoldersGiveTwoOutputs) {
  const ReducedFriction truth{0.3, 1.0, 0.045};
  const std::string in = NewDir("tripod_same_name"), out = NewDir("tripod_same_out");
  std::filesystem::create_directories(in + "/config_a");
  std::filesystem::create_directories(in + "/config_b");
  for (const char* config : {"config_a", "config_b"}) {
    WriteZhouTripodLog(TripodLogFromPushes(SimulateSpringPushes(TripodSynthSpec(truth, 12, 5))),
                       in + "/" + config + "/exp_08_17_50.txt");
  }
  const ToolRun imported =
      RunTool("import-log", "--format zhou-tripod --out " + out + " " + in +
                                "/config_a/exp_08_17_50.txt " + in + "/config_b/exp_08_17_50.txt");
  ASSERT_EQ(imported.code, 0) << imported.all();
  EXPECT_NE(imported.all().find("imported 2 of 2 files"), std::string::npos) << imported.all();
  EXPECT_EQ(imported.all().find("<file>"), std::string::npos) << imported.all();
  EXPECT_TRUE(std::filesystem::exists(out + "/exp_08_17_50.csv"));
  EXPECT_TRUE(std::filesystem::exists(out + "/config_b_exp_08_17_50.csv"));
  EXPECT_TRUE(std::filesystem::exists(out + "/exp_08_17_50_import_report.csv"));
  EXPECT_TRUE(std::filesystem::exists(out + "/config_b_exp_08_17_50_import_report.csv"));
  EXPECT_NE(imported.out.find(in + "/config_b/exp_08_17_50.txt"), std::string::npos)
      << "each output names its source: " << imported.out;
  const ToolRun fit = RunTool("identify", "--method quasi-static --logs " + out);
  EXPECT_EQ(fit.code, 0) << fit.all();
  EXPECT_EQ(fit.all().find("missing"), std::string::npos) << fit.all();
}

}  // namespace
}  // namespace slideid
