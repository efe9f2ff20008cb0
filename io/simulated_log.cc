#include "io/simulated_log.h"

#include "forward_model/number_format.h"
#include "forward_model/slider.h"

namespace slideid {
namespace {

using Metadata = std::vector<std::pair<std::string, std::string>>;

/// What the simulator was given beyond the log's physics: the truth's reduced form (the
/// estimator's parameters), the step, the scene's name and the pusher's tip friction.
void AddSceneMetadata(const Scene& scene, Metadata* out) {
  const ReducedFriction& reduced = scene.friction.reduced();
  auto add = [&](const char* key, double v) { out->emplace_back(key, ExactNumber(v)); };
  add("e_t_mu", reduced.a);
  add("e_o_over_e_t", reduced.b);
  add("e_r_over_e_t", reduced.c);
  add("dt", scene.dt_s);
  if (!scene.source.empty()) out->emplace_back("scene", scene.source);
  if (scene.pusher) add("mu_p", scene.pusher->mu);
}

/// What MakeLog did to the simulated rows: decimation, the wrench's form, the noise.
void AddSamplingMetadata(const LogSpec& spec, const Trajectory& log, Metadata* out) {
  if (spec.log_every > 1) {
    out->emplace_back("log_every", std::to_string(spec.log_every));
    if (log.samples.size() >= 2) {
      out->emplace_back("log_dt", ExactNumber(log.samples[1].t_s - log.samples[0].t_s));
    }
  }
  if (spec.wrench == LogWrench::kIntervalMean) {
    out->emplace_back("log_wrench", ToString(spec.wrench));
  }
  if (!spec.noise.IsZero() || spec.noise.HasDefects()) {
    for (const auto& entry : spec.noise.Metadata()) out->push_back(entry);
  }
}

}  // namespace

Metadata SimulatedLogMetadata(const LoggedScene& scene, const Trajectory& log) {
  Metadata out;
  AddSceneMetadata(scene, &out);
  AddSamplingMetadata(scene.log, log, &out);
  return out;
}

PushLogFile SimulatedLogFile(const LoggedScene& scene, Trajectory log) {
  PushLogFile file;
  file.extra_metadata = SimulatedLogMetadata(scene, log);
  file.log = std::move(log);
  return file;
}

}  // namespace slideid
