#include "datasets/coverage_conditions.h"

#include <stdexcept>

#include "datasets/dataset.h"

namespace slideid {
namespace {

// A push of the random program lasts 0.2-0.6 s and rests 0.2-0.5 s: at least 40 rows at
// 100 Hz. A program of rows / 40 + 1 pushes is therefore long enough to cut to `rows`.
constexpr int kMinRowsPerPush = 40;

NoiseSpec MotionCapture() {
  NoiseSpec n;
  n.pose_m = 3e-4;     // typical motion capture: 0.3 mm
  n.angle_rad = 3e-3;  // and 3 mrad
  return n;
}

}  // namespace

std::vector<CoverageCondition> CoverageConditions() {
  const CoverageCondition base{
      "base",         "1000 rows, poses, 0.3 mm / 3 mrad, simulated at 1 ms",
      1000,           10,
      false,          LogMotion::kPoses,
      MotionCapture()};
  std::vector<CoverageCondition> c;
  auto add = [&](const std::string& name, const std::string& what, auto change) {
    CoverageCondition x = base;
    x.name = name;
    x.what = what;
    change(x);
    c.push_back(x);
  };
  add("exact-rate", "base simulated at the log rate (10 ms): the fit's model is exact",
      [](CoverageCondition& x) { x.log_every = 1; });
  c.push_back(base);
  add("finer-0.1ms", "base simulated at 0.1 ms (100 steps per row)",
      [](CoverageCondition& x) { x.log_every = 100; });
  add("force-1%", "base + 1% multiplicative force noise",
      [](CoverageCondition& x) { x.noise.force_relative = 0.01; });
  add("force-3%", "base + 3% multiplicative force noise",
      [](CoverageCondition& x) { x.noise.force_relative = 0.03; });
  add("push-point", "base + 0.4 mm noise on the push point",
      [](CoverageCondition& x) { x.noise.push_point_m = 4e-4; });
  add("short-300", "base cut to 300 rows", [](CoverageCondition& x) { x.rows = 300; });
  add("long-3000", "base at 3000 rows", [](CoverageCondition& x) { x.rows = 3000; });
  add("poses+velocities", "base with measured velocities too (3 mm/s, 0.03 rad/s)",
      [](CoverageCondition& x) {
        x.motion = LogMotion::kBoth;
        x.noise.velocity_mps = 3e-3;
        x.noise.spin_radps = 3e-2;
      });
  add("outliers", "base + 1% of rows jump 5 mm (and 0.1 rad)", [](CoverageCondition& x) {
    x.noise.outlier_fraction = 0.01;
    x.noise.outlier_m = 5e-3;
  });
  add("users", "300 rows, 2% force noise, 0.4 mm push-point noise (issue 11's users' logs)",
      [](CoverageCondition& x) {
        x.rows = 300;
        x.noise.force_relative = 0.02;
        x.noise.push_point_m = 4e-4;
      });
  return c;
}

CoverageCondition FindCoverageCondition(const std::string& name) {
  for (const CoverageCondition& c : CoverageConditions()) {
    if (c.name == name) return c;
  }
  throw std::invalid_argument("unknown coverage condition '" + name + "'");
}

CoverageLog MakeCoverageLog(const CoverageCondition& condition, int index, std::uint64_t seed) {
  DatasetSpec spec;
  spec.seed = seed;
  spec.dt_s = kCoverageLogDt_s / condition.log_every;
  spec.program.count = condition.rows / kMinRowsPerPush + 1;
  spec.log.log_every = condition.log_every;
  if (condition.mean_wrench) {
    spec.log.wrench = LogWrench::kIntervalMean;
    spec.log.push = LogPush::kMoments;  // a mean wrench has no single push point
  }
  spec.log.motion = condition.motion;
  spec.log.noise = condition.noise;
  CoverageLog made;
  const DatasetEntry entry = DrawDatasetLog(spec, index, &made.log);
  if (static_cast<int>(made.log.samples.size()) < condition.rows) {
    throw std::runtime_error(condition.name + " log " + std::to_string(index) + ": only " +
                             std::to_string(made.log.samples.size()) + " rows");
  }
  KeepFirstRows(&made.log, condition.rows);
  const ReducedFriction& t = entry.scene.friction.reduced();
  made.truth = {t.a, t.b, t.c};
  return made;
}

}  // namespace slideid
