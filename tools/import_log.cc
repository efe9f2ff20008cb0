// import-log: convert real push recordings into push logs (docs/real-data.md). One format
// per --format; each file is imported, or rejected with its reason, on its own: a bad file
// never stops the others. Exit codes: 0 every file imported; 1 a file was rejected or
// unreadable (the others are still written); 2 usage; 4 a file could not be written.

#include <cmath>
#include <filesystem>
#include <iostream>
#include <set>

#include "io/mit_push_files.h"
#include "io/mit_push_report.h"
#include "io/object_table.h"
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

int ImportMitPushFiles(const po::variables_map& vm) {
  const MitImportOptions options = MitOptions(vm);
  MitObjectSource objects;
  objects.mass_kg = Physical(vm, "mass", false);
  objects.inertia_kgm2 = Physical(vm, "inertia", false);
  objects.com_height_m = Physical(vm, "com-height", true);
  if (vm.count("patch")) objects.patch_spec = vm["patch"].as<std::string>();
  ObjectTable table;
  if (vm.count("objects")) {
    table = ReadObjectTable(vm["objects"].as<std::string>());
    objects.table = &table;
  } else if (!objects.mass_kg || !objects.inertia_kgm2 || !objects.com_height_m || !objects.patch_spec) {
    throw po::error("the object is not known: give --mass, --inertia, --com-height and --patch, "
                    "or an --objects table (masses are never guessed)");
  }
  const std::string dir = vm["out"].as<std::string>();
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    std::cerr << "import-log: error: cannot create '" << dir << "': " << error.message() << "\n";
    return tools::kExitIo;
  }
  std::vector<MitImportReport> reports;
  std::set<std::string> used_names{"import_report.csv"};
  try {
    for (const std::string& file : vm["files"].as<std::vector<std::string>>()) {
      reports.push_back(ImportMitPushFile(file, objects, options, dir, &used_names));
      const MitImportReport& r = reports.back();
      if (r.verdict == ImportVerdict::kAccepted) {
        if (!vm.count("quiet")) {
          std::cout << "accepted " << r.output << " (" << r.rows << " rows"
                    << (r.force_flipped ? ", force flipped" : "") << ")\n";
        }
      } else {
        // An unreadable file's reason starts with its name (and line, column or JSON path).
        std::cerr << "import-log: " << ToString(r.verdict) << ": "
                  << (r.verdict == ImportVerdict::kUnreadable ? "" : file + ": ") << r.reason << "\n";
      }
    }
    WriteMitImportReport(reports, dir + "/import_report.csv");
  } catch (const std::runtime_error& e) {
    std::cerr << "import-log: error: " << e.what() << "\n";
    return tools::kExitIo;
  }
  int accepted = 0;
  for (const MitImportReport& r : reports) accepted += r.verdict == ImportVerdict::kAccepted;
  std::cout << "imported " << accepted << " of " << reports.size() << " files; report "
            << dir << "/import_report.csv\n";
  if (const int code = tools::FlushStdout("import-log")) return code;
  if (accepted < static_cast<int>(reports.size())) {
    std::cerr << "import-log: " << reports.size() - accepted
              << " file(s) rejected or unreadable (reasons above and in the report)\n";
    return tools::kExitBadInput;
  }
  return tools::kExitOk;
}

/// Hook for the Zhou et al. tripod logs (an importer in io/ still to come).
int ImportZhouTripodFiles(const po::variables_map&) {
  std::cerr << "import-log: --format zhou-tripod is not yet available\n";
  return tools::kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  return tools::RunTool("import-log", [&]() -> int {
    po::options_description opts(
        "import-log: convert real push recordings into push logs (docs/real-data.md).\n\n"
        "Usage: import-log --format mit-push --out DIR [--objects FILE | --mass KG --inertia "
        "KG_M2\n         --com-height M --patch SPEC] [options] FILE.json...\n\nOptions");
    opts.add_options()
        ("help,h", "print this help and exit")
        ("version", "print the version and exit")
        ("format", po::value<std::string>()->value_name("NAME"), "mit-push (zhou-tripod: to come)")
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
    if (format == "mit-push") return ImportMitPushFiles(vm);
    if (format == "zhou-tripod") return ImportZhouTripodFiles(vm);
    throw po::error("--format must be mit-push or zhou-tripod");
  });
}
