#include "estimator/log_diagnostics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "estimator/robust_statistics.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A pose that moves by more than this from the first row has moved [m]: far above any
// tracker's noise, far below any push.
constexpr double kMovedM = 2e-3;
// Forces within this of each other [N] are the same value: a live sensor's noise and
// quantisation are far above it.
constexpr double kSameForceN = 1e-9;

// Robust standard deviation of white noise on `x` from its k-th differences: the MAD of
// the differences over the square root of sum binomial(k, j)^2 (20 for k = 3, 6 for 2).
double NoiseFromDifferences(const std::vector<double>& x, int k) {
  if (static_cast<int>(x.size()) < kMinDiagnosticRows) return kNaN;
  std::vector<double> d = x;
  for (int order = 0; order < k; ++order) {
    for (size_t i = 0; i + 1 < d.size(); ++i) d[i] = d[i + 1] - d[i];
    d.pop_back();
  }
  for (double& v : d) v = std::abs(v);
  const double gain = k == 3 ? std::sqrt(20.0) : std::sqrt(6.0);
  return kMadToSigma * Median(d) / gain;
}

std::vector<double> Channel(const Trajectory& log, double PlanarState::*field) {
  std::vector<double> x;
  x.reserve(log.samples.size());
  for (const TrajectorySample& s : log.samples) x.push_back(s.state.*field);
  return x;
}

std::optional<std::string> DeadForceChannel(const Trajectory& log) {
  if (!log.measured.force || log.samples.size() < 2) return std::nullopt;
  const AppliedWrench& first = log.samples.front().applied;
  bool constant = true, moved = false;
  for (const TrajectorySample& s : log.samples) {
    constant = constant && std::abs(s.applied.fx - first.fx) <= kSameForceN &&
               std::abs(s.applied.fy - first.fy) <= kSameForceN;
    moved = moved || std::hypot(s.state.x - log.samples.front().state.x,
                                s.state.y - log.samples.front().state.y) > kMovedM;
  }
  if (!constant || !log.measured.pose || !moved) return std::nullopt;
  const PlanarState& s0 = log.samples.front().state;
  const bool starts_at_rest = !log.measured.velocity || (s0.vx == 0 && s0.vy == 0 && s0.wz == 0);
  const bool nonzero = std::hypot(first.fx, first.fy) > kSameForceN;
  // A free slide may log a force of zero throughout; a push that never changes, or an
  // object that leaves rest with nothing pushing it, cannot be right.
  if (!nonzero && !starts_at_rest) return std::nullopt;
  return "force channel constant (dead sensor?): fx, fy stay at (" + std::to_string(first.fx) +
         ", " + std::to_string(first.fy) + ") N on every row while the object moves";
}

}  // namespace

LogDiagnostics DiagnoseLog(const Trajectory& log) {
  LogDiagnostics d;
  d.pose_noise_m = d.angle_noise_rad = d.velocity_noise_mps = d.spin_noise_radps = kNaN;
  if (log.measured.pose) {
    const double sx = NoiseFromDifferences(Channel(log, &PlanarState::x), 3);
    const double sy = NoiseFromDifferences(Channel(log, &PlanarState::y), 3);
    d.pose_noise_m = std::sqrt(0.5 * (sx * sx + sy * sy));
    d.angle_noise_rad = NoiseFromDifferences(Channel(log, &PlanarState::theta), 3);
  }
  if (log.measured.velocity) {
    const double sx = NoiseFromDifferences(Channel(log, &PlanarState::vx), 2);
    const double sy = NoiseFromDifferences(Channel(log, &PlanarState::vy), 2);
    d.velocity_noise_mps = std::sqrt(0.5 * (sx * sx + sy * sy));
    d.spin_noise_radps = NoiseFromDifferences(Channel(log, &PlanarState::wz), 2);
  }
  for (const TrajectorySample& s : log.samples) {
    d.max_push_n = std::max(d.max_push_n, std::hypot(s.applied.fx, s.applied.fy));
  }
  d.dead_force_channel = DeadForceChannel(log);
  return d;
}

double RowNoise(const LogDiagnostics& d, bool poses, double length_m) {
  const double linear = poses ? d.pose_noise_m : d.velocity_noise_mps;
  const double angular = poses ? d.angle_noise_rad : d.spin_noise_radps;
  return std::sqrt(2 * linear * linear + length_m * length_m * angular * angular);
}

}  // namespace slideid
