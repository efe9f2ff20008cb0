#include "datasets/push_program.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "forward_model/constants.h"

namespace slideid {
namespace {

// Default force range in multiples of the sliding limit a m g: above 1 the push slides the
// slider; 1.6 keeps accelerations (and speeds, below ~1.5 m/s) moderate.
constexpr double kForceLoOverLimit = 1.1;
constexpr double kForceHiOverLimit = 1.6;
// Default heights as fractions of com_height: below the CM the push tilts the slider less.
constexpr double kHeightLoOverCom = 0.25;
constexpr double kHeightHiOverCom = 0.75;

bool RangeOk(const ValueRange& r, bool non_negative) {
  return std::isfinite(r.lo) && std::isfinite(r.hi) && r.lo <= r.hi &&
         (!non_negative || r.lo >= 0.0);
}

/// A point uniformly distributed along the closed outline.
Eigen::Vector2d BoundaryPoint(const std::vector<Eigen::Vector2d>& outline, double fraction) {
  double perimeter = 0.0;
  for (size_t i = 0; i + 1 < outline.size(); ++i) perimeter += (outline[i + 1] - outline[i]).norm();
  double s = fraction * perimeter;
  for (size_t i = 0; i + 1 < outline.size(); ++i) {
    const Eigen::Vector2d edge = outline[i + 1] - outline[i];
    const double length = edge.norm();
    if (length == 0.0) continue;
    if (s <= length || i + 2 == outline.size())
      return outline[i] + std::min(s / length, 1.0) * edge;
    s -= length;
  }
  throw std::logic_error("RandomPushProgram: empty patch outline");
}

}  // namespace

bool RandomProgramSpec::IsValid(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  // The upper limit keeps a run finite: a billion pushes would be drawn before the
  // simulator's own limit on steps could refuse them.
  if (count < 1 || count > kMaxCount) {
    return fail("program: count = " + std::to_string(count) + ": must be 1 to " +
                std::to_string(kMaxCount));
  }
  if (force_n && !RangeOk(*force_n, false)) return fail("program: force range needs lo <= hi");
  if (!RangeOk(amplitude_fraction, true)) {
    return fail("program: amplitude range needs 0 <= lo <= hi");
  }
  if (!RangeOk(period_s, true) || !(period_s.lo > 0.0)) {
    return fail("program: period range needs 0 < lo <= hi");
  }
  if (!RangeOk(duration_s, true) || !(duration_s.lo > 0.0)) {
    return fail("program: duration range needs 0 < lo <= hi");
  }
  if (!RangeOk(rest_s, true)) return fail("program: rest range needs 0 <= lo <= hi");
  if (height_m && !RangeOk(*height_m, false)) return fail("program: height range needs lo <= hi");
  if (!(spread_rad >= 0.0 && spread_rad <= kPi / 2)) {
    return fail("program: spread must be in [0, pi/2] rad");
  }
  if (!(max_lever_fraction >= 0.0 && max_lever_fraction <= 1.0)) {
    return fail("program: max lever fraction must be in [0, 1]");
  }
  if (!std::isfinite(start_s)) return fail("program: start must be finite");
  if (!(time_grid_s >= 0.0 && std::isfinite(time_grid_s))) {
    return fail("program: time grid must be >= 0");
  }
  if (!(grid_lead_s >= 0.0 && (time_grid_s == 0.0 || grid_lead_s <= time_grid_s / 2))) {
    return fail("program: grid lead must be >= 0 and at most half the time grid");
  }
  return true;
}

PushProgram RandomPushProgram(const RandomProgramSpec& spec, const ContactPatch& patch,
                              const SliderProperties& slider, const ReducedFriction& friction) {
  std::string why;
  if (!spec.IsValid(&why)) throw std::invalid_argument("RandomPushProgram: " + why);
  const double limit_n = friction.a * slider.mass_kg * slider.gravity_mps2;
  const ValueRange force =
      spec.force_n.value_or(ValueRange{kForceLoOverLimit * limit_n, kForceHiOverLimit * limit_n});
  const ValueRange height = spec.height_m.value_or(
      ValueRange{kHeightLoOverCom * slider.com_height_m, kHeightHiOverCom * slider.com_height_m});
  const std::vector<Eigen::Vector2d> outline = patch.Outline();
  double radius = 0.0;
  for (const Eigen::Vector2d& p : outline) radius = std::max(radius, p.norm());
  const double max_lever = spec.through_cm ? 0.0 : spec.max_lever_fraction * radius;

  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto draw = [&](const ValueRange& r) { return r.lo + (r.hi - r.lo) * unit(rng); };

  PushProgram program;
  double t = spec.start_s;
  for (int i = 0; i < spec.count; ++i) {
    // Every variate is drawn whatever the options, in this order: one seed, one stream.
    const double duration = draw(spec.duration_s);
    const double rest = draw(spec.rest_s);
    const double magnitude = draw(force);
    const double amplitude = draw(spec.amplitude_fraction) * magnitude;
    const double period = draw(spec.period_s);
    const double where = unit(rng);
    const double angle = draw({-spec.spread_rad, spec.spread_rad});
    const double z = draw(height);

    PushSpec p;
    p.point_body = BoundaryPoint(outline, where);
    // Turned from the CM direction by `angle`, the line of action passes at |p| sin(angle)
    // from the CM: cap the angle so that this stays within max_lever.
    const double distance = p.point_body.norm();
    const double cap = distance > max_lever ? std::asin(max_lever / distance) : kPi / 2;
    const double turn =
        spec.spread_rad > 0.0 ? angle / spec.spread_rad * std::min(spec.spread_rad, cap) : 0.0;
    const Eigen::Vector2d to_cm = -p.point_body / distance;
    const double c = std::cos(turn), s = std::sin(turn);
    p.direction_body =
        Eigen::Vector2d(c * to_cm.x() - s * to_cm.y(), s * to_cm.x() + c * to_cm.y());
    p.height_m = spec.through_cm ? slider.com_height_m : z;
    p.force_n = magnitude;
    p.amplitude_n = amplitude;
    p.period_s = period;
    p.start_s = t;
    p.stop_s = t + duration;
    if (spec.time_grid_s > 0.0) {
      const auto snap = [&](double time) {
        return std::round(time / spec.time_grid_s) * spec.time_grid_s - spec.grid_lead_s;
      };
      p.start_s = snap(p.start_s);
      p.stop_s = std::max(snap(p.stop_s), p.start_s + spec.time_grid_s);
    }
    program.pushes.push_back(p);
    t = p.stop_s + spec.grid_lead_s + rest;
  }
  program.end_s = t;
  return program;
}

}  // namespace slideid
