#include "datasets/scene_suite.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "datasets/dataset.h"
#include "datasets/logged_scene.h"
#include "datasets/push_program.h"
#include "datasets/sensor_model.h"
#include "forward_model/constants.h"
#include "forward_model/number_format.h"
#include "forward_model/simulator.h"

namespace slideid {
namespace {

constexpr int kMaxAttempts = 50;
constexpr double kRates_hz[] = {100, 200, 250, 500, 1000};
// Finest simulation step drawn [s]: 10 substeps of a 1 kHz log.
constexpr double kMinSimulationStep_s = 1e-4;
// A free slide is thrown so that it slides for this fraction of the log, then rests; a
// throw faster than this [m/s] is not a table-top experiment, so such logs are shorter.
constexpr double kSlideFraction = 0.8;
constexpr double kMaxThrow_mps = 3.0;

class Draw {
 public:
  Draw(std::uint64_t seed, int index, int attempt) {
    std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                      static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(attempt)};
    rng_.seed(seq);
  }
  double Uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  double LogUniform(double lo, double hi) { return std::exp(Uniform(std::log(lo), std::log(hi))); }
  bool Chance(double p) { return Uniform(0, 1) < p; }
  int Pick(int n) { return std::min(n - 1, static_cast<int>(Uniform(0, n))); }
  std::uint64_t Seed() { return rng_(); }

 private:
  std::mt19937_64 rng_;
};

// The slider: its patch, mass, inertia and CM height.
void DrawSlider(Draw* d, LoggedScene* scene, std::string* name) {
  static const char* kNames[] = {"box", "disk", "ring", "tall box", "flat box"};
  const int kind = d->Pick(5);
  *name = kNames[kind];
  const double mass = d->Uniform(0.2, 2.0);
  switch (kind) {
    case 0:
    case 4:
      scene->patch = ContactPatch::Rectangle(d->Uniform(0.05, 0.16), d->Uniform(0.05, 0.16));
      scene->slider.com_height_m = kind == 4 ? 0.0 : d->Uniform(0.01, 0.05);
      break;
    case 1:
      scene->patch = ContactPatch::Disk(d->Uniform(0.03, 0.08));
      scene->slider.com_height_m = d->Uniform(0.01, 0.05);
      break;
    case 2: {
      const double outer = d->Uniform(0.04, 0.1);
      scene->patch = ContactPatch::Ring(outer, outer * d->Uniform(0.3, 0.8));
      scene->slider.com_height_m = d->Uniform(0.01, 0.05);
      break;
    }
    default:  // tall: the CM 1.5-3 times the footprint's half-width up
      const double w = d->Uniform(0.04, 0.07), l = d->Uniform(0.04, 0.07);
      scene->patch = ContactPatch::Rectangle(w, l);
      scene->slider.com_height_m = d->Uniform(0.75, 1.5) * std::min(w, l);
      break;
  }
  scene->slider.mass_kg = mass;
  scene->slider.inertia_kgm2 = UniformInertia(scene->patch, mass);
}

void DrawFriction(Draw* d, LoggedScene* scene) {
  FrictionParameters f;
  f.mu = d->Uniform(0.15, 0.7);
  f.e_t = d->Uniform(0.8, 1.2);
  f.e_o = d->Chance(0.4) ? f.e_t : f.e_t * d->LogUniform(0.6, 1.6);
  // c of the order of the patch's radius of gyration (a uniform pressure gives 0.6-0.7 of it).
  const double gyration = std::sqrt(UniformInertia(scene->patch, 1.0));
  f.e_r = f.e_t * gyration * d->Uniform(0.3, 1.0);
  scene->friction = f;
}

void DrawNoise(Draw* d, bool pushed, bool velocities, bool outliers, NoiseSpec* n) {
  n->pose_m = d->LogUniform(1e-4, 1e-3);
  n->angle_rad = d->LogUniform(1e-3, 5e-3);
  if (velocities) {
    n->velocity_mps = d->LogUniform(1e-3, 1e-2);
    n->spin_radps = d->LogUniform(1e-2, 1e-1);
  }
  if (pushed) {
    n->force_relative = d->Chance(0.25) ? 0.0 : d->Uniform(0.0, 0.03);
    n->push_point_m = d->Chance(0.4) ? 0.0 : d->Uniform(0.0, 5e-4);
  }
  if (outliers) {
    n->outlier_fraction = d->Uniform(0.005, 0.03);
    n->outlier_m = d->Uniform(0.005, 0.03);
  }
  n->seed = d->Seed();
}

void ScaleNoise(double scale, NoiseSpec* n) {
  for (double* level : {&n->pose_m, &n->angle_rad, &n->velocity_mps, &n->spin_radps,
                        &n->force_relative, &n->force_n, &n->push_point_m, &n->outlier_fraction})
    *level *= scale;
}

}  // namespace

const char* ToString(SuiteMotion motion) {
  switch (motion) {
    case SuiteMotion::kFreeSlide:
      return "free slide";
    case SuiteMotion::kPushesWithRests:
      return "pushes+rests";
    case SuiteMotion::kPushesBackToBack:
      return "pushes";
  }
  return "?";
}

std::string SuiteLog::Describe() const {
  return Printf("%s; %s; %zu rows at %.0f Hz; %s%s", slider, ToString(motion), log.samples.size(),
                rate_hz, log.measured.velocity ? "poses+velocities" : "poses",
                outliers ? "; outliers" : "");
}

SuiteLog MakeSuiteLog(int index, std::uint64_t seed, const SceneSuiteLimits& limits) {
  std::string reasons;
  for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
    Draw d(seed, index, attempt);
    SuiteLog made;
    LoggedScene scene;
    scene.source = "scene suite " + std::to_string(index);
    DrawSlider(&d, &scene, &made.slider);
    DrawFriction(&d, &scene);
    const double motion_draw = d.Uniform(0, 1);
    made.motion = motion_draw < 0.25   ? SuiteMotion::kFreeSlide
                  : motion_draw < 0.75 ? SuiteMotion::kPushesWithRests
                                       : SuiteMotion::kPushesBackToBack;
    made.rate_hz = kRates_hz[d.Pick(5)];
    const double interval_s = 1.0 / made.rate_hz;
    static const int kEvery[] = {1, 2, 5, 10};
    int every = kEvery[d.Pick(4)];
    while (interval_s / every < kMinSimulationStep_s) --every;
    int rows = static_cast<int>(d.LogUniform(limits.min_rows, limits.max_rows));
    const bool velocities = d.Chance(0.3);
    made.outliers = d.Chance(0.1);
    const bool pushed = made.motion != SuiteMotion::kFreeSlide;
    const double a = scene.friction.reduced().a;
    const double g = scene.slider.gravity_mps2;

    scene.dt_s = interval_s / every;
    scene.log.log_every = every;
    scene.log.motion = velocities ? LogMotion::kBoth : LogMotion::kPoses;
    scene.log.push = LogPush::kPoint;
    DrawNoise(&d, pushed, velocities, made.outliers, &scene.log.noise);
    ScaleNoise(limits.noise_scale, &scene.log.noise);
    if (pushed) {
      RandomProgramSpec program;
      program.seed = d.Seed();
      program.max_lever_fraction = d.Uniform(0.03, 0.25);
      program.spread_rad = d.Uniform(0.2, 0.8);
      if (made.motion == SuiteMotion::kPushesBackToBack) program.rest_s = {0.0, 0.0};
      program.count = static_cast<int>(rows * interval_s / 0.2) + 2;
      if (d.Chance(0.7)) {
        program.time_grid_s = interval_s;
        program.grid_lead_s = scene.dt_s / 2;
      }
      const PushProgram p =
          RandomPushProgram(program, scene.patch, scene.slider, scene.friction.reduced());
      scene.pushes = p.pushes;
      scene.duration_s = rows * interval_s;
    } else {
      const double slide_s = std::min(kSlideFraction * rows * interval_s, kMaxThrow_mps / (a * g));
      rows = std::max(limits.min_rows,
                      std::min(rows, static_cast<int>(slide_s / kSlideFraction / interval_s)));
      const double speed = a * g * slide_s, heading = d.Uniform(-kPi, kPi);
      scene.initial.vx = speed * std::cos(heading);
      scene.initial.vy = speed * std::sin(heading);
      scene.initial.wz = (d.Chance(0.5) ? 1 : -1) * d.Uniform(3.0, 25.0);
      scene.duration_s = rows * interval_s;
    }
    scene.duration_s += 2 * interval_s;  // the cut below keeps exactly `rows` rows
    const SimulationResult sim = Simulate(scene);
    if (!sim.summary.ok()) {
      reasons += "\n  attempt " + std::to_string(attempt) + ": " + sim.summary.message;
      continue;
    }
    made.log = MakeLog(sim.trajectory, scene.log);
    made.scene = scene;
    if (static_cast<int>(made.log.samples.size()) < rows) {
      reasons += "\n  attempt " + std::to_string(attempt) + ": too few rows";
      continue;
    }
    KeepFirstRows(&made.log, rows);
    const ReducedFriction& t = scene.friction.reduced();
    made.truth = {t.a, t.b, t.c};
    return made;
  }
  throw std::runtime_error("scene suite log " + std::to_string(index) + ": no valid draw in " +
                           std::to_string(kMaxAttempts) + " attempts:" + reasons);
}

}  // namespace slideid
