#include "pipeline/log_cli_options.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>

#include "forward_model/number_format.h"

namespace slideid::cli {
namespace {

namespace po = boost::program_options;

std::string G(double v) { return Printf("%g", v); }

/// " (default: X)" when there are defaults to quote.
std::string Default(const LogSpec* d, const std::string& value) {
  return d ? " (default: " + value + ")" : "";
}

/// One --noise-* option: its name, the NoiseSpec field and its help.
struct NoiseOption {
  const char* name;
  double NoiseSpec::*field;
  const char* help;
};
const NoiseOption kNoiseOptions[] = {
    {"noise-pose", &NoiseSpec::pose_m, "Gaussian std of x, y [m]"},
    {"noise-angle", &NoiseSpec::angle_rad, "Gaussian std of theta [rad]"},
    {"noise-velocity", &NoiseSpec::velocity_mps, "Gaussian std of vx, vy [m/s]"},
    {"noise-spin", &NoiseSpec::spin_radps, "Gaussian std of wz [rad/s]"},
    {"noise-force-relative", &NoiseSpec::force_relative,
     "Gaussian std of fx, fy as a fraction of the force"},
    {"noise-force", &NoiseSpec::force_n, "Gaussian std of fx, fy [N]"},
    {"noise-push-point", &NoiseSpec::push_point_m, "Gaussian std of px, py [m]"},
    {"noise-outlier-fraction", &NoiseSpec::outlier_fraction,
     "fraction of rows whose pose jumps (motion-capture glitch)"},
    {"noise-outlier", &NoiseSpec::outlier_m, "size of such a jump [m]"},
    {"force-bias-x", &NoiseSpec::force_bias_x_n,
     "constant offset of the force channel's fx, also at rest [N] (any sign)"},
    {"force-bias-y", &NoiseSpec::force_bias_y_n,
     "constant offset of the force channel's fy, also at rest [N] (any sign)"},
    {"force-delay", &NoiseSpec::force_delay_s,
     "delay of the push stream against the poses: the force logged at t is the one at "
     "t - S [s] (negative: it leads)"},
};

ValueRange RangeOption(const po::variables_map& vm, const char* name) {
  try {
    return ParseRange(vm[name].as<std::string>(), std::string("--") + name);
  } catch (const std::invalid_argument& e) {
    throw po::error(e.what());
  }
}

/// A "LO:HI" option with its default shown.
void AddRange(po::options_description* o, const char* name, const ValueRange& d, const char* help) {
  o->add_options()(name, po::value<std::string>()->default_value(ToString(d))->value_name("LO:HI"),
                   help);
}

}  // namespace

std::uint64_t ParseSeed(const std::string& text, const std::string& option) {
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || *end != '\0' ||
      errno == ERANGE) {
    throw po::error("--" + option + ": '" + text + "' is not an integer in [0, 2^64)");
  }
  return v;
}

void AddLogOptions(po::options_description* o, const LogSpec* d, bool with_seed) {
  o->add_options()(
      "log-every", po::value<int>()->value_name("K"),
      ("log every K-th simulated step, e.g. dt 1e-4 s and K = 100 for a 100 Hz log; a row's "
       "force is the one --wrench says" +
       Default(d, d ? std::to_string(d->log_every) : ""))
          .c_str())(
      "wrench", po::value<std::string>()->value_name("WHICH"),
      ("a row's wrench: at-row-time (the one applied at its time) or interval-mean (the mean "
       "over its log interval; needs --push-columns moments)" +
       Default(d, d ? ToString(d->wrench) : ""))
          .c_str())("write", po::value<std::string>()->value_name("WHAT"),
                    ("motion columns: poses (motion capture), velocities or both" +
                     Default(d, d ? ToString(d->motion) : ""))
                        .c_str())(
      "push-columns", po::value<std::string>()->value_name("HOW"),
      ("push as point (fx, fy, px, py, pz) or moments (fx, fy, tx, ty, tz)" +
       Default(d, d ? ToString(d->push) : ""))
          .c_str())(
      "step-info", po::value<std::string>()->value_name("yes|no"),
      "write the simulator's ECP, impulses, sigma and mode (default: only without noise)")(
      "wrap-theta", "write theta wrapped to (-pi, pi] (noise is added before wrapping)");
  for (const NoiseOption& n : kNoiseOptions) {
    o->add_options()(n.name, po::value<double>()->value_name("X"),
                     (std::string(n.help) + Default(d, d ? G(d->noise.*n.field) : "")).c_str());
  }
  if (with_seed) {
    o->add_options()("seed", po::value<std::string>()->value_name("S"),
                     "seed of the noise: the same seed gives the same file, byte for byte");
  }
}

void ApplyLogOptions(const po::variables_map& vm, LogSpec* spec) {
  if (vm.count("log-every")) spec->log_every = vm["log-every"].as<int>();
  if (vm.count("write") && !ParseLogMotion(vm["write"].as<std::string>(), &spec->motion)) {
    throw po::error("--write: '" + vm["write"].as<std::string>() +
                    "' is not poses, velocities or both");
  }
  if (vm.count("push-columns") &&
      !ParseLogPush(vm["push-columns"].as<std::string>(), &spec->push)) {
    throw po::error("--push-columns: '" + vm["push-columns"].as<std::string>() +
                    "' is not point or moments");
  }
  if (vm.count("wrench") && !ParseLogWrench(vm["wrench"].as<std::string>(), &spec->wrench)) {
    throw po::error("--wrench: '" + vm["wrench"].as<std::string>() +
                    "' is not at-row-time or interval-mean");
  }
  if (vm.count("step-info")) {
    const std::string v = vm["step-info"].as<std::string>();
    if (v != "yes" && v != "no") throw po::error("--step-info: '" + v + "' is not yes or no");
    spec->step_info = v == "yes";
  }
  if (vm.count("wrap-theta")) spec->wrap_theta = true;
  for (const NoiseOption& n : kNoiseOptions) {
    if (vm.count(n.name)) spec->noise.*n.field = vm[n.name].as<double>();
  }
  if (vm.count("seed")) spec->noise.seed = ParseSeed(vm["seed"].as<std::string>(), "seed");
  std::string why;
  if (!spec->IsValid(&why)) throw po::error(why);
}

void AddDatasetOptions(po::options_description* o, const DatasetSpec& d) {
  o->add_options()("count", po::value<int>()->default_value(d.count)->value_name("N"),
                   "number of logs")(
      "seed", po::value<std::string>()->default_value(std::to_string(d.seed))->value_name("S"),
      "seed of every draw (sliders, friction, programs, noise): same seed, same files")(
      "out", po::value<std::string>()->value_name("DIR"),
      "directory for log_0000.csv ... and truth.csv (created if missing; required)");
  AddRange(o, "mass-range", d.mass_kg, "slider mass [kg]");
  o->add_options()("inertia-range", po::value<std::string>()->value_name("LO:HI"),
                   "moment of inertia about the vertical axis [kg m^2] (default: that of a "
                   "uniform slider over the drawn patch, e.g. m (W^2 + L^2) / 12)");
  AddRange(o, "com-height-range", d.com_height_m, "CM height above the support plane [m]");
  o->add_options()("patch",
                   po::value<std::string>()->default_value(d.patch.ToString())->value_name("SHAPE"),
                   "contact patch: 'rectangle W L', 'disk R', 'ring R r' or 'polygon x1 y1 "
                   "...' [m], each number a value or a range LO:HI");
  AddRange(o, "mu-range", d.mu, "friction coefficient mu");
  AddRange(o, "e-t-range", d.e_t, "ellipsoid constant e_t");
  AddRange(o, "e-o-range", d.e_o, "ellipsoid constant e_o");
  AddRange(o, "e-r-range", d.e_r_m, "ellipsoid constant e_r [m]");
  o->add_options()("pushes", po::value<int>()->default_value(d.program.count)->value_name("N"),
                   "pushes in each log's random program");
  o->add_options()("force-range", po::value<std::string>()->value_name("LO:HI"),
                   "constant part of each push [N] (default: 1.1:1.6 times the sliding limit "
                   "e_t mu m g of the drawn slider)");
  AddRange(o, "amplitude-range", d.program.amplitude_fraction,
           "cosine amplitude as a fraction of the constant part");
  AddRange(o, "period-range", d.program.period_s, "cosine period [s]");
  AddRange(o, "push-duration-range", d.program.duration_s, "duration of each push [s]");
  AddRange(o, "rest-range", d.program.rest_s, "rest after each push [s]");
  o->add_options()("height-range", po::value<std::string>()->value_name("LO:HI"),
                   "height of the push point [m] (default: 0.25:0.75 times the drawn CM height)")(
      "spread",
      po::value<double>()
          ->default_value(d.program.spread_rad, G(d.program.spread_rad))
          ->value_name("RAD"),
      "push directions within this angle [rad] of the direction to the CM")(
      "max-lever",
      po::value<double>()
          ->default_value(d.program.max_lever_fraction, G(d.program.max_lever_fraction))
          ->value_name("F"),
      "largest distance of a push's line of action from the CM, as a fraction of the patch "
      "radius (pushes turn with the slider: a long lever spins it up)")(
      "through-cm", "aim every push at the CM at CM height: no rotation (c not identifiable)")(
      "unaligned-pushes",
      "let pushes start and stop between log samples (default: on "
      "them, as a pusher commanded at the log rate)")(
      "dt", po::value<double>()->default_value(d.dt_s, G(d.dt_s))->value_name("S"),
      "simulation step [s]")(
      "max-redraws", po::value<int>()->default_value(d.max_redraws)->value_name("N"),
      "redraws allowed per log when a draw tips the slider (ECP leaves the patch hull)")(
      "drive", po::value<std::string>()->default_value("force"),
      "force: each log a random program of force pushes; pusher: each log one straight push "
      "by a round tip (4.75 mm) from a random heading and offset, its path in the log "
      "(tip_x, tip_y)");
  const PusherDraw p;
  AddRange(o, "mu-pusher-range", p.mu, "pusher drive: tip-edge friction mu_p");
  AddRange(o, "tip-speed-range", p.speed_mps, "pusher drive: tip speed [m/s]");
  AddRange(o, "push-distance-range", p.distance_m,
           "pusher drive: distance pushed after the tip meets the slider [m]");
  AddLogOptions(o, &d.log, /*with_seed=*/false);
}

DatasetSpec DatasetSpecFromOptions(const po::variables_map& vm) {
  DatasetSpec s;
  s.count = vm["count"].as<int>();
  s.seed = ParseSeed(vm["seed"].as<std::string>(), "seed");
  s.mass_kg = RangeOption(vm, "mass-range");
  if (vm.count("inertia-range")) s.inertia_kgm2 = RangeOption(vm, "inertia-range");
  s.com_height_m = RangeOption(vm, "com-height-range");
  try {
    s.patch = PatchRange::Parse(vm["patch"].as<std::string>());
  } catch (const std::invalid_argument& e) {
    throw po::error(e.what());
  }
  s.mu = RangeOption(vm, "mu-range");
  s.e_t = RangeOption(vm, "e-t-range");
  s.e_o = RangeOption(vm, "e-o-range");
  s.e_r_m = RangeOption(vm, "e-r-range");
  s.program.count = vm["pushes"].as<int>();
  if (vm.count("force-range")) s.program.force_n = RangeOption(vm, "force-range");
  s.program.amplitude_fraction = RangeOption(vm, "amplitude-range");
  s.program.period_s = RangeOption(vm, "period-range");
  s.program.duration_s = RangeOption(vm, "push-duration-range");
  s.program.rest_s = RangeOption(vm, "rest-range");
  if (vm.count("height-range")) s.program.height_m = RangeOption(vm, "height-range");
  s.program.spread_rad = vm["spread"].as<double>();
  s.program.max_lever_fraction = vm["max-lever"].as<double>();
  s.program.through_cm = vm.count("through-cm") > 0;
  s.align_pushes = vm.count("unaligned-pushes") == 0;
  s.dt_s = vm["dt"].as<double>();
  s.max_redraws = vm["max-redraws"].as<int>();
  const std::string drive = vm["drive"].as<std::string>();
  if (drive == "pusher") {
    PusherDraw p;
    p.mu = RangeOption(vm, "mu-pusher-range");
    p.speed_mps = RangeOption(vm, "tip-speed-range");
    p.distance_m = RangeOption(vm, "push-distance-range");
    s.pusher = p;
  } else if (drive != "force") {
    throw po::error("--drive must be force or pusher");
  }
  ApplyLogOptions(vm, &s.log);
  std::string why;
  if (!s.IsValid(&why)) throw po::error(why);
  return s;
}

}  // namespace slideid::cli
