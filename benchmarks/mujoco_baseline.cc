// MuJoCo as a prediction baseline: the simulator most users would reach for, given the same
// friction and the same pusher path as validate's folds.
//
// For each held-out push of a validate run (its JSON: each fold's friction and mu_p), the
// slider is a body with the log's mass and inertia on slide joints x, y, z and a hinge about
// z (a free body balanced on one support point would tip over); its support is one condim-4
// contact under the CM with an elliptic cone, sliding friction a and torsional friction
// a c (MuJoCo's elliptic cone with torsion is the isotropic ellipsoidal limit surface with
// its ECP at the contact: anisotropy, b, has no place in it); its outline is a box that
// only the tip touches, with friction mu_p. The tip is a mocap cylinder driven along the
// log's tip path (its radius registered as predict registers it). MuJoCo's own defaults
// otherwise (soft contacts, solref 0.02), at a 1 ms step. The errors are predict's
// (prediction/predict.h), and the summary validate's.
//
// Measured with this mapping (a = 0.3, c = 35 mm, the rect1 plate, 0.1 ms steps): a spin
// of 5 rad/s stops in 0.126 s where the ellipsoid's torsion a c m g stops it in 0.065 s, and
// a slide of 0.5 m/s in 0.196 s against 0.170 s: MuJoCo's soft contact transmits about half
// the torsional friction and 87% of the sliding friction it is given.
//
// Usage: mujoco_baseline --validation VALIDATE.json [--json OUT.json] [--timestep S]
// Links Debian's libmujoco-dev (2.2); a benchmark, not part of the library.

#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "benchmarks/bench_args.h"
#include "forward_model/constants.h"
#include "forward_model/contact_patch.h"
#include "forward_model/number_format.h"
#include "io/push_log.h"
#include "prediction/predict.h"
#include "prediction/validate.h"

namespace slideid {
namespace {

using Json = nlohmann::json;
// The support's sphere: small, so that its one contact sits under the CM [m].
constexpr double kSupportRadius = 1e-3;

std::string Num(double v) { return ExactNumber(v); }

/// The MJCF of one push: the slider resting at the origin of its own frame.
std::string Model(const Trajectory& log, const ReducedFriction& f, double mu_p, double tip_radius,
                  double timestep) {
  const ContactPatch& patch = log.patch.value();
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const Eigen::Vector2d& p : patch.Outline()) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double hz = std::max(log.slider.com_height_m, kSupportRadius);
  const Eigen::Vector2d half = 0.5 * (hi - lo), centre = 0.5 * (hi + lo);
  const double inertia = log.slider.inertia_kgm2, m = log.slider.mass_kg;
  std::ostringstream x;
  x << "<mujoco><option timestep='" << Num(timestep) << "' cone='elliptic' gravity='0 0 "
    << Num(-log.slider.gravity_mps2) << "'/><worldbody>"
    << "<geom name='floor' type='plane' size='10 10 0.1' contype='1' conaffinity='1' "
       "condim='4' friction='"
    << Num(f.a) << " " << Num(f.a * f.c) << " 0'/>"
    << "<body name='slider' pos='0 0 " << Num(hz) << "'>"
    << "<joint name='x' type='slide' axis='1 0 0'/><joint name='y' type='slide' axis='0 1 0'/>"
    << "<joint name='z' type='slide' axis='0 0 1'/><joint name='yaw' type='hinge' axis='0 0 1'/>"
    << "<inertial pos='0 0 0' mass='" << Num(m) << "' diaginertia='" << Num(inertia / 2) << " "
    << Num(inertia / 2) << " " << Num(inertia) << "'/>"
    << "<geom type='sphere' size='" << Num(kSupportRadius) << "' pos='0 0 "
    << Num(-hz + kSupportRadius) << "' contype='1' conaffinity='1' condim='4' friction='"
    << Num(f.a) << " " << Num(f.a * f.c) << " 0' mass='0'/>"
    << "<geom type='box' size='" << Num(half.x()) << " " << Num(half.y()) << " " << Num(hz)
    << "' pos='" << Num(centre.x()) << " " << Num(centre.y())
    << " 0' contype='2' "
       "conaffinity='2' condim='3' friction='"
    << Num(mu_p) << " 0 0' mass='0'/></body>"
    << "<body name='tip' mocap='true' pos='0 0 " << Num(hz) << "'><geom type='cylinder' size='"
    << Num(tip_radius) << " 0.03' contype='2' conaffinity='2' condim='3' friction='" << Num(mu_p)
    << " 0 0'/></body></worldbody></mujoco>";
  return x.str();
}

/// The push replayed in MuJoCo: rows at the log's times.
Trajectory Simulate(const Trajectory& log, const ReducedFriction& f, double mu_p, double timestep) {
  const std::string path = "/tmp/slideid_mujoco_" + std::to_string(::getpid()) + ".xml";
  std::ofstream(path) << Model(log, f, mu_p, RegisteredTipRadius(log), timestep);
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  std::remove(path.c_str());
  if (!m) throw std::runtime_error(std::string("MuJoCo: ") + error);
  mjData* d = mj_makeData(m);
  const PlanarState s0 = ReplayStart(log);
  d->qpos[0] = s0.x;
  d->qpos[1] = s0.y;
  d->qpos[3] = s0.theta;
  d->qvel[0] = s0.vx;
  d->qvel[1] = s0.vy;
  d->qvel[3] = s0.wz;
  std::vector<double> times;
  std::vector<Eigen::Vector2d> tips;
  for (const TrajectorySample& s : log.samples) {
    times.push_back(s.t_s);
    tips.push_back(*s.tip_world);
  }
  const PusherPath tip(times, tips);
  Trajectory out;
  out.slider = log.slider;
  for (const TrajectorySample& row : log.samples) {
    while (d->time + log.samples[0].t_s < row.t_s - 1e-12) {
      const Eigen::Vector2d at = tip.PositionAt(log.samples[0].t_s + d->time + m->opt.timestep);
      d->mocap_pos[0] = at.x();
      d->mocap_pos[1] = at.y();
      mj_step(m, d);
    }
    TrajectorySample s;
    s.t_s = row.t_s;
    const double* q = d->qpos;
    s.state = {q[0], q[1], q[3], d->qvel[0], d->qvel[1], d->qvel[3]};
    s.tip_world = row.tip_world;
    out.samples.push_back(s);
  }
  mj_deleteData(d);
  mj_deleteModel(m);
  return out;
}

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) {
  using namespace slideid;
  const char* usage =
      "usage: mujoco_baseline --validation VALIDATE.json [--json OUT] [--timestep S]\n";
  std::string validation, json_out;
  double timestep = 1e-3;
  try {
    bench::Args args(argc, argv);
    while (args.Next()) {
      if (args.Is("--validation"))
        validation = args.Value();
      else if (args.Is("--json"))
        json_out = args.Value();
      else if (args.Is("--timestep"))
        timestep = args.Number();
      else
        throw std::invalid_argument("unknown option " + args.option());
    }
  } catch (const std::invalid_argument& e) {
    std::cerr << "mujoco_baseline: " << e.what() << "\n" << usage;
    return 2;
  }
  if (validation.empty() || !(timestep > 0)) {
    std::cerr << usage;
    return 2;
  }
  std::ifstream in(validation);
  if (!in) {
    std::cerr << "mujoco_baseline: " << validation << ": cannot read\n";
    return 1;
  }
  const Json v = Json::parse(in);
  MethodValidation mujoco;
  mujoco.method = "mujoco";
  std::vector<double> position, rotation, per_100mm, fraction;
  for (const Json& fold : v.at("fold_fits")) {
    if (!fold.at("ok").get<bool>()) continue;
    const ReducedFriction f{fold.at("e_t_mu").get<double>(), fold.at("e_o_over_e_t").get<double>(),
                            fold.at("e_r_over_e_t").get<double>()};
    for (const Json& name : fold.at("held_out")) {
      PushPrediction p;
      p.log = name.get<std::string>();
      p.fold = fold.at("fold").get<int>();
      try {
        const Trajectory log = ReadPushLog(p.log);
        const Trajectory predicted = Simulate(log, f, fold.at("mu_pusher").get<double>(), timestep);
        p.errors = CompareWithLog(log, predicted, PredictionOptions{});
        p.ok = true;
        position.push_back(p.errors.final_position_m);
        rotation.push_back(p.errors.final_rotation_rad);
        per_100mm.push_back(p.errors.final_position_per_100mm_m);
        fraction.push_back(p.errors.final_position_fraction);
      } catch (const std::exception& e) {
        p.error = e.what();
        ++mujoco.failed;
      }
      mujoco.pushes.push_back(p);
    }
  }
  if (position.empty()) {
    std::cerr << "mujoco_baseline: no push predicted (" << mujoco.failed << " failed)\n";
    for (const PushPrediction& p : mujoco.pushes)
      std::cerr << "  " << p.log << ": " << p.error << "\n";
    return 1;
  }
  const ErrorSummary sp = Summarise(position), sr = Summarise(rotation),
                     s100 = Summarise(per_100mm), sf = Summarise(fraction);
  std::printf("mujoco: %zu pushes (%d failed), MuJoCo %s, step %g s\n", mujoco.pushes.size(),
              mujoco.failed, mj_versionString(), timestep);
  std::printf(
      "final position %.2f [%.2f, %.2f] %.2f mm; rotation %.2f [%.2f, %.2f] %.2f deg; "
      "per 100 mm %.2f mm; %.1f%% of the displacement\n",
      sp.median * 1e3, sp.q25 * 1e3, sp.q75 * 1e3, sp.worst * 1e3, sr.median * kRadToDeg,
      sr.q25 * kRadToDeg, sr.q75 * kRadToDeg, sr.worst * kRadToDeg, s100.median * 1e3,
      100 * sf.median);
  for (const PushPrediction& p : mujoco.pushes) {
    if (!p.ok) std::printf("  %s: %s\n", p.log.c_str(), p.error.c_str());
  }
  if (!json_out.empty()) {
    auto summary = [](const ErrorSummary& s) {
      return Json{{"pushes", s.pushes},
                  {"median", s.median},
                  {"q25", s.q25},
                  {"q75", s.q75},
                  {"worst", s.worst}};
    };
    Json j = {{"method", "mujoco"},
              {"mujoco_version", mj_versionString()},
              {"timestep_s", timestep},
              {"failed", mujoco.failed},
              {"final_position_m", summary(sp)},
              {"final_rotation_rad", summary(sr)},
              {"final_position_per_100mm_m", summary(s100)},
              {"final_position_fraction", summary(sf)}};
    std::ofstream(json_out) << j.dump() << "\n";
  }
  return 0;
}
