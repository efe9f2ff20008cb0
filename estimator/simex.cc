#include "estimator/simex.h"

#include <cmath>
#include <limits>
#include <random>

#include "estimator/log_diagnostics.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Seeds of the copies: fixed, never the clock.
constexpr std::uint64_t kSimexSeed = 0x51AE5ull;

double ZeroIfNaN(double x) { return std::isfinite(x) ? x : 0.0; }

/// `log` with as much noise again as it shows, on the channels the estimators read.
Trajectory Noisier(const Trajectory& log, std::mt19937_64* rng) {
  const LogDiagnostics d = DiagnoseLog(log);
  Trajectory out = log;
  std::normal_distribution<double> normal(0.0, 1.0);
  if (log.measured.velocity) {
    const double v = ZeroIfNaN(d.velocity_noise_mps), w = ZeroIfNaN(d.spin_noise_radps);
    for (TrajectorySample& s : out.samples) {
      s.state.vx += v * normal(*rng);
      s.state.vy += v * normal(*rng);
      s.state.wz += w * normal(*rng);
    }
  } else {
    const double q = ZeroIfNaN(d.pose_noise_m), a = ZeroIfNaN(d.angle_noise_rad);
    for (TrajectorySample& s : out.samples) {
      s.state.x += q * normal(*rng);
      s.state.y += q * normal(*rng);
      s.state.theta += a * normal(*rng);
    }
  }
  return out;
}

}  // namespace

SimexBias EstimateSimexBias(const std::vector<const Trajectory*>& logs,
                            const std::array<double, 3>& at_log_noise,
                            const LogEstimator& estimate) {
  std::mt19937_64 rng(kSimexSeed);
  std::array<double, 3> sum{}, sum2{};
  SimexBias out;
  for (int b = 0; b < kSimexReplicates; ++b) {
    std::vector<Trajectory> copies;
    copies.reserve(logs.size());
    for (const Trajectory* log : logs) copies.push_back(Noisier(*log, &rng));
    std::vector<const Trajectory*> pointers;
    for (const Trajectory& c : copies) pointers.push_back(&c);
    const std::array<double, 3> theta = estimate(pointers);
    for (int i = 0; i < 3; ++i) {
      const double change = theta[i] - at_log_noise[i];
      if (!std::isfinite(change)) continue;
      sum[i] += change;
      sum2[i] += change * change;
      ++out.replicates[i];
    }
  }
  for (int i = 0; i < 3; ++i) {
    const int n = out.replicates[i];
    out.bias_log[i] = out.stderr_log[i] = kNaN;
    if (n < kMinSimexReplicates) continue;
    const double mean = sum[i] / n;
    out.bias_log[i] = mean;
    out.stderr_log[i] = std::sqrt(std::max(0.0, sum2[i] / n - mean * mean) / (n - 1));
  }
  return out;
}

bool CorrectNoiseBias(const SimexBias& bias, int i, LogEstimate* e, std::string* reason) {
  const double b = bias.bias_log[i];
  if (!std::isfinite(b)) return true;
  if (std::abs(b) > kMaxSimexBiasLog) {
    *reason = Printf(
        "the log's noise biases it by about %+.0f%% (SIMEX), beyond what a "
        "correction can be trusted for (%.0f%%)",
        100 * std::expm1(b), 100 * std::expm1(kMaxSimexBiasLog));
    return false;
  }
  e->log_value -= b;
  e->stderr_log = std::hypot(e->stderr_log, bias.stderr_log[i]);
  e->note +=
      (e->note.empty() ? "" : "; ") +
      Printf("corrected by %+.2f%% for the bias of the log's noise (SIMEX)", 100 * std::expm1(-b));
  return true;
}

}  // namespace slideid
