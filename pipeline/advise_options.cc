#include "pipeline/advise_options.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "datasets/dataset.h"
#include "forward_model/number_format.h"
#include "io/push_advice_report.h"
#include "io/push_log.h"
#include "io/result_json.h"
#include "pipeline/friction_file.h"

namespace slideid::cli {
namespace po = boost::program_options;

namespace {

double Positive(const po::variables_map& vm, const char* name) {
  const double v = vm[name].as<double>();
  if (!(v > 0 && std::isfinite(v))) {
    throw po::error(std::string("--") + name + " must be > 0, not " + ShortNumber(v));
  }
  return v;
}

PriorRange RangeOption(const po::variables_map& vm, const char* name) {
  ValueRange r;
  try {
    r = ParseRange(vm[name].as<std::string>(), std::string("--") + name);
  } catch (const std::invalid_argument& e) {
    throw po::error(e.what());
  }
  if (!(r.lo > 0 && r.hi > r.lo && std::isfinite(r.hi))) {
    throw po::error(std::string("--") + name + " must be LO:HI with 0 < LO < HI");
  }
  return {r.lo, r.hi};
}

/// A comma-separated list of numbers.
std::vector<double> List(const po::variables_map& vm, const char* name) {
  std::vector<double> out;
  std::stringstream in(vm[name].as<std::string>());
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (item.find_first_not_of(" ", used) != std::string::npos) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw po::error(std::string("--") + name + ": not a number: '" + item + "'");
    }
  }
  if (out.empty()) throw po::error(std::string("--") + name + " needs at least one number");
  return out;
}

}  // namespace

void AddAdviseOptions(po::options_description* options) {
  options->add_options()(
      "friction", po::value<std::string>()->value_name("RESULT.json"),
      "what is known: identify --json's result (a, b, c with their standard errors; "
      "without it, the prior below)")(
      "log", po::value<std::vector<std::string>>()->value_name("PUSH.csv"),
      "a log the result was fitted to (repeat for each): their information at the estimate "
      "gives the correlations of a, b, c, which a result file does not hold (needs "
      "--friction)")(
      "patch", po::value<std::string>()->value_name("SPEC"),
      "the slider's contact patch, \"rectangle W L\", \"disk R\", \"ring R R_IN\" or "
      "\"polygon x1 y1 ...\" [m] (required)")(
      "mass", po::value<double>()->default_value(1.0)->value_name("KG"), "the slider's mass [kg]")(
      "inertia", po::value<double>()->value_name("KG_M2"),
      "its moment of inertia about the CM [kg m^2] (default: a uniform slab over the patch)")(
      "com-height", po::value<double>()->default_value(0.0)->value_name("M"),
      "its CM's height above the support [m]")("candidates",
                                               po::value<int>()->default_value(10)->value_name("N"),
                                               "how many of the best pushes to print (0: all)")(
      "criterion", po::value<std::string>()->default_value("least-known"),
      "least-known (the largest relative standard error after the push, smallest first) "
      "or d-optimal (the determinant of the covariance after it)")(
      "mu-pusher", po::value<double>()->value_name("MU_P"),
      "tip-edge friction bounding the push directions' cone (default: the result's "
      "mu_pusher, else 0.25)")(
      "pose-noise", po::value<double>()->value_name("M"),
      "standard deviation of each logged pose coordinate [m] (default: the result's "
      "residual RMS per coordinate, else 0.0003)")(
      "rate", po::value<double>()->default_value(100.0)->value_name("HZ"), "the log's rate [Hz]")(
      "contact-points", po::value<int>()->default_value(16)->value_name("N"),
      "contact points, equally spaced along the outline")(
      "cone-fractions", po::value<std::string>()->default_value("-0.8,-0.4,0,0.4,0.8"),
      "push directions at each point, as fractions of the friction cone's half-angle "
      "atan(mu_p) from the inward normal")(
      "lengths", po::value<std::string>()->default_value("0.03,0.055,0.08")->value_name("M,..."),
      "tip travel after touching [m]")(
      "tip-speed", po::value<double>()->default_value(0.05, "0.05")->value_name("MPS"),
      "tip speed [m/s]")("tip-radius",
                         po::value<double>()->default_value(0.00475, "0.00475")->value_name("M"),
                         "tip radius [m]")(
      "prior-a", po::value<std::string>()->default_value("0.1:1")->value_name("LO:HI"),
      "prior 95% range of a (used without --friction, or where the result does not identify a)")(
      "prior-b", po::value<std::string>()->default_value("0.5:2")->value_name("LO:HI"),
      "prior 95% range of b")(
      "prior-c", po::value<std::string>()->value_name("LO:HI"),
      "prior 95% range of c [m] (default: 0.1 to 1 times the outline's largest distance "
      "from the CM)")("threads", po::value<int>()->default_value(1)->value_name("N"),
                      "candidates simulated at once");
}

AdviseRequest ReadAdviseOptions(const po::variables_map& vm) {
  AdviseRequest r;
  if (!vm.count("patch")) throw po::error("the option '--patch' is required");
  try {
    r.patch = ContactPatch::Parse(vm["patch"].as<std::string>());
  } catch (const std::invalid_argument& e) {
    throw po::error(std::string("--patch: ") + e.what());
  }
  r.slider.mass_kg = Positive(vm, "mass");
  r.slider.inertia_kgm2 =
      vm.count("inertia") ? Positive(vm, "inertia") : UniformInertia(r.patch, r.slider.mass_kg);
  if (!(r.slider.inertia_kgm2 > 0 && std::isfinite(r.slider.inertia_kgm2))) {
    // A patch of 1e300 m (or a mass of 1e300 kg) overflows the slab's inertia: every
    // candidate then failed on NaN contact points.
    throw po::error("--patch and --mass give a uniform slab's inertia of " +
                    ShortNumber(r.slider.inertia_kgm2) + " kg m^2: give --inertia");
  }
  r.slider.com_height_m = vm["com-height"].as<double>();
  if (!(r.slider.com_height_m >= 0 && std::isfinite(r.slider.com_height_m))) {
    throw po::error("--com-height must be >= 0");
  }
  r.top = vm["candidates"].as<int>();
  if (r.top < 0) throw po::error("--candidates must be >= 0");
  if (!ParseAdviceCriterion(vm["criterion"].as<std::string>(), &r.options.criterion)) {
    throw po::error("--criterion must be least-known or d-optimal, not '" +
                    vm["criterion"].as<std::string>() + "'");
  }
  FrictionPrior prior;
  prior.a = RangeOption(vm, "prior-a");
  prior.b = RangeOption(vm, "prior-b");
  if (vm.count("prior-c")) {
    const PriorRange c = RangeOption(vm, "prior-c");
    double reach = 0;
    for (const Eigen::Vector2d& p : r.patch.Outline()) reach = std::max(reach, p.norm());
    prior.c_fraction = {c.lo / reach, c.hi / reach};
  }
  r.knowledge = KnowledgeFromPrior(prior, r.patch);
  r.noise_from = "default";
  r.mu_pusher_from = "default";
  if (vm.count("friction")) {
    const std::string path = vm["friction"].as<std::string>();
    const std::string text = ReadFrictionFile(path);
    AdviceResultInput result;
    try {
      result = ParseAdviceResult(text);
      r.knowledge = KnowledgeFromResult(result.result, r.knowledge);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(path + ": " + e.what());
    }
    if (result.pose_noise_m) {
      r.options.pose_noise_m = *result.pose_noise_m;
      r.noise_from = "the result's residuals";
    }
    if (result.mu_pusher) {
      r.options.candidates.mu_pusher = *result.mu_pusher;
      r.mu_pusher_from = "the result";
    }
  }
  if (vm.count("pose-noise")) {
    r.options.pose_noise_m = Positive(vm, "pose-noise");
    r.noise_from = "--pose-noise";
  }
  if (vm.count("log")) {
    if (!vm.count("friction")) throw po::error("--log needs --friction (the result fitted to it)");
    Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
    for (const std::string& path : vm["log"].as<std::vector<std::string>>()) {
      const Trajectory log = ReadPushLog(path);
      information += LogInformation(log, r.knowledge.estimate, r.options.pose_noise_m);
    }
    r.knowledge = WithCorrelations(r.knowledge, information);
    r.correlations_from =
        std::to_string(vm["log"].as<std::vector<std::string>>().size()) + " log(s)";
  }
  if (vm.count("mu-pusher")) {
    r.options.candidates.mu_pusher = vm["mu-pusher"].as<double>();
    r.mu_pusher_from = "--mu-pusher";
    if (!(r.options.candidates.mu_pusher >= 0)) throw po::error("--mu-pusher must be >= 0");
  }
  r.options.log_rate_hz = Positive(vm, "rate");
  r.options.candidates.contact_points = vm["contact-points"].as<int>();
  // The upper limit keeps a run finite: each point is simulated for every direction and length.
  if (r.options.candidates.contact_points < 1 || r.options.candidates.contact_points > 1000) {
    throw po::error("--contact-points must be 1 to 1000");
  }
  r.options.candidates.cone_fractions = List(vm, "cone-fractions");
  for (double f : r.options.candidates.cone_fractions) {
    if (!(f >= -1 && f <= 1)) throw po::error("--cone-fractions must each lie in [-1, 1]");
  }
  r.options.candidates.lengths_m = List(vm, "lengths");
  for (double l : r.options.candidates.lengths_m) {
    if (!(l > 0 && std::isfinite(l))) throw po::error("--lengths must each be > 0");
  }
  r.options.candidates.tip_speed_mps = Positive(vm, "tip-speed");
  r.options.candidates.tip_radius_m = vm["tip-radius"].as<double>();
  if (!(r.options.candidates.tip_radius_m >= 0)) throw po::error("--tip-radius must be >= 0");
  r.options.threads = vm["threads"].as<int>();
  if (r.options.threads < 1) throw po::error("--threads must be >= 1");
  std::string why;
  if (!r.options.IsValid(&why)) throw po::error(why);
  return r;
}

PushAdvice Advise(const AdviseRequest& request) {
  return AdvisePush(request.slider, request.patch, request.knowledge, request.options);
}

std::string AdviceJson(const AdviseRequest& request, const PushAdvice& advice) {
  return FormatAdviceJson(advice, request.slider, request.patch, request.options, request.top);
}

}  // namespace slideid::cli
