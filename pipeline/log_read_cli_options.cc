#include "pipeline/log_read_cli_options.h"

#include <cmath>
#include <optional>
#include <string>

namespace slideid::cli {
namespace {

namespace po = boost::program_options;

/// The value of a physical option, checked like the log's metadata would be.
std::optional<double> PhysicalOption(const po::variables_map& vm, const char* option,
                                     bool zero_allowed) {
  if (!vm.count(option)) return std::nullopt;
  const double value = vm[option].as<double>();
  if (!std::isfinite(value) || value < 0.0 || (!zero_allowed && value == 0.0)) {
    throw po::error(
        std::string("--") + option + " = " + std::to_string(value) +
        (zero_allowed ? ": must be a finite number >= 0" : ": must be a finite number > 0"));
  }
  return value;
}

}  // namespace

void AddLogReadOptions(po::options_description* options, po::options_description* advanced) {
  options->add_options()("mass", po::value<double>()->value_name("KG"),
                         "slider mass; overrides the logs'")(
      "inertia", po::value<double>()->value_name("KG_M2"),
      "moment of inertia about the vertical axis through the CM; overrides the logs'")(
      "com-height", po::value<double>()->value_name("M"), "CM height; overrides the logs'")(
      "gravity", po::value<double>()->value_name("M_S2"), "gravity; overrides the logs' (9.81)");
  advanced->add_options()(
      "max-gap-ratio",
      po::value<double>()->default_value(LogReadOptions{}.max_gap_ratio)->value_name("R"),
      "an interval between rows longer than R times the median one is an error (the force "
      "is held across it); 0 accepts any gap")(
      "regular-times",
      "put each run's rows on a regular grid (its first time plus k times its mean "
      "interval): for a logger that samples regularly but stamps rows on arrival, whose "
      "jittered times the reader warns of")(
      "missing-as-gaps",
      "drop a row with an empty or NaN cell (a motion-capture dropout) and start a new run "
      "at the next row, instead of failing on it");
}

LogReadOptions ReadLogReadOptions(const po::variables_map& vm) {
  LogReadOptions o;
  o.overrides.mass_kg = PhysicalOption(vm, "mass", false);
  o.overrides.inertia_kgm2 = PhysicalOption(vm, "inertia", false);
  o.overrides.com_height_m = PhysicalOption(vm, "com-height", true);
  o.overrides.gravity_mps2 = PhysicalOption(vm, "gravity", false);
  if (vm.count("max-gap-ratio")) {
    o.max_gap_ratio = vm["max-gap-ratio"].as<double>();
    if (std::isnan(o.max_gap_ratio)) throw po::error("--max-gap-ratio must be a number");
  }
  o.regular_times = vm.count("regular-times") > 0;
  o.missing_as_gaps = vm.count("missing-as-gaps") > 0;
  return o;
}

}  // namespace slideid::cli
