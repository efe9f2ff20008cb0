#include "pipeline/predict_options.h"

#include <nlohmann/json.hpp>
#include <stdexcept>

#include "io/result_json.h"
#include "pipeline/friction_file.h"

namespace slideid::cli {
namespace po = boost::program_options;
using Json = nlohmann::json;

namespace {

Json Optional(const std::optional<double>& v) { return v ? Json(*v) : Json(nullptr); }

Json SummaryJson(const ErrorSummary& s) {
  return {{"pushes", s.pushes},
          {"median", s.median},
          {"q25", s.q25},
          {"q75", s.q75},
          {"worst", s.worst}};
}

Json ErrorsJson(const PredictionErrors& e) {
  return {{"final_position_m", e.final_position_m},
          {"final_rotation_rad", e.final_rotation_rad},
          {"mean_position_m", e.mean_position_m},
          {"mean_rotation_rad", e.mean_rotation_rad},
          {"travel_m", e.travel_m},
          {"travel_of", e.travel_of},
          {"final_position_per_100mm_m", e.final_position_per_100mm_m},
          {"final_rotation_per_100mm_rad", e.final_rotation_per_100mm_rad},
          {"logged_displacement_m", e.logged_displacement_m},
          {"final_position_fraction", e.final_position_fraction},
          {"parting_time_s", Optional(e.parting_time_s)}};
}

}  // namespace

void AddPredictOptions(po::options_description* options) {
  options->add_options()(
      "friction", po::value<std::string>()->value_name("RESULT.json"),
      "the friction: what identify --json printed (a, b, c, and mu_pusher when found)")(
      "mu", po::value<double>()->value_name("A"), "a = e_t mu (overrides the result's)")(
      "b", po::value<double>()->value_name("B"), "b = e_o / e_t")(
      "c", po::value<double>()->value_name("C"), "c = e_r / e_t [m]")(
      "mu-pusher", po::value<double>()->value_name("MU_P"),
      "tip-edge friction coefficient (the pusher drive needs it)")(
      "drive", po::value<std::string>(),
      "pusher, force or quasi-static (the tip's path through the quasi-static ellipsoid "
      "model; default: pusher when the log has tip_x, tip_y, else force)")(
      "substeps", po::value<int>()->default_value(1), "simulation steps per log interval")(
      "no-register-tip",
      "use the log's tip radius as it is (by default it is set so that the tip touches the "
      "outline, on the median, where the log pushes)");
}

PredictRequest ReadPredictOptions(const po::variables_map& vm) {
  PredictRequest r;
  bool a = false, b = false, c = false;
  if (vm.count("friction")) {
    const std::string path = vm["friction"].as<std::string>();
    const std::string text = ReadFrictionFile(path);
    EstimateResult fit;
    try {
      fit = ParseResultJson(text);
    } catch (const ResultJsonError& e) {
      throw std::runtime_error(path + ": " + e.what());
    }
    const ParameterEstimate* p = fit.parameters.data();
    if (p[kA].identifiable) r.friction.a = p[kA].value, a = true;
    if (p[kB].identifiable) r.friction.b = p[kB].value, b = true;
    if (p[kC].identifiable) r.friction.c = p[kC].value, c = true;
    if (fit.mu_pusher.identifiable) r.mu_pusher = fit.mu_pusher.value;
  }
  if (vm.count("mu")) r.friction.a = vm["mu"].as<double>(), a = true;
  if (vm.count("b")) r.friction.b = vm["b"].as<double>(), b = true;
  if (vm.count("c")) r.friction.c = vm["c"].as<double>(), c = true;
  if (vm.count("mu-pusher")) r.mu_pusher = vm["mu-pusher"].as<double>();
  const char* missing = !a ? "a (--mu)" : !b ? "b (--b)" : !c ? "c (--c)" : nullptr;
  if (missing) {
    throw po::error(std::string("no value for ") + missing +
                    ": give --friction RESULT.json "
                    "where it is identified, or the option");
  }
  if (!(r.friction.a > 0 && r.friction.b > 0 && r.friction.c > 0)) {
    throw po::error("--mu, --b and --c must be > 0");
  }
  if (r.mu_pusher && !(*r.mu_pusher >= 0)) throw po::error("--mu-pusher must be >= 0");
  if (vm.count("drive")) {
    PredictionDrive drive;
    if (!ParsePredictionDrive(vm["drive"].as<std::string>(), &drive)) {
      throw po::error("--drive must be pusher, force or quasi-static");
    }
    r.drive = drive;
  }
  r.options.substeps = vm["substeps"].as<int>();
  r.options.register_tip = !vm.count("no-register-tip");
  std::string why;
  if (!r.options.IsValid(&why)) throw po::error(why);
  return r;
}

PredictionDrive DriveFor(const PredictRequest& request, const Trajectory& log) {
  if (request.drive) return *request.drive;
  return log.measured.tip ? PredictionDrive::kPusher : PredictionDrive::kForce;
}

std::string PredictionJson(const Prediction& p, const ReducedFriction& friction) {
  const bool pusher = p.drive == PredictionDrive::kPusher;
  Json j = {{"drive", ToString(p.drive)},
            {"e_t_mu", friction.a},
            {"e_o_over_e_t", friction.b},
            {"e_r_over_e_t", friction.c},
            {"mu_pusher", pusher ? Json(p.mu_pusher) : Json(nullptr)},
            {"tip_radius_m", pusher ? Json(p.tip_radius_m) : Json(nullptr)},
            {"ok", p.summary.ok()},
            {"message", p.summary.message},
            {"rows_predicted", p.predicted.samples.size()},
            {"tip_stick_steps", p.summary.tip_stick_steps},
            {"tip_slide_steps", p.summary.tip_slide_steps}};
  j.update(ErrorsJson(p.errors));
  return j.dump();
}

void AddValidateOptions(po::options_description* options) {
  options->add_options()("folds", po::value<int>()->value_name("K"),
                         "K folds, the logs dealt round-robin")("leave-one-out",
                                                                "one fold per log (the default)")(
      "drive", po::value<std::string>(),
      "pusher or force (default: pusher when every log has the tip's path, else force); "
      "the pusher drive also runs the folds' friction through the quasi-static model")(
      "mu-pusher", po::value<double>()->value_name("MU_P"), "mu_p for every prediction")(
      "substeps", po::value<int>()->default_value(1), "simulation steps per log interval")(
      "threads", po::value<int>()->default_value(1), "folds and pushes in parallel");
}

ValidationOptions ReadValidateOptions(const po::variables_map& vm, bool all_tip) {
  if (vm.count("folds") && vm.count("leave-one-out")) {
    throw po::error("--folds and --leave-one-out exclude each other");
  }
  ValidationOptions o;
  o.folds = vm.count("folds") ? vm["folds"].as<int>() : 0;
  o.prediction.drive = all_tip ? PredictionDrive::kPusher : PredictionDrive::kForce;
  if (vm.count("drive") &&
      (!ParsePredictionDrive(vm["drive"].as<std::string>(), &o.prediction.drive) ||
       o.prediction.drive == PredictionDrive::kQuasiStatic)) {
    throw po::error("--drive must be pusher or force");
  }
  if (vm.count("mu-pusher")) o.mu_pusher = vm["mu-pusher"].as<double>();
  o.prediction.substeps = vm["substeps"].as<int>();
  o.threads = vm["threads"].as<int>();
  std::string why;
  if (!o.IsValid(&why)) throw po::error(why);
  return o;
}

std::string ValidationJson(const ValidationResult& r) {
  Json j = {
      {"drive", ToString(r.drive)}, {"folds", r.folds}, {"logs", r.logs}, {"seconds", r.seconds}};
  j["fold_fits"] = Json::array();
  for (const FoldFit& f : r.fold_fits) {
    j["fold_fits"].push_back({{"fold", f.fold},
                              {"held_out", f.held_out},
                              {"ok", f.ok},
                              {"error", f.error},
                              {"e_t_mu", f.friction.a},
                              {"e_o_over_e_t", f.friction.b},
                              {"e_r_over_e_t", f.friction.c},
                              {"mu_pusher", f.mu_pusher},
                              {"mu_pusher_from", f.mu_pusher_from}});
  }
  j["methods"] = Json::array();
  for (const MethodValidation& m : r.methods) {
    Json method = {{"method", m.method},
                   {"failed", m.failed},
                   {"final_position_m", SummaryJson(m.final_position_m)},
                   {"final_rotation_rad", SummaryJson(m.final_rotation_rad)},
                   {"final_position_per_100mm_m", SummaryJson(m.final_position_per_100mm_m)},
                   {"final_position_fraction", SummaryJson(m.final_position_fraction)}};
    method["pushes"] = Json::array();
    for (const PushPrediction& p : m.pushes) {
      Json push = {{"log", p.log}, {"fold", p.fold}, {"ok", p.ok}, {"error", p.error}};
      push.update(ErrorsJson(p.errors));
      method["pushes"].push_back(push);
    }
    j["methods"].push_back(method);
  }
  return j.dump();
}

}  // namespace slideid::cli
