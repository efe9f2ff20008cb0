#include "io/mit_push_files.h"

#include "io/mit_push_json.h"
#include "io/push_log.h"

namespace slideid {
namespace {

std::string Stem(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  // Only the known extensions: MIT names hold dots ("_t=0.524") that are not one.
  for (const std::string ext : {".json", ".h5", ".hdf5", ".bag", ".mcap", ".csv"}) {
    if (name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0) {
      name.resize(name.size() - ext.size());
      break;
    }
  }
  return name.empty() ? "log" : name;
}

std::string UniqueName(const std::string& stem, std::set<std::string>* used) {
  std::string name = stem + ".csv";
  for (int k = 2; used->count(name); ++k) name = stem + "_" + std::to_string(k) + ".csv";
  used->insert(name);
  return name;
}

/// Fills the slider and patch of `options` for `object`; the missing ones, if any.
std::string ResolveObject(const std::string& object, const MitObjectSource& source,
                          MitImportOptions* options) {
  const ObjectProperties* row = nullptr;
  if (source.table) {
    const auto it = source.table->find(object);
    if (it != source.table->end()) row = &it->second;
  }
  std::string missing;
  auto pick = [&](const std::optional<double>& given, double ObjectProperties::*field,
                  const char* name, double* out) {
    if (given) {
      *out = *given;
    } else if (row) {
      *out = row->*field;
    } else {
      missing += std::string(missing.empty() ? "" : ", ") + name;
    }
  };
  pick(source.mass_kg, &ObjectProperties::mass_kg, "mass", &options->slider.mass_kg);
  pick(source.inertia_kgm2, &ObjectProperties::inertia_kgm2, "inertia",
       &options->slider.inertia_kgm2);
  pick(source.com_height_m, &ObjectProperties::com_height_m, "com_height",
       &options->slider.com_height_m);
  if (source.patch_spec) {
    options->patch_spec = *source.patch_spec;
  } else if (row && !row->patch_spec.empty()) {
    options->patch_spec = row->patch_spec;
  } else {
    missing += std::string(missing.empty() ? "" : ", ") + "patch";
  }
  if (row) options->cm_offset_m = row->cm_offset_m;
  if (row && !row->source.empty())
    options->extra_metadata.emplace_back("object_source", row->source);
  return missing;
}

}  // namespace

MitImportReport ImportMitPushFile(const std::string& path, const MitObjectSource& objects,
                                  MitImportOptions options, const std::string& out_dir,
                                  std::set<std::string>* used_names) {
  const RecordingReader read_json = [](const std::string& file) {
    RecordingRead read;
    read.recording = ReadMitPushJson(file);
    return read;
  };
  return ImportRecordingFile(path, read_json, objects, std::move(options), out_dir, used_names);
}

MitImportReport ImportRecordingFile(const std::string& path, const RecordingReader& read,
                                    const MitObjectSource& objects, MitImportOptions options,
                                    const std::string& out_dir, std::set<std::string>* used_names) {
  MitImportReport failed;
  failed.source = path;
  failed.object = ParseMitPushFileName(path).shape;
  RecordingRead input;
  try {
    input = read(path);
  } catch (const std::runtime_error& e) {  // each reader's error names the file and place
    failed.verdict = ImportVerdict::kUnreadable;
    failed.reason = e.what();
    return failed;
  }
  if (!input.rejection.empty()) {
    failed.reason = input.rejection;
    failed.notes = input.notes;
    return failed;
  }
  const std::string missing = ResolveObject(failed.object, objects, &options);
  if (!missing.empty()) {
    failed.reason = "object '" + (failed.object.empty() ? std::string("?") : failed.object) +
                    "': " + missing +
                    " unknown (give them as options or in an --objects row; "
                    "they are never guessed)";
    return failed;
  }
  MitImportResult result = ImportMitPush(input.recording, path, options);
  result.report.notes.insert(result.report.notes.begin(), input.notes.begin(), input.notes.end());
  if (result.report.verdict == ImportVerdict::kAccepted) {
    const std::string name = UniqueName(Stem(path), used_names);
    const std::string out = out_dir.empty() ? name : out_dir + "/" + name;
    WritePushLog(result.file, out);
    result.report.output = out;
  }
  return result.report;
}

}  // namespace slideid
