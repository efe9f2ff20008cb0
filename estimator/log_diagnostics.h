#pragma once
// What a log shows about itself before any fit: the noise on its motion channels, read off
// its high-frequency content, and whether its force channel is alive. The estimators use
// the noise to scale their robust losses and to judge their residuals (a fit whose
// residuals sit far above the log's own noise does not describe the log: model mismatch).

#include <optional>
#include <string>

#include "forward_model/trajectory.h"

namespace slideid {

/// Noise of a log's motion channels and the size of its push.
struct LogDiagnostics {
  /// Standard deviation of the noise on x and y [m] and on theta [rad], from the MAD of the
  /// poses' third differences (a smooth motion's are ~ jerk h^3, white noise's 20 sigma^2 in
  /// variance; the median ignores the few rows where stick-slip makes the jerk large). NaN
  /// without poses or with fewer than kMinDiagnosticRows rows.
  double pose_noise_m;
  double angle_noise_rad;
  /// The same for measured velocities [m/s, rad/s] from second differences (variance
  /// 6 sigma^2); NaN when the log has no velocity columns of its own.
  double velocity_noise_mps;
  double spin_noise_radps;
  /// Largest applied horizontal force [N] over the rows (0 without a force channel).
  double max_push_n = 0;
  /// Set when the log has a force channel that is the same on every row although the
  /// object moves from rest, or is not zero: "force channel constant (dead sensor?)".
  std::optional<std::string> dead_force_channel;
};

/// Fewest rows from which the noise is read (a median of fewer differences is too rough).
constexpr int kMinDiagnosticRows = 8;

/// Reads the diagnostics of `log` (rows strictly increasing in time).
LogDiagnostics DiagnoseLog(const Trajectory& log);

/// The noise a fit's residual row of three channels (x, y, L theta) or (v_x, v_y, L w_z)
/// should show on this log: sqrt(s_x^2 + s_y^2 + (L s_theta)^2), L = `length_m`. NaN
/// when the log does not show it.
double RowNoise(const LogDiagnostics& d, bool poses, double length_m);

}  // namespace slideid
