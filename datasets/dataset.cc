#include "datasets/dataset.h"

#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

#include "datasets/sensor_model.h"
#include "forward_model/constants.h"
#include "forward_model/number_format.h"
#include "forward_model/simulator.h"

namespace slideid {
namespace {

// A pusher-driven log's tip starts this far outside the slider's reach [m], and the
// simulation runs kPusherRunOutS past the path's end, for the slider to stop.
constexpr double kPusherClearanceM = 0.005;
constexpr double kPusherRunOutS = 0.2;

std::string LogFileName(int index) { return Printf("log_%04d.csv", index); }

/// Second polar moment of area of a CCW polygon about the origin, divided by its area [m^2].
double PolygonRadiusOfGyrationSquared(const std::vector<Eigen::Vector2d>& closed) {
  double area2 = 0.0, j = 0.0;
  for (size_t i = 0; i + 1 < closed.size(); ++i) {
    const Eigen::Vector2d& p = closed[i];
    const Eigen::Vector2d& q = closed[i + 1];
    const double cross = p.x() * q.y() - q.x() * p.y();
    area2 += cross;
    j += cross * (p.x() * p.x() + p.x() * q.x() + q.x() * q.x() + p.y() * p.y() + p.y() * q.y() +
                  q.y() * q.y());
  }
  return (j / 12.0) / (area2 / 2.0);
}

bool RangeOk(const ValueRange& r, bool positive) {
  return std::isfinite(r.lo) && std::isfinite(r.hi) && r.lo <= r.hi &&
         (positive ? r.lo > 0.0 : r.lo >= 0.0);
}

/// The patch for drawn sizes (ContactPatch validates; invalid draws throw).
ContactPatch BuildPatch(const std::string& shape, const std::vector<double>& v) {
  std::string spec = shape;
  for (double x : v) spec += " " + ExactNumber(x);
  return ContactPatch::Parse(spec);
}

}  // namespace

// ---- ranges and patches ----

ValueRange ParseRange(const std::string& text, const std::string& what) {
  const auto colon = text.find(':');
  const auto number = [&](const std::string& s) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !std::isfinite(v)) {
      throw std::invalid_argument(what + ": '" + text + "' is not LO:HI (or one number)");
    }
    return v;
  };
  const ValueRange r = colon == std::string::npos ? ValueRange{number(text), number(text)}
                                                  : ValueRange{number(text.substr(0, colon)),
                                                               number(text.substr(colon + 1))};
  if (!(r.lo <= r.hi)) throw std::invalid_argument(what + ": '" + text + "' needs LO <= HI");
  return r;
}

std::string ToString(const ValueRange& range) {
  if (range.lo == range.hi) return Printf("%g", range.lo);
  return Printf("%g:%g", range.lo, range.hi);
}

PatchRange PatchRange::Parse(const std::string& text) {
  std::istringstream in(text);
  PatchRange p;
  p.sizes.clear();
  if (!(in >> p.shape)) throw std::invalid_argument("--patch: empty");
  for (std::string token; in >> token;) p.sizes.push_back(ParseRange(token, "--patch"));
  const std::size_t want = p.shape == "rectangle" ? 2
                           : p.shape == "disk"    ? 1
                           : p.shape == "ring"    ? 2
                                                  : 0;
  if (p.shape == "polygon") {
    if (p.sizes.size() < 6 || p.sizes.size() % 2 != 0) {
      throw std::invalid_argument("--patch: polygon needs x1 y1 x2 y2 x3 y3 ...");
    }
  } else if (want == 0) {
    throw std::invalid_argument("--patch: unknown shape '" + p.shape +
                                "' (rectangle, disk, ring, polygon)");
  } else if (p.sizes.size() != want) {
    throw std::invalid_argument("--patch: " + p.shape + " needs " + std::to_string(want) +
                                " sizes, got " + std::to_string(p.sizes.size()));
  }
  if (p.shape != "polygon") {
    for (const ValueRange& r : p.sizes) {
      if (!(r.lo > 0.0) && !(p.shape == "ring" && &r == &p.sizes.back() && r.lo >= 0.0)) {
        throw std::invalid_argument("--patch: sizes must be > 0 in '" + text + "'");
      }
    }
  }
  return p;
}

std::string PatchRange::ToString() const {
  std::string out = shape;
  for (const ValueRange& r : sizes) out += " " + slideid::ToString(r);
  return out;
}

double UniformInertia(const ContactPatch& patch, double mass_kg) {
  std::istringstream spec(patch.Spec());
  std::string shape;
  double p = 0.0, q = 0.0;
  spec >> shape >> p >> q;
  switch (patch.shape()) {
    case ContactPatch::Shape::kRectangle:
      return mass_kg * (p * p + q * q) / 12.0;
    case ContactPatch::Shape::kDisk:
      return mass_kg * p * p / 2.0;
    case ContactPatch::Shape::kRing:
      return mass_kg * (p * p + q * q) / 2.0;
    case ContactPatch::Shape::kPolygon:
      break;
  }
  return mass_kg * PolygonRadiusOfGyrationSquared(patch.Outline());
}

// ---- the spec ----

LogSpec DatasetSpec::DefaultLog() {
  LogSpec log;
  log.log_every = 10;
  log.motion = LogMotion::kPoses;
  log.push = LogPush::kPoint;
  return log;
}

bool DatasetSpec::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (count < 1) return fail("count must be >= 1");
  if (!RangeOk(mass_kg, true)) return fail("mass range must be 0 < LO <= HI");
  if (inertia_kgm2 && !RangeOk(*inertia_kgm2, true)) {
    return fail("inertia range must be 0 < LO <= HI");
  }
  if (!RangeOk(com_height_m, false)) return fail("com-height range must be 0 <= LO <= HI");
  if (!RangeOk(mu, true)) return fail("mu range must be 0 < LO <= HI");
  if (!RangeOk(e_t, true)) return fail("e_t range must be 0 < LO <= HI");
  if (!RangeOk(e_o, true)) return fail("e_o range must be 0 < LO <= HI");
  if (!RangeOk(e_r_m, true)) return fail("e_r range must be 0 < LO <= HI");
  if (!(dt_s > 0.0 && std::isfinite(dt_s))) return fail("dt must be > 0");
  if (max_redraws < 0) return fail("max-redraws must be >= 0");
  if (pusher) {
    if (!RangeOk(pusher->mu, false)) return fail("mu-pusher range must be 0 <= LO <= HI");
    if (!RangeOk(pusher->speed_mps, true)) return fail("tip-speed range must be 0 < LO <= HI");
    if (!RangeOk(pusher->distance_m, true)) return fail("push-distance range must be 0 < LO <= HI");
    if (!(pusher->offset_fraction.lo >= -1 && pusher->offset_fraction.hi <= 1 &&
          pusher->offset_fraction.lo <= pusher->offset_fraction.hi)) {
      return fail("the pusher's offset fraction must lie in [-1, 1]");
    }
    if (!(pusher->tip_radius_m >= 0)) return fail("tip radius must be >= 0");
  }
  try {
    PatchRange::Parse(patch.ToString());
  } catch (const std::invalid_argument& e) {
    return fail(e.what());
  }
  return program.IsValid(why) && log.IsValidFor(/*has_pushes=*/true, why);
}

// ---- drawing ----

Pusher DrawPusher(const PusherDraw& d, const ContactPatch& patch, std::uint64_t seed, int index,
                  int attempt) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(attempt),
                    0x70757368u};
  std::mt19937_64 rng(seq);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto draw = [&](const ValueRange& r) { return r.lo + (r.hi - r.lo) * unit(rng); };
  double reach = 0, half = 0;  // the outline's farthest point, and its smallest half-size
  const std::vector<Eigen::Vector2d> outline = patch.Outline();
  Eigen::Vector2d lo = outline.front(), hi = outline.front();
  for (const Eigen::Vector2d& p : outline) {
    reach = std::max(reach, p.norm());
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  half = 0.5 * (hi - lo).minCoeff();
  const double heading = 2 * kPi * unit(rng);
  const Eigen::Vector2d along(std::cos(heading), std::sin(heading)), across(-along.y(), along.x());
  Pusher p;
  p.tip_radius_m = d.tip_radius_m;
  p.mu = draw(d.mu);
  const double speed = draw(d.speed_mps), distance = draw(d.distance_m);
  const double offset = draw(d.offset_fraction) * half;
  // From just outside the slider's reach (the slider at the origin, at rest) to `distance`
  // beyond where the tip meets the outline.
  const double approach = reach + d.tip_radius_m + kPusherClearanceM;
  const Eigen::Vector2d start = -approach * along + offset * across;
  const double meets =
      TravelToTouch(patch, PlanarState{}, start, along, d.tip_radius_m, 2 * approach);
  p.path = PusherPath::Polyline(0.0, start, {start + (meets + distance) * along}, {speed});
  return p;
}

DatasetEntry DrawDatasetLog(const DatasetSpec& spec, int index, Trajectory* log) {
  std::string why;
  if (!spec.IsValid(&why)) throw std::invalid_argument("dataset: " + why);
  std::seed_seq seq{static_cast<std::uint32_t>(spec.seed),
                    static_cast<std::uint32_t>(spec.seed >> 32), static_cast<std::uint32_t>(index)};
  std::mt19937_64 rng(seq);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto draw = [&](const ValueRange& r) { return r.lo + (r.hi - r.lo) * unit(rng); };

  DatasetEntry entry;
  entry.file = LogFileName(index);
  for (int attempt = 0; attempt <= spec.max_redraws; ++attempt) {
    // Every variate of an attempt is drawn, in this order, whatever the options.
    LoggedScene scene;
    scene.source = "make-dataset seed " + std::to_string(spec.seed) + " " + entry.file;
    scene.slider.mass_kg = draw(spec.mass_kg);
    scene.slider.com_height_m = draw(spec.com_height_m);
    std::vector<double> sizes;
    for (const ValueRange& r : spec.patch.sizes) sizes.push_back(draw(r));
    const double inertia_draw = unit(rng);
    FrictionParameters friction;
    friction.mu = draw(spec.mu);
    friction.e_t = draw(spec.e_t);
    friction.e_o = draw(spec.e_o);
    friction.e_r = draw(spec.e_r_m);
    scene.friction = friction;
    RandomProgramSpec program = spec.program;
    program.seed = rng();
    if (spec.align_pushes) {
      program.time_grid_s = spec.dt_s * spec.log.log_every;
      program.grid_lead_s = spec.dt_s / 2;
    }
    scene.log = spec.log;
    scene.log.noise.seed = rng();
    scene.dt_s = spec.dt_s;

    const std::string tag = "draw " + std::to_string(attempt) + ": ";
    try {
      scene.patch = BuildPatch(spec.patch.shape, sizes);
    } catch (const std::invalid_argument& e) {
      entry.redraw_reasons.push_back(tag + "invalid patch: " + e.what());
      continue;
    }
    scene.slider.inertia_kgm2 =
        spec.inertia_kgm2
            ? spec.inertia_kgm2->lo + (spec.inertia_kgm2->hi - spec.inertia_kgm2->lo) * inertia_draw
            : UniformInertia(scene.patch, scene.slider.mass_kg);
    if (spec.pusher) {
      scene.pusher = DrawPusher(*spec.pusher, scene.patch, spec.seed, index, attempt);
      scene.duration_s = scene.pusher->path.end_s() + kPusherRunOutS;
    } else {
      const PushProgram pushes =
          RandomPushProgram(program, scene.patch, scene.slider, scene.friction.reduced());
      scene.pushes = pushes.pushes;
      scene.duration_s = pushes.end_s;
    }
    const SimulationResult sim = Simulate(scene);
    if (!sim.summary.ok()) {
      entry.redraw_reasons.push_back(tag + ToString(sim.summary.status) + ": " +
                                     sim.summary.message);
      continue;
    }
    entry.scene = scene;
    *log = MakeLog(sim.trajectory, scene.log);
    entry.rows = static_cast<int>(log->samples.size());
    return entry;
  }
  std::string reasons;
  for (const std::string& r : entry.redraw_reasons) reasons += "\n  " + r;
  throw NoValidDraw("dataset: " + entry.file + ": no valid draw in " +
                    std::to_string(spec.max_redraws + 1) + " attempts:" + reasons);
}

}  // namespace slideid
