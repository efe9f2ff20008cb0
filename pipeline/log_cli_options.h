#pragma once
// Command-line options shared by the tools that make logs (simulate, make-dataset): the
// sampling, columns and noise of a log, and the ranges of a dataset. Declares and reads
// Boost.Program_options; never prints. Bad values throw boost::program_options::error
// naming the option (the tools map that to the usage exit code).

#include <boost/program_options.hpp>

#include "datasets/dataset.h"
#include "datasets/log_spec.h"

namespace slideid::cli {

/// Adds --log-every, --wrench, --write, --push-columns, --step-info, --wrap-theta, --noise-*,
/// the push stream's defects --force-bias-x, --force-bias-y, --force-delay and,
/// when `with_seed`, --seed (the noise seed). `defaults`, when given, are quoted in the
/// help text; an option not given leaves the value it overrides unchanged.
void AddLogOptions(boost::program_options::options_description* options, const LogSpec* defaults,
                   bool with_seed);

/// Overrides the fields of `spec` whose options were given.
void ApplyLogOptions(const boost::program_options::variables_map& vm, LogSpec* spec);

/// Adds --count, --seed, --out, the slider and friction ranges, the push-program ranges,
/// --dt, --max-redraws and the log options, each with its default from `defaults`.
void AddDatasetOptions(boost::program_options::options_description* options,
                       const DatasetSpec& defaults);

/// The spec given by the options of AddDatasetOptions (defaults where not given).
DatasetSpec DatasetSpecFromOptions(const boost::program_options::variables_map& vm);

/// A seed: a non-negative integer below 2^64 ("-1" and "1.5" are errors naming `option`).
std::uint64_t ParseSeed(const std::string& text, const std::string& option);

}  // namespace slideid::cli
