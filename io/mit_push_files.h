#pragma once
// One MIT push file in, one push log out: read the JSON (io/mit_push_json.h), find the
// object's properties, import (io/mit_push_import.h) and write DIR/<stem>.csv. What
// `import-log --format mit-push` does for each of its files.

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "io/mit_push_import.h"
#include "io/object_table.h"

namespace slideid {

/// Where an imported file's object properties come from: the given values, else the
/// table's row for the object named in the file name ("shape=rect1"). Never a default.
struct MitObjectSource {
  const ObjectTable* table = nullptr;  ///< not owned; may be null
  std::optional<double> mass_kg, inertia_kgm2, com_height_m;
  std::optional<std::string> patch_spec;
};

/// Imports `path` into `out_dir` with `options` (whose slider and patch are replaced by
/// those `objects` gives). The log is `out_dir/<stem>.csv`, where <stem> is the file name
/// without ".json", made unique against `used_names` (then added to it). A file that cannot
/// be read is reported kUnreadable; an object whose properties are not all known, or a
/// failed check, kRejected. Throws std::runtime_error only when the log cannot be written.
MitImportReport ImportMitPushFile(const std::string& path, const MitObjectSource& objects,
                                  MitImportOptions options, const std::string& out_dir,
                                  std::set<std::string>* used_names);

/// One recording as a reader of any format found it: the streams, facts for the report's
/// notes (e.g. stamps replaced by receive times), and a reason found while reading to reject
/// it (empty: none; e.g. streams whose clocks never overlap, named by topic).
struct RecordingRead {
  MitPushRecording recording;
  std::vector<std::string> notes;
  std::string rejection;
};

/// Reads the file at a path. Throws std::runtime_error (its message names the file and the
/// place in it) when the file cannot be read: the file is then reported kUnreadable.
using RecordingReader = std::function<RecordingRead(const std::string& path)>;

/// ImportMitPushFile for a file of any format that `read` reads; <stem> is its name without
/// the extension .json, .h5, .hdf5, .bag, .mcap or .csv (streams: the pose file's).
MitImportReport ImportRecordingFile(const std::string& path, const RecordingReader& read,
                                    const MitObjectSource& objects, MitImportOptions options,
                                    const std::string& out_dir, std::set<std::string>* used_names);

}  // namespace slideid
