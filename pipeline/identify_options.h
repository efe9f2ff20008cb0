#pragma once
// The command line of `identify`: its options declared and read with
// Boost.Program_options. Bad values throw boost::program_options::error naming the option
// (the tool maps that to the usage exit code). Never prints.

#include <boost/program_options.hpp>
#include <string>
#include <vector>

#include "pipeline/batch.h"
#include "pipeline/identify_files.h"

namespace slideid::cli {

/// What identify was asked to do.
struct IdentifyRequest {
  std::vector<std::string> files;  ///< --log (repeatable) and --logs DIR|GLOB, in order
  FileIdentifyOptions options;
  bool json = false;
  bool verbose = false;
  bool strict = false;         ///< a suspect verdict exits with the numerical code
  std::string residuals_path;  ///< --residuals, empty when not asked
  std::string report_path;     ///< --report: the HTML report (pipeline/report_files.h)
  /// --batch: fit each file on its own (files come from --batch DIR|GLOB, sharded) on
  /// `jobs` threads and write JSON lines to `batch_out`.
  bool batch = false;
  int jobs = 1;
  std::string batch_out;
  /// --check: fit nothing; say per log what a fit could identify (estimator/log_check.h).
  bool check = false;
  bool resume = false;  ///< --resume: keep batch_out's lines, fit only the logs they lack
  /// --follow: one log from standard input, a JSON line per `follow_every` rows
  /// (pipeline/follow.h); only the slider overrides apply.
  bool follow = false;
  int follow_every = 1;
  int follow_batch_check_rows = 128;  ///< OnlineOptions::batch_check_first_rows
};

/// Adds every option of identify (general ones to `options`, the rest to `advanced`).
void AddIdentifyOptions(boost::program_options::options_description* options,
                        boost::program_options::options_description* advanced);

/// How to read and identify, from the options (all but the files and the output ones).
/// Rejects options the method ignores, values out of range and conflicting options.
FileIdentifyOptions ReadFileIdentifyOptions(const boost::program_options::variables_map& vm);

/// The request the options make (the files required). Rejects options the method ignores,
/// values out of range and conflicting options.
IdentifyRequest ReadIdentifyOptions(const boost::program_options::variables_map& vm);

}  // namespace slideid::cli
