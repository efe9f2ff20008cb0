#include "io/zhou_tripod_import.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "forward_model/constants.h"
#include "forward_model/number_format.h"
#include "io/atomic_file.h"
#include "io/text_lines.h"

namespace slideid {
namespace {

constexpr double kDegPerRad = 180.0 / kPi;
/// Quaternions in the logs are unit to their printed precision (the tool's 3 decimals leave
/// |q| - 1 up to 7e-4); one off by more than 1% is not a rotation that was meant.
constexpr double kQuaternionNormTolerance = 0.01;
/// Magnitudes no pushing experiment reaches (as the push-log reader's, forward_model/
/// push_log.cc): a push holding one is rejected before any arithmetic can overflow.
constexpr double kAbsurdForce_n = 1e5;
constexpr double kAbsurdPosition_mm = 1e7;  // 10 km
constexpr double kAbsurdTime_s = 1e12;      // 30,000 years of Unix time
/// MAD of Gaussian data times this estimates its standard deviation.
constexpr double kMadToSigma = 1.4826;

double Median(std::vector<double> x) {
  const std::size_t n = x.size();
  std::nth_element(x.begin(), x.begin() + n / 2, x.end());
  const double upper = x[n / 2];
  if (n % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(x.begin(), x.begin() + n / 2));
}

Eigen::Matrix2d Rotation(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

double WrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

double QuaternionNorm(const TripodPose& p) {
  return std::sqrt(p.qw * p.qw + p.qx * p.qx + p.qy * p.qy + p.qz * p.qz);
}

Eigen::Matrix3d RotationOf(const TripodPose& p) {
  return Eigen::Quaterniond(p.qw, p.qx, p.qy, p.qz).normalized().toRotationMatrix();
}

/// A rejected push: the reason, thrown inside the per-push import and caught by its caller.
struct Rejected {
  std::string reason;
};

/// Nearest point of the block's boundary to `p` (object frame): edge, point, distance.
struct EdgePoint {
  int edge = -1;
  Eigen::Vector2d point;
  double distance = 0;
};

EdgePoint NearestEdge(const std::array<Eigen::Vector2d, 3>& v, const Eigen::Vector2d& p) {
  EdgePoint best;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector2d a = v[i];
    const Eigen::Vector2d d = v[(i + 1) % 3] - a;
    const double s = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    const Eigen::Vector2d q = a + s * d;
    const double dist = (p - q).norm();
    if (best.edge < 0 || dist < best.distance) best = {i, q, dist};
  }
  return best;
}

/// Inward unit normal of edge i of a counter-clockwise polygon.
Eigen::Vector2d InwardNormal(const std::array<Eigen::Vector2d, 3>& v, int i) {
  const Eigen::Vector2d d = v[(i + 1) % 3] - v[i];
  return Eigen::Vector2d(-d.y(), d.x()).normalized();
}

double AngleDeg(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double na = a.norm(), nb = b.norm();
  if (!(na > 0.0) || !(nb > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return kDegPerRad * std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0));
}

// ---------------------------------------------------------------------------------------
// One push
// ---------------------------------------------------------------------------------------

/// The tool's position [m] and yaw [rad] over time, linearly interpolated (held at the ends).
class ToolTrack {
 public:
  explicit ToolTrack(const std::vector<TripodRobotSample>& robot) {
    double prev_yaw = 0.0;
    for (std::size_t i = 0; i < robot.size(); ++i) {
      const TripodRobotSample& r = robot[i];
      double yaw = TripodToolYaw(r.pose);
      if (i > 0) yaw = prev_yaw + WrapAngle(yaw - prev_yaw);  // unwrapped
      prev_yaw = yaw;
      t_.push_back(r.t_s);
      x_.push_back(Eigen::Vector3d(r.pose.x_mm / 1000.0, r.pose.y_mm / 1000.0, yaw));
    }
  }
  /// (x, y, yaw) at time t.
  Eigen::Vector3d At(double t) const {
    if (t <= t_.front()) return x_.front();
    if (t >= t_.back()) return x_.back();
    const auto it = std::upper_bound(t_.begin(), t_.end(), t);
    const std::size_t j = static_cast<std::size_t>(it - t_.begin());
    const double s = (t - t_[j - 1]) / (t_[j] - t_[j - 1]);
    return x_[j - 1] + s * (x_[j] - x_[j - 1]);
  }

 private:
  std::vector<double> t_;
  std::vector<Eigen::Vector3d> x_;
};

void CheckQuaternion(const TripodPose& p, int line, const char* what) {
  const double n = QuaternionNorm(p);
  if (!(std::abs(n - 1.0) <= kQuaternionNormTolerance)) {
    throw Rejected{"line " + std::to_string(line) + ": the " + what + " quaternion has norm " +
                   ShortNumber(n) + ", not 1"};
  }
}

template <typename Sample>
void CheckIncreasing(const std::vector<Sample>& samples, const char* what) {
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (!(samples[i].t_s > samples[i - 1].t_s)) {
      throw Rejected{"line " + std::to_string(samples[i].line) + ": " + what + " time " +
                     ShortNumber(samples[i].t_s) + " s is not after the previous one, " +
                     ShortNumber(samples[i - 1].t_s) + " s"};
    }
  }
}

void CheckPush(const TripodPush& push, const TripodImportOptions& options) {
  if (static_cast<int>(push.forces.size()) < options.min_samples + 2) {
    throw Rejected{"line " + std::to_string(push.force_count_line) + ": only " +
                   std::to_string(push.forces.size()) + " force samples"};
  }
  if (push.robot.size() < 2) {
    throw Rejected{"line " + std::to_string(push.robot_count_line) + ": fewer than 2 robot poses"};
  }
  auto absurd = [](int line, const std::string& what, double value, double limit) {
    if (std::abs(value) > limit) {
      throw Rejected{"line " + std::to_string(line) + ": " + what + " " + ShortNumber(value) +
                     " is beyond " + ShortNumber(limit) +
                     " (absurd for a pushing experiment: a unit error?)"};
    }
  };
  for (const TripodForceSample& f : push.forces) {
    absurd(f.line, "time", f.t_s, kAbsurdTime_s);
    absurd(f.line, "force [N]", std::hypot(f.fx_n, f.fy_n), kAbsurdForce_n);
  }
  for (const TripodRobotSample& r : push.robot) {
    absurd(r.line, "time", r.t_s, kAbsurdTime_s);
    absurd(r.line, "tool position [mm]", std::hypot(r.pose.x_mm, r.pose.y_mm), kAbsurdPosition_mm);
  }
  for (const auto& [pose, line] : {std::pair{push.pre, push.line}, {push.post, push.line + 1}}) {
    absurd(line, "object position [mm]", std::hypot(pose.x_mm, pose.y_mm, pose.z_mm),
           kAbsurdPosition_mm);
  }
  CheckQuaternion(push.pre, push.line, "pre-push object");
  CheckQuaternion(push.post, push.line + 1, "post-push object");
  for (const TripodRobotSample& r : push.robot) CheckQuaternion(r.pose, r.line, "robot tool");
  CheckIncreasing(push.forces, "force sample");
  CheckIncreasing(push.robot, "robot pose");
}

/// Contact and sliding phases of one force trace (indices into the samples).
struct Phases {
  double sigma = 0, threshold = 0, contact_force = 0;
  std::size_t onset = 0;            ///< first sample of the contact run
  std::size_t first = 0, last = 0;  ///< sliding part, inclusive
  std::vector<std::size_t> kept;    ///< samples of the sliding part at or above the fraction
};

Phases FindPhases(const std::vector<Eigen::Vector2d>& force, const TripodImportOptions& options) {
  Phases ph;
  const std::size_t lead = std::min<std::size_t>(options.noise_samples, force.size() - 1);
  std::vector<double> diffs;
  for (std::size_t i = 1; i <= lead; ++i) {
    for (int c = 0; c < 2; ++c) diffs.push_back(force[i](c) - force[i - 1](c));
  }
  const double centre = Median(diffs);
  for (double& d : diffs) d = std::abs(d - centre);
  ph.sigma = kMadToSigma * Median(diffs) / std::sqrt(2.0);
  ph.threshold = std::max(options.onset_sigmas * ph.sigma, options.min_contact_force_n);

  // The longest run above the threshold: contact (short excursions of drift are not).
  std::size_t best_start = 0, best_length = 0;
  for (std::size_t i = 0; i < force.size();) {
    if (!(force[i].norm() > ph.threshold)) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < force.size() && force[j].norm() > ph.threshold) ++j;
    if (j - i > best_length) best_start = i, best_length = j - i;
    i = j;
  }
  if (best_length == 0) {
    throw Rejected{"no contact: |f| never exceeds " + Printf("%.3g", ph.threshold) + " N"};
  }
  ph.onset = best_start;
  std::vector<double> magnitude;
  for (std::size_t i = best_start; i < best_start + best_length; ++i) {
    magnitude.push_back(force[i].norm());
  }
  ph.contact_force = Median(magnitude);
  const double floor = options.sliding_fraction * ph.contact_force;
  const std::size_t end = best_start + best_length;
  std::size_t first = end, last = best_start;
  for (std::size_t i = best_start; i < end; ++i) {
    if (force[i].norm() >= floor) {
      first = std::min(first, i);
      last = i;
    }
  }
  // The median lies within the run, so some sample reaches the floor: first <= last.
  ph.first = first;
  ph.last = last;
  for (std::size_t i = first; i <= last; ++i) {
    if (force[i].norm() >= floor) ph.kept.push_back(i);
  }
  return ph;
}

/// The object's pose along the constant body twist from q0 (fraction s of the push).
struct PoseTrack {
  Eigen::Vector3d q0;
  Eigen::Vector3d twist_unit;  ///< body twist over the unit interval [m, m, rad]

  Eigen::Vector3d At(double s) const {
    const Eigen::Vector3d d = PoseChangeFromBodyTwist(twist_unit, s);
    const Eigen::Vector2d p = q0.head<2>() + Rotation(q0.z()) * d.head<2>();
    return {p.x(), p.y(), q0.z() + d.z()};
  }
};

struct PushResult {
  WrenchTwistRow row;
  TripodPushReport report;
};

/// Phase figures into the report, and the rejections they decide.
void JudgePhases(const std::vector<TripodForceSample>& fs, const Phases& ph,
                 const Eigen::Vector2d& median_offset, const TripodImportOptions& options,
                 TripodPushReport& rep) {
  const double t0 = fs[0].t_s;
  rep.noise_sigma_n = ph.sigma;
  rep.threshold_n = ph.threshold;
  rep.contact_force_n = ph.contact_force;
  rep.onset_s = fs[ph.onset].t_s - t0;
  rep.start_s = fs[ph.first].t_s - t0;
  rep.end_s = fs[ph.last].t_s - t0;
  rep.samples = static_cast<int>(ph.kept.size());
  rep.dropped_low = static_cast<int>(ph.last - ph.first + 1 - ph.kept.size());
  rep.offset_error_n = (Eigen::Vector2d(fs[0].fx_n, fs[0].fy_n) - median_offset).norm();
  if (rep.onset_s < options.min_rest_s) {
    throw Rejected{"line " + std::to_string(fs[ph.onset].line) + ": contact " +
                   Printf("%.2f", rep.onset_s) + " s into the trace, less than " +
                   Printf("%.2f", options.min_rest_s) +
                   " s: the offset (the first sample) may hold contact force"};
  }
  if (rep.offset_error_n > options.max_offset_error_fraction * ph.contact_force) {
    throw Rejected{"line " + std::to_string(fs[0].line) + ": the first sample differs by " +
                   Printf("%.3f", rep.offset_error_n) + " N from the file's median first sample, " +
                   Printf("%.1f", 100.0 * rep.offset_error_n / ph.contact_force) +
                   "% of the contact force: contact or a sensor jump before the trace"};
  }
  if (rep.samples < options.min_samples) {
    throw Rejected{"only " + std::to_string(rep.samples) + " samples in the sliding part"};
  }
}

/// Means over the kept samples, in the object frame along the pose track.
struct PushMeans {
  Eigen::Vector2d force = Eigen::Vector2d::Zero();    ///< [N]
  Eigen::Vector2d contact = Eigen::Vector2d::Zero();  ///< [m]
  double moment = 0, peak = 0, max_distance = 0;
  int edge = -1;  ///< the edge most samples touch
};

PushMeans Average(const std::vector<TripodForceSample>& fs,
                  const std::vector<Eigen::Vector2d>& force, const Phases& ph,
                  const PoseTrack& track, const ToolTrack& tool) {
  const std::array<Eigen::Vector2d, 3> vertices = TripodBlockVertices();
  const double start = fs[ph.first].t_s, duration = fs[ph.last].t_s - start;
  PushMeans m;
  std::array<int, 3> edge_count{};
  for (std::size_t i : ph.kept) {
    const double t = fs[i].t_s;
    const Eigen::Vector3d q = track.At(std::clamp((t - start) / duration, 0.0, 1.0));
    const Eigen::Vector3d tool_pose = tool.At(t);
    const Eigen::Matrix2d to_object = Rotation(-q.z());
    const Eigen::Vector2d f = to_object * Rotation(tool_pose.z()) * force[i];
    const EdgePoint e = NearestEdge(vertices, to_object * (tool_pose.head<2>() - q.head<2>()));
    m.force += f;
    m.contact += e.point;
    m.moment += e.point.x() * f.y() - e.point.y() * f.x();
    m.peak = std::max(m.peak, f.norm());
    m.max_distance = std::max(m.max_distance, e.distance);
    ++edge_count[e.edge];
  }
  const double n = static_cast<double>(ph.kept.size());
  m.force /= n;
  m.contact /= n;
  m.moment /= n;
  m.edge =
      static_cast<int>(std::max_element(edge_count.begin(), edge_count.end()) - edge_count.begin());
  return m;
}

void ImportPush(const TripodPush& push, const Eigen::Vector2d& median_offset,
                const TripodImportOptions& options, PushResult& out) {
  TripodPushReport& rep = out.report;
  CheckPush(push, options);
  const std::vector<TripodForceSample>& fs = push.forces;
  std::vector<Eigen::Vector2d> force;  // on the object, tool frame, offset removed
  const Eigen::Vector2d offset = TripodToolForce(fs[0].fx_n, fs[0].fy_n);
  for (const TripodForceSample& s : fs) force.push_back(TripodToolForce(s.fx_n, s.fy_n) - offset);
  const Phases ph = FindPhases(force, options);
  JudgePhases(fs, ph, median_offset, options, rep);

  // Pose change and the constant body twist that explains it.
  const Eigen::Vector3d q0 = TripodObjectPose(push.pre);
  const Eigen::Vector3d q1 = TripodObjectPose(push.post);
  const Eigen::Vector2d d = Rotation(-q0.z()) * (q1.head<2>() - q0.head<2>());
  const double dtheta = WrapAngle(q1.z() - q0.z());
  const Eigen::Vector3d twist_unit = BodyTwistFromPoseChange(d, dtheta);
  const PushMeans m = Average(fs, force, ph, PoseTrack{q0, twist_unit}, ToolTrack(push.robot));

  const std::array<Eigen::Vector2d, 3> vertices = TripodBlockVertices();
  rep.edge = m.edge;
  rep.max_edge_distance_m = m.max_distance;
  rep.force_normal_angle_deg = AngleDeg(m.force, InwardNormal(vertices, m.edge));
  rep.force_twist_angle_deg = AngleDeg(m.force, twist_unit.head<2>());
  rep.displacement_m = d.norm();
  rep.rotation_rad = dtheta;
  if (m.max_distance > options.max_edge_distance_m) {
    throw Rejected{"the tool point is up to " + Printf("%.1f", 1000.0 * m.max_distance) +
                   " mm from the block's edge (limit " +
                   Printf("%.1f", 1000.0 * options.max_edge_distance_m) +
                   " mm): not in contact where the poses say"};
  }
  if (!(rep.force_normal_angle_deg < 90.0)) {
    throw Rejected{"the mean force points out of the block (" +
                   Printf("%.0f", rep.force_normal_angle_deg) +
                   " deg from the inward normal of the pushed edge): a sign or frame error"};
  }
  if (d.isZero(0.0) && dtheta == 0.0) throw Rejected{"the object did not move"};
  const double duration = fs[ph.last].t_s - fs[ph.first].t_s;
  const Eigen::Vector3d twist = twist_unit / duration;
  if (!(std::isfinite(m.moment) && m.force.allFinite() && std::isfinite(duration) &&
        duration > 0.0 && twist.allFinite())) {
    throw Rejected{"the wrench or the twist is not a finite number (values too large?)"};
  }

  WrenchTwistRow& row = out.row;
  row.pair = {m.force.x(), m.force.y(), 0.0, m.moment, twist.x(), twist.y(), twist.z()};
  row.duration_s = duration;
  row.dx_m = d.x();
  row.dy_m = d.y();
  row.dtheta_rad = dtheta;
  row.contact_x_m = m.contact.x();
  row.contact_y_m = m.contact.y();
  row.peak_force_n = m.peak;
  row.samples = rep.samples;
}

std::string SupportsText(const std::array<Eigen::Vector2d, 3>& s) {
  std::string out;
  for (int i = 0; i < 3; ++i) {
    out += (i ? "; " : "") + ShortNumber(s[i].x()) + " " + ShortNumber(s[i].y());
  }
  return out;
}

void FillMetadata(const std::string& source, const TripodImportOptions& options,
                  WrenchTwistData& data) {
  data.mass_kg = options.mass_kg.value_or(kTripodMass_kg);
  data.gravity_mps2 = options.gravity_mps2;
  data.inertia_kgm2 = options.inertia_kgm2.value_or(kTripodInertiaEstimate_kgm2);
  data.com_height_m = options.com_height_m;
  data.source = source;
  data.extra_metadata.emplace_back(
      "frame",
      "object: origin at the CM, axes of the block frame (Vicon body frame shifted by "
      "(50, 50, 0) mm)");
  data.extra_metadata.emplace_back("mass_source", options.mass_kg ? "option" : "dataset README");
  data.extra_metadata.emplace_back(
      "inertia_source", options.inertia_kgm2 ? "option" : "dataset README estimate (thin plate)");
  const std::string folder = std::filesystem::path(source).parent_path().filename().string();
  if (options.supports) {
    data.supports = *options.supports;
  } else if (const auto s = ParseTripodSupports(folder)) {
    data.supports = SupportsText(*s);
    const SupportSpread spread = TripodSupportSpread(*s);
    data.extra_metadata.emplace_back("support_spread_rms", ShortNumber(spread.rms_m));
    data.extra_metadata.emplace_back("support_spread_weighted",
                                     ShortNumber(spread.weighted_mean_m));
  }
  if (folder.rfind("wood_", 0) == 0) {
    data.extra_metadata.emplace_back("surface", "plywood (README: wood_ prefix)");
  } else if (!folder.empty() && (ParseTripodSupports(folder) || folder == "patch")) {
    data.extra_metadata.emplace_back("surface", "hardboard (README: no prefix)");
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Conventions
// ---------------------------------------------------------------------------------------

std::array<Eigen::Vector2d, 3> TripodBlockVertices() {
  const Eigen::Vector2d cm(kTripodCmInBlock_m, kTripodCmInBlock_m);
  return {Eigen::Vector2d(0.0, 0.0) - cm, Eigen::Vector2d(kTripodLeg_m, 0.0) - cm,
          Eigen::Vector2d(0.0, kTripodLeg_m) - cm};
}

Eigen::Vector2d TripodToolForce(double fx_sensor_n, double fy_sensor_n) {
  const double s = std::sqrt(0.5);
  return {-(s * fx_sensor_n + s * fy_sensor_n), -(s * fx_sensor_n - s * fy_sensor_n)};
}

Eigen::Vector2d TripodSensorForce(const Eigen::Vector2d& tool_force) {
  return TripodToolForce(tool_force.x(), tool_force.y());  // (-R)(-R) = R^2 = I
}

Eigen::Vector3d TripodObjectPose(const TripodPose& vicon) {
  const Eigen::Matrix3d r = RotationOf(vicon);
  const Eigen::Vector3d cm = Eigen::Vector3d(vicon.x_mm, vicon.y_mm, vicon.z_mm) / 1000.0 +
                             r * Eigen::Vector3d(kTripodCmInBlock_m, kTripodCmInBlock_m, 0.0);
  return {cm.x(), cm.y(), std::atan2(r(1, 0), r(0, 0))};
}

TripodPose TripodViconPose(const Eigen::Vector3d& pose, double z_mm) {
  const Eigen::Vector2d corner =
      pose.head<2>() - Rotation(pose.z()) * Eigen::Vector2d(kTripodCmInBlock_m, kTripodCmInBlock_m);
  return {1000.0 * corner.x(),   1000.0 * corner.y(), z_mm, std::cos(pose.z() / 2), 0.0, 0.0,
          std::sin(pose.z() / 2)};
}

double TripodToolYaw(const TripodPose& p) {
  return std::atan2(2.0 * (p.qw * p.qz + p.qx * p.qy), 1.0 - 2.0 * (p.qy * p.qy + p.qz * p.qz));
}

std::optional<std::array<Eigen::Vector2d, 3>> ParseTripodSupports(const std::string& name) {
  std::string_view s = name;
  if (s.rfind("wood_", 0) == 0) s.remove_prefix(5);
  std::array<double, 6> v;
  for (int i = 0; i < 6; ++i) {
    const std::size_t end = s.find('_');
    if ((end == std::string_view::npos) != (i == 5)) return std::nullopt;
    const auto x = text::ParseFiniteNumber(s.substr(0, end));
    if (!x) return std::nullopt;
    v[i] = *x;
    s.remove_prefix(end == std::string_view::npos ? s.size() : end + 1);
  }
  std::array<Eigen::Vector2d, 3> out;
  for (int i = 0; i < 3; ++i) {
    // In mm first: (30 - 50) / 1000 is -0.02 exactly, 0.03 - 0.05 is not.
    const double cm_mm = 1000.0 * kTripodCmInBlock_m;
    out[i] = Eigen::Vector2d(v[i] - cm_mm, v[i + 3] - cm_mm) / 1000.0;
  }
  return out;
}

SupportSpread TripodSupportSpread(const std::array<Eigen::Vector2d, 3>& s) {
  // Barycentric coordinates of the origin (the CM): sum w_i s_i = 0, sum w_i = 1.
  Eigen::Matrix3d a;
  a << s[0].x(), s[1].x(), s[2].x(), s[0].y(), s[1].y(), s[2].y(), 1.0, 1.0, 1.0;
  const double scale = std::max({s[0].squaredNorm(), s[1].squaredNorm(), s[2].squaredNorm()});
  // Twice the triangle's area over the largest squared distance: 0 for collinear points;
  // 1e-9 is far below any real layout (the tripod's smallest is ~0.3).
  if (!(std::abs(a.determinant()) > 1e-9 * scale)) {
    throw std::invalid_argument("TripodSupportSpread: the supports are collinear");
  }
  const Eigen::Vector3d w = a.partialPivLu().solve(Eigen::Vector3d(0.0, 0.0, 1.0));
  SupportSpread out;
  double sum_sq = 0;
  for (int i = 0; i < 3; ++i) {
    out.weights[i] = w(i);
    sum_sq += s[i].squaredNorm();
    out.weighted_mean_m += w(i) * s[i].norm();
  }
  out.rms_m = std::sqrt(sum_sq / 3.0);
  out.cm_inside = w.minCoeff() >= 0.0;
  return out;
}

bool TripodImportOptions::IsValid(std::string* why) const {
  auto fail = [why](const std::string& text) {
    if (why) *why = text;
    return false;
  };
  auto positive = [](const std::optional<double>& x) {
    return !x || (std::isfinite(*x) && *x > 0.0);
  };
  if (!positive(mass_kg)) return fail("mass must be a finite number > 0");
  if (!(std::isfinite(gravity_mps2) && gravity_mps2 > 0.0)) return fail("gravity must be > 0");
  if (!positive(inertia_kgm2)) return fail("inertia must be a finite number > 0");
  if (com_height_m && !(std::isfinite(*com_height_m) && *com_height_m >= 0.0)) {
    return fail("com_height must be a finite number >= 0");
  }
  if (supports && supports->find_first_of("\r\n") != std::string::npos) {
    return fail("supports must be one line");
  }
  if (noise_samples < 4) return fail("noise_samples must be >= 4");
  if (!(onset_sigmas > 0.0)) return fail("onset_sigmas must be > 0");
  if (!(min_contact_force_n >= 0.0) || !std::isfinite(min_contact_force_n)) {
    return fail("min_contact_force_n must be >= 0");
  }
  if (!(sliding_fraction > 0.0 && sliding_fraction < 1.0)) {
    return fail("sliding_fraction must be in (0, 1)");
  }
  if (!(min_rest_s >= 0.0) || !std::isfinite(min_rest_s)) return fail("min_rest_s must be >= 0");
  if (!(max_offset_error_fraction > 0.0)) return fail("max_offset_error_fraction must be > 0");
  if (!(max_edge_distance_m > 0.0)) return fail("max_edge_distance_m must be > 0");
  if (min_samples < 2) return fail("min_samples must be >= 2");
  return true;
}

// ---------------------------------------------------------------------------------------
// Import
// ---------------------------------------------------------------------------------------

WrenchTwistData ImportZhouTripod(const TripodLog& log, const std::string& source,
                                 const TripodImportOptions& options, TripodImportReport* report) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("tripod import: " + why);
  TripodImportReport local;
  TripodImportReport& rep = report ? *report : local;
  rep = TripodImportReport{};
  rep.source = source;
  rep.pushes = static_cast<int>(log.pushes.size());

  WrenchTwistData data;
  FillMetadata(source, options, data);
  std::vector<double> fx0, fy0;
  for (const TripodPush& push : log.pushes) {
    if (push.forces.empty()) continue;
    fx0.push_back(push.forces[0].fx_n);
    fy0.push_back(push.forces[0].fy_n);
  }
  if (!fx0.empty()) rep.median_offset_sensor_n = Eigen::Vector2d(Median(fx0), Median(fy0));

  for (std::size_t p = 0; p < log.pushes.size(); ++p) {
    PushResult result;
    result.report.push = static_cast<int>(p + 1);
    result.report.line = log.pushes[p].line;
    try {
      ImportPush(log.pushes[p], rep.median_offset_sensor_n, options, result);
      result.report.accepted = true;
      result.row.push = result.report.push;
      data.rows.push_back(result.row);
      ++rep.accepted;
    } catch (const Rejected& r) {
      result.report.reason = r.reason;
    }
    rep.push_reports.push_back(result.report);
  }
  if (rep.accepted == 0) rep.notes.push_back("no push could be used");
  data.extra_metadata.emplace_back("pushes_in_source", std::to_string(rep.pushes));
  data.extra_metadata.emplace_back("pushes_accepted", std::to_string(rep.accepted));
  return data;
}

WrenchTwistData ImportZhouTripod(const std::string& path, const TripodImportOptions& options,
                                 TripodImportReport* report) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("tripod import: " + why);
  return ImportZhouTripod(ReadZhouTripodLog(path), path, options, report);
}

void WriteTripodImportReport(const TripodImportReport& report, const std::string& path) {
  std::ostringstream out;
  out << "# tripod import report: " << report.source << "\n# pushes = " << report.pushes
      << "\n# accepted = " << report.accepted << "\n";
  out << "push,line,verdict,noise_sigma,threshold,contact_force,offset_error,onset,start,end,"
         "samples,dropped_low,edge,max_edge_distance,force_normal_angle_deg,"
         "force_twist_angle_deg,displacement,rotation,reason\n";
  for (const TripodPushReport& r : report.push_reports) {
    std::string reason = r.reason;
    std::replace(reason.begin(), reason.end(), '"', '\'');
    out << r.push << ',' << r.line << ',' << (r.accepted ? "accepted" : "rejected");
    for (double x : {r.noise_sigma_n, r.threshold_n, r.contact_force_n, r.offset_error_n, r.onset_s,
                     r.start_s, r.end_s}) {
      out << ',' << ShortNumber(x);
    }
    out << ',' << r.samples << ',' << r.dropped_low << ',' << r.edge;
    for (double x : {r.max_edge_distance_m, r.force_normal_angle_deg, r.force_twist_angle_deg,
                     r.displacement_m, r.rotation_rad}) {
      out << ',' << (std::isfinite(x) ? ShortNumber(x) : "");
    }
    out << ",\"" << reason << "\"\n";
  }
  WriteFileAtomically(path, "the tripod import report", out.str());
}

}  // namespace slideid
