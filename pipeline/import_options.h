#pragma once
// The command line of `import-log`: its options declared and read with
// Boost.Program_options. Bad values throw boost::program_options::error naming the option
// (the tool maps that to the usage exit code); a bad --objects table throws the reader's
// error (bad input). Never prints.

#include <boost/program_options.hpp>

#include "pipeline/import_files.h"

namespace slideid::cli {

/// Adds the options of import-log to `options`, and the input files (positional "files")
/// to `hidden`.
void AddImportOptions(boost::program_options::options_description* options,
                      boost::program_options::options_description* hidden);

/// The import the options ask for; reads the --objects table, before any import.
ImportRequest ReadImportOptions(const boost::program_options::variables_map& vm);

}  // namespace slideid::cli
