#pragma once
// From one MIT push-dataset recording (io/mit_push_recording.h) to a push log (the
// Trajectory of log-format.md) and a report of what was found and done. What it does, in
// order, and why (details in docs/real-data.md):
//  1. sorts each stream and drops repeated times;
//  2. rejects a dead force channel (one value throughout) and drops frozen force samples
//     (the same reading repeated: a stalled sensor never repeats its noise); a frozen run
//     inside the push rejects the file (saturated or stalled during the push);
//  3. unwraps theta and repairs jumps by multiples of pi/2 (symmetric marker sets make
//     Vicon swap axes);
//  4. finds the push: the tip moving and touching the object (its centre within the tip
//     radius plus a tolerance of the object's outline, placed at the object pose);
//  5. estimates the force offset from the samples before and after it (tip still or away
//     from the object), rejects a drift between them above a threshold, and subtracts the
//     offset, interpolated linearly in time between the two estimates;
//  6. checks the sign: the force on the object points into it along the contact normal;
//     a stored reaction (pointing out) is flipped;
//  7. keeps the push window (touching, force above the noise) plus a margin, rejects a log
//     too short, or one whose motion-capture gaps (longer than a threshold) leave too
//     little of the push;
//  8. resamples onto one clock: pose and tip linear at the row times, a row's force the mean
//     over [t_u, t_u+1) (the log holds a row's force over that interval), applied at the
//     point of the outline nearest the tip centre, at pz = com_height (no tilting moment:
//     the pusher height is not recorded); rows inside a long pose gap are left out and the
//     row after it starts a new run (mode `start`), so that the fit's segments end there.
// A file that fails a check is rejected with its reason; nothing throws for bad data.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "forward_model/constants.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"
#include "io/mit_push_json.h"
#include "io/mit_push_recording.h"
#include "io/push_log.h"

namespace slideid {

/// How the stored force relates to the force on the object.
enum class ForceSign {
  kAuto,      ///< decided per file by the contact normal (step 6)
  kApplied,   ///< stored as the force on the object
  kReaction,  ///< stored as the reaction on the sensor: flipped
};

struct MitImportOptions {
  /// The object: mass, inertia about the vertical axis through the CM, CM height, gravity.
  SliderProperties slider;
  /// The object's outline in its frame, centred on the CM (log-format.md patch forms); the
  /// pusher touches this outline and the log records it as the contact patch.
  std::string patch_spec;
  /// The CM in the frame whose pose the recording tracks [m, object axes]: the MIT
  /// triangles' frame is not their centroid (datasets/mit_objects.csv). The object poses are
  /// moved to the CM before anything else uses them; zero leaves them as recorded.
  Eigen::Vector2d cm_offset_m = Eigen::Vector2d::Zero();
  double tip_radius_m = 0.00475;  ///< the MIT pusher (pdproc, get_and_plot_data.m)
  /// Row rate of the log [Hz]. 100 Hz: below every stream's median rate in the real files
  /// (object poses 104-255 Hz), so rows are not interpolated more finely than measured,
  /// and each row averages 2-3 force samples.
  double rate_hz = 100.0;
  /// Kept before the first and after the last push sample [s] (capped by the streams).
  double margin_s = 0.05;
  /// Largest accepted |offset after - offset before| [N]. At 0.5 N, interpolating
  /// between the two leaves at most 0.25 N of error mid-push, about 10% of a 2-3 N push.
  double max_offset_drift_n = 0.5;
  /// Longest gap between object poses inside the push window that is interpolated over
  /// [s]: at 50 ms and an angular acceleration of 5 rad/s^2 the error is alpha T^2 / 8 =
  /// 1.6 mrad, comparable to the motion-capture noise. A longer gap splits the log into
  /// runs (its rows left out); the file is rejected only when the gaps leave less than
  /// min_push_duration_s of the push.
  double max_pose_gap_s = 0.05;
  double min_push_duration_s = 0.2;  ///< shorter pushes are rejected as too short [s]
  /// A step of theta between consecutive samples above this is a tracking jump, repaired
  /// when it is near a multiple of pi/2 [rad]. 10 deg: pdproc uses 8-15 deg by speed; the
  /// real rect1 pushes turn by at most 6.4 deg between samples (over a 78 ms gap).
  double theta_jump_rad = 10.0 * kPi / 180.0;
  /// The tip touches the object when its centre is within tip_radius + this of the
  /// outline [m]: motion-capture error and the plate's machining (about 1-2 mm).
  double contact_tolerance_m = 2e-3;
  /// A force sample measures the sensor's offset only when the tip is farther than this
  /// from the outline (beyond its radius) [m]: the MIT pushes often start with the tip
  /// resting against the object, pressing it with 0.4-1.9 N (the dataset paper: "the
  /// pusher starts in contact with the object"), a real force and not an offset. 3 mm: past
  /// the contact tolerance with a millimetre to spare for motion-capture error.
  double offset_clearance_m = 3e-3;
  /// The tip moves when faster than this [m/s]: pushes run at 10-150 mm/s; the robot's
  /// stationary jitter is below 1 mm/s.
  double still_speed_mps = 5e-3;
  ForceSign force_sign = ForceSign::kAuto;
  /// Appended to the log's metadata (keys: identifiers), e.g. where the mass comes from.
  std::vector<std::pair<std::string, std::string>> extra_metadata;

  /// False (and why) for a non-positive or non-finite setting. The slider and the patch
  /// are checked by ImportMitPush (each file may have its own object).
  bool IsValid(std::string* why) const;
};

/// One stream as found.
struct StreamSummary {
  StreamCleanup cleanup;      ///< sorting and repeated times
  int rows = 0;               ///< after cleanup
  double median_rate_hz = 0;  ///< 1 / median interval
  double largest_gap_s = 0;   ///< longest interval, whole stream
};

enum class ImportVerdict { kAccepted, kRejected, kUnreadable };

/// What the import found and did, one per input file (a row of import_report.csv).
struct MitImportReport {
  std::string source;  ///< input file
  std::string output;  ///< written log, empty when none
  std::string object;  ///< object name from the file name, or empty
  ImportVerdict verdict = ImportVerdict::kRejected;
  std::string reason;  ///< why rejected or unreadable; empty when accepted

  StreamSummary object_pose, tip_pose, ft_wrench;
  int frozen_force_samples = 0;       ///< dropped (a repeated reading)
  int pose_glitches = 0;              ///< object poses dropped as isolated outliers
  int theta_wraps = 0;                ///< 2 pi unwraps
  int theta_jumps_repaired = 0;       ///< steps near a non-zero multiple of pi/2 (not 2 pi)
  int theta_jumps_unrepaired = 0;     ///< steps above the threshold, not near one
  double largest_theta_step_rad = 0;  ///< after repair
  double largest_pose_gap_in_window_s = 0;
  int pose_gaps_split = 0;            ///< gaps over max_pose_gap_s: the log's runs less one
  int rows_dropped_in_pose_gaps = 0;  ///< rows whose time fell inside such a gap

  /// Offsets [N] (stored force, world axes) from the still samples before / after the push.
  std::optional<Eigen::Vector2d> offset_before_n, offset_after_n;
  int offset_before_samples = 0, offset_after_samples = 0;
  std::optional<double> offset_drift_n;  ///< |after - before| when both exist
  /// The force the tip pressed with while resting against the object before the push
  /// (median of those samples, offset removed) [N]: kept in the log as a real force.
  std::optional<Eigen::Vector2d> preload_n;
  double force_noise_n = 0;      ///< robust std of the still samples, offset removed
  double force_threshold_n = 0;  ///< "force above noise"

  /// Sign check over the push samples: mean of f . n_in / mean |f| for the stored force
  /// (n_in: contact normal into the object), and the correlation of the stored force with
  /// the tip velocity. A stored reaction gives about -1 and a negative correlation.
  std::optional<double> normal_alignment, velocity_correlation;
  bool force_flipped = false;

  /// Contact distance over the kept rows with force above the noise: tip centre to outline
  /// minus tip radius [m] (about 0 in contact; negative: overlap).
  std::optional<double> contact_gap_median_m, contact_gap_p05_m, contact_gap_p95_m;
  double rows_out_of_contact_fraction = 0;  ///< of the kept rows with force above noise

  double window_start_s = 0, window_end_s = 0;  ///< kept, relative to time_origin_s
  double time_origin_s = 0;                     ///< Unix time of the log's t = 0
  int rows = 0;                                 ///< rows written
  double peak_force_n = 0;                      ///< over the kept rows
  std::vector<std::string> notes;               ///< further facts (offsets not available, ...)
};

/// A push log file (empty samples when rejected) and its report.
struct MitImportResult {
  PushLogFile file;
  MitImportReport report;
};

/// Imports one recording; `source` names it in the report and the log's metadata. Throws
/// std::invalid_argument for invalid options only: bad data is a rejection in the report.
MitImportResult ImportMitPush(const MitPushRecording& recording, const std::string& source,
                              const MitImportOptions& options);

const char* ToString(ImportVerdict verdict);  ///< "accepted", "rejected", "unreadable"
const char* ToString(ForceSign sign);         ///< "auto", "applied", "reaction"

}  // namespace slideid
