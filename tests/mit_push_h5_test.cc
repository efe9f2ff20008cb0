// The MIT push dataset as HDF5 (io/mit_push_h5.h) on synthetic pushes made by the simulator
// (datasets/mit_push_synth.h), written by our own writer: every stream round-trips exactly
// (contiguous and gzip-compressed); a push with each defect the MIT tests inject imports
// from the .h5 to the same log, byte for byte, as from the MIT JSON of the same push (or is
// rejected for the same reason); and bad files (a missing dataset, a wrong shape or type, a
// truncated file, not HDF5 at all) fail with a message naming the file and the dataset.

#include "io/mit_push_h5.h"

#include <H5Cpp.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

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
using testing::NewDir;
using testing::Rect1;
using testing::WithoutSource;

/// The pushes of the MIT importer's tests: each defect it repairs, and each it rejects.
std::vector<std::pair<std::string, MitSynthSpec>> DefectCases() {
  std::vector<std::pair<std::string, MitSynthSpec>> cases;
  cases.emplace_back("clean", MitSynthSpec{});
  cases.emplace_back("every_repairable_defect", DefectiveSpec());
  MitSynthSpec s;
  s.store_reaction = false;
  cases.emplace_back("force_stored_as_applied", s);
  s = MitSynthSpec{};
  s.defects.dead_force = true;
  cases.emplace_back("dead_force", s);
  s = MitSynthSpec{};
  s.defects.saturation_n = 2.0;
  cases.emplace_back("saturated_force", s);
  s = MitSynthSpec{};
  s.defects.tip_clearance_m = 0.02;
  cases.emplace_back("tip_misses", s);
  s = MitSynthSpec{};
  s.defects.force_frame_rad = 1.5707963267948966;  // a sensor frame turned by 90 degrees
  cases.emplace_back("force_across_the_normal", s);
  s = MitSynthSpec{};
  s.rest_clearance_m = 5e-3;
  s.offset_after_n = {0.0, 0.0};  // 1.58 N from (-1.5, -0.5)
  cases.emplace_back("offset_drift", s);
  s = MitSynthSpec{};
  s.defects.pose_gaps = {{0.35, 0.75}, {0.8, 1.15}};  // 0.15 s of the 0.9 s push left
  cases.emplace_back("pose_gaps_leave_too_little", s);
  s = MitSynthSpec{};
  s.push_s = 0.12;
  s.amplitude_ratio = 0.0;
  s.force_ratio = 1.3;
  cases.emplace_back("short_push", s);
  return cases;
}

void ExpectSameRows(const std::vector<MitStreamRow>& a, const std::vector<MitStreamRow>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << i;
}

TEST(MitPushH5, EveryStreamRoundTripsExactlyContiguousAndCompressed) {
  const MitPushRecording rec = MakeMitPushRecording(DefectiveSpec()).recording;
  for (bool deflate : {false, true}) {
    MitPushH5WriteOptions o;
    o.deflate = deflate;
    const MitPushRecording back = ParseMitPushH5(FormatMitPushH5(rec, o), "push.h5");
    ExpectSameRows(rec.object_pose, back.object_pose);
    ExpectSameRows(rec.tip_pose, back.tip_pose);
    ExpectSameRows(rec.ft_wrench, back.ft_wrench);
  }
  // Compression is real where there is something to compress (noisy doubles barely shrink).
  MitPushRecording still = rec;
  for (MitStreamRow& row : still.ft_wrench) row = {row[0], 1.0, 2.0, 0.0};
  MitPushH5WriteOptions gzip;
  gzip.deflate = true;
  EXPECT_LT(FormatMitPushH5(still, gzip).size(), FormatMitPushH5(still).size());
}

TEST(MitPushH5, EachDefectImportsToTheSameLogBytesAsTheJson) {
  const std::string dir = NewDir("h5_same");
  std::filesystem::create_directories(dir + "/json");
  std::filesystem::create_directories(dir + "/h5");
  int accepted = 0;
  for (const auto& [name, spec] : DefectCases()) {
    SCOPED_TRACE(name);
    const MitPushRecording rec = MakeMitPushRecording(spec).recording;
    WriteMitPushJson(rec, dir + "/" + name + ".json");
    MitPushH5WriteOptions o;
    o.deflate = accepted % 2 == 1;  // both layouts
    WriteMitPushH5(rec, dir + "/" + name + ".h5", o);
    MitImportOptions options;
    options.tip_radius_m = spec.tip_radius_m;
    std::set<std::string> used_json, used_h5;
    const RecordingReader json = [](const std::string& path) {
      RecordingRead r;
      r.recording = ReadMitPushJson(path);
      return r;
    };
    const MitImportReport a = ImportRecordingFile(dir + "/" + name + ".json", json, Rect1(),
                                                  options, dir + "/json", &used_json);
    const MitImportReport b = ImportRecordingFile(dir + "/" + name + ".h5", MitPushH5Reader(),
                                                  Rect1(), options, dir + "/h5", &used_h5);
    EXPECT_EQ(a.verdict, b.verdict);
    EXPECT_EQ(a.reason, b.reason);
    EXPECT_EQ(a.rows, b.rows);
    if (a.verdict != ImportVerdict::kAccepted) continue;
    ++accepted;
    const std::string ja = testing::ReadText(a.output), hb = testing::ReadText(b.output);
    ASSERT_FALSE(ja.empty());
    EXPECT_EQ(WithoutSource(ja), WithoutSource(hb));  // byte for byte but the input's name
    EXPECT_NE(ja, hb);                                // which does differ: .json, .h5
  }
  EXPECT_EQ(accepted, 3);  // clean, defective, as applied; the others are rejections
}

// ---------------------------------------------------------------------------------------
// Bad files, made with HDF5's own API
// ---------------------------------------------------------------------------------------

/// An HDF5 file at `path` whose datasets `make` creates.
void MakeH5(const std::string& path, const std::function<void(H5::H5File&)>& make) {
  H5::H5File file(path, H5F_ACC_TRUNC);
  make(file);
}

void AddDoubles(H5::H5File& f, const char* name, hsize_t rows, hsize_t cols, double value = 1.0) {
  const hsize_t dims[2] = {rows, cols};
  const std::vector<double> data(rows * cols, value);
  H5::DataSet ds = f.createDataSet(name, H5::PredType::IEEE_F64LE, H5::DataSpace(2, dims));
  if (!data.empty()) ds.write(data.data(), H5::PredType::NATIVE_DOUBLE);
}

TEST(MitPushH5BadInput, AMissingDatasetIsNamedWithTheDatasetsPresent) {
  const std::string dir = NewDir("h5_bad"), path = dir + "/x.h5";
  MakeH5(path, [](H5::H5File& f) {
    AddDoubles(f, "object_pose", 20, 4);
    AddDoubles(f, "tip_pose", 20, 4);
  });
  ExpectError([&] { ReadMitPushH5(path); },
              {path + ": dataset '/ft_wrench': missing (the file needs object_pose, tip_pose and "
                      "ft_wrench; it holds /object_pose, /tip_pose)"});
}

TEST(MitPushH5BadInput, AWrongShapeOrTypeIsNamedWithWhatWasFound) {
  const std::string dir = NewDir("h5_shape"), path = dir + "/x.h5";
  MakeH5(path, [](H5::H5File& f) {
    AddDoubles(f, "object_pose", 20, 4);
    AddDoubles(f, "tip_pose", 20, 4);
    AddDoubles(f, "ft_wrench", 7, 3);
  });
  ExpectError([&] { ReadMitPushH5(path); },
              {path + ": dataset '/ft_wrench': expected N x 4 doubles, found 7 x 3"});
  MakeH5(path, [](H5::H5File& f) {
    AddDoubles(f, "object_pose", 20, 4);
    const hsize_t dims[2] = {7, 4};
    const std::vector<int> data(28, 3);
    f.createDataSet("tip_pose", H5::PredType::STD_I32LE, H5::DataSpace(2, dims))
        .write(data.data(), H5::PredType::NATIVE_INT);
    AddDoubles(f, "ft_wrench", 7, 4);
  });
  ExpectError([&] { ReadMitPushH5(path); },
              {path + ": dataset '/tip_pose': expected N x 4 doubles, found 7 x 4 integers"});
  MakeH5(path, [](H5::H5File& f) {
    const hsize_t n = 28;
    f.createDataSet("object_pose", H5::PredType::IEEE_F64LE, H5::DataSpace(1, &n));
  });
  ExpectError([&] { ReadMitPushH5(path); },
              {path + ": dataset '/object_pose': expected N x 4 doubles, found 28"});
  MakeH5(path, [](H5::H5File& f) { f.createGroup("object_pose"); });
  ExpectError([&] { ReadMitPushH5(path); },
              {path + ": dataset '/object_pose': is a group, not a dataset"});
  MakeH5(path, [](H5::H5File& f) {
    AddDoubles(f, "object_pose", 0, 4);
    AddDoubles(f, "tip_pose", 20, 4);
    AddDoubles(f, "ft_wrench", 7, 4);
  });
  ExpectError([&] { ReadMitPushH5(path); }, {path + ": dataset '/object_pose': empty (no rows)"});
}

TEST(MitPushH5BadInput, ANonFiniteValueIsNamedByRowAndColumn) {
  MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  rec.tip_pose[12][2] = std::nan("");
  ExpectError([&] { ParseMitPushH5(FormatMitPushH5(rec), "n.h5"); },
              {"n.h5: dataset '/tip_pose': row 12, column 2 (from 0): not a finite number"});
}

TEST(MitPushH5BadInput, ATruncatedFileOrAnotherFormatIsUnreadableNamingTheFile) {
  const std::string bytes = FormatMitPushH5(MakeMitPushRecording(MitSynthSpec{}).recording);
  // Cut anywhere past the signature: an error naming the file, never a crash or a hang.
  for (std::size_t n : {std::size_t{8}, std::size_t{100}, std::size_t{1000}, bytes.size() / 2,
                        bytes.size() - 1000, bytes.size() - 1}) {
    try {
      ParseMitPushH5(bytes.substr(0, n), "cut.h5");
      ADD_FAILURE() << n;
    } catch (const MitPushH5Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("cut.h5: ", 0), 0u) << e.what();
    }
  }
  ExpectError([&] { ParseMitPushH5(bytes.substr(0, 300), "cut.h5"); },
              {"cut.h5: cannot be opened as HDF5 (truncated or damaged file?): truncated file: "
               "eof = 300"});  // HDF5's own reason, from its error stack
  ExpectError([&] { ParseMitPushH5("{\"object_pose\": []}", "a.h5"); },
              {"a.h5: not an HDF5 file (no HDF5 signature)"});
  ExpectError([&] { ParseMitPushH5("", "e.h5"); }, {"e.h5: empty file"});
  const std::string dir = NewDir("h5_files");
  ExpectError([&] { ReadMitPushH5(dir); }, {dir + ": not a regular file"});
  ExpectError([&] { ReadMitPushH5(dir + "/none.h5"); },
              {dir + "/none.h5: cannot be opened for reading"});
}

TEST(MitPushH5BadInput, ADamagedFileIsReadOrUnreadableNeverACrash) {
  // One byte changed at spread places of the superblock, the object headers, the B-trees and
  // the data, contiguous and gzip: each file is read (a change in the data) or refused with
  // an error naming it (libhdf5 reads in a child process: each read is a fork).
  const MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  int errors = 0, reads = 0;
  for (bool deflate : {false, true}) {
    MitPushH5WriteOptions o;
    o.deflate = deflate;
    const std::string bytes = FormatMitPushH5(rec, o);
    for (std::size_t k = 0; k < bytes.size(); k += (k < 4096 ? 37 : 1999)) {
      for (unsigned char flip : {0x01, 0xFF}) {
        std::string damaged = bytes;
        damaged[k] = static_cast<char>(damaged[k] ^ flip);
        try {
          ParseMitPushH5(damaged, "d.h5");
          ++reads;
        } catch (const MitPushH5Error& e) {
          ++errors;
          EXPECT_EQ(std::string(e.what()).rfind("d.h5: ", 0), 0u) << e.what();
        }
      }
    }
  }
  EXPECT_GT(errors, 0);
  EXPECT_GT(reads, 0);
}

TEST(MitPushH5BadInput, AFileThatCrashesLibhdf5IsUnreadableNamingIt) {
  // Found by fuzz_mit_push_h5: libhdf5 copies to a null pointer reading it (SIGSEGV). The
  // child process that reads it dies; the file is unreadable (under ASan the child exits
  // instead of dying by the signal: then it ended without an answer).
  const std::string path = SLIDEID_SOURCE_DIR "/fuzz/corpus/mit_push_h5/bad_crashes_libhdf5.h5";
  try {
    ReadMitPushH5(path);
    ADD_FAILURE() << "read";
  } catch (const MitPushH5Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_TRUE(what.find("libhdf5 crashed reading it (signal ") != std::string::npos ||
                what.find("ended without an answer") != std::string::npos)
        << what;
  }
}

TEST(ImportLogTool, ReadsH5FilesAndNamesTheBadOnes) {
  const std::string in = NewDir("h5_tool_in"), out = NewDir("h5_tool_out");
  const MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  const std::string good = in + "/shape=rect1_push.h5";
  WriteMitPushH5(rec, good);
  const std::string bytes = FormatMitPushH5(rec);
  std::ofstream(in + "/cut.h5", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const testing::ToolRun run = testing::RunTool(
      "import-log", "--format mit-push-h5 --objects " + std::string(SLIDEID_SOURCE_DIR) +
                        "/datasets/mit_objects.csv --mass 0.835 --inertia 0.00112725 --out " + out +
                        " " + good + " " + in + "/cut.h5");
  EXPECT_EQ(run.code, 1) << run.all();
  EXPECT_NE(run.all().find("accepted " + out + "/shape=rect1_push.csv"), std::string::npos)
      << run.all();
  EXPECT_NE(run.all().find("unreadable: " + in + "/cut.h5: "), std::string::npos) << run.all();
  const testing::ToolRun bad =
      testing::RunTool("import-log", "--format mit-push-h5 --pose x.csv --objects " +
                                         std::string(SLIDEID_SOURCE_DIR) +
                                         "/datasets/mit_objects.csv --out " + out + " " + good);
  EXPECT_EQ(bad.code, 2) << bad.all();
  EXPECT_NE(bad.all().find("--pose applies to --format streams only"), std::string::npos)
      << bad.all();
}

}  // namespace
}  // namespace slideid
