#include "datasets/noise.h"

#include <cmath>
#include <random>
#include <stdexcept>

namespace slideid {
namespace {

constexpr double kTwoPi = 6.283185307179586;
// Outliers turn theta by outlier_m over this lever [m]: a marker 5 cm from the CM.
constexpr double kOutlierLever_m = 0.05;
// Seeds the second engine (fz and moments) from the same seed, on a separate stream.
constexpr std::uint64_t kSecondStream = 0x9E3779B97F4A7C15ull;
// Seeds the third engine (push-point noise), so that adding it left the first two streams,
// and every log made before it, unchanged.
constexpr std::uint64_t kThirdStream = 0xC2B2AE3D27D4EB4Full;

// A single push's residual moment (total minus r x f) is rounding only: r recomputed from the
// push point and the CM differs from the simulator's rotated r by a few ulps, so the residual
// is ~1e-16 of |f| |r|. Below this fraction it is taken as exactly 0, so that a log of single
// pushes needs no tx, ty, tz columns.
constexpr double kResidualRounding = 1e-12;

bool HasForce(const AppliedWrench& w) { return w.fx != 0 || w.fy != 0 || w.fz != 0; }

/// The residual moment `total - at_point`, 0 when it is rounding of a moment of size `scale`.
double Residual(double total, double at_point, double scale) {
  const double residual = total - at_point;
  return std::abs(residual) <= kResidualRounding * scale ? 0.0 : residual;
}

}  // namespace

void ApplyNoise(Trajectory* log, const NoiseSpec& noise) {
  std::string why;
  if (!noise.IsValid(&why)) throw std::invalid_argument("ApplyNoise: " + why);
  const bool force_noise = noise.force_relative != 0 || noise.force_n != 0;
  const bool pose_moves_r =
      log->measured.pose && (noise.pose_m != 0 || noise.outlier_fraction != 0);
  const bool point_moves = noise.push_point_m != 0;
  const double com_height = log->slider.com_height_m;
  std::mt19937_64 rng(noise.seed);
  std::mt19937_64 rng2(noise.seed ^ kSecondStream);
  std::mt19937_64 rng3(noise.seed ^ kThirdStream);
  std::normal_distribution<double> normal(0.0, 1.0), normal2(0.0, 1.0), normal3(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (TrajectorySample& s : log->samples) {
    // Every variate is drawn whatever the spec, in a fixed order: one seed, one stream.
    const double n[11] = {normal(rng), normal(rng), normal(rng), normal(rng),
                          normal(rng), normal(rng), normal(rng), normal(rng),
                          normal(rng), normal(rng), normal(rng)};
    const double jump = uniform(rng), jump_angle = uniform(rng) * kTwoPi;
    const double m[5] = {normal2(rng2), normal2(rng2), normal2(rng2), normal2(rng2), normal2(rng2)};
    const double point_noise[2] = {normal3(rng3), normal3(rng3)};

    const PlanarState truth = s.state;
    s.state.x += noise.pose_m * n[0];
    s.state.y += noise.pose_m * n[1];
    s.state.theta += noise.angle_rad * n[2];
    s.state.vx += noise.velocity_mps * n[3];
    s.state.vy += noise.velocity_mps * n[4];
    s.state.wz += noise.spin_radps * n[5];
    if (jump < noise.outlier_fraction) {
      s.state.x += noise.outlier_m * std::cos(jump_angle);
      s.state.y += noise.outlier_m * std::sin(jump_angle);
      s.state.theta += noise.outlier_m / kOutlierLever_m * (n[10] > 0 ? 1 : -1);
    }

    AppliedWrench& w = s.applied;
    if (!HasForce(w)) continue;
    const AppliedWrench f_true = w;
    AppliedWrench f = w;
    if (force_noise) {
      f.fx += noise.force_relative * w.fx * n[6] + noise.force_n * n[7];
      f.fy += noise.force_relative * w.fy * n[8] + noise.force_n * n[9];
      if (w.fz != 0) f.fz += noise.force_relative * w.fz * m[0] + noise.force_n * m[1];
    }
    if (s.push_point_world) {
      if (!force_noise && !pose_moves_r && !point_moves) continue;
      const Eigen::Vector3d p = *s.push_point_world;
      const AppliedWrench at_truth = WrenchFromForceAt(
          f_true.fx, f_true.fy, f_true.fz, p.x() - truth.x, p.y() - truth.y, p.z() - com_height);
      const PlanarState& q = log->measured.pose ? s.state : truth;
      Eigen::Vector3d& reported = *s.push_point_world;
      reported.x() += noise.push_point_m * point_noise[0];
      reported.y() += noise.push_point_m * point_noise[1];
      const AppliedWrench measured = WrenchFromForceAt(
          f.fx, f.fy, f.fz, reported.x() - q.x, reported.y() - q.y, reported.z() - com_height);
      const double scale = std::hypot(f_true.fx, f_true.fy, f_true.fz) *
                           std::hypot(p.x() - truth.x, p.y() - truth.y, p.z() - com_height);
      w = measured;  // plus the residual moment, the part not due to f
      w.tx += Residual(f_true.tx, at_truth.tx, scale);
      w.ty += Residual(f_true.ty, at_truth.ty, scale);
      w.tz += Residual(f_true.tz, at_truth.tz, scale);
    } else if (force_noise) {
      w.fx = f.fx;
      w.fy = f.fy;
      w.fz = f.fz;
      w.tx += noise.force_relative * w.tx * m[2];
      w.ty += noise.force_relative * w.ty * m[3];
      w.tz += noise.force_relative * w.tz * m[4];
    }
  }
}

Trajectory AddNoise(const Trajectory& log, const NoiseSpec& noise) {
  Trajectory out = log;
  ApplyNoise(&out, noise);
  out.measured.step_info = false;
  out.steps = {};
  return out;
}

}  // namespace slideid
