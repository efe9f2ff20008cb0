// import-log: convert real push recordings into push logs (docs/real-data.md). One format
// per --format; each file is imported, or rejected with its reason, on its own: a bad file
// never stops the others. Exit codes: 0 every file imported; 1 a file was rejected or
// unreadable (the others are still written); 2 usage; 4 a file could not be written.

#include <cmath>
#include <filesystem>
#include <iostream>

#include "io/object_table.h"
#include "pipeline/import_files.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

namespace {

std::optional<double> Physical(const po::variables_map& vm, const char* option, bool zero_ok) {
  if (!vm.count(option)) return std::nullopt;
  const double value = vm[option].as<double>();
  if (!std::isfinite(value) || value < 0.0 || (!zero_ok && value == 0.0)) {
    throw po::error(std::string("--") + option + " must be a finite number " + (zero_ok ? ">= 0" : "> 0"));
  }
  return value;
}

MitImportOptions MitOptions(const po::variables_map& vm) {
  MitImportOptions o;
  o.tip_radius_m = vm["tip-radius"].as<double>();
  o.rate_hz = vm["rate"].as<double>();
  o.margin_s = vm["margin"].as<double>();
  o.max_offset_drift_N = vm["max-offset-drift"].as<double>();
  o.max_pose_gap_s = vm["max-pose-gap"].as<double>();
  o.min_push_duration_s = vm["min-push-duration"].as<double>();
  const std::string sign = vm["force-sign"].as<std::string>();
  if (sign == "auto") o.force_sign = ForceSign::kAuto;
  else if (sign == "applied") o.force_sign = ForceSign::kApplied;
  else if (sign == "reaction") o.force_sign = ForceSign::kReaction;
  else throw po::error("--force-sign must be auto, applied or reaction");
  std::string why;
  if (!o.IsValid(&why)) throw po::error("invalid import setting: " + why);
  return o;
}

MitObjectSource Objects(const po::variables_map& vm, ObjectTable* table) {
  MitObjectSource objects;
  objects.mass_kg = Physical(vm, "mass", false);
  objects.inertia_kgm2 = Physical(vm, "inertia", false);
  objects.com_height_m = Physical(vm, "com-height", true);
  if (vm.count("patch")) objects.patch_spec = vm["patch"].as<std::string>();
  if (vm.count("objects")) {
    *table = ReadObjectTable(vm["objects"].as<std::string>());
    objects.table = table;
  } else if (!objects.mass_kg || !objects.inertia_kgm2 || !objects.com_height_m || !objects.patch_spec) {
    throw po::error("the object is not known: give --mass, --inertia, --com-height and --patch, "
                    "or an --objects table (masses are never guessed)");
  }
  return objects;
}

TripodImportOptions TripodOptions(const po::variables_map& vm) {
  TripodImportOptions o;
  o.mass_kg = Physical(vm, "mass", false);
  o.inertia_kgm2 = Physical(vm, "inertia", false);
  o.com_height_m = Physical(vm, "com-height", true);
  std::string why;
  if (!o.IsValid(&why)) throw po::error("invalid import setting: " + why);
  return o;
}

int Report(const ImportSummary& summary, bool quiet) {
  if (!quiet) {
    for (const std::string& line : summary.accepted_lines) std::cout << line << "\n";
  }
  for (const std::string& line : summary.rejections) std::cerr << "import-log: " << line << "\n";
  std::cout << "imported " << summary.accepted << " of " << summary.files << " files; report "
            << summary.report_path << "\n";
  if (const int code = tools::FlushStdout("import-log")) return code;
  if (summary.accepted < summary.files) {
    std::cerr << "import-log: " << summary.files - summary.accepted
              << " file(s) rejected or unreadable (reasons above and in the report)\n";
    return tools::kExitBadInput;
  }
  return tools::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return tools::RunTool("import-log", [&]() -> int {
    po::options_description opts(
        "import-log: convert real push recordings into push logs (docs/real-data.md).\n\n"
        "Usage: import-log --format mit-push --out DIR [--objects FILE | --mass KG --inertia "
        "KG_M2\n         --com-height M --patch SPEC] [options] FILE.json...\n"
        "       import-log --format zhou-tripod --out DIR [--mass KG --inertia KG_M2] FILE.txt..."
        "\n\nOptions");
    opts.add_options()
        ("help,h", "print this help and exit")
        ("version", "print the version and exit")
        ("format", po::value<std::string>()->value_name("NAME"), "mit-push (MIT push dataset JSON: push logs) or zhou-tripod (ICRA 2016 tripod logs: wrench-twist pairs)")
        ("out", po::value<std::string>()->value_name("DIR"),
         "output directory: one DIR/<stem>.csv per accepted file and DIR/import_report.csv")
        ("objects", po::value<std::string>()->value_name("FILE"),
         "CSV table name,mass,inertia,com_height[,patch,source] by object name (shape=NAME)")
        ("mass", po::value<double>()->value_name("KG"), "object mass (overrides the table)")
        ("inertia", po::value<double>()->value_name("KG_M2"),
         "moment of inertia about the vertical axis through the CM (overrides the table)")
        ("com-height", po::value<double>()->value_name("M"), "CM height (overrides the table)")
        ("patch", po::value<std::string>()->value_name("SPEC"),
         "object outline = contact patch, e.g. \"rectangle 0.09 0.09\" (overrides the table)")
        ("tip-radius", po::value<double>()->default_value(0.00475)->value_name("M"), "pusher radius")
        ("rate", po::value<double>()->default_value(100.0)->value_name("HZ"), "rows per second")
        ("margin", po::value<double>()->default_value(0.05)->value_name("S"),
         "kept before and after the push")
        ("max-offset-drift", po::value<double>()->default_value(0.5)->value_name("N"),
         "reject a file whose force offsets before and after the push differ by more")
        ("max-pose-gap", po::value<double>()->default_value(0.05)->value_name("S"),
         "reject a file with a longer gap between object poses inside the push")
        ("min-push-duration", po::value<double>()->default_value(0.2)->value_name("S"),
         "reject a shorter push")
        ("force-sign", po::value<std::string>()->default_value("auto"),
         "auto (per file, from the contact normal), applied or reaction (stored = -force)")
        ("quiet,q", "print only rejections and the summary");
    po::options_description hidden;
    hidden.add_options()("files", po::value<std::vector<std::string>>());
    po::options_description all;
    all.add(opts).add(hidden);
    po::positional_options_description positional;
    positional.add("files", -1);
    po::variables_map vm;
    po::store(po::command_line_parser(argc, argv).options(all).positional(positional).run(), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts << "\nExit codes: 0 every file imported; 1 a file was rejected or "
                           "unreadable (the others are still\nwritten); 2 usage; 4 a file "
                           "could not be written.\n";
      return tools::FlushStdout("import-log");
    }
    if (vm.count("version")) {
      std::cout << "import-log (slideid) " << SLIDEID_VERSION << "\n";
      return tools::FlushStdout("import-log");
    }
    if (!vm.count("format")) throw po::error("the option '--format' is required");
    if (!vm.count("out")) throw po::error("the option '--out' is required");
    if (!vm.count("files")) throw po::error("no input FILE given");
    const std::string format = vm["format"].as<std::string>();
    const auto files = vm["files"].as<std::vector<std::string>>();
    const std::string dir = vm["out"].as<std::string>();
    if (format != "mit-push" && format != "zhou-tripod") {
      throw po::error("--format must be mit-push or zhou-tripod");
    }
    ObjectTable table;  // read before any import: a bad table is bad input, not I/O
    const bool mit = format == "mit-push";
    const MitObjectSource objects = mit ? Objects(vm, &table) : MitObjectSource{};
    const MitImportOptions mit_options = mit ? MitOptions(vm) : MitImportOptions{};
    const TripodImportOptions tripod_options = mit ? TripodImportOptions{} : TripodOptions(vm);
    ImportSummary summary;
    try {
      summary = mit ? ImportMitFiles(files, objects, mit_options, dir)
                    : ImportTripodFiles(files, tripod_options, dir);
    } catch (const std::runtime_error& e) {  // an output that cannot be written
      std::cerr << "import-log: error: " << e.what() << "\n";
      return tools::kExitIo;
    }
    return Report(summary, vm.count("quiet") > 0);
  });
}
