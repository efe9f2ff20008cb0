// import-log: convert real push recordings into push logs (docs/real-data.md). One format
// per --format; each file is imported, or rejected with its reason, on its own: a bad file
// never stops the others. Exit codes: 0 every file imported; 1 a file was rejected or
// unreadable (the others are still written); 2 usage; 4 a file could not be written.

#include <iostream>

#include "pipeline/import_options.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

namespace {

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
        "       import-log --format mit-push-h5 --out DIR [object options] FILE.h5...\n"
        "       import-log --format streams --pose FILE[:MAP] --tip FILE[:MAP] --force "
        "FILE[:MAP]\n         --out DIR [object options]\n"
        "       import-log --format rosbag|mcap --object-topic T --tip-topic T --force-topic T\n"
        "         [--object-frame F --tip-frame F] --out DIR [object options] FILE.bag|.mcap...\n"
        "       import-log --format zhou-tripod --out DIR [--mass KG --inertia KG_M2] FILE.txt..."
        "\n\nOptions");
    opts.add_options()("help,h", "print this help and exit")("version",
                                                             "print the version and exit");
    po::options_description hidden;
    cli::AddImportOptions(&opts, &hidden);
    opts.add_options()("quiet,q", "print only rejections and the summary");
    po::options_description all;
    all.add(opts).add(hidden);
    po::positional_options_description positional;
    positional.add("files", -1);
    po::variables_map vm;
    po::store(po::command_line_parser(argc, argv).options(all).positional(positional).run(), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts
                << "\nExit codes: 0 every file imported; 1 a file was rejected or "
                   "unreadable (the others are still\nwritten); 2 usage; 4 a file "
                   "could not be written.\n";
      return tools::FlushStdout("import-log");
    }
    if (vm.count("version")) {
      std::cout << "import-log (slideid) " << SLIDEID_VERSION << "\n";
      return tools::FlushStdout("import-log");
    }
    const ImportRequest request = cli::ReadImportOptions(vm);
    ImportSummary summary;
    try {
      summary = ImportFiles(request);
    } catch (const std::runtime_error& e) {  // an output that cannot be written
      std::cerr << "import-log: error: " << e.what() << "\n";
      return tools::kExitIo;
    }
    return Report(summary, vm.count("quiet") > 0);
  });
}
