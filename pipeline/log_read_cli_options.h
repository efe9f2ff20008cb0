#pragma once
// Command-line options of every tool that reads push logs (identify, predict, validate,
// plot-log, advise-push --log): the slider's properties overriding the logs', the largest
// gap between rows, and what to do with logs as other labs' loggers write them (times
// stamped on arrival, motion-capture dropouts; docs/log-format.md). Declares and reads
// Boost.Program_options; never prints. Bad values throw boost::program_options::error
// naming the option (the tools map that to the usage exit code).

#include <boost/program_options.hpp>

#include "io/push_log.h"

namespace slideid::cli {

/// Adds --mass, --inertia, --com-height and --gravity to `options`, and --max-gap-ratio,
/// --regular-times and --missing-as-gaps to `advanced` (which may be `options`).
void AddLogReadOptions(boost::program_options::options_description* options,
                       boost::program_options::options_description* advanced);

/// The reader's options as given (LogReadOptions' defaults where not given).
LogReadOptions ReadLogReadOptions(const boost::program_options::variables_map& vm);

}  // namespace slideid::cli
