// Noise and the sensor model: determinism by seed, noise statistics against the spec,
// force noise that keeps a push-point log consistent, decimation and columns.

#include "datasets/noise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "datasets/sensor_model.h"
#include "forward_model/constants.h"
#include "io/push_log.h"
#include "io/simulated_log.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

// Statistics over kRows samples: the sample mean of N(0, s^2) has standard deviation
// s / sqrt(N), the sample standard deviation about s / sqrt(2 N). Five of those is a
// tolerance a correct generator fails with probability ~1e-6 (the seed is fixed anyway).
constexpr int kRows = 20000;
constexpr double kSigmas = 5.0;

/// A log of kRows rows at rest at (1, 2, 0.5) with a constant push of (3, -4) N at a point.
Trajectory StillLog(bool push_point) {
  Trajectory t;
  t.slider = {1.0, 1e-3, 0.05, 9.81};
  t.measured.push_point = push_point;
  for (int u = 0; u < kRows; ++u) {
    TrajectorySample s;
    s.t_s = 0.01 * u;
    s.state = {1.0, 2.0, 0.5, 0.0, 0.0, 0.0};
    s.applied = WrenchFromForceAt(3.0, -4.0, 0.0, -0.05, 0.01, -0.02);
    if (push_point) s.push_point_world = Eigen::Vector3d(0.95, 2.01, 0.03);
    t.samples.push_back(s);
  }
  return t;
}

struct Moments {
  double mean = 0, std = 0;
};

template <typename F>
Moments Statistics(const Trajectory& t, F value) {
  double sum = 0, sum2 = 0;
  for (const TrajectorySample& s : t.samples) sum += value(s);
  const double mean = sum / t.samples.size();
  for (const TrajectorySample& s : t.samples) sum2 += std::pow(value(s) - mean, 2);
  return {mean, std::sqrt(sum2 / (t.samples.size() - 1))};
}

void ExpectGaussian(const Moments& m, double mean, double sigma, const char* what) {
  const double n = kRows;
  EXPECT_NEAR(m.mean, mean, kSigmas * sigma / std::sqrt(n)) << what;
  EXPECT_NEAR(m.std, sigma, kSigmas * sigma / std::sqrt(2 * n)) << what;
}

std::string Written(const PushLogFile& file) {
  std::ostringstream out;
  WritePushLog(file, out);
  return out.str();
}

std::string Written(const Trajectory& t) { return Written(PushLogFile{t, "", {}}); }

/// `log`, made by MakeLog with `spec`, as simulate writes it: its file says how it was made
/// (io/simulated_log.h).
std::string WrittenAs(const Trajectory& log, const LogSpec& spec) {
  LoggedScene scene;
  scene.log = spec;
  return Written(SimulatedLogFile(scene, log));
}

TEST(Noise, PoseVelocityAndAngleNoiseHaveTheSpecifiedMeanAndStd) {
  NoiseSpec n;
  n.pose_m = 3e-4;
  n.angle_rad = 3e-3;
  n.velocity_mps = 0.01;
  n.spin_radps = 0.2;
  n.seed = 11;
  const Trajectory noisy = AddNoise(StillLog(false), n);
  ExpectGaussian(Statistics(noisy, [](auto& s) { return s.state.x; }), 1.0, n.pose_m, "x");
  ExpectGaussian(Statistics(noisy, [](auto& s) { return s.state.y; }), 2.0, n.pose_m, "y");
  ExpectGaussian(Statistics(noisy, [](auto& s) { return s.state.theta; }), 0.5, n.angle_rad,
                 "theta");
  ExpectGaussian(Statistics(noisy, [](auto& s) { return s.state.vx; }), 0, n.velocity_mps, "vx");
  ExpectGaussian(Statistics(noisy, [](auto& s) { return s.state.wz; }), 0, n.spin_radps, "wz");
}

TEST(Noise, ForceNoiseIsRelativePlusAbsolute) {
  NoiseSpec n;
  n.force_relative = 0.02;
  n.force_n = 0.05;
  n.seed = 12;
  const Trajectory noisy = AddNoise(StillLog(false), n);
  // fx = 3: std = hypot(0.02 * 3, 0.05); fy = -4: hypot(0.02 * 4, 0.05).
  ExpectGaussian(Statistics(noisy, [](auto& s) { return s.applied.fx; }), 3.0,
                 std::hypot(0.06, 0.05), "fx");
  ExpectGaussian(Statistics(noisy, [](auto& s) { return s.applied.fy; }), -4.0,
                 std::hypot(0.08, 0.05), "fy");
  // Without a push point the moments get the relative part.
  const double tz = StillLog(false).samples[0].applied.tz;
  ExpectGaussian(Statistics(noisy, [](auto& s) { return s.applied.tz; }), tz, 0.02 * std::abs(tz),
                 "tz");
}

TEST(Noise, OutliersHitTheSpecifiedFractionOfRowsWithTheSpecifiedJump) {
  NoiseSpec n;
  n.outlier_fraction = 0.05;
  n.outlier_m = 0.02;
  n.seed = 13;
  const Trajectory noisy = AddNoise(StillLog(false), n);
  int jumps = 0;
  for (const TrajectorySample& s : noisy.samples) {
    const double d = std::hypot(s.state.x - 1.0, s.state.y - 2.0);
    if (d == 0.0) continue;
    ++jumps;
    EXPECT_NEAR(d, n.outlier_m, 1e-12);
    EXPECT_NEAR(std::abs(s.state.theta - 0.5), n.outlier_m / 0.05, 1e-12);
  }
  // Binomial(N, p): standard deviation sqrt(N p (1 - p)).
  const double expected = n.outlier_fraction * kRows;
  EXPECT_NEAR(jumps, expected, kSigmas * std::sqrt(expected * (1 - n.outlier_fraction)));
}

TEST(Noise, SameSeedGivesTheSameBytesAndAnotherSeedOtherBytes) {
  NoiseSpec n;
  n.pose_m = 3e-4;
  n.angle_rad = 3e-3;
  n.force_relative = 0.02;
  n.force_n = 0.05;
  n.outlier_fraction = 0.01;
  n.outlier_m = 0.01;
  n.seed = 42;
  const Trajectory clean = testing::SimulateOrFail(testing::PushedSlider());
  const std::string a = Written(AddNoise(clean, n));
  EXPECT_EQ(a, Written(AddNoise(clean, n)));
  n.seed = 43;
  EXPECT_NE(a, Written(AddNoise(clean, n)));
}

TEST(Noise, AddNoiseKeepsTheFirstVersionsStreamForPoseAngleAndVelocity) {
  // The first AddNoise drew 11 normals and 2 uniforms per row from mt19937_64(seed), the
  // first six for x, y, theta, vx, vy, wz. Tests with fixed seeds rely on that stream.
  NoiseSpec n;
  n.pose_m = 1e-3;
  n.angle_rad = 1e-2;
  n.velocity_mps = 0.1;
  n.spin_radps = 1.0;
  n.seed = 5;
  const Trajectory clean = testing::SimulateOrFail(testing::FreeSlideWithSpin());
  const Trajectory noisy = AddNoise(clean, n);
  std::mt19937_64 rng(n.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (size_t u = 0; u < clean.samples.size(); ++u) {
    double z[11];
    for (double& v : z) v = normal(rng);
    uniform(rng);
    uniform(rng);
    const PlanarState& c = clean.samples[u].state;
    const PlanarState& q = noisy.samples[u].state;
    EXPECT_EQ(q.x, c.x + n.pose_m * z[0]) << u;
    EXPECT_EQ(q.y, c.y + n.pose_m * z[1]) << u;
    EXPECT_EQ(q.theta, c.theta + n.angle_rad * z[2]) << u;
    EXPECT_EQ(q.vx, c.vx + n.velocity_mps * z[3]) << u;
    EXPECT_EQ(q.vy, c.vy + n.velocity_mps * z[4]) << u;
    EXPECT_EQ(q.wz, c.wz + n.spin_radps * z[5]) << u;
  }
  EXPECT_FALSE(noisy.measured.step_info);
  EXPECT_TRUE(noisy.steps.empty());
  // What a file says of the noise (io/simulated_log.h writes it).
  EXPECT_EQ(n.Metadata().back(), std::make_pair(std::string("noise_seed"), std::string("5")));
}

TEST(Noise, PushPointMomentsFollowTheNoisyForceAndKeepTheResidualMoment) {
  NoiseSpec n;
  n.pose_m = 1e-3;
  n.force_relative = 0.05;
  n.force_n = 0.1;
  n.seed = 21;
  Trajectory clean = StillLog(true);
  clean.samples.resize(50);
  const AppliedWrench residual{0, 0, 0, 0.001, -0.002, 0.003};  // a second, pure moment
  for (TrajectorySample& s : clean.samples) {
    s.applied.tx += residual.tx;
    s.applied.ty += residual.ty;
    s.applied.tz += residual.tz;
  }
  const Trajectory noisy = AddNoise(clean, n);
  for (const TrajectorySample& s : noisy.samples) {
    const Eigen::Vector3d& p = *s.push_point_world;
    const AppliedWrench rxf =
        WrenchFromForceAt(s.applied.fx, s.applied.fy, s.applied.fz, p.x() - s.state.x,
                          p.y() - s.state.y, p.z() - noisy.slider.com_height_m);
    EXPECT_NEAR(s.applied.tx - rxf.tx, residual.tx, 1e-15);
    EXPECT_NEAR(s.applied.ty - rxf.ty, residual.ty, 1e-15);
    EXPECT_NEAR(s.applied.tz - rxf.tz, residual.tz, 1e-15);
  }
  // Written and read back, the log gives the same wrenches: it is consistent.
  const std::string path = ::testing::TempDir() + "/noise_push_point.csv";
  WritePushLog(noisy, path);
  const Trajectory back = ReadPushLog(path);
  for (size_t u = 0; u < noisy.samples.size(); ++u) {
    EXPECT_EQ(back.samples[u].applied.tz, noisy.samples[u].applied.tz) << u;
    EXPECT_EQ(back.samples[u].applied.fx, noisy.samples[u].applied.fx) << u;
  }
}

TEST(Noise, PushPointNoiseHasTheSpecifiedStdAndTheMomentFollowsTheReportedPoint) {
  NoiseSpec n;
  n.push_point_m = 4e-4;
  n.seed = 9;
  const Trajectory clean = StillLog(true);
  const Trajectory noisy = AddNoise(clean, n);
  ExpectGaussian(
      Statistics(noisy, [](const TrajectorySample& s) { return s.push_point_world->x(); }), 0.95,
      n.push_point_m, "px");
  ExpectGaussian(
      Statistics(noisy, [](const TrajectorySample& s) { return s.push_point_world->y(); }), 2.01,
      n.push_point_m, "py");
  for (const TrajectorySample& s : noisy.samples) {
    EXPECT_EQ(s.push_point_world->z(), 0.03);  // the height is not tracked
    const Eigen::Vector3d& p = *s.push_point_world;
    const AppliedWrench rxf =
        WrenchFromForceAt(s.applied.fx, s.applied.fy, s.applied.fz, p.x() - s.state.x,
                          p.y() - s.state.y, p.z() - noisy.slider.com_height_m);
    ASSERT_NEAR(s.applied.tz, rxf.tz, 1e-15);  // consistent with its own columns
    ASSERT_EQ(s.applied.fx, 3.0);              // the force itself is untouched
  }
  bool listed = false;
  for (const auto& [key, value] : n.Metadata()) {
    listed = listed || (key == "noise_push_point_m" && std::stod(value) == n.push_point_m);
  }
  EXPECT_TRUE(listed);
}

TEST(Noise, PushPointNoiseLeavesTheOtherStreamsAsTheyWere) {
  NoiseSpec n;
  n.pose_m = 1e-3;
  n.force_relative = 0.02;
  n.seed = 12;
  const Trajectory a = AddNoise(StillLog(true), n);
  n.push_point_m = 1e-3;
  const Trajectory b = AddNoise(StillLog(true), n);
  for (size_t u = 0; u < a.samples.size(); ++u) {
    ASSERT_EQ(a.samples[u].state.x, b.samples[u].state.x) << u;
    ASSERT_EQ(a.samples[u].applied.fx, b.samples[u].applied.fx) << u;
  }
}

TEST(Noise, RowsWithoutForceGetNoForceNoise) {
  NoiseSpec n;
  n.force_relative = 0.1;
  n.force_n = 1.0;
  const Trajectory clean = testing::SimulateOrFail(testing::FreeSlideWithSpin());
  for (const TrajectorySample& s : AddNoise(clean, n).samples) {
    EXPECT_TRUE(s.applied.IsZero());
  }
}

TEST(Noise, InvalidSpecIsRejected) {
  NoiseSpec n;
  n.pose_m = -1;
  std::string why;
  EXPECT_FALSE(n.IsValid(&why));
  EXPECT_NE(why.find("pose_m"), std::string::npos) << why;
  EXPECT_THROW(AddNoise(StillLog(false), n), std::invalid_argument);
  n.pose_m = 0;
  n.outlier_fraction = 2;
  EXPECT_FALSE(n.IsValid(&why));
}

// ---- the sensor model ----

TEST(SensorModel, DecimationKeepsEveryKthRowWithTheForceAtItsTime) {
  Scene scene = testing::PushedSlider();
  scene.dt_s = 0.001;
  const Trajectory fine = testing::SimulateOrFail(scene);
  LogSpec spec;
  spec.log_every = 10;
  const Trajectory log = MakeLog(fine, spec);
  ASSERT_EQ(log.samples.size(), (fine.samples.size() - 1) / 10 + 1);
  ASSERT_EQ(log.steps.size(), log.samples.size());
  for (size_t j = 0; j < log.samples.size(); ++j) {
    const TrajectorySample& a = log.samples[j];
    const TrajectorySample& b = fine.samples[10 * j];
    EXPECT_EQ(a.t_s, b.t_s);
    EXPECT_EQ(a.state.x, b.state.x);
    EXPECT_EQ(a.state.wz, b.state.wz);
    EXPECT_EQ(a.applied.fx, b.applied.fx);  // the force applied at the row's time
    EXPECT_EQ(a.applied.tz, b.applied.tz);
    EXPECT_EQ(log.steps[j].ecp_world, fine.steps[10 * j].ecp_world);
    if (j == 0) continue;
    double pt = 0;  // the impulse over the log interval: the sum over its steps
    for (size_t i = 10 * j - 9; i <= 10 * j; ++i) pt += fine.steps[i].pt;
    EXPECT_NEAR(log.steps[j].pt, pt, 1e-15);
  }
  EXPECT_TRUE(log.measured.step_info);  // noiseless: the truth columns stay
}

// Sums of about a thousand doubles of one sign: rounding stays far below this, relative.
constexpr double kSumRounding = 1e-12;

TEST(SensorModel, IntervalMeanWrenchCarriesTheAppliedImpulseOfEachInterval) {
  Scene scene = testing::PushedSlider();  // periodic, body-fixed push: it varies within 10 ms
  scene.dt_s = 0.001;
  const Trajectory fine = testing::SimulateOrFail(scene);
  LogSpec spec;
  spec.log_every = 10;
  spec.push = LogPush::kMoments;
  const Trajectory at_row = MakeLog(fine, spec);
  spec.wrench = LogWrench::kIntervalMean;
  const Trajectory log = MakeLog(fine, spec);
  ASSERT_EQ(log.samples.size(), at_row.samples.size());
  ASSERT_EQ(log.samples.size(), (fine.samples.size() - 1) / 10 + 1);
  double logged_fx = 0, logged_tz = 0, scale_fx = 0, scale_tz = 0;
  int differs = 0;
  for (size_t j = 0; j + 1 < log.samples.size(); ++j) {
    const TrajectorySample& a = log.samples[j];
    EXPECT_EQ(a.t_s, at_row.samples[j].t_s);  // only the wrench differs
    EXPECT_EQ(a.state.x, at_row.samples[j].state.x);
    EXPECT_EQ(StepAt(log, j).pt, StepAt(at_row, j).pt);
    EXPECT_FALSE(a.push_point_world.has_value());  // a mean wrench has no point
    double fx = 0, tz = 0;  // the mean over the 10 simulated steps the row starts
    for (size_t i = 10 * j; i < 10 * j + 10; ++i) {
      fx += fine.samples[i].applied.fx / 10;
      tz += fine.samples[i].applied.tz / 10;
    }
    EXPECT_NEAR(a.applied.fx, fx, kSumRounding * (std::abs(fx) + 1e-300)) << "row " << j;
    EXPECT_NEAR(a.applied.tz, tz, kSumRounding * (std::abs(tz) + 1e-300)) << "row " << j;
    differs += a.applied.fx != at_row.samples[j].applied.fx;
    const double interval_s = log.samples[j + 1].t_s - a.t_s;
    logged_fx += a.applied.fx * interval_s;
    logged_tz += a.applied.tz * interval_s;
  }
  EXPECT_GT(differs, static_cast<int>(log.samples.size()) / 2);  // not the row's own value
  // The logged impulse over the whole log is the applied one.
  double applied_fx = 0, applied_tz = 0;
  for (size_t i = 0; i + 1 < fine.samples.size(); ++i) {
    const double step_s = fine.samples[i + 1].t_s - fine.samples[i].t_s;
    applied_fx += fine.samples[i].applied.fx * step_s;
    applied_tz += fine.samples[i].applied.tz * step_s;
    scale_fx += std::abs(fine.samples[i].applied.fx) * step_s;
    scale_tz += std::abs(fine.samples[i].applied.tz) * step_s;
  }
  EXPECT_NEAR(logged_fx, applied_fx, kSumRounding * scale_fx);
  EXPECT_NEAR(logged_tz, applied_tz, kSumRounding * scale_tz);
  // The last row starts no interval: it keeps its own wrench.
  EXPECT_EQ(log.samples.back().applied.fx, fine.samples.back().applied.fx);
  EXPECT_TRUE(log.measured.moments);
  EXPECT_FALSE(log.measured.push_point);
  EXPECT_NE(WrittenAs(log, spec).find("# log_wrench = interval-mean\n"), std::string::npos);
  spec.wrench = LogWrench::kAtRowTime;
  EXPECT_EQ(WrittenAs(at_row, spec).find("log_wrench"), std::string::npos);
  spec.wrench = LogWrench::kIntervalMean;

  // Logged every step, the mean is the simulated wrench itself.
  spec.log_every = 1;
  const Trajectory every = MakeLog(fine, spec);
  EXPECT_EQ(every.samples[123].applied.fx, fine.samples[123].applied.fx);
  EXPECT_FALSE(every.samples[123].push_point_world.has_value());

  spec.push = LogPush::kPoint;  // a mean wrench has no push point to write
  try {
    MakeLog(fine, spec);
    ADD_FAILURE() << "interval-mean with push points must throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("interval-mean needs push = moments"), std::string::npos)
        << e.what();
  }
  // Without pushes there is nothing to average: any push columns will do.
  EXPECT_NO_THROW(MakeLog(testing::SimulateOrFail(testing::FreeSlideWithSpin()), spec));
}

TEST(SensorModel, ColumnsFollowTheSpec) {
  const Trajectory fine = testing::SimulateOrFail(testing::PushedSlider());
  LogSpec spec;
  spec.motion = LogMotion::kPoses;
  spec.noise.pose_m = 1e-4;
  Trajectory log = MakeLog(fine, spec);
  EXPECT_TRUE(log.measured.pose);
  EXPECT_FALSE(log.measured.velocity);
  EXPECT_TRUE(log.measured.push_point);
  EXPECT_FALSE(log.measured.step_info);  // noisy: a sensor does not see the ECP
  EXPECT_TRUE(log.steps.empty());
  // Poses only: the velocities are those a reader derives.
  Trajectory derived = log;
  SetVelocitiesFromPoses(&derived);
  EXPECT_EQ(log.samples[7].state.vx, derived.samples[7].state.vx);
  std::string text = WrittenAs(log, spec);
  EXPECT_NE(text.find("t,x,y,theta,fx,fy,px,py,pz\n"), std::string::npos);
  EXPECT_NE(text.find("# noise_pose_m = 0.0001"), std::string::npos);

  spec.motion = LogMotion::kVelocities;
  spec.push = LogPush::kMoments;
  spec.step_info = true;
  log = MakeLog(fine, spec);
  text = Written(log);
  EXPECT_NE(text.find("t,vx,vy,wz,fx,fy,tx,ty,tz,ax,ay"), std::string::npos) << text.substr(0, 900);

  spec.push = LogPush::kPoint;
  EXPECT_THROW(MakeLog(fine, spec), std::invalid_argument);  // points need poses
}

TEST(SensorModel, ThetaNoiseIsAddedBeforeWrapping) {
  Scene scene = testing::FreeSlideWithSpin();  // turns by several radians
  const Trajectory fine = testing::SimulateOrFail(scene);
  LogSpec spec;
  spec.wrap_theta = true;
  spec.noise.angle_rad = 1e-3;
  spec.noise.seed = 3;
  const Trajectory wrapped = MakeLog(fine, spec);
  spec.wrap_theta = false;
  const Trajectory unwrapped = MakeLog(fine, spec);
  bool wrapped_some = false;
  for (size_t u = 0; u < fine.samples.size(); ++u) {
    const double w = wrapped.samples[u].state.theta, raw = unwrapped.samples[u].state.theta;
    EXPECT_GT(w, -kPi);
    EXPECT_LE(w, kPi);
    EXPECT_NEAR(std::remainder(raw - w, 2 * kPi), 0.0, 1e-12) << u;
    wrapped_some = wrapped_some || w != raw;
  }
  EXPECT_TRUE(wrapped_some);
  // Read back, the reader unwraps: the same angles as without wrapping.
  const std::string path = ::testing::TempDir() + "/wrapped_theta.csv";
  WritePushLog(wrapped, path);
  const Trajectory back = ReadPushLog(path);
  EXPECT_NEAR(back.samples.back().state.theta, unwrapped.samples.back().state.theta, 1e-9);
}

// ---- sensor defects: a force offset and a delay of the push stream ----

TEST(SensorModel, ForceBiasIsAddedToEveryRowWithItsMomentAtThePushPoint) {
  Scene scene = testing::TiltingPush();
  scene.pushes[0].stop_s = 0.7;  // then the pusher leaves: rows without a push point
  const Trajectory fine = testing::SimulateOrFail(scene);
  LogSpec spec;
  spec.motion = LogMotion::kPoses;
  spec.noise.pose_m = 1e-4;
  spec.noise.force_n = 0.05;
  const Trajectory clean = MakeLog(fine, spec);
  const LogSpec clean_spec = spec;
  spec.noise.force_bias_x_n = 0.3;
  spec.noise.force_bias_y_n = -0.2;
  const Trajectory biased = MakeLog(fine, spec);
  ASSERT_EQ(biased.samples.size(), clean.samples.size());
  int rows_at_rest = 0;
  for (size_t u = 0; u < clean.samples.size(); ++u) {
    const TrajectorySample& a = clean.samples[u];
    const TrajectorySample& b = biased.samples[u];
    EXPECT_EQ(b.state.x, a.state.x) << u;  // the same noise stream
    EXPECT_NEAR(b.applied.fx - a.applied.fx, 0.3, 1e-12) << u;
    EXPECT_NEAR(b.applied.fy - a.applied.fy, -0.2, 1e-12) << u;
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    if (a.push_point_world) {
      r = *a.push_point_world - Eigen::Vector3d(a.state.x, a.state.y, fine.slider.com_height_m);
    } else {
      ++rows_at_rest;
    }
    const AppliedWrench o = WrenchFromForceAt(0.3, -0.2, 0.0, r.x(), r.y(), r.z());
    EXPECT_NEAR(b.applied.tz - a.applied.tz, o.tz, 1e-12) << u;
    EXPECT_NEAR(b.applied.tx - a.applied.tx, o.tx, 1e-12) << u;
  }
  EXPECT_GT(rows_at_rest, 0) << "the scene should have rows without a push";
  // Written and read back, a reader sees the same wrench, and the metadata says what it is.
  const std::string path = ::testing::TempDir() + "/biased.csv";
  WritePushLog(biased, path);
  const Trajectory back = ReadPushLog(path);
  for (size_t u = 0; u < back.samples.size(); ++u) {
    EXPECT_NEAR(back.samples[u].applied.fx, biased.samples[u].applied.fx, 1e-12) << u;
    EXPECT_NEAR(back.samples[u].applied.tz, biased.samples[u].applied.tz, 1e-12) << u;
  }
  const std::string text = WrittenAs(biased, spec);
  EXPECT_NE(text.find("# noise_force_bias_x_n = 0.29999999999999999\n"), std::string::npos);
  EXPECT_NE(text.find("# noise_force_bias_y_n = -0.20000000000000001\n"), std::string::npos);
  EXPECT_EQ(text.find("noise_force_delay_s"), std::string::npos);  // not set, not written
  EXPECT_EQ(WrittenAs(clean, clean_spec).find("force_bias"), std::string::npos);
}

TEST(SensorModel, DelayShiftsThePushStreamAgainstThePoses) {
  Scene scene = testing::PushedSlider();
  scene.dt_s = 0.001;
  const Trajectory fine = testing::SimulateOrFail(scene);
  LogSpec spec;
  spec.log_every = 10;
  spec.step_info = true;
  const Trajectory plain = MakeLog(fine, spec);
  for (const double delay : {0.02, 0.0137, -0.03}) {
    spec.noise.force_delay_s = delay;
    const Trajectory delayed = MakeLog(fine, spec);
    ASSERT_EQ(delayed.samples.size(), plain.samples.size());
    for (size_t u = 0; u < delayed.samples.size(); ++u) {
      // The simulated row in force at t - delay (1 ms rows), clamped to the simulation.
      const double t = delayed.samples[u].t_s - delay;
      const long row = std::clamp<long>(std::lround(std::floor(t / scene.dt_s + 1e-6)), 0,
                                        static_cast<long>(fine.samples.size()) - 1);
      const TrajectorySample& source = fine.samples[row];
      EXPECT_EQ(delayed.samples[u].applied.fx, source.applied.fx) << delay << " row " << u;
      EXPECT_EQ(delayed.samples[u].applied.tz, source.applied.tz) << delay << " row " << u;
      EXPECT_EQ(delayed.samples[u].push_point_world, source.push_point_world) << u;
      EXPECT_EQ(delayed.samples[u].state.x, plain.samples[u].state.x) << u;  // poses as they were
    }
    EXPECT_NE(WrittenAs(delayed, spec).find("# noise_force_delay_s = "), std::string::npos);
  }
  // A whole number of log intervals: row u logs what row u - 2 logged without the delay.
  spec.noise.force_delay_s = 0.02;
  const Trajectory two_rows = MakeLog(fine, spec);
  for (size_t u = 2; u < two_rows.samples.size(); ++u) {
    EXPECT_EQ(two_rows.samples[u].applied.fy, plain.samples[u - 2].applied.fy) << u;
  }
}

TEST(SensorModel, DefectsMustBeFinite) {
  NoiseSpec n;
  n.force_bias_x_n = -2.0;  // any sign
  n.force_delay_s = -0.01;
  std::string why;
  EXPECT_TRUE(n.IsValid(&why)) << why;
  EXPECT_TRUE(n.IsZero());  // defects are not noise
  EXPECT_TRUE(n.HasDefects());
  n.force_delay_s = std::nan("");
  EXPECT_FALSE(n.IsValid(&why));
  EXPECT_NE(why.find("force_delay_s"), std::string::npos) << why;
  n.force_delay_s = 0;
  n.force_bias_y_n = HUGE_VAL;
  EXPECT_FALSE(n.IsValid(&why));
  EXPECT_NE(why.find("force_bias_y_n"), std::string::npos) << why;
}

}  // namespace
}  // namespace slideid
