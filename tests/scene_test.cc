#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

#include "datasets/push_program.h"
#include "forward_model/constants.h"
#include "io/scene_file.h"

namespace slideid {
namespace {

/// Wrench components are a few products of short decimals and cos/sin: exact to ulps.
constexpr double kTol = 1e-12;

std::string ScenePath(const std::string& name) {
  return std::string(SLIDEID_SOURCE_DIR) + "/datasets/scenes/" + name;
}

/// A complete, valid scene without a push; tests append or replace lines.
const char* const kMinimal = R"(# minimal scene
[slider]
mass = 0.5   # kg
inertia = 2e-4
com_height = 0.08
[friction]
mu = 0.31
e_t = 1
e_o = 1
e_r = 0.01
[sim]
dt = 0.01
duration = 0.45
)";
const char* const kSquare = "[patch]\nshape = rectangle\nwidth = 0.05\nlength = 0.05\n";

/// Minimal scene with `patch` and `extra` sections appended.
std::string SceneText(const std::string& extra, const std::string& patch = kSquare) {
  return std::string(kMinimal) + patch + extra;
}

/// ParseScene's SceneError message, or "" when it parses.
std::string ErrorOf(const std::string& text) {
  try {
    ParseScene(text, "scene.ini");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

/// Expects a SceneError whose message contains the file name and every fragment.
void ExpectError(const std::string& text, const std::string& key, const std::string& detail) {
  const std::string message = ErrorOf(text);
  EXPECT_NE(message.find("scene.ini: "), std::string::npos) << message;
  EXPECT_NE(message.find(key), std::string::npos) << "wanted '" << key << "' in: " << message;
  EXPECT_NE(message.find(detail), std::string::npos) << "wanted '" << detail << "' in: " << message;
}

TEST(Scene, MinimalSceneTakesDefaultsForOptionalKeys) {
  const Scene s = ParseScene(SceneText(""), "scene.ini");
  EXPECT_EQ(s.source, "scene.ini");
  EXPECT_EQ(s.slider.mass_kg, 0.5);
  EXPECT_EQ(s.slider.gravity_mps2, 9.81);
  EXPECT_EQ(s.initial.x, 0.0);
  EXPECT_EQ(s.initial.wz, 0.0);
  EXPECT_TRUE(s.pushes.empty());
  EXPECT_EQ(s.patch.shape(), ContactPatch::Shape::kRectangle);
}

TEST(Scene, UnknownKeyOrSectionIsAnErrorNamingIt) {
  ExpectError(SceneText("[foo]\nbar = 1\n"), "unknown key 'foo.bar'", "line 19");
  ExpectError(SceneText("[sim]\nsteps = 3\n"), "'sim.steps'", "unknown key");
  ExpectError(SceneText("[empty]\n"), "unknown section [empty]", "line 18");
}

TEST(Scene, MissingRequiredKeyIsAnErrorNamingIt) {
  std::string text = SceneText("");
  text.erase(text.find("mu = 0.31\n"), 10);
  ExpectError(text, "[friction] mu", "missing required key");
  ExpectError(SceneText("", "[patch]\nshape = rectangle\nwidth = 0.05\n"), "[patch] length",
              "missing");
  ExpectError(SceneText("[push]\nforce = 1\n"), "[push] point", "missing");
  ExpectError(SceneText("[push]\npoint = 0 0\n"), "[push] force", "missing");
}

TEST(Scene, NonNumericValueNamesKeyAndText) {
  std::string text = SceneText("");
  text.replace(text.find("e_r = 0.01"), 10, "e_r = 1cm");
  ExpectError(text, "[friction] e_r", "'1cm' is not a number");
  ExpectError(SceneText("[initial]\nvx = nan\n"), "[initial] vx", "not finite");
  ExpectError(SceneText("[push]\npoint = 0 x\nforce = 1\n"), "[push] point", "'x'");
}

TEST(Scene, OutOfRangeValueNamesKeyValueAndLine) {
  std::string text = SceneText("");
  text.replace(text.find("mass = 0.5"), 10, "mass = -1");
  ExpectError(text, "[slider] mass = -1", "must be > 0 (line 3)");
  text = SceneText("");
  text.replace(text.find("dt = 0.01"), 9, "dt = 0");
  ExpectError(text, "[sim] dt = 0", "must be > 0");
  text = SceneText("");
  text.replace(text.find("com_height = 0.08"), 17, "com_height = -0.01");
  ExpectError(text, "[slider] com_height", ">= 0");
}

TEST(Scene, DuplicateKeyAndBadSyntaxAreErrors) {
  ExpectError(SceneText("[sim]\ndt = 0.02\n"), "[sim] dt", "more than once");
  ExpectError(SceneText("[initial]\nvx 3\n"), "invalid line 'vx 3'", "(line 19)");
}

// A byte-order mark (Notepad writes one) is skipped, as the log reader skips it; it was an
// error: "invalid line '\xEF\xBB\xBF'". CRLF line ends read too. Line numbers are unchanged.
TEST(Scene, AByteOrderMarkAndCrlfLineEndsAreRead) {
  const Scene plain = ParseScene(SceneText(""), "scene.ini");
  const Scene bom = ParseScene("\xEF\xBB\xBF" + SceneText(""), "scene.ini");
  EXPECT_EQ(bom.slider.mass_kg, plain.slider.mass_kg);
  EXPECT_EQ(bom.dt_s, plain.dt_s);
  EXPECT_EQ(bom.duration_s, plain.duration_s);
  EXPECT_EQ(ErrorOf("\xEF\xBB\xBF# a comment first\n" + SceneText("")), "");
  std::string crlf = "\xEF\xBB\xBF" + SceneText("");
  for (std::size_t at = crlf.find('\n'); at != std::string::npos; at = crlf.find('\n', at + 2)) {
    crlf.replace(at, 1, "\r\n");
  }
  EXPECT_EQ(ParseScene(crlf, "scene.ini").slider.mass_kg, plain.slider.mass_kg);
  ExpectError("\xEF\xBB\xBF" + SceneText("[foo]\nbar = 1\n"), "unknown key 'foo.bar'", "line 19");
}

TEST(Scene, PatchKeyIrrelevantToShapeIsAnError) {
  ExpectError(SceneText("", "[patch]\nshape = disk\nradius = 0.1\nwidth = 0.05\n"), "[patch] width",
              "not used by shape 'disk'");
  ExpectError(SceneText("", std::string(kSquare) + "inner_radius = 0.01\n"), "[patch] inner_radius",
              "not used by shape 'rectangle'");
  ExpectError(SceneText("", "[patch]\nshape = hexagon\n"), "[patch] shape = hexagon",
              "unknown shape");
}

TEST(Scene, DegeneratePatchIsAnErrorNamingTheKey) {
  ExpectError(SceneText("", "[patch]\nshape = ring\nradius = 0.1\ninner_radius = 0.1\n"),
              "[patch] inner_radius = 0.1", "must be >= 0 and < the outer radius");
  ExpectError(SceneText("", "[patch]\nshape = polygon\nvertices = 0 0 0 1 1 1 1 0\n"),
              "[patch] vertices", "counter-clockwise");
  ExpectError(SceneText("", "[patch]\nshape = polygon\nvertices = 0 0 1 0 2 0\n"),
              "[patch] vertices", "zero area");
}

TEST(Scene, PolygonAndDiskPatchesLoad) {
  const Scene poly = ParseScene(
      SceneText("", "[patch]\nshape = polygon\nvertices = 0 0 0.1 0 0 0.1\n"), "scene.ini");
  EXPECT_EQ(poly.patch.Spec(), ContactPatch::Parse("polygon 0 0 0.1 0 0 0.1").Spec());
  const Scene disk = ParseScene(SceneText("", "[patch]\nshape = disk\nradius = 0.1\n"), "s");
  EXPECT_EQ(disk.patch.Spec(), ContactPatch::Disk(0.1).Spec());
}

TEST(Scene, PushDefaultsAndNormalisedDirection) {
  const Scene s = ParseScene(SceneText("[push]\npoint = 0.01 -0.02\ndirection = 3 4\nforce = 1\n"),
                             "scene.ini");
  ASSERT_EQ(s.pushes.size(), 1u);
  const PushSpec& p = s.pushes[0];
  EXPECT_EQ(p.point_body, Eigen::Vector2d(0.01, -0.02));
  EXPECT_NEAR(p.direction_body.x(), 0.6, kTol);
  EXPECT_NEAR(p.direction_body.y(), 0.8, kTol);
  EXPECT_EQ(p.height_m, 0.08);  // com_height
  EXPECT_EQ(p.amplitude_n, 0.0);
  EXPECT_EQ(p.period_s, 0.0);
  EXPECT_EQ(p.start_s, 0.0);
  EXPECT_EQ(p.stop_s, 1e300);
}

TEST(Scene, PushValuesAreChecked) {
  const std::string point = "[push]\npoint = 0 0\nforce = 1\n";
  ExpectError(SceneText(point + "direction = 0 0\n"), "[push] direction", "non-zero");
  ExpectError(SceneText(point + "amplitude = 1\n"), "[push] period", "must be > 0");
  ExpectError(SceneText(point + "start = 2\nstop = 1\n"), "[push] stop = 1", "must be > start");
  ExpectError(SceneText("[push]\npoint = 0 0 0\nforce = 1\n"), "[push] point", "two numbers");
}

TEST(Scene, UnreadableFileIsAnErrorNamingThePath) {
  for (const std::string& path :
       {std::string("/nonexistent/dir/scene.ini"), std::string(SLIDEID_SOURCE_DIR)}) {
    try {
      LoadScene(path);
      ADD_FAILURE() << "no SceneError for " << path;
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
    }
  }
}

TEST(PushSpec, MagnitudeIsPeriodicClampedAndWindowed) {
  PushSpec p;
  p.force_n = 2.2;
  p.amplitude_n = 2.0;
  p.period_s = 0.1;
  EXPECT_NEAR(p.MagnitudeAt(0.0), 4.2, kTol);
  EXPECT_NEAR(p.MagnitudeAt(0.05), 0.2, kTol);
  EXPECT_NEAR(p.MagnitudeAt(0.025), 2.2, kTol);
  p.force_n = 1.0;  // 1 + 2 cos: negative half the time, and a pusher cannot pull
  EXPECT_EQ(p.MagnitudeAt(0.05), 0.0);
  p.start_s = 1.0;
  p.stop_s = 2.0;
  EXPECT_EQ(p.MagnitudeAt(0.999), 0.0);
  EXPECT_NEAR(p.MagnitudeAt(1.0), 3.0, kTol);
  EXPECT_EQ(p.MagnitudeAt(2.0), 0.0);
}

TEST(PushSpec, PeriodZeroMeansConstantForce) {
  PushSpec p;
  p.force_n = 1.5;
  EXPECT_EQ(p.MagnitudeAt(0.0), 1.5);
  EXPECT_EQ(p.MagnitudeAt(123.4), 1.5);
}

TEST(PushSpec, WrenchIsRCrossFWithRotatedPointAndDirection) {
  PushSpec p;
  p.point_body = {-0.025, -0.0025};
  p.direction_body = {1.0, 0.0};
  p.height_m = 0.08;
  p.force_n = 2.0;
  PlanarState pose;
  pose.x = 1.0;
  pose.y = 2.0;
  pose.theta = kPi / 2;  // body x -> world y, body y -> world -x
  Eigen::Vector3d point;
  const AppliedWrench w = p.WrenchAt(0.0, pose, 0.08, &point);
  // World: r = (0.0025, -0.025, 0), f = (0, 2, 0); r x f = (0, 0, 0.0025 * 2).
  EXPECT_NEAR(w.fx, 0.0, kTol);
  EXPECT_NEAR(w.fy, 2.0, kTol);
  EXPECT_EQ(w.fz, 0.0);
  EXPECT_NEAR(w.tx, 0.0, kTol);
  EXPECT_NEAR(w.ty, 0.0, kTol);
  EXPECT_NEAR(w.tz, 0.005, kTol);
  EXPECT_NEAR(point.x(), 1.0025, kTol);
  EXPECT_NEAR(point.y(), 1.975, kTol);
  EXPECT_EQ(point.z(), 0.08);
}

TEST(PushSpec, PushBelowTheCmGivesTiltingMoments) {
  PushSpec p;
  p.point_body = {-0.025, 0.0};
  p.direction_body = {1.0, 0.0};
  p.height_m = 0.02;
  p.force_n = 3.0;
  const AppliedWrench w = p.WrenchAt(0.0, PlanarState{}, 0.08, nullptr);
  // r = (-0.025, 0, -0.06), f = (3, 0, 0): r x f = (0, rz fx, -ry fx) = (0, -0.18, 0).
  EXPECT_NEAR(w.tx, 0.0, kTol);
  EXPECT_NEAR(w.ty, -0.18, kTol);
  EXPECT_NEAR(w.tz, 0.0, kTol);
  p.direction_body = {0.0, 1.0};  // f = (0, 3, 0): r x f = (-rz fy, 0, rx fy)
  const AppliedWrench v = p.WrenchAt(0.0, PlanarState{}, 0.08);
  EXPECT_NEAR(v.tx, 0.18, kTol);
  EXPECT_NEAR(v.tz, -0.075, kTol);
}

TEST(PushSpec, ClampedForceGivesZeroWrench) {
  PushSpec p;
  p.point_body = {0.01, 0.02};
  p.force_n = -1.0;
  EXPECT_TRUE(p.WrenchAt(0.3, PlanarState{}, 0.05).IsZero());
}

// ---- push programs, logging and noise sections ----

TEST(Scene, NumberedPushSectionsLoadInNumericOrderAfterPush) {
  const Scene s = ParseScene(SceneText("[push.10]\npoint = 0 0\nforce = 3\nstart = 2\nstop = 3\n"
                                       "[push]\npoint = 0 0\nforce = 1\nstop = 0.5\n"
                                       "[push.2]\npoint = -0.025 0.01\ndirection = 0 1\n"
                                       "force = 2\namplitude = 0.5\nperiod = 0.2\nstart = 1\n"
                                       "stop = 1.5\nheight = 0.02\n"),
                             "scene.ini");
  ASSERT_EQ(s.pushes.size(), 3u);
  EXPECT_EQ(s.pushes[0].force_n, 1.0);
  EXPECT_EQ(s.pushes[0].stop_s, 0.5);
  EXPECT_EQ(s.pushes[1].force_n, 2.0);  // [push.2] before [push.10]
  EXPECT_EQ(s.pushes[1].point_body, Eigen::Vector2d(-0.025, 0.01));
  EXPECT_EQ(s.pushes[1].direction_body, Eigen::Vector2d(0, 1));
  EXPECT_EQ(s.pushes[1].amplitude_n, 0.5);
  EXPECT_EQ(s.pushes[1].period_s, 0.2);
  EXPECT_EQ(s.pushes[1].height_m, 0.02);
  EXPECT_EQ(s.pushes[1].start_s, 1.0);
  EXPECT_EQ(s.pushes[1].stop_s, 1.5);
  EXPECT_EQ(s.pushes[2].force_n, 3.0);
  EXPECT_EQ(s.pushes[2].height_m, 0.08);  // com_height by default, as in [push]
}

TEST(Scene, BadNumberedPushValuesNameTheirSection) {
  ExpectError(SceneText("[push.2]\npoint = 0 0\nforce = strong\n"), "[push.2] force",
              "'strong' is not a number");
  ExpectError(SceneText("[push.1]\npoint = 0 0\nforce = 1\nstart = 2\nstop = 1\n"),
              "[push.1] stop = 1", "must be > start");
  ExpectError(SceneText("[push.1]\nforce = 1\n"), "[push.1] point", "missing required key");
  ExpectError(SceneText("[push.1]\npoint = 0 0\nforce = 1\nspeed = 2\n"),
              "unknown key 'push.1.speed'", "(line 21)");
  ExpectError(SceneText("[push.x]\npoint = 0 0\n"), "unknown section [push.x]", "[push.1]");
  ExpectError(SceneText("[push.01]\npoint = 0 0\n"), "unknown section [push.01]", "");
  ExpectError(SceneText("[push.1]\npoint = 0 0\nforce = 1\n[push.1]\nforce = 2\n"),
              "[push.1] force", "more than once");
}

TEST(Scene, LogAndNoiseSectionsSetTheLogSpec) {
  const LoggedScene plain = ParseScene(SceneText(""), "scene.ini");
  EXPECT_EQ(plain.log.log_every, 1);
  EXPECT_EQ(plain.log.motion, LogMotion::kBoth);
  EXPECT_EQ(plain.log.push, LogPush::kPoint);
  EXPECT_EQ(plain.log.wrench, LogWrench::kAtRowTime);
  EXPECT_FALSE(plain.log.step_info.has_value());
  EXPECT_TRUE(plain.log.noise.IsZero());

  std::string text = SceneText(
      "[log]\nwrite = poses\npush = moments\nwrench = interval-mean\nstep_info = yes\n"
      "wrap_theta = true\n"
      "[noise]\npose = 3e-4\nangle = 3e-3\nvelocity = 0.01\nspin = 0.1\n"
      "force_relative = 0.02\nforce = 0.05\noutlier_fraction = 0.01\noutlier = 0.02\n"
      "seed = 18446744073709551615\n");
  text.replace(text.find("dt = 0.01"), 9, "dt = 0.001\nlog_every = 10");
  const LoggedScene s = ParseScene(text, "scene.ini");
  EXPECT_EQ(s.log.log_every, 10);
  EXPECT_EQ(s.log.motion, LogMotion::kPoses);
  EXPECT_EQ(s.log.push, LogPush::kMoments);
  EXPECT_EQ(s.log.wrench, LogWrench::kIntervalMean);
  EXPECT_EQ(s.log.step_info, std::optional<bool>(true));
  EXPECT_TRUE(s.log.wrap_theta);
  EXPECT_EQ(s.log.noise.pose_m, 3e-4);
  EXPECT_EQ(s.log.noise.angle_rad, 3e-3);
  EXPECT_EQ(s.log.noise.velocity_mps, 0.01);
  EXPECT_EQ(s.log.noise.spin_radps, 0.1);
  EXPECT_EQ(s.log.noise.force_relative, 0.02);
  EXPECT_EQ(s.log.noise.force_n, 0.05);
  EXPECT_EQ(s.log.noise.outlier_fraction, 0.01);
  EXPECT_EQ(s.log.noise.outlier_m, 0.02);
  EXPECT_EQ(s.log.noise.seed, 18446744073709551615ull);  // the whole 64-bit range
  EXPECT_FALSE(s.log.noise.HasDefects());

  const LoggedScene d = ParseScene(
      SceneText("[noise]\nforce_bias_x = 0.25\nforce_bias_y = -0.1\nforce_delay = 0.012\n"),
      "scene.ini");
  EXPECT_EQ(d.log.noise.force_bias_x_n, 0.25);
  EXPECT_EQ(d.log.noise.force_bias_y_n, -0.1);
  EXPECT_EQ(d.log.noise.force_delay_s, 0.012);
  EXPECT_TRUE(d.log.noise.IsZero());
}

TEST(Scene, BadLogAndNoiseValuesNameFileKeyAndValue) {
  ExpectError(SceneText("[log]\nwrite = everything\n"), "[log] write = everything",
              "poses, velocities or both");
  ExpectError(SceneText("[log]\npush = pointy\n"), "[log] push = pointy", "point or moments");
  ExpectError(SceneText("[log]\nwrite = velocities\n[push]\npoint = 0 0\nforce = 1\n"),
              "[log] write", "push = moments");
  EXPECT_EQ(ErrorOf(SceneText("[log]\nwrite = velocities\n")), "");  // no push, no points
  ExpectError(SceneText("[log]\nwrench = average\n"), "[log] wrench = average",
              "at-row-time or interval-mean");
  ExpectError(SceneText("[log]\nwrench = interval-mean\n[push]\npoint = 0 0\nforce = 1\n"),
              "[log] wrench = interval-mean", "push = moments");
  EXPECT_EQ(ErrorOf(SceneText("[log]\nwrench = interval-mean\npush = moments\n[push]\n"
                              "point = 0 0\nforce = 1\n")),
            "");
  ExpectError(SceneText("[log]\nstep_info = maybe\n"), "[log] step_info", "true or false");
  ExpectError(SceneText("[noise]\npose = -1e-3\n"), "[noise] pose = -1e-3", "must be >= 0");
  ExpectError(SceneText("[noise]\nangle = 3 mrad\n"), "[noise] angle", "not a number");
  ExpectError(SceneText("[noise]\noutlier_fraction = 1.5\n"), "[noise] outlier_fraction", "<= 1");
  ExpectError(SceneText("[noise]\nseed = -3\n"), "[noise] seed = -3", "non-negative integer");
  ExpectError(SceneText("[noise]\nseed = 1.5\n"), "[noise] seed", "non-negative integer");
  ExpectError(SceneText("[noise]\nseed = 99999999999999999999999\n"), "[noise] seed", "too large");
  ExpectError(SceneText("[noise]\nsigma = 1\n"), "unknown key 'noise.sigma'", "line 19");
  ExpectError(SceneText("[noise]\nforce_delay = 10 ms\n"), "[noise] force_delay", "not a number");
  ExpectError(SceneText("[noise]\nforce_bias_x = inf\n"), "[noise] force_bias_x", "finite");
  std::string text = SceneText("");
  text.replace(text.find("dt = 0.01"), 9, "dt = 0.01\nlog_every = 0");
  ExpectError(text, "[sim] log_every = 0", "must be >= 1");
  text = SceneText("");
  text.replace(text.find("dt = 0.01"), 9, "dt = 0.01\nlog_every = 2.5");
  ExpectError(text, "[sim] log_every", "not a non-negative integer");
}

/// A scene with a random program and no [sim] duration.
std::string ProgramScene(const std::string& program_keys) {
  std::string text = SceneText("[program]\n" + program_keys);
  text.erase(text.find("duration = 0.45\n"), 16);
  return text;
}

TEST(Scene, RandomProgramIsDrawnIntoThePushesAndSetsTheDuration) {
  const Scene s = ParseScene(ProgramScene("random = 4\nseed = 7\nforce = 2 3\n"
                                          "duration = 0.2 0.3\nrest = 0.1\n"),
                             "scene.ini");
  ASSERT_EQ(s.pushes.size(), 4u);
  RandomProgramSpec spec;
  spec.count = 4;
  spec.seed = 7;
  spec.force_n = ValueRange{2, 3};
  spec.duration_s = {0.2, 0.3};
  spec.rest_s = {0.1, 0.1};
  const PushProgram expected = RandomPushProgram(spec, s.patch, s.slider, s.friction.reduced());
  for (size_t i = 0; i < s.pushes.size(); ++i) {
    EXPECT_EQ(s.pushes[i].point_body, expected.pushes[i].point_body) << i;
    EXPECT_EQ(s.pushes[i].force_n, expected.pushes[i].force_n) << i;
    EXPECT_GE(s.pushes[i].force_n, 2.0);
    EXPECT_LE(s.pushes[i].force_n, 3.0);
    EXPECT_EQ(s.pushes[i].start_s, expected.pushes[i].start_s) << i;
  }
  EXPECT_EQ(s.duration_s, expected.end_s);
  EXPECT_NEAR(s.pushes[1].start_s - s.pushes[0].stop_s, 0.1, 1e-12);  // rest = 0.1
}

TEST(Scene, ProgramSettingsAreChecked) {
  ExpectError(ProgramScene("seed = 3\n"), "[program] random", "missing required key");
  ExpectError(ProgramScene("random = 0\n"), "[program] random = 0", "must be >= 1");
  ExpectError(ProgramScene("random = 3\nforce = 3 1\n"), "[program] force = 3 1", "lo <= hi");
  ExpectError(ProgramScene("random = 3\nduration = 0 1\n"), "[program] duration", "> 0");
  ExpectError(ProgramScene("random = 3\nrest = 1 2 3\n"), "[program] rest", "\"lo hi\"");
  ExpectError(ProgramScene("random = 3\nspread = 2\n"), "[program] spread", "pi/2");
  ExpectError(ProgramScene("random = 3\nthrough_cm = sometimes\n"), "[program] through_cm",
              "true or false");
  ExpectError(ProgramScene("random = 3\n") + "[push.1]\npoint = 0 0\nforce = 1\n",
              "[program] cannot be combined with [push]", "line");
  EXPECT_EQ(ErrorOf(ProgramScene("random = 2\n")), "");          // duration from the program
  EXPECT_EQ(ErrorOf(SceneText("[program]\nrandom = 2\n")), "");  // or given
}

TEST(Scene, BundledDefaultPushSceneIsARealisticExperiment) {
  const LoggedScene s = LoadScene(ScenePath("default_push.ini"));
  EXPECT_GE(s.slider.mass_kg, 0.5);
  EXPECT_LE(s.slider.mass_kg, 1.0);
  EXPECT_NE(s.friction.paper().e_o, s.friction.paper().e_t);  // b != 1
  EXPECT_GE(s.pushes.size(), 4u);
  EXPECT_EQ(s.dt_s * s.log.log_every, 0.01);  // 100 Hz log of a finer simulation
  EXPECT_GT(s.log.log_every, 1);
  EXPECT_EQ(s.log.motion, LogMotion::kPoses);
  EXPECT_EQ(s.log.push, LogPush::kPoint);
  EXPECT_EQ(s.log.noise.pose_m, 3e-4);
  EXPECT_EQ(s.log.noise.angle_rad, 3e-3);
  EXPECT_EQ(s.log.noise.force_relative, 0.02);
  EXPECT_EQ(s.log.noise.force_n, 0.05);
}

TEST(Scene, BundledExample1LoadsWithThePapersNumbers) {
  const Scene s = LoadScene(ScenePath("example1_square.ini"));
  EXPECT_EQ(s.slider.mass_kg, 0.5);
  EXPECT_EQ(s.slider.inertia_kgm2, 2.0833333333333333e-4);
  EXPECT_NEAR(s.slider.inertia_kgm2, 0.5 * (0.05 * 0.05 + 0.05 * 0.05) / 12, 1e-18);
  EXPECT_EQ(s.slider.com_height_m, 0.08);
  EXPECT_EQ(s.slider.gravity_mps2, 9.8);
  EXPECT_EQ(s.friction.paper().mu, 0.31);
  EXPECT_EQ(s.friction.paper().e_t, 1.0);
  EXPECT_EQ(s.friction.paper().e_o, 1.0);
  EXPECT_EQ(s.friction.paper().e_r, 0.01);
  EXPECT_EQ(s.patch.Spec(), ContactPatch::Rectangle(0.05, 0.05).Spec());
  EXPECT_EQ(s.initial.vx, 0.7);
  EXPECT_EQ(s.initial.vy, 0.9);
  EXPECT_EQ(s.initial.wz, 10.0);
  EXPECT_TRUE(s.pushes.empty());
  EXPECT_EQ(s.dt_s, 0.01);
  EXPECT_EQ(s.duration_s, 0.45);
}

TEST(Scene, BundledExample2LoadsWithThePapersNumbers) {
  const Scene s = LoadScene(ScenePath("example2_ring.ini"));
  EXPECT_EQ(s.slider.mass_kg, 1.0);
  EXPECT_EQ(s.slider.inertia_kgm2, 0.00625);
  EXPECT_EQ(s.slider.com_height_m, 0.08);
  EXPECT_EQ(s.slider.gravity_mps2, 9.8);
  EXPECT_EQ(s.friction.paper().mu, 0.31);
  EXPECT_EQ(s.friction.paper().e_r, 0.01);
  EXPECT_EQ(s.patch.Spec(), ContactPatch::Ring(0.1, 0.05).Spec());
  EXPECT_EQ(s.initial.vx, 1.3);
  EXPECT_EQ(s.initial.vy, 0.8);
  EXPECT_EQ(s.initial.wz, 11.0);
  EXPECT_TRUE(s.pushes.empty());
  EXPECT_EQ(s.dt_s, 0.01);
  EXPECT_EQ(s.duration_s, 0.65);
}

TEST(Scene, BundledExample3LoadsWithThePapersPush) {
  const Scene s = LoadScene(ScenePath("example3_pushed_square.ini"));
  EXPECT_EQ(s.slider.mass_kg, 1.0);  // the previous example's mass (scene comment)
  EXPECT_NEAR(s.slider.inertia_kgm2, 1.0 * (0.05 * 0.05 + 0.05 * 0.05) / 12, 1e-18);
  EXPECT_EQ(s.patch.Spec(), ContactPatch::Rectangle(0.05, 0.05).Spec());
  EXPECT_EQ(s.initial.vx, 0.2);
  EXPECT_EQ(s.initial.vy, 0.3);
  EXPECT_EQ(s.initial.wz, 0.0);
  EXPECT_EQ(s.dt_s, 0.01);
  EXPECT_EQ(s.duration_s, 3.0);
  ASSERT_EQ(s.pushes.size(), 1u);
  const PushSpec& p = s.pushes[0];
  EXPECT_EQ(p.point_body, Eigen::Vector2d(-0.025, -0.0025));
  EXPECT_EQ(p.direction_body, Eigen::Vector2d(1.0, 0.0));
  EXPECT_EQ(p.height_m, s.slider.com_height_m);
  EXPECT_EQ(p.force_n, 2.2);
  EXPECT_EQ(p.amplitude_n, 2.0);
  EXPECT_EQ(p.period_s, 0.1);
  // Pushing at CM height: no tilting moment; the offset below the middle turns it.
  const AppliedWrench w = p.WrenchAt(0.0, s.initial, s.slider.com_height_m);
  EXPECT_EQ(w.tx, 0.0);
  EXPECT_EQ(w.ty, 0.0);
  EXPECT_NEAR(w.fx, 4.2, kTol);
  EXPECT_NEAR(w.tz, 0.0025 * 4.2, kTol);
}

}  // namespace
// [pusher]: a straight push from a point of the outline, or waypoints, and their errors.
TEST(Scene, PusherSectionGivesAStraightPushOrWaypoints) {
  const Scene straight =
      ParseScene(SceneText("[pusher]\npoint = -0.025 0.01\ndirection = 1 0\ndistance = 0.05\n"
                           "speed = 0.02\nmu = 0.4\ntip_radius = 0.005\nstart_time = 0.1\n"),
                 "scene.ini");
  ASSERT_TRUE(straight.pusher.has_value());
  const Pusher& p = *straight.pusher;
  EXPECT_EQ(p.mu, 0.4);
  EXPECT_EQ(p.tip_radius_m, 0.005);
  EXPECT_FALSE(p.height_m.has_value());
  // One tip radius behind the point along the normal, then 50 mm at 20 mm/s.
  EXPECT_NEAR((p.path.PositionAt(0.1) - Eigen::Vector2d(-0.030, 0.01)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((p.path.PositionAt(10) - Eigen::Vector2d(0.020, 0.01)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(p.path.end_s(), 0.1 + 2.5, 1e-12);
  EXPECT_EQ(straight.duration_s, 0.45);  // [sim] duration wins when given

  // Oblique, at 45 degrees: the tip starts just touching, r sqrt(2) back along the direction.
  const Scene oblique =
      ParseScene(SceneText("[pusher]\npoint = -0.025 0\ndirection = 1 1\ndistance = 0.01\n"
                           "speed = 0.02\ntip_radius = 0.005\n"),
                 "scene.ini");
  EXPECT_NEAR((oblique.pusher->path.PositionAt(0) - Eigen::Vector2d(-0.030, -0.005)).norm(), 0.0,
              1e-12);

  const Scene waypoints = ParseScene(
      SceneText("[pusher]\nstart = -0.1 0\npath = -0.03 0 -0.03 0.02\nspeed = 0.1 0.02\n"),
      "scene.ini");
  ASSERT_TRUE(waypoints.pusher.has_value());
  EXPECT_NEAR(waypoints.pusher->path.end_s(), 0.07 / 0.1 + 0.02 / 0.02, 1e-12);

  ExpectError(SceneText("[pusher]\nspeed = 0.1\n"), "[pusher] point", "needs one of");
  ExpectError(SceneText("[pusher]\npoint = 0 0\ndirection = 0 0\ndistance = 1\nspeed = 1\n"),
              "[pusher] direction", "non-zero");
  ExpectError(SceneText("[pusher]\nstart = 0 0\npath = 1 1 2\nspeed = 1\n"), "[pusher] path",
              "pairs");
  ExpectError(SceneText("[pusher]\nstart = 0 0\npath = 1 1 2 2\nspeed = 1 1 1\n"), "[pusher] speed",
              "one per path segment");
  ExpectError(SceneText("[pusher]\npoint = 0 0\ndirection = 1 0\ndistance = 1\nspeed = 1\n"
                        "mu = -1\n"),
              "[pusher] mu", ">= 0");
  ExpectError(SceneText("[push]\npoint = 0 0\nforce = 1\n[pusher]\npoint = 0 0\n"
                        "direction = 1 0\ndistance = 1\nspeed = 1\n"),
              "[pusher] cannot be combined", "line");
}

// [pusher] path_file: the tip's path from a CSV of t, x, y beside the scene file, shifted by
// start_time; a bad file is an error naming the key, the file, the line and the column.
TEST(Scene, PusherPathFileIsReadBesideTheScene) {
  const std::string dir = ::testing::TempDir() + "/pusher_path_scene";
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  std::ofstream(dir + "/path.csv") << "# the tip\nt,x,y,note\n0,-0.04,0,a\n0.5,-0.02,0.001,b\n"
                                      "1.5,0.01,0.002,c\n";
  std::ofstream(dir + "/scene.ini")
      << SceneText("[pusher]\npath_file = path.csv\nstart_time = 0.25\n");
  const Scene scene = LoadScene(dir + "/scene.ini");
  ASSERT_TRUE(scene.pusher.has_value());
  EXPECT_EQ(scene.pusher->path.times_s().front(), 0.25);
  EXPECT_EQ(scene.pusher->path.end_s(), 1.75);
  EXPECT_EQ(scene.pusher->path.PositionAt(0.75), Eigen::Vector2d(-0.02, 0.001));

  std::ofstream(dir + "/back.csv") << "t,x,y\n0,0,0\n0.5,0,0\n0.5,1,1\n";
  std::ofstream(dir + "/back.ini") << SceneText("[pusher]\npath_file = back.csv\n");
  try {
    LoadScene(dir + "/back.ini");
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("[pusher] path_file"), std::string::npos) << what;
    EXPECT_NE(what.find("back.csv:4: column 't'"), std::string::npos) << what;
  }
  std::ofstream(dir + "/noy.csv") << "t,x\n0,0\n";
  std::ofstream(dir + "/noy.ini") << SceneText("[pusher]\npath_file = noy.csv\n");
  EXPECT_THROW(LoadScene(dir + "/noy.ini"), SceneError);
  ExpectError(SceneText("[pusher]\npath_file = p.csv\npoint = 0 0\n"), "[pusher]", "one of");
}

}  // namespace slideid
