#include "pipeline/import_files.h"

#include <filesystem>
#include <set>

#include "io/mcap_push.h"
#include "io/mit_push_h5.h"
#include "io/mit_push_json.h"
#include "io/mit_push_report.h"
#include "io/rosbag_push.h"
#include "io/wrench_twist_csv.h"

namespace slideid {
namespace {

void CreateDirectory(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw std::runtime_error("cannot create '" + dir + "': " + error.message());
}

}  // namespace

ImportSummary ImportMitFiles(const std::vector<std::string>& files, const MitObjectSource& objects,
                             const MitImportOptions& options, const std::string& out_dir) {
  const RecordingReader read_json = [](const std::string& path) {
    RecordingRead read;
    read.recording = ReadMitPushJson(path);
    return read;
  };
  return ImportRecordingFiles(files, read_json, objects, options, out_dir);
}

RecordingReader RosLogReader(const std::string& format, const RosTopics& topics) {
  if (format != "rosbag" && format != "mcap") {
    throw std::invalid_argument("'" + format + "' is not a ROS log format (rosbag or mcap)");
  }
  return [format, topics](const std::string& path) {
    RosPushLog log =
        format == "rosbag" ? ReadRosbagPushLog(path, topics) : ReadMcapPushLog(path, topics);
    RecordingRead read;
    read.recording = std::move(log.recording);
    read.notes = std::move(log.notes);
    read.rejection = StreamOverlapProblem(read.recording, topics);
    return read;
  };
}

RecordingReader MitPushH5Reader() {
  return [](const std::string& path) {
    RecordingRead read;
    read.recording = ReadMitPushH5(path);
    return read;
  };
}

RecordingReader PushStreamsReader(const PushStreamsCsv& files) {
  return [files](const std::string&) {
    PushStreamsRead streams = ReadPushStreamsCsv(files);
    RecordingRead read;
    read.recording = std::move(streams.recording);
    read.notes = std::move(streams.notes);
    read.rejection = StreamFilesOverlapProblem(read.recording, files);
    return read;
  };
}

ImportSummary ImportRecordingFiles(const std::vector<std::string>& files,
                                   const RecordingReader& read, const MitObjectSource& objects,
                                   const MitImportOptions& options, const std::string& out_dir) {
  CreateDirectory(out_dir);
  ImportSummary summary;
  std::vector<MitImportReport> reports;
  std::set<std::string> used_names{"import_report.csv"};
  for (const std::string& file : files) {
    reports.push_back(ImportRecordingFile(file, read, objects, options, out_dir, &used_names));
    const MitImportReport& r = reports.back();
    ++summary.files;
    if (r.verdict == ImportVerdict::kAccepted) {
      ++summary.accepted;
      summary.accepted_lines.push_back("accepted " + r.output + " (" + std::to_string(r.rows) +
                                       " rows" + (r.force_flipped ? ", force flipped" : "") + ")");
    } else {
      // An unreadable file's reason starts with its name (and line, column or JSON path).
      summary.rejections.push_back(std::string(ToString(r.verdict)) + ": " +
                                   (r.verdict == ImportVerdict::kUnreadable ? "" : file + ": ") +
                                   r.reason);
    }
  }
  summary.report_path = out_dir + "/import_report.csv";
  WriteMitImportReport(reports, summary.report_path);
  return summary;
}

// The output name of a tripod file: its stem, or, when another input already took that
// (the ICRA 2016 logs of different configurations share names such as exp_08_17_50.txt),
// its folder's name and its stem; then a counter. Two inputs never map to one output.
std::string TripodOutputStem(const std::string& file, std::set<std::string>* used) {
  const std::filesystem::path path(file);
  const std::string stem = path.stem().string();
  const std::string folder = path.parent_path().filename().string();
  std::string name = stem;
  if (used->count(name) && !folder.empty()) name = folder + "_" + stem;
  const std::string base = name;
  for (int k = 2; used->count(name); ++k) name = base + "_" + std::to_string(k);
  used->insert(name);
  return name;
}

ImportSummary ImportTripodFiles(const std::vector<std::string>& files,
                                const TripodImportOptions& options, const std::string& out_dir) {
  CreateDirectory(out_dir);
  ImportSummary summary;
  // "import_report" is the MIT importer's report name: no pair file may take it.
  std::set<std::string> used_stems{"import_report"};
  for (const std::string& file : files) {
    ++summary.files;
    const std::string stem = out_dir + "/" + TripodOutputStem(file, &used_stems);
    TripodImportReport report;
    WrenchTwistData data;
    try {
      data = ImportZhouTripod(file, options, &report);
    } catch (const std::invalid_argument&) {
      throw;                                 // invalid options: a usage error, not the file's
    } catch (const std::runtime_error& e) {  // LogError: unreadable; its message names it
      summary.rejections.push_back(std::string("unreadable: ") + e.what());
      continue;
    }
    WriteTripodImportReport(report, stem + "_import_report.csv");
    if (data.rows.empty()) {
      summary.rejections.push_back("rejected: " + file + ": no push could be used (" +
                                   std::to_string(report.pushes) + " pushes; see " + stem +
                                   "_import_report.csv)");
      continue;
    }
    WriteWrenchTwistCsv(data, stem + ".csv");
    ++summary.accepted;
    summary.accepted_lines.push_back(
        "accepted " + stem + ".csv from " + file + " (" + std::to_string(data.rows.size()) +
        " of " + std::to_string(report.pushes) + " pushes; report " + stem + "_import_report.csv)");
  }
  // One report per file, each named after its pairs (identify --logs skips them).
  summary.report_path = out_dir + "/*_import_report.csv (one per file)";
  return summary;
}

/// The reader of MIT JSON files that also writes each recording it read as DIR/<stem>.h5,
/// the stems made unique in the order read (as ImportRecordingFile names the logs).
RecordingReader JsonReaderWithH5Copies(const std::string& dir) {
  CreateDirectory(dir);
  auto used = std::make_shared<std::set<std::string>>();
  return [dir, used](const std::string& path) {
    RecordingRead read;
    read.recording = ReadMitPushJson(path);
    std::string stem = std::filesystem::path(path).filename().string();
    if (stem.size() > 5 && stem.compare(stem.size() - 5, 5, ".json") == 0)
      stem.resize(stem.size() - 5);
    std::string name = stem;
    for (int k = 2; used->count(name); ++k) name = stem + "_" + std::to_string(k);
    used->insert(name);
    WriteMitPushH5(read.recording, dir + "/" + name + ".h5");
    return read;
  };
}

ImportSummary ImportFiles(const ImportRequest& request) {
  if (request.format == "mit-push") {
    MitObjectSource objects = request.objects;
    objects.table = request.table.get();
    if (!request.h5_copies_dir.empty()) {
      return ImportRecordingFiles(request.files, JsonReaderWithH5Copies(request.h5_copies_dir),
                                  objects, request.mit, request.out_dir);
    }
    return ImportMitFiles(request.files, objects, request.mit, request.out_dir);
  }
  if (request.format == "rosbag" || request.format == "mcap" || request.format == "mit-push-h5" ||
      request.format == "streams") {
    MitObjectSource objects = request.objects;
    objects.table = request.table.get();
    const RecordingReader read = request.format == "mit-push-h5" ? MitPushH5Reader()
                                 : request.format == "streams"
                                     ? PushStreamsReader(request.streams)
                                     : RosLogReader(request.format, request.ros);
    return ImportRecordingFiles(request.files, read, objects, request.mit, request.out_dir);
  }
  if (request.format == "zhou-tripod") {
    return ImportTripodFiles(request.files, request.tripod, request.out_dir);
  }
  throw std::invalid_argument("unknown import format '" + request.format +
                              "' (mit-push, mit-push-h5, streams, rosbag, mcap or zhou-tripod)");
}

}  // namespace slideid
