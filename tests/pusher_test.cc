// The position-controlled pusher (forward_model/pusher_step.h), checked against what is
// known independently of it: the paper's quasi-static closed form, Lynch & Mason's motion
// cone, symmetry, the energy balance, and the force-driven step replaying the tip's force.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "forward_model/constants.h"
#include "forward_model/pusher_step.h"
#include "forward_model/quasi_static.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"
#include "io/simulated_log.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

constexpr double kHalfSide = 0.045;  // a 90 mm square, like the MIT rect1
constexpr double kTip = 0.00475;

Scene SquareScene(double c_m = 0.035) {
  Scene scene;
  scene.slider = {0.837, 1.13e-3, 0.0, 9.81};  // q_z = 0: the ECP under the CM
  scene.friction = ReducedFriction{0.3, 1.0, c_m};
  scene.patch = ContactPatch::Rectangle(2 * kHalfSide, 2 * kHalfSide);
  scene.dt_s = 1e-3;
  return scene;
}

/// A pusher touching the left edge at body y = offset, moving at `speed` along `direction`.
Pusher StraightPusher(double offset_m, const Eigen::Vector2d& direction, double speed_mps,
                      double duration_s, double mu_p) {
  Pusher p;
  const Eigen::Vector2d start(-kHalfSide - kTip, offset_m);
  p.path = PusherPath({0.0, duration_s},
                      {start, start + speed_mps * duration_s * direction.normalized()});
  p.tip_radius_m = kTip;
  p.mu = mu_p;
  return p;
}

SimulationResult RunPush(Scene scene, const Pusher& pusher, double duration_s) {
  scene.pusher = pusher;
  scene.duration_s = duration_s;
  SimulationResult r = Simulate(scene);
  EXPECT_TRUE(r.summary.ok()) << r.summary.message;
  return r;
}

// Slow limit, tip sticking: the slider's twist is the paper's quasi-static closed form
// (equations quasi_1..3) for the contact point moving with the tip, within 1%.
TEST(Pusher, SlowStickingPushMatchesTheQuasiStaticClosedForm) {
  for (const double offset : {0.0, 0.01, 0.025}) {
    for (const double angle_deg : {0.0, 10.0, -15.0}) {
      SCOPED_TRACE(::testing::Message() << "offset " << offset << " angle " << angle_deg);
      const double a = angle_deg * kPi / 180;
      const Eigen::Vector2d direction(std::cos(a), std::sin(a));
      const double speed = 2e-3;
      const SimulationResult r =
          RunPush(SquareScene(), StraightPusher(offset, direction, speed, 1.0, 1.0), 0.4);
      EXPECT_EQ(r.summary.tip_slide_steps, 0);
      const TrajectorySample& s = r.trajectory.samples.back();
      const TrajectorySample& before = r.trajectory.samples[r.trajectory.samples.size() - 2];
      const Eigen::Vector2d arm =
          before.push_point_world->head<2>() - Eigen::Vector2d(before.state.x, before.state.y);
      const Eigen::Vector3d expected = QuasiStaticTwist(arm, speed * direction, 0.035);
      const Eigen::Vector3d got(s.state.vx, s.state.vy, s.state.wz);
      const double scale = std::max(expected.head<2>().norm(), 1e-12);
      EXPECT_NEAR(got.x(), expected.x(), 0.01 * scale);
      EXPECT_NEAR(got.y(), expected.y(), 0.01 * scale);
      EXPECT_NEAR(got.z(), expected.z(), 0.01 * std::max(std::abs(expected.z()), scale / 0.035));
    }
  }
}

/// The angle [rad] of the contact-point velocity that the friction-cone edge force
/// (1, side * mu_p) at (-L, offset) gives through the isotropic ellipsoid (Lynch & Mason
/// 1996: the motion cone's edge).
double MotionConeEdge(double offset, double mu_p, double c_m, double side) {
  const Eigen::Vector2d f(1.0, side * mu_p), r(-kHalfSide, offset);
  const double moment = r.x() * f.y() - r.y() * f.x();
  const double w = moment / (c_m * c_m);
  const Eigen::Vector2d vc(f.x() - w * r.y(), f.y() + w * r.x());
  return std::atan2(vc.y(), vc.x());
}

// The sticking/sliding boundary is the motion cone: a tip moving 4 degrees inside either
// edge sticks, 4 degrees outside it slides along the edge.
TEST(Pusher, TheTipSticksInsideTheMotionConeAndSlidesOutsideIt) {
  const double mu_p = 0.3, c = 0.035;
  for (const double offset : {0.0, 0.02}) {
    for (const double side : {1.0, -1.0}) {
      const double edge = MotionConeEdge(offset, mu_p, c, side);
      for (const double margin_deg : {-4.0, 4.0}) {
        const double a = edge + side * margin_deg * kPi / 180;
        SCOPED_TRACE(::testing::Message() << "offset " << offset << " edge " << edge * 180 / kPi
                                          << " deg, tip at " << a * 180 / kPi << " deg");
        const SimulationResult r =
            RunPush(SquareScene(c),
                    StraightPusher(offset, {std::cos(a), std::sin(a)}, 2e-3, 1.0, mu_p), 0.3);
        const int contact = r.summary.tip_stick_steps + r.summary.tip_slide_steps;
        ASSERT_GT(contact, 250);
        if (margin_deg < 0) {
          EXPECT_EQ(r.summary.tip_slide_steps, 0);
        } else {
          EXPECT_GT(r.summary.tip_slide_steps, contact - 20);
        }
      }
    }
  }
}

// Through the CM along a principal axis: the slider translates without turning.
TEST(Pusher, APushThroughTheCentreAlongAnAxisDoesNotTurnTheSlider) {
  for (const double speed : {0.01, 0.2}) {
    const SimulationResult r = RunPush(
        SquareScene(), StraightPusher(0.0, Eigen::Vector2d::UnitX(), speed, 1.0, 0.25), 0.5);
    for (const TrajectorySample& s : r.trajectory.samples) {
      ASSERT_NEAR(s.state.theta, 0.0, 1e-12);
      ASSERT_NEAR(s.state.y, 0.0, 1e-12);
    }
    EXPECT_GT(r.trajectory.samples.back().state.x, 0.5 * speed * 0.5);
  }
}

double KineticEnergy(const SliderProperties& s, const PlanarState& q) {
  return 0.5 * s.mass_kg * (q.vx * q.vx + q.vy * q.vy) + 0.5 * s.inertia_kgm2 * q.wz * q.wz;
}

// Energy never rises by more than the tip's work over the step (the impulse times the
// contact point's end velocity), and not at all while the tip is apart; every step meets
// the tip's conditions: no overlap at its end, no slip while sticking. Random tip paths that
// approach, push, leave and come back, random mu_p, slider and step.
TEST(Pusher, EnergyNeverRisesWithoutTheTipsWorkAndEveryStepMeetsItsConditions) {
  std::mt19937 rng(20261125);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int apart = 0, stick = 0, slide = 0;
  for (int k = 0; k < 40; ++k) {
    Scene scene = SquareScene(0.02 + 0.03 * u(rng));
    scene.slider.mass_kg = 0.01 + 2 * u(rng);
    scene.slider.inertia_kgm2 =
        scene.slider.mass_kg * 2 * kHalfSide * kHalfSide / 3 * (0.5 + u(rng));
    scene.slider.com_height_m = k % 2 ? 0.0 : 0.006;
    ReducedFriction drawn = scene.friction.reduced();
    drawn.b = 0.7 + 0.8 * u(rng);
    scene.friction = drawn;
    scene.dt_s = k % 3 == 0 ? 1e-4 : k % 3 == 1 ? 1e-3 : 1e-2;
    Pusher pusher;
    pusher.mu = k % 5 == 0 ? 0.0 : 1.5 * u(rng);
    pusher.tip_radius_m = kTip;
    const double y = (2 * u(rng) - 1) * 0.035, speed = 0.01 + 0.3 * u(rng);
    const double turn = (2 * u(rng) - 1) * 0.8;
    const Eigen::Vector2d start(-kHalfSide - kTip - 0.005, y);
    const Eigen::Vector2d in = start + Eigen::Vector2d(0.04, 0.04 * std::tan(turn));
    const Eigen::Vector2d out = in - Eigen::Vector2d(0.01, 0);
    pusher.path = PusherPath::Polyline(0.0, start, {in, out, in + Eigen::Vector2d(0.02, 0)},
                                       {speed, speed, speed});
    const ReducedFriction friction = scene.friction.reduced();
    PlanarState q;
    const double end = pusher.path.end_s() + 0.2;
    for (double t = 0; t < end; t += scene.dt_s) {
      const PusherStepResult r =
          SolvePusherStep(scene.slider, friction, scene.patch, pusher, q, pusher.path.PositionAt(t),
                          pusher.path.PositionAt(t + scene.dt_s), AppliedWrench{}, scene.dt_s);
      ASSERT_TRUE(r.ok()) << "log " << k << " t " << t << ": " << r.message;
      ASSERT_LE(r.residual, 1e-9) << "log " << k << " t " << t;
      const PlanarState& e = r.step.state;
      const Eigen::Vector2d arm = r.contact.point_world - Eigen::Vector2d(q.x, q.y);
      const Eigen::Vector2d vc(e.vx - e.wz * arm.y(), e.vy + e.wz * arm.x());
      const double work = r.impulse_world.dot(vc);
      const double rise = KineticEnergy(scene.slider, e) - KineticEnergy(scene.slider, q);
      const double energy_scale =
          KineticEnergy(scene.slider, e) + KineticEnergy(scene.slider, q) + 1e-15;
      ASSERT_LE(rise, work + 1e-9 * energy_scale) << "log " << k << " t " << t;
      if (r.tip_mode == TipMode::kApart) ASSERT_LE(rise, 1e-12 * energy_scale);
      ASSERT_GE(r.lambda_n, 0.0);
      ASSERT_LE(std::abs(r.lambda_t), pusher.mu * r.lambda_n * (1 + 1e-8) + 1e-15);
      apart += r.tip_mode == TipMode::kApart;
      stick += r.tip_mode == TipMode::kStick;
      slide += r.tip_mode == TipMode::kSlide;
      q = e;
    }
  }
  // The suite reaches every mode of the tip.
  EXPECT_GT(apart, 100);
  EXPECT_GT(stick, 100);
  EXPECT_GT(slide, 100);
}

// The tip leaves the edge and comes back: between, no force; after, the push resumes.
TEST(Pusher, TheTipCanLeaveTheEdgeAndComeBack) {
  Scene scene = SquareScene();
  Pusher p;
  p.tip_radius_m = kTip;
  p.mu = 0.25;
  const Eigen::Vector2d start(-kHalfSide - kTip, 0.01);
  p.path = PusherPath::Polyline(0.0, start,
                                {start + Eigen::Vector2d(0.02, 0), start + Eigen::Vector2d(0.0, 0),
                                 start + Eigen::Vector2d(0.05, 0)},
                                {0.05, 0.2, 0.05});
  const SimulationResult r = RunPush(scene, p, p.path.end_s());
  bool left = false, back = false;
  for (size_t u = 0; u + 1 < r.trajectory.samples.size(); ++u) {
    const bool pushing = r.trajectory.samples[u].applied.fx != 0;
    if (!pushing && u > 10) left = true;
    if (left && pushing) back = true;
  }
  EXPECT_TRUE(left);
  EXPECT_TRUE(back);
  EXPECT_GT(r.trajectory.samples.back().state.x, 0.01);
}

// The force-driven step, replaying the force the tip applied, reproduces the pusher-driven
// trajectory: the two drives are one model.
TEST(Pusher, ReplayingTheTipsForceReproducesThePusherDrivenTrajectory) {
  Scene scene = SquareScene();
  ReducedFriction friction = scene.friction.reduced();
  friction.b = 1.3;
  scene.friction = friction;
  scene.slider.com_height_m = 0.0065;
  const double a = 1.0;  // 57 degrees off the normal: outside the motion cone, the tip slides
  const SimulationResult r =
      RunPush(scene, StraightPusher(0.02, {std::cos(a), std::sin(a)}, 0.05, 1.0, 0.2), 0.8);
  EXPECT_GT(r.summary.tip_slide_steps, 100);
  const SimulationResult replay = ReplayLog(r.trajectory, scene.friction);
  ASSERT_TRUE(replay.summary.ok()) << replay.summary.message;
  ASSERT_EQ(replay.trajectory.samples.size(), r.trajectory.samples.size());
  for (size_t u = 0; u < r.trajectory.samples.size(); ++u) {
    const PlanarState &p = r.trajectory.samples[u].state, &q = replay.trajectory.samples[u].state;
    ASSERT_NEAR(p.x, q.x, 1e-9) << u;
    ASSERT_NEAR(p.y, q.y, 1e-9) << u;
    ASSERT_NEAR(p.theta, q.theta, 1e-9) << u;
  }
}

TEST(Pusher, ContactGeometryOfBoxesAndDisks) {
  const ContactPatch box = ContactPatch::Rectangle(0.09, 0.09);
  PlanarState pose;
  pose.x = 1.0;
  pose.theta = kPi / 2;  // the box's left edge faces -y
  TipContact c = ContactWithTip(box, pose, {1.0 + 0.01, -0.045 - 0.01}, 0.005);
  EXPECT_NEAR(c.gap_m, 0.005, 1e-12);
  EXPECT_NEAR(c.normal_world.y(), -1.0, 1e-12);
  EXPECT_NEAR(c.point_world.y(), -0.045, 1e-12);
  c = ContactWithTip(box, pose, {1.0, -0.04}, 0.005);  // inside, 5 mm from the edge
  EXPECT_NEAR(c.gap_m, -0.01, 1e-12);
  EXPECT_NEAR(c.normal_world.y(), -1.0, 1e-12);
  // Beyond a corner: the normal points from the corner to the tip.
  c = ContactWithTip(box, PlanarState{}, {0.045 + 0.003, 0.045 + 0.004}, 0.0);
  EXPECT_NEAR(c.gap_m, 0.005, 1e-12);
  EXPECT_NEAR(c.normal_world.x(), 0.6, 1e-12);
  const ContactPatch disk = ContactPatch::Disk(0.05);
  c = ContactWithTip(disk, PlanarState{}, {0.0, 0.06}, 0.004);
  EXPECT_NEAR(c.gap_m, 0.006, 1e-12);
  EXPECT_NEAR(c.normal_world.y(), 1.0, 1e-12);
  // The travel to the touch: head-on to a box's edge, obliquely to a disk, or a miss.
  EXPECT_NEAR(TravelToTouch(box, PlanarState{}, {-0.1, 0.01}, {1, 0}, 0.005, 1.0), 0.05, 1e-13);
  const Eigen::Vector2d d = Eigen::Vector2d(1, 1).normalized();
  const double s = TravelToTouch(disk, PlanarState{}, {-0.1, -0.1}, d, 0.004, 1.0);
  EXPECT_NEAR((Eigen::Vector2d(-0.1, -0.1) + s * d).norm(), 0.054, 1e-13);
  EXPECT_EQ(TravelToTouch(box, PlanarState{}, {-0.1, 0.2}, {1, 0}, 0.005, 0.5), 0.5);
}

TEST(Pusher, BadPathsAndPushersAreRejectedNamingWhat) {
  EXPECT_THROW(PusherPath({0.0, 0.0}, {Eigen::Vector2d::Zero(), Eigen::Vector2d::Ones()}),
               std::invalid_argument);
  EXPECT_THROW(PusherPath::Polyline(0, Eigen::Vector2d::Zero(), {Eigen::Vector2d::Ones()}, {0.0}),
               std::invalid_argument);
  Scene scene = SquareScene();
  Pusher p;
  p.mu = -0.1;
  scene.pusher = p;
  try {
    Simulate(scene);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mu_p"), std::string::npos) << e.what();
  }
  p.mu = 0.2;
  scene.pusher = p;
  scene.pushes.push_back(PushSpec{});
  EXPECT_THROW(Simulate(scene), std::invalid_argument);
}

// The log of a pusher-driven scene carries the tip's path (tip_x, tip_y) and radius, and
// reads back bit for bit.
TEST(Pusher, TheLogCarriesTheTipsPathAndRadius) {
  LoggedScene scene;
  static_cast<Scene&>(scene) = SquareScene();
  scene.pusher = StraightPusher(0.01, Eigen::Vector2d::UnitX(), 0.05, 1.0, 0.3);
  const SimulationResult r = RunPush(scene, *scene.pusher, 0.3);
  const std::string path = testing::TempPath("pusher_log.csv");
  WritePushLog(SimulatedLogFile(scene, r.trajectory), path);
  const PushLogFile file = ReadPushLogFile(path);
  const Trajectory& back = file.log;
  EXPECT_TRUE(back.measured.tip);
  ASSERT_TRUE(back.tip_radius_m.has_value());
  EXPECT_EQ(*back.tip_radius_m, kTip);
  ASSERT_EQ(back.samples.size(), r.trajectory.samples.size());
  for (size_t u = 0; u < back.samples.size(); ++u) {
    ASSERT_TRUE(back.samples[u].tip_world.has_value());
    EXPECT_EQ(*back.samples[u].tip_world, *r.trajectory.samples[u].tip_world);
  }
  bool mu_p = false;
  for (const auto& [key, value] : file.extra_metadata)
    mu_p = mu_p || (key == "mu_p" && std::stod(value) == 0.3);
  EXPECT_TRUE(mu_p);
}

// Extremes: a 1 g slider hit at 1 m/s, a 100 kg one, a pointed tip (radius 0), mu_p = 10,
// a disk and a hexagon, steps of 0.1 ms and 20 ms: every step converges and meets the tip's
// conditions, and the slider ends ahead of where it started.
TEST(Pusher, ExtremeSlidersTipsAndStepsConvergeAndMeetTheirConditions) {
  struct Case {
    double mass, speed, radius, mu_p, dt;
    ContactPatch patch;
  };
  const std::vector<Eigen::Vector2d> hexagon = {{0.0605, 0},         {0.03025, 0.0524},
                                                {-0.03025, 0.0524},  {-0.0605, 0},
                                                {-0.03025, -0.0524}, {0.03025, -0.0524}};
  const std::vector<Case> cases = {
      {0.001, 1.0, kTip, 0.25, 1e-3, ContactPatch::Rectangle(0.09, 0.09)},
      {100.0, 0.05, kTip, 0.25, 1e-3, ContactPatch::Rectangle(0.09, 0.09)},
      {0.8, 0.1, 0.0, 0.25, 1e-3, ContactPatch::Rectangle(0.09, 0.09)},
      {0.8, 0.1, kTip, 10.0, 1e-3, ContactPatch::Rectangle(0.09, 0.09)},
      {0.8, 0.1, kTip, 0.3, 1e-4, ContactPatch::Disk(0.05)},
      {0.8, 0.1, kTip, 0.3, 2e-2, ContactPatch::Polygon(hexagon)},
      {0.001, 1.0, 0.0, 10.0, 2e-2, ContactPatch::Disk(0.05)}};
  for (size_t k = 0; k < cases.size(); ++k) {
    const Case& c = cases[k];
    Scene scene = SquareScene();
    scene.slider.mass_kg = c.mass;
    scene.slider.inertia_kgm2 = c.mass * 0.09 * 0.09 / 6;
    scene.patch = c.patch;
    scene.dt_s = c.dt;
    Pusher p;
    p.tip_radius_m = c.radius;
    p.mu = c.mu_p;
    const Eigen::Vector2d start(-0.0605 - c.radius - 0.002, 0.01);
    p.path = PusherPath::Polyline(0.0, start, {start + Eigen::Vector2d(0.05, 0.02)}, {c.speed});
    scene.pusher = p;
    scene.duration_s = p.path.end_s() + 0.05;
    const SimulationResult r = Simulate(scene);
    ASSERT_TRUE(r.summary.ok()) << "case " << k << ": " << r.summary.message;
    EXPECT_LE(r.summary.max_step_residual, 1e-9) << "case " << k;
    EXPECT_GT(r.trajectory.samples.back().state.x, 0.005) << "case " << k;
  }
}

}  // namespace
}  // namespace slideid
