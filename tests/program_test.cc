// Push programs: sections [push.N] run in sequence with rests; random programs are
// reproducible by seed, stay within their ranges and excite rotation and stick-slip.

#include <gtest/gtest.h>

#include <cmath>

#include "datasets/push_program.h"
#include "forward_model/constants.h"
#include "forward_model/simulator.h"

namespace slideid {
namespace {

// Geometry recomputed by another route (sin, acos of products): exact to ulps.
constexpr double kGeometryTol = 1e-12;

SliderProperties Box() { return {0.8, 1.3867e-3, 0.04, 9.81}; }
ReducedFriction Friction() { return {0.4, 1.3, 0.03}; }
const ContactPatch kPatch = ContactPatch::Rectangle(0.12, 0.08);

TEST(RandomProgram, SameSeedGivesTheSameProgramAndAnotherSeedAnother) {
  RandomProgramSpec spec;
  spec.seed = 9;
  const PushProgram a = RandomPushProgram(spec, kPatch, Box(), Friction());
  const PushProgram b = RandomPushProgram(spec, kPatch, Box(), Friction());
  ASSERT_EQ(a.pushes.size(), static_cast<size_t>(spec.count));
  for (size_t i = 0; i < a.pushes.size(); ++i) {
    EXPECT_EQ(a.pushes[i].point_body, b.pushes[i].point_body);
    EXPECT_EQ(a.pushes[i].direction_body, b.pushes[i].direction_body);
    EXPECT_EQ(a.pushes[i].force_n, b.pushes[i].force_n);
    EXPECT_EQ(a.pushes[i].start_s, b.pushes[i].start_s);
  }
  spec.seed = 10;
  const PushProgram c = RandomPushProgram(spec, kPatch, Box(), Friction());
  EXPECT_NE(a.pushes[0].force_n, c.pushes[0].force_n);
  EXPECT_NE(a.pushes[0].point_body, c.pushes[0].point_body);
}

TEST(RandomProgram, PushesStayWithinTheirRangesAndRestBetween) {
  RandomProgramSpec spec;
  spec.count = 40;
  spec.force_n = ValueRange{2.0, 4.0};
  spec.height_m = ValueRange{0.01, 0.02};
  spec.start_s = 0.5;
  const PushProgram p = RandomPushProgram(spec, kPatch, Box(), Friction());
  double previous_stop = spec.start_s;
  for (size_t i = 0; i < p.pushes.size(); ++i) {
    const PushSpec& q = p.pushes[i];
    const double rest = q.start_s - previous_stop;
    if (i == 0) {
      EXPECT_EQ(q.start_s, spec.start_s);
    } else {
      EXPECT_GE(rest, spec.rest_s.lo - kGeometryTol);
      EXPECT_LE(rest, spec.rest_s.hi + kGeometryTol);
    }
    EXPECT_GE(q.stop_s - q.start_s, spec.duration_s.lo - kGeometryTol);
    EXPECT_LE(q.stop_s - q.start_s, spec.duration_s.hi + kGeometryTol);
    EXPECT_GE(q.force_n, 2.0);
    EXPECT_LE(q.force_n, 4.0);
    EXPECT_LE(q.amplitude_n, spec.amplitude_fraction.hi * q.force_n);
    EXPECT_GE(q.period_s, spec.period_s.lo);
    EXPECT_LE(q.period_s, spec.period_s.hi);
    EXPECT_GE(q.height_m, 0.01);
    EXPECT_LE(q.height_m, 0.02);
    // On the patch boundary, pointing inwards, within the spread of the CM direction and
    // within the largest lever.
    EXPECT_NEAR(kPatch.SignedDistanceToHull(q.point_body), 0.0, kGeometryTol);
    EXPECT_NEAR(q.direction_body.norm(), 1.0, kGeometryTol);
    const Eigen::Vector2d to_cm = -q.point_body.normalized();
    EXPECT_GE(q.direction_body.dot(to_cm), std::cos(spec.spread_rad) - kGeometryTol);
    const double lever =
        std::abs(q.point_body.x() * q.direction_body.y() - q.point_body.y() * q.direction_body.x());
    EXPECT_LE(lever, spec.max_lever_fraction * std::hypot(0.06, 0.04) + kGeometryTol);
    previous_stop = q.stop_s;
  }
  EXPECT_GE(p.end_s - previous_stop, spec.rest_s.lo);
}

TEST(RandomProgram, PushesComeFromAllSidesAndMostAreOffCentre) {
  RandomProgramSpec spec;
  spec.count = 60;
  const PushProgram p = RandomPushProgram(spec, kPatch, Box(), Friction());
  int quadrant[4] = {0, 0, 0, 0}, off_centre = 0;
  for (const PushSpec& q : p.pushes) {
    const double angle = std::atan2(q.direction_body.y(), q.direction_body.x());
    ++quadrant[static_cast<int>(std::floor((angle + kPi) / (kPi / 2))) % 4];
    const double lever =
        std::abs(q.point_body.x() * q.direction_body.y() - q.point_body.y() * q.direction_body.x());
    if (lever > 1e-3) ++off_centre;
  }
  for (int k = 0; k < 4; ++k) EXPECT_GE(quadrant[k], 5) << "directions in quadrant " << k;
  EXPECT_GE(off_centre, 40);
}

TEST(RandomProgram, DefaultForceAndHeightScaleWithTheSlider) {
  RandomProgramSpec spec;
  spec.count = 30;
  const PushProgram p = RandomPushProgram(spec, kPatch, Box(), Friction());
  const double limit = 0.4 * 0.8 * 9.81;  // a m g
  for (const PushSpec& q : p.pushes) {
    EXPECT_GE(q.force_n, 1.1 * limit);  // every push slides the slider
    EXPECT_LE(q.force_n, 1.6 * limit);
    EXPECT_GE(q.height_m, 0.25 * 0.04);
    EXPECT_LE(q.height_m, 0.75 * 0.04);
  }
}

TEST(RandomProgram, ThroughTheCmMeansNoMomentAboutAnyAxis) {
  RandomProgramSpec spec;
  spec.through_cm = true;
  const PushProgram p = RandomPushProgram(spec, kPatch, Box(), Friction());
  for (const PushSpec& q : p.pushes) {
    const AppliedWrench w = q.WrenchAt(q.start_s, PlanarState{}, Box().com_height_m);
    EXPECT_NEAR(w.tx, 0.0, kGeometryTol);
    EXPECT_NEAR(w.ty, 0.0, kGeometryTol);
    EXPECT_NEAR(w.tz, 0.0, kGeometryTol);
  }
}

TEST(RandomProgram, TimeGridPutsSwitchesJustBeforeGridTimes) {
  RandomProgramSpec spec;
  spec.time_grid_s = 0.01;
  spec.grid_lead_s = 0.0005;
  const PushProgram p = RandomPushProgram(spec, kPatch, Box(), Friction());
  for (const PushSpec& q : p.pushes) {
    for (double t : {q.start_s, q.stop_s}) {
      const double k = (t + spec.grid_lead_s) / spec.time_grid_s;
      EXPECT_NEAR(k, std::round(k), 1e-9) << t;
    }
  }
}

TEST(RandomProgram, InvalidSpecsAreRejected) {
  RandomProgramSpec spec;
  spec.count = 0;
  EXPECT_THROW(RandomPushProgram(spec, kPatch, Box(), Friction()), std::invalid_argument);
  spec = {};
  spec.duration_s = {0.5, 0.2};
  std::string why;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("duration"), std::string::npos) << why;
  spec = {};
  spec.spread_rad = 2.0;
  EXPECT_FALSE(spec.IsValid(&why));
}

/// The default scene's box with a random program.
Scene ProgramScene(const RandomProgramSpec& spec) {
  Scene s;
  s.slider = Box();
  s.friction = Friction();
  s.patch = kPatch;
  s.dt_s = 1e-3;
  const PushProgram p = RandomPushProgram(spec, s.patch, s.slider, s.friction.reduced());
  s.pushes = p.pushes;
  s.duration_s = p.end_s;
  return s;
}

TEST(RandomProgram, SimulatedProgramHasStickSlipTransitionsAndRotation) {
  RandomProgramSpec spec;
  spec.seed = 4;
  const SimulationResult r = Simulate(ProgramScene(spec));
  ASSERT_TRUE(r.summary.ok()) << r.summary.message;
  int stick_to_slide = 0, slide_to_stick = 0;
  double max_spin = 0;
  for (size_t u = 2; u < r.trajectory.samples.size(); ++u) {
    const SampleMode a = r.trajectory.samples[u - 1].mode, b = r.trajectory.samples[u].mode;
    stick_to_slide += a == SampleMode::kStick && b == SampleMode::kSlide;
    slide_to_stick += a == SampleMode::kSlide && b == SampleMode::kStick;
    max_spin = std::max(max_spin, std::abs(r.trajectory.samples[u].state.wz));
  }
  // Each push starts from rest, each rest ends at rest (the first push starts at t = 0).
  EXPECT_GE(stick_to_slide, spec.count - 1);
  EXPECT_GE(slide_to_stick, spec.count);
  EXPECT_GT(max_spin, 0.5);   // off-centre pushes turn the slider...
  EXPECT_LT(max_spin, 20.0);  // ...but the lever cap keeps it from spinning like a top
}

TEST(RandomProgram, ThroughTheCmProgramDoesNotRotate) {
  RandomProgramSpec spec;
  spec.through_cm = true;
  const SimulationResult r = Simulate(ProgramScene(spec));
  ASSERT_TRUE(r.summary.ok()) << r.summary.message;
  for (const TrajectorySample& s : r.trajectory.samples) EXPECT_NEAR(s.state.wz, 0.0, 1e-9);
}

}  // namespace
}  // namespace slideid
