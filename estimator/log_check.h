#pragma once
// The check before a fit (identify --check, slideid.check): what one log shows about itself
// and what the trajectory fit could make of it, without fitting it. Isaac Sim's system
// identification has such a "Check" stage, mujoco.sysid its cond(J^T J).
//
// Per log it says:
//  - the sampling and the sensors: rate, gaps, noise, the force the channel reads while the
//    object rests (an offset, or a push too weak to move it), a dead force channel;
//  - the excitation: how far the object turns, in which directions of its own it is pushed
//    and slides, how far the pushes pass from the CM, the share of the time it slides;
//  - which of a, b, c (and mu_p, for a log with the tip's path) the fit could identify and
//    roughly how precisely: the fit's own identifiability rules (estimator/identifiability.h)
//    applied to J^T J at the point the fit starts from (its seed), J from the fit's own
//    residuals through Ceres, with its condition number and the correlations of a, b, c;
//  - in words, what would help ("c is not identifiable: every push passes within 3 mm of
//    the CM; push off-centre or turn the object").
// The verdicts are a forecast: docs/identify.md, "Check before fitting", gives how often
// they agree with the fit's (tests/log_check_test.cc, benchmarks/check_agreement.cc).

#include <array>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// What the check expects of one parameter.
struct ParameterOutlook {
  bool identifiable = false;
  /// The value the fit starts from (a, b, c [m]; mu_p: the check's own estimate). NaN when
  /// there is none.
  double seed = std::numeric_limits<double>::quiet_NaN();
  /// Expected one-sigma relative error (of log(parameter): 0.01 = about 1%), white noise at
  /// the seed; the fit's interval is usually wider (docs/identify.md). NaN when not
  /// identifiable.
  double relative_stderr = std::numeric_limits<double>::quiet_NaN();
  /// Why not identifiable, in the fit's words (empty when identifiable).
  std::string reason;
};

/// The check of one log: its sensors, its excitation, and what a fit could identify.
struct LogCheck {
  std::string name;  ///< the log's source (file name), or "" when it has none

  // ---- sampling and sensors --------------------------------------------------------------
  int rows = 0;
  double duration_s = 0;
  double rate_hz = 0;  ///< 1 / the median interval
  /// Intervals longer than kGapIntervals median intervals, or holes the log marks (a run
  /// starting), and the longest such interval [s] (0 without any).
  int gaps = 0;
  double longest_gap_s = 0;
  bool has_pose = false, has_velocity = false, has_force = false, has_push_point = false,
       has_tip = false;
  /// Noise the log shows by itself (estimator/log_diagnostics.h); NaN where not shown.
  double pose_noise_m = std::numeric_limits<double>::quiet_NaN();
  double angle_noise_rad = std::numeric_limits<double>::quiet_NaN();
  /// The force channel while the object rests: rows at rest, and the median force over them
  /// [N] (NaN without rest rows or without a force channel). A force at rest is an offset of
  /// the sensor or a push too weak to move the object; the check cannot tell which.
  int rest_rows = 0;
  double rest_force_x_n = std::numeric_limits<double>::quiet_NaN();
  double rest_force_y_n = std::numeric_limits<double>::quiet_NaN();
  double max_push_n = 0;  ///< largest horizontal force [N]
  /// Channels that carry nothing: "force channel constant (dead sensor?) ...", "theta
  /// constant while the object moves", ... (empty when all live).
  std::vector<std::string> dead_channels;

  // ---- excitation ------------------------------------------------------------------------
  double rotation_range_rad = 0;  ///< max - min of the unwrapped heading
  /// The smallest arc [rad] holding every direction, in the object's own frame, of the
  /// pushing force (rows with at least kPushFraction of the largest push) and of the sliding
  /// velocity; 0 when there is none.
  double push_directions_rad = 0;
  double slide_directions_rad = 0;
  /// How far the line of each push passes from the CM (|moment| / |force|) [m]: the largest
  /// over the pushing rows (NaN without a push).
  double max_push_offset_m = std::numeric_limits<double>::quiet_NaN();
  /// Share of the log's time the object slides (moves beyond its noise).
  double sliding_share = 0;

  // ---- what a fit could identify ---------------------------------------------------------
  /// Why the check could not look at the information ("" when it did): what the fit would
  /// end with as "too little excitation" (too short, a dead force channel).
  std::string failure;
  std::array<ParameterOutlook, 3> parameters;  ///< a, b, c (ParameterIndex)
  /// J^T J of (log a, log b, log c) at the seed, states and nuisances marginalised out: its
  /// condition number (largest over smallest eigenvalue; infinite when singular) and the
  /// correlations its inverse implies (NaN where singular).
  double condition_number = std::numeric_limits<double>::quiet_NaN();
  std::array<std::array<double, 3>, 3> correlation{};
  /// mu_p, for a log with the tip's path, radius and outline (estimator/pusher_friction.h).
  bool mu_pusher_examined = false;
  ParameterOutlook mu_pusher;
  int tip_contact_rows = 0, tip_sliding_rows = 0;
  /// Sensor nuisances the options would fit, and whether the log determines them.
  std::vector<std::pair<std::string, ParameterOutlook>> nuisances;

  /// What would help, one sentence each ("c is not identifiable: every push passes within
  /// 3 mm of the CM; push off-centre or turn the object"); empty when nothing is amiss.
  std::vector<std::string> advice;

  /// Whether the check expects the fit to identify at least one parameter.
  bool AnyIdentifiable() const;
};

/// An interval longer than this many median intervals counts as a gap.
constexpr double kGapIntervals = 3.0;
/// Rows pushed with at least this fraction of the largest push count as pushing.
constexpr double kPushFraction = 0.1;

/// Checks `log` (slider properties set, rows strictly increasing in time) for the
/// trajectory fit of `options` (its segments, substeps and sensor nuisances). Fits nothing:
/// it costs the fit's seeding. Throws std::invalid_argument for invalid options or a method
/// other than the trajectory fit (the only one whose information it forecasts).
LogCheck CheckLog(const Trajectory& log, const IdentifyOptions& options);

}  // namespace slideid
