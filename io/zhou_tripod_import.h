#pragma once
// Zhou et al.'s ICRA 2016 tripod logs (io/zhou_tripod_log.h) to wrench-twist pairs: one
// row per push, in the object frame (origin at the CM, the block's axes), for quasi-static
// identification (docs/real-data.md, "Wrench-twist pairs").
//
// Conventions (../shared/data/real-pushes/README.md, section 2, and the authors'
// ExtractFromLog.m and ComputeWrench.m; checked against the data, see docs/real-data.md):
// - object frame: the Vicon body frame (the block frame, vertices (0, 0), (0.15, 0),
//   (0, 0.15) m) shifted by (50, 50, 0) mm to the CM;
// - force on the object, in the tool frame: -R_tool (f - f_first), R_tool = [[s, s], [s, -s]],
//   s = sqrt(2)/2; then rotated by the tool's yaw (from its quaternion) into the world frame,
//   and by the object's yaw into the object frame;
// - contact point: the tool point projected onto the nearest edge of the block.
//
// Per push: the contact phase is found from the force magnitude (see TripodImportOptions),
// the force and the moment about the CM are averaged over its sliding part in the object
// frame, and the twist is the constant body twist that carries the pre-push pose to the
// post-push pose (the SE(2) logarithm) over that part's duration. Only the two end poses are
// logged, so the object's pose in between is taken along that same constant twist.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "forward_model/wrench_twist_pair.h"
#include "io/zhou_tripod_log.h"

namespace slideid {

/// The block (README, section 2): a right triangle with legs 0.15 m, mass 1.518 kg.
constexpr double kTripodLeg_m = 0.15;
/// CM in the block frame, both coordinates [m] (the centroid of the triangle).
constexpr double kTripodCmInBlock_m = 0.05;
constexpr double kTripodMass_kg = 1.518;
/// m (a^2 + b^2) / 36 of a thin right-triangle plate with legs 0.15 m (README's estimate;
/// legs and markers not included) [kg m^2].
constexpr double kTripodInertiaEstimate_kgm2 = 1.9e-3;

/// The block's vertices in the object frame (from the CM), counter-clockwise [m]. Edge i
/// joins vertex i to vertex i + 1: 0 the leg on the block's x axis, 1 the hypotenuse, 2 the
/// leg on its y axis.
std::array<Eigen::Vector2d, 3> TripodBlockVertices();

/// Force on the object in the tool frame from a sensor reading, before the offset:
/// -R_tool f [N].
Eigen::Vector2d TripodToolForce(double fx_sensor_n, double fy_sensor_n);
/// The sensor reading whose TripodToolForce is `tool_force` (R_tool is its own inverse).
Eigen::Vector2d TripodSensorForce(const Eigen::Vector2d& tool_force);

/// The object's planar pose (CM x, y [m], yaw [rad]) from a Vicon pose of the block frame.
Eigen::Vector3d TripodObjectPose(const TripodPose& vicon);
/// The Vicon pose of a block lying flat whose CM is at `pose` (x, y [m], yaw), at height z.
TripodPose TripodViconPose(const Eigen::Vector3d& pose, double z_mm);
/// Yaw of a tool pose [rad].
double TripodToolYaw(const TripodPose& tool);

/// Support points from a name "x1_x2_x3_y1_y2_y3" (mm, block frame; an optional "wood_"
/// prefix is ignored), in the object frame [m]; nullopt when the name is not of that form.
std::optional<std::array<Eigen::Vector2d, 3>> ParseTripodSupports(const std::string& name);

/// How far three supports spread around the CM (object frame, from the CM).
struct SupportSpread {
  double rms_m = 0;  ///< RMS distance of the supports from the CM [m]
  /// The supports' share of the weight: barycentric coordinates of the CM in their triangle
  /// (statics fixes them for three points); some are negative when the CM is outside.
  std::array<double, 3> weights{};
  /// Sum of weight times distance [m]: the ratio of the largest friction moment about the CM
  /// to the largest friction force, mu m g sum w_i r_i / (mu m g), for point supports with
  /// isotropic Coulomb friction: what the ellipsoid's c approximates.
  double weighted_mean_m = 0;
  bool cm_inside = false;  ///< the CM lies inside the support triangle
};
/// Spread of `supports` (object frame). Throws std::invalid_argument for collinear supports.
SupportSpread TripodSupportSpread(const std::array<Eigen::Vector2d, 3>& supports);

/// How pushes are cut and checked.
struct TripodImportOptions {
  std::optional<double> mass_kg;       ///< unset: kTripodMass_kg (README)
  double gravity_mps2 = 9.81;          ///< [m/s^2]
  std::optional<double> inertia_kgm2;  ///< unset: kTripodInertiaEstimate_kgm2 (an estimate)
  std::optional<double> com_height_m;  ///< not in the logs; unset: unknown
  /// Support layout metadata; unset: from the name of the file's folder
  /// (ParseTripodSupports), written as "x y; x y; x y" in the object frame [m].
  std::optional<std::string> supports;
  /// The first samples of each trace (before any contact, ~0.25 s at 100 Hz) estimate the
  /// sensor's noise: sigma = 1.4826 MAD of the sample-to-sample change / sqrt(2).
  int noise_samples = 25;
  /// Contact: the longest run of samples with |f| above max(onset_sigmas sigma,
  /// min_contact_force_n). The noise is 0.002 to 0.08 N on these logs and contact forces are
  /// 1.5 to 9 N; 10 sigma is far above the noise (no false onsets) and far below any push.
  double onset_sigmas = 10.0;
  /// Floor under the onset threshold [N]: above the slow drift of up to 0.03 N that some
  /// traces show before contact.
  double min_contact_force_n = 0.05;
  /// Sliding part of the contact: the samples with |f| at least this fraction of the
  /// contact's median |f|, from the first such sample to the last (samples below it in
  /// between are dropped). Leaves out most of the loading ramp, in which the block sticks
  /// while the finger loads it (the force inside the limit surface), and any unloading. Not
  /// higher: the sliding force itself drifts along a push as the line of action moves (by
  /// 40% over the first 0.6 s of one synthetic push), and a higher cut would drop sliding
  /// samples. What stays of the ramp is short on these logs (0.01 to 0.19 s to reach half
  /// the force, median 0.05 s, of ~5 s): it lowers the mean force by a few tenths of a
  /// percent at most.
  double sliding_fraction = 0.5;
  /// The trace must be at rest this long before contact [s]: the offset is the first sample,
  /// and a trace that starts in contact would subtract contact force; also the noise
  /// samples (0.25 s) must precede contact. 0.3 s is that window plus a margin.
  double min_rest_s = 0.3;
  /// A push whose first sample differs from the file's median first sample by more than this
  /// fraction of the push's median contact force is rejected: the offset, and every force of
  /// the push, would be off by that much (contact or a sensor jump before the trace).
  double max_offset_error_fraction = 0.05;
  /// Largest distance of the tool point from the block's nearest edge during the sliding
  /// part [m]; the logs stay within 2.6 mm, 1.0 mm median (the finger's radius, Vicon error
  /// and the interpolated pose).
  double max_edge_distance_m = 0.005;
  int min_samples = 20;  ///< fewest force samples a push's sliding part must keep

  bool IsValid(std::string* why) const;
};

/// What happened to one push.
struct TripodPushReport {
  int push = 0;  ///< 1-based
  int line = 0;  ///< line of its pre-push pose
  bool accepted = false;
  std::string reason;  ///< why it was rejected (names the line where one applies)
  double noise_sigma_n = 0, threshold_n = 0, contact_force_n = 0;  ///< [N]
  double offset_error_n = 0;         ///< first sample minus the file's median first sample, |.| [N]
  double onset_s = 0;                ///< contact start after the trace's first sample [s]
  double start_s = 0, end_s = 0;     ///< sliding part, after the trace's first sample [s]
  int samples = 0, dropped_low = 0;  ///< kept, and dropped below the sliding fraction
  int edge = -1;                     ///< edge of the block pushed (TripodBlockVertices)
  double max_edge_distance_m = 0;    ///< of the tool point [m]
  /// Angle between the mean force and the inward normal of the pushed edge [deg]: the force
  /// should point into the block (within the finger's friction cone).
  double force_normal_angle_deg = 0;
  /// Angle between the mean force and the CM's velocity [deg] (0 for isotropic translation).
  double force_twist_angle_deg = 0;
  double displacement_m = 0, rotation_rad = 0;  ///< of the object over the push
};

/// What the import did to a file.
struct TripodImportReport {
  std::string source;
  int pushes = 0, accepted = 0;
  std::vector<TripodPushReport> push_reports;
  Eigen::Vector2d median_offset_sensor_n = Eigen::Vector2d::Zero();  ///< file's median f_first
  std::vector<std::string> notes;
};

/// Reads `path` and turns each push into a row (rejected pushes are left out and reported).
/// Throws LogError for a file that cannot be read (io/zhou_tripod_log.h) and
/// std::invalid_argument for invalid options; a file with no acceptable push is not an
/// error (the data has no rows; the report says why).
WrenchTwistData ImportZhouTripod(const std::string& path, const TripodImportOptions& options,
                                 TripodImportReport* report = nullptr);
/// Same, from a log in memory; `source` names it (its folder name gives the supports).
WrenchTwistData ImportZhouTripod(const TripodLog& log, const std::string& source,
                                 const TripodImportOptions& options,
                                 TripodImportReport* report = nullptr);

/// One row per push (push, line, verdict, reason and the figures above) as CSV. Throws
/// std::runtime_error naming the path if it cannot be written.
void WriteTripodImportReport(const TripodImportReport& report, const std::string& path);

}  // namespace slideid
