#include "estimator/step_observations.h"

#include <stdexcept>

namespace slideid {

std::vector<StepObservation> ExtractStepObservations(const Trajectory& logged) {
  // A poses-only log means kinematic-map velocities, whatever the samples carry.
  Trajectory derived;
  if (!logged.columns.velocity) {
    derived = logged;
    SetVelocitiesFromPoses(&derived);
  }
  const Trajectory& log = logged.columns.velocity ? logged : derived;
  const SliderProperties& s = log.slider;
  if (!(s.mass_kg > 0 && s.inertia_kgm2 > 0 && s.com_height_m >= 0 && s.gravity_mps2 > 0)) {
    throw std::invalid_argument("ExtractStepObservations: slider properties not set");
  }
  std::vector<StepObservation> steps;
  if (log.samples.size() < 2) return steps;
  steps.reserve(log.samples.size() - 1);
  const bool has_mode = log.columns.step_info;
  for (size_t u = 0; u + 1 < log.samples.size(); ++u) {
    const TrajectorySample& a = log.samples[u];
    const TrajectorySample& b = log.samples[u + 1];
    StepObservation o;
    o.row = static_cast<int>(u);
    o.h_s = b.t_s - a.t_s;
    o.start = a.state;
    o.end = b.state;
    o.applied = a.applied;
    o.start_velocity_known = log.columns.velocity || u > 0;
    const double h = o.h_s;
    o.pn = h * (s.mass_kg * s.gravity_mps2 - a.applied.fz);
    // Appendix A, corrected: friction impulses from Newton-Euler with the coupling term (*).
    const double pt = s.mass_kg * (b.state.vx - a.state.vx) - h * a.applied.fx;
    const double po = s.mass_kg * (b.state.vy - a.state.vy) - h * a.applied.fy;
    const double pr = s.inertia_kgm2 * (b.state.wz - a.state.wz) - h * a.applied.tz -
                      (pt * h * a.applied.tx + po * h * a.applied.ty) / o.pn;
    o.friction_impulse << pt, po, pr;
    const double rx = (h * a.applied.ty - s.com_height_m * pt) / o.pn;
    const double ry = (-h * a.applied.tx - s.com_height_m * po) / o.pn;
    const double w = b.state.wz;
    o.ecp_velocity << b.state.vx - w * ry, b.state.vy + w * rx, w;
    o.logged_stick = has_mode ? b.mode == SampleMode::kStick
                              : (b.state.vx == 0 && b.state.vy == 0 && b.state.wz == 0);
    steps.push_back(o);
  }
  return steps;
}

bool InformativeStep(const StepObservation& step, EstimateResult* result) {
  if (step.logged_stick) {
    result->Exclude("sticking");
    return false;
  }
  if (!step.start_velocity_known) {
    result->Exclude("start velocity unknown");
    return false;
  }
  return true;
}

}  // namespace slideid
