#pragma once
// import-log's work on a set of files, one format at a time: each file imported into the
// output directory, or rejected with its reason, on its own (a bad file never stops the
// others), and the import report written beside them.

#include <memory>
#include <string>
#include <vector>

#include "io/mit_push_files.h"
#include "io/object_table.h"
#include "io/push_streams_csv.h"
#include "io/ros_push_log.h"
#include "io/zhou_tripod_import.h"

namespace slideid {

/// What happened, for the tool to print.
struct ImportSummary {
  int files = 0;
  int accepted = 0;
  std::vector<std::string> accepted_lines;  ///< "accepted DIR/x.csv (61 rows)" per file
  std::vector<std::string> rejections;      ///< one line per rejected or unreadable file
  /// Where the report went: DIR/import_report.csv (mit-push), or DIR/*_import_report.csv,
  /// one beside each file's pairs (zhou-tripod); identify --logs skips both kinds.
  std::string report_path;
};

/// MIT push JSON files into DIR/<stem>.csv push logs. Throws std::runtime_error naming a
/// path that cannot be written.
ImportSummary ImportMitFiles(const std::vector<std::string>& files, const MitObjectSource& objects,
                             const MitImportOptions& options, const std::string& out_dir);

/// Push recordings of any format, each read by `read`, imported as ImportMitFiles does.
ImportSummary ImportRecordingFiles(const std::vector<std::string>& files,
                                   const RecordingReader& read, const MitObjectSource& objects,
                                   const MitImportOptions& options, const std::string& out_dir);

/// The reader of ROS logs, `format` "rosbag" (ROS 1 bags) or "mcap" (ROS 2 MCAP files): the
/// streams on `topics`, the report's notes, and a rejection when their clocks never
/// overlap. Throws std::invalid_argument for another format.
RecordingReader RosLogReader(const std::string& format, const RosTopics& topics);

/// The reader of the MIT push dataset's HDF5 files (io/mit_push_h5.h).
RecordingReader MitPushH5Reader();

/// The reader of a push as one CSV file per stream (io/push_streams_csv.h): it reads the
/// three files of `files` whatever path it is given (the pose file's, which names the push),
/// with a note naming them and a rejection when their clocks never overlap.
RecordingReader PushStreamsReader(const PushStreamsCsv& files);

/// Zhou tripod logs into DIR/<stem>.csv wrench-twist pairs (one row per accepted push) and
/// DIR/<stem>_import_report.csv (one row per push). A file is rejected when it cannot be read or
/// has no acceptable push. Throws std::runtime_error naming a path that cannot be written.
ImportSummary ImportTripodFiles(const std::vector<std::string>& files,
                                const TripodImportOptions& options, const std::string& out_dir);

/// One import: the format, the files, where to and how (import-log's options, or the
/// Python module's import_log).
struct ImportRequest {
  /// "mit-push", "mit-push-h5", "streams", "rosbag", "mcap" or "zhou-tripod"
  std::string format;
  std::vector<std::string> files;  ///< streams: the pose file (named by `streams`)
  std::string out_dir;
  std::shared_ptr<const ObjectTable> table;  ///< mit-push: the --objects table, if any
  /// the push formats (all but zhou-tripod); its table pointer is set from `table`
  MitObjectSource objects;
  MitImportOptions mit;    ///< the push formats
  RosTopics ros;           ///< rosbag and mcap: the streams' topics and frames
  PushStreamsCsv streams;  ///< streams: the three files and their mappings
  /// mit-push, for checks (scripts/real_data.sh): each JSON file read is also written, by
  /// our HDF5 writer, as DIR/<stem>.h5 (stems made unique as the logs' names are), so that
  /// importing those with mit-push-h5 must give the same logs. Empty: none.
  std::string h5_copies_dir;
  TripodImportOptions tripod;
};

/// Runs ImportMitFiles, ImportRecordingFiles (mit-push-h5, streams, rosbag, mcap) or
/// ImportTripodFiles. Throws
/// std::invalid_argument for an unknown format, std::runtime_error naming a path that cannot be
/// written.
ImportSummary ImportFiles(const ImportRequest& request);

}  // namespace slideid
