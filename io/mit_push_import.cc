#include "io/mit_push_import.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "estimator/robust_statistics.h"
#include "forward_model/constants.h"
#include "forward_model/contact_patch.h"
#include "forward_model/number_format.h"
#include "forward_model/planar_state.h"
#include "forward_model/pusher.h"
#include "io/cm_offset.h"

namespace slideid {
namespace {

constexpr double kHalfPi = kPi / 2;
// A stream needs this many rows after cleanup for rates, speeds and interpolation to mean
// anything (40 ms at 250 Hz; the real streams hold 87-313).
constexpr int kMinStreamRows = 10;
// A live sensor whose resolution is finer than its noise does not repeat a reading exactly
// (the real files print 16 digits; still noise is about 0.05 N): this many identical
// consecutive readings of fx or fy (20 ms at 250 Hz) are a stalled or saturated channel.
constexpr int kFrozenRun = 5;
// Two offset windows, one with the tip resting against the object, that differ by more
// than this [N] hold a pre-load (EstimateOffset): below the smallest pre-load the MIT files
// show (0.4 N), and above their force noise (0.05 N per sample, about 5 mN on a window's
// median).
constexpr double kMinPreloadN = 0.3;
// Still samples needed for an offset estimate: 10 samples (40 ms at 250 Hz) make the
// median's error about 0.4 sigma.
constexpr int kMinStillSamples = 10;
// Still samples are taken this far from the push [s]: the sensor and the object settle
// (the real force decays within about 50 ms of the tip stopping).
constexpr double kGuardS = 0.05;
// Force "above noise": kNoiseSigmas robust standard deviations of the still samples, and
// never below kMinForceThresholdN (a noiseless synthetic sensor would otherwise make any
// rounding a push).
constexpr double kNoiseSigmas = 5.0;
constexpr double kMinForceThresholdN = 0.05;
constexpr double kMadToSigma = 1.4826;
// The force on the object lies in the friction cone of the contact normal. |alignment|
// below 0.5 (a cone of 60 deg, a pusher friction coefficient of 1.7) is no pushing force:
// a wrong outline, pose or force frame, not a sign to pick.
constexpr double kMinNormalAlignment = 0.5;
// Plausible magnitudes: beyond them a value is a unit or format error, and arithmetic on it
// (differences of angles, products of arms and forces) could overflow. Times: Unix seconds
// (about 1.5e9) or seconds from a start; positions: a robot's workspace; forces: far beyond
// any pushing sensor.
constexpr double kMaxAbsTimeS = 1e11;
constexpr double kMaxAbsPositionM = 1e3;
constexpr double kMaxAbsAngleRad = 1e4;
constexpr double kMaxAbsForceN = 1e5;
// Most rows one log may have (a push window of 10^4 s at 100 Hz): beyond, the times are
// not seconds, or the rate is absurd.
constexpr double kMaxRows = 1e6;
// The fewest rows an imported log may have: fewer leave the estimators no step to fit.
constexpr int kMinRows = 3;
// The tip speed is a central difference over +-20 ms: the robot's position noise (about
// 1e-5 m) then makes at most 0.5 mm/s of speed noise, far below the still threshold, while
// a push (0.1-0.2 s to reach its speed) is still resolved.
constexpr double kSpeedHalfWindowS = 0.02;

/// Linear interpolation of column k of sorted `rows` at t (clamped at the ends).
double Interpolate(const std::vector<MitStreamRow>& rows, double t, int k) {
  if (t <= rows.front()[0]) return rows.front()[k];
  if (t >= rows.back()[0]) return rows.back()[k];
  const auto hi =
      std::upper_bound(rows.begin(), rows.end(), t,
                       [](double value, const MitStreamRow& r) { return value < r[0]; });
  const auto lo = hi - 1;
  const double w = (t - (*lo)[0]) / ((*hi)[0] - (*lo)[0]);  // rows strictly increase in t
  return (*lo)[k] + w * ((*hi)[k] - (*lo)[k]);
}

std::string Vec(const Eigen::Vector2d& v) { return Printf("%.4g %.4g", v.x(), v.y()); }

StreamSummary Clean(std::vector<MitStreamRow>* rows) {
  StreamSummary s;
  s.cleanup = SortAndDeduplicate(rows);
  s.rows = static_cast<int>(rows->size());
  if (rows->size() < 2) return s;
  std::vector<double> dt;
  for (std::size_t i = 1; i < rows->size(); ++i) dt.push_back((*rows)[i][0] - (*rows)[i - 1][0]);
  s.median_rate_hz = 1.0 / Median(dt);  // dt > 0: times strictly increase after cleanup
  s.largest_gap_s = *std::max_element(dt.begin(), dt.end());
  return s;
}

/// The first value beyond a plausible magnitude, as a reason, or empty.
std::string Implausible(const std::vector<MitStreamRow>& rows, const char* stream,
                        const std::array<double, 4>& limits,
                        const std::array<const char*, 4>& names) {
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (int k = 0; k < 4; ++k) {
      if (std::abs(rows[i][k]) <= limits[k]) continue;
      return std::string(stream) + ": " + names[k] +
             Printf(" = %.6g beyond any plausible value ", rows[i][k]) +
             Printf("(|value| <= %.0e): a unit or format error?", limits[k]);
    }
  }
  return "";
}

/// "fx" or "fy" when that channel holds one value throughout, else empty.
std::string DeadChannel(const std::vector<MitStreamRow>& ft) {
  for (int k : {1, 2}) {
    const bool constant = std::all_of(ft.begin(), ft.end(),
                                      [&](const MitStreamRow& r) { return r[k] == ft.front()[k]; });
    if (constant) return k == 1 ? "fx" : "fy";
  }
  return "";
}

/// A run of identical readings of one force channel: [first, last] time and the value.
struct FrozenRun {
  double t_first, t_last;
  const char* channel;  ///< "fx" or "fy"
  double value_n;
  int samples;
};

/// Removes the samples where fx or fy repeats one reading kFrozenRun times or more in a
/// row; returns the runs.
std::vector<FrozenRun> DropFrozen(std::vector<MitStreamRow>* ft) {
  std::vector<FrozenRun> runs;
  std::vector<bool> frozen(ft->size(), false);
  for (int k : {1, 2}) {
    std::size_t i = 0;
    while (i < ft->size()) {
      std::size_t j = i + 1;
      while (j < ft->size() && (*ft)[j][k] == (*ft)[i][k]) ++j;
      if (j - i >= static_cast<std::size_t>(kFrozenRun)) {
        runs.push_back({(*ft)[i][0], (*ft)[j - 1][0], k == 1 ? "fx" : "fy", (*ft)[i][k],
                        static_cast<int>(j - i)});
        std::fill(frozen.begin() + i, frozen.begin() + j, true);
      }
      i = j;
    }
  }
  std::vector<MitStreamRow> kept;
  for (std::size_t i = 0; i < ft->size(); ++i) {
    if (!frozen[i]) kept.push_back((*ft)[i]);
  }
  *ft = std::move(kept);
  return runs;
}

// Motion-capture glitches: a marker swap puts the object metres away on isolated samples.
// A pose farther than kGlitchDistanceM from the median of its kGlitchNeighbours neighbours
// on either side is one: in the 3 samples (12 ms at 250 Hz) either side an object pushed at
// 0.1-0.15 m/s moves under 2 mm, a tenth of that. Dropped poses are counted in the report;
// above kMaxGlitchFraction of the stream the file is rejected, the stream untrustworthy.
constexpr double kGlitchDistanceM = 0.02;
constexpr int kGlitchNeighbours = 3;
constexpr double kMaxGlitchFraction = 0.2;

/// Drops the isolated outliers of an object-pose stream; returns how many.
int DropPoseGlitches(std::vector<MitStreamRow>* pose) {
  const int n = static_cast<int>(pose->size());
  std::vector<char> glitch(n, 0);
  for (int i = 0; i < n; ++i) {
    std::vector<double> x, y;
    for (int j = std::max(0, i - kGlitchNeighbours); j <= std::min(n - 1, i + kGlitchNeighbours);
         ++j) {
      if (j == i) continue;
      x.push_back((*pose)[j][1]);
      y.push_back((*pose)[j][2]);
    }
    if (x.empty()) continue;
    glitch[i] = std::hypot((*pose)[i][1] - Median(x), (*pose)[i][2] - Median(y)) > kGlitchDistanceM;
  }
  std::vector<MitStreamRow> kept;
  for (int i = 0; i < n; ++i) {
    if (!glitch[i]) kept.push_back((*pose)[i]);
  }
  const int dropped = n - static_cast<int>(kept.size());
  *pose = std::move(kept);
  return dropped;
}

/// Unwraps theta and repairs steps near a non-zero multiple of pi/2 (model: the tracker
/// swapped to a symmetric marker assignment; every later sample carries the same offset).
void RepairTheta(std::vector<MitStreamRow>* pose, double threshold, MitImportReport* report) {
  double previous_raw = (*pose)[0][3];
  double previous = previous_raw;
  for (std::size_t i = 1; i < pose->size(); ++i) {
    const double raw = (*pose)[i][3];
    double step = raw - previous_raw;
    if (std::abs(step) > threshold) {
      const double k = std::round(step / kHalfPi);
      const double residual = step - k * kHalfPi;
      if (k != 0.0 && std::abs(residual) <= threshold) {
        step = residual;
        (std::fmod(std::abs(k), 4.0) == 0.0 ? report->theta_wraps : report->theta_jumps_repaired)++;
      } else {
        ++report->theta_jumps_unrepaired;
      }
    }
    report->largest_theta_step_rad = std::max(report->largest_theta_step_rad, std::abs(step));
    previous_raw = raw;
    previous += step;
    (*pose)[i][3] = previous;
  }
}

/// Where the tip is relative to the object at one time.
struct Contact {
  double gap_m;                 ///< centre to outline (negative inside) minus tip radius
  Eigen::Vector2d point_world;  ///< outline point nearest the tip centre
  Eigen::Vector2d normal_in;    ///< unit, world: from the tip into the object
};

/// The recording after cleanup, with what later steps evaluate at any time.
class Streams {
 public:
  Streams(const MitPushRecording& r, const MitImportOptions& o)
      : object(r.object_pose),
        tip(r.tip_pose),
        ft(r.ft_wrench),
        options_(o),
        patch_(ContactPatch::Parse(o.patch_spec)) {}

  std::vector<MitStreamRow> object, tip, ft;

  Eigen::Vector3d PoseAt(double t) const {
    return {Interpolate(object, t, 1), Interpolate(object, t, 2), Interpolate(object, t, 3)};
  }
  Eigen::Vector2d TipAt(double t) const { return {Interpolate(tip, t, 1), Interpolate(tip, t, 2)}; }
  /// The tip against the outline (forward_model/pusher.h, as the pusher-driven model sees it).
  Contact ContactAtTime(double t) const {
    const Eigen::Vector3d pose = PoseAt(t);
    const TipContact c = ContactWithTip(patch_, PlanarState{pose.x(), pose.y(), pose.z()}, TipAt(t),
                                        options_.tip_radius_m);
    return {c.gap_m, c.point_world, -c.normal_world};
  }
  /// Tip velocity by a central difference over +-kSpeedHalfWindowS, inside the stream [m/s].
  Eigen::Vector2d TipVelocityAt(double t) const {
    const double lo = std::max(t - kSpeedHalfWindowS, tip.front()[0]);
    const double hi = std::min(t + kSpeedHalfWindowS, tip.back()[0]);
    if (hi <= lo) return Eigen::Vector2d::Zero();  // cannot happen: >= kMinStreamRows times
    return (TipAt(hi) - TipAt(lo)) / (hi - lo);
  }
  bool InTipSpan(double t) const { return t >= tip.front()[0] && t <= tip.back()[0]; }
  bool InObjectSpan(double t) const { return t >= object.front()[0] && t <= object.back()[0]; }

 private:
  const MitImportOptions& options_;
  ContactPatch patch_;
};

/// A force sample with what the push detection needs.
struct ForceSample {
  double t;
  Eigen::Vector2d f;    ///< stored force [N]
  bool known = false;   ///< tip and object streams cover t
  bool active = false;  ///< tip moving and touching
  Contact contact{};
  Eigen::Vector2d tip_velocity = Eigen::Vector2d::Zero();
};

std::vector<ForceSample> ClassifyForceSamples(const Streams& s, const MitImportOptions& o) {
  std::vector<ForceSample> out;
  for (const MitStreamRow& r : s.ft) {
    ForceSample f{r[0], {r[1], r[2]}};
    f.known = s.InTipSpan(f.t) && s.InObjectSpan(f.t);
    if (f.known) {
      f.contact = s.ContactAtTime(f.t);
      f.tip_velocity = s.TipVelocityAt(f.t);
      f.active =
          f.tip_velocity.norm() > o.still_speed_mps && f.contact.gap_m < o.contact_tolerance_m;
    }
    out.push_back(f);
  }
  return out;
}

/// The force offset over time: the still samples' medians before and after the push,
/// linear in between (or the one that exists).
class Offset {
 public:
  std::optional<Eigen::Vector2d> before, after;
  double t_before = 0, t_after = 0;  ///< last before-sample, first after-sample

  Eigen::Vector2d At(double t) const {
    if (!after) return *before;
    if (!before || t >= t_after) return *after;
    if (t <= t_before) return *before;
    const double w = (t - t_before) / (t_after - t_before);  // t_after > t_before here
    return *before + w * (*after - *before);
  }
};

Eigen::Vector2d ComponentMedian(const std::vector<const ForceSample*>& samples) {
  std::vector<double> x, y;
  for (const ForceSample* s : samples) {
    x.push_back(s->f.x());
    y.push_back(s->f.y());
  }
  return {Median(x), Median(y)};
}

/// What went wrong, if anything, as the report's reason.
using Rejection = std::optional<std::string>;

// The samples outside the push on one side, split by whether the tip is clear of the
// outline (they measure the sensor's offset) or rests against the object (they may carry a
// real pre-load).
struct OffsetWindow {
  std::vector<const ForceSample*> clear, resting;
  bool HasClear() const { return static_cast<int>(clear.size()) >= kMinStillSamples; }
  bool HasResting() const { return static_cast<int>(resting.size()) >= kMinStillSamples; }
};

/// Where the offset is measured (docs/real-data.md, "Offsets and pre-loads"):
///  - a window with the tip clear of the object (MitImportOptions::offset_clearance_m)
///    measures it; with both clear and disagreeing by more than max_offset_drift_n the
///    file is rejected for drift;
///  - a window where the tip only rests against the object measures it too when it agrees
///    with the other window within kMinPreloadN, or when there is no other; when it
///    disagrees, the clear window, else the one after the push, is the offset, and the other
///    holds a pre-load: the tip pressing the object, a real force kept in the log (the MIT
///    pushes start "in contact with the object" and read 0.4-1.9 N more than once the tip
///    has left). A drift of the sensor while the tip rests on both sides cannot be told
///    from a pre-load, and is taken for one.
Rejection EstimateOffset(const std::vector<ForceSample>& samples, double t_first_active,
                         double t_last_active, const MitImportOptions& o, Offset* offset,
                         MitImportReport* report) {
  OffsetWindow side[2];  // before, after
  for (const ForceSample& s : samples) {
    if (!s.known) continue;
    const int k = s.t < t_first_active - kGuardS ? 0 : s.t > t_last_active + kGuardS ? 1 : -1;
    if (k < 0) continue;
    (s.contact.gap_m > o.offset_clearance_m ? side[k].clear : side[k].resting).push_back(&s);
  }
  // Each side's samples for the offset: the clear ones, else the resting ones.
  std::vector<const ForceSample*> used[2];
  std::optional<Eigen::Vector2d> median[2];
  for (int k = 0; k < 2; ++k) {
    used[k] = side[k].HasClear()     ? side[k].clear
              : side[k].HasResting() ? side[k].resting
                                     : std::vector<const ForceSample*>{};
    if (!used[k].empty()) median[k] = ComponentMedian(used[k]);
  }
  report->offset_before_samples = static_cast<int>(used[0].size());
  report->offset_after_samples = static_cast<int>(used[1].size());
  if (!median[0] && !median[1]) {
    return "force offset unknown: too few force samples outside the push before (" +
           std::to_string(side[0].clear.size() + side[0].resting.size()) + ") and after (" +
           std::to_string(side[1].clear.size() + side[1].resting.size()) + ") it (need " +
           std::to_string(kMinStillSamples) + ")";
  }
  const bool both_clear = side[0].HasClear() && side[1].HasClear();
  const double differ_by = median[0] && median[1] ? (*median[1] - *median[0]).norm() : 0.0;
  if (differ_by > (both_clear ? o.max_offset_drift_n : kMinPreloadN)) {
    if (both_clear) {
      report->offset_drift_n = differ_by;
      return Printf("force offset drift %.3g N between before (", *report->offset_drift_n) +
             Vec(*median[0]) + ") and after (" + Vec(*median[1]) +
             Printf(
                 ") the push, both with the tip clear of the object, exceeds %.3g N "
                 "(--max-offset-drift)",
                 o.max_offset_drift_n);
    }
    // A resting side that disagrees: a clear side, else the side after the push, is the
    // offset (a pushing tip stops pressing once the push is over: the MIT rig then reads
    // 0.02-0.07 N), and the other side's tip presses the object.
    const int load = side[0].HasClear() ? 1 : 0;
    const Eigen::Vector2d preload = *median[load] - *median[1 - load];
    report->preload_n = preload;
    report->notes.push_back(std::string("the tip rests against the object ") +
                            (load == 0 ? "before" : "after") +
                            Printf(" the push, pressing it with %.3g N: kept as a real force, "
                                   "not taken for the sensor's offset",
                                   preload.norm()));
    median[load].reset();
    used[load].clear();
  }
  if (median[0]) {
    offset->before = median[0];
    offset->t_before = used[0].back()->t;
  } else {
    report->notes.push_back("no offset before the push: " +
                            std::to_string(side[0].clear.size() + side[0].resting.size()) +
                            " force samples outside it (the streams start during the push?)");
  }
  if (median[1]) {
    offset->after = median[1];
    offset->t_after = used[1].front()->t;
  } else {
    report->notes.push_back("no offset after the push: " +
                            std::to_string(side[1].clear.size() + side[1].resting.size()) +
                            " force samples outside it");
  }
  report->offset_before_n = offset->before;
  report->offset_after_n = offset->after;
  if (offset->before && offset->after) {
    report->offset_drift_n = (*offset->after - *offset->before).norm();
  }
  const std::vector<const ForceSample*>& before = used[0];
  const std::vector<const ForceSample*>& after = used[1];
  std::vector<double> deviations;
  for (const auto* side : {&before, &after}) {
    for (const ForceSample* s : *side) deviations.push_back((s->f - offset->At(s->t)).norm());
  }
  // |deviation| of a 2-D Gaussian has median sigma sqrt(2 ln 2) = 1.177 sigma.
  report->force_noise_n = Median(deviations) / 1.1774;
  report->force_threshold_n = std::max(kMinForceThresholdN, kNoiseSigmas * report->force_noise_n);
  return std::nullopt;
}

/// Step 6: decides whether to flip the stored force; returns a rejection when it cannot.
Rejection CheckSign(const std::vector<const ForceSample*>& push, const Offset& offset,
                    const MitImportOptions& o, MitImportReport* report) {
  double along = 0, magnitude = 0, fv = 0, ff = 0, vv = 0;
  for (const ForceSample* s : push) {
    const Eigen::Vector2d g = s->f - offset.At(s->t);
    along += g.dot(s->contact.normal_in);
    magnitude += g.norm();
    fv += g.dot(s->tip_velocity);
    ff += g.squaredNorm();
    vv += s->tip_velocity.squaredNorm();
  }
  report->normal_alignment = along / magnitude;  // magnitude > 0: push samples exceed the threshold
  if (ff > 0 && vv > 0) report->velocity_correlation = fv / std::sqrt(ff * vv);
  const double alignment = *report->normal_alignment;
  if (o.force_sign == ForceSign::kAuto) {
    if (std::abs(alignment) < kMinNormalAlignment) {
      return Printf(
          "sign check inconclusive: the force is not along the contact normal "
          "(alignment %+.2f; a push gives about +-1)",
          alignment);
    }
    report->force_flipped = alignment < 0;
    return std::nullopt;
  }
  report->force_flipped = o.force_sign == ForceSign::kReaction;
  const double effective = report->force_flipped ? -alignment : alignment;
  if (effective < kMinNormalAlignment) {
    report->notes.push_back(std::string("--force-sign ") + ToString(o.force_sign) +
                            Printf(" disagrees with the contact normal (alignment of the "
                                   "force used %+.2f)",
                                   effective));
  }
  return std::nullopt;
}

/// A row's force [N] and its moment about the CM [N m]: means over the row's interval.
struct RowWrench {
  Eigen::Vector2d force_n = Eigen::Vector2d::Zero();
  double moment_Nm = 0;
};

/// Means over [t0, t1] of the corrected force (the linear interpolant of its samples) and of
/// its moment about the CM at the contact point (both move within the interval: the mean
/// moment is not the moment of the mean force at either end).
RowWrench MeanWrench(const Streams& s, const Offset& offset, double sign, double t0, double t1) {
  t0 = std::max(t0, s.ft.front()[0]);
  t1 = std::min(t1, s.ft.back()[0]);
  auto at = [&](double t) {
    const Eigen::Vector2d f(Interpolate(s.ft, t, 1), Interpolate(s.ft, t, 2));
    RowWrench w;
    w.force_n = sign * (f - offset.At(t));
    const Eigen::Vector2d arm = s.ContactAtTime(t).point_world - s.PoseAt(t).head<2>();
    w.moment_Nm = arm.x() * w.force_n.y() - arm.y() * w.force_n.x();
    return w;
  };
  if (t1 <= t0) return at(t0);
  // Trapezoids between t0, every force sample inside and t1.
  std::vector<double> knots{t0};
  auto by_time = [](const MitStreamRow& r, double t) { return r[0] < t; };
  for (auto it = std::lower_bound(s.ft.begin(), s.ft.end(), t0, by_time);
       it != s.ft.end() && (*it)[0] < t1; ++it) {
    if ((*it)[0] > t0) knots.push_back((*it)[0]);
  }
  knots.push_back(t1);
  RowWrench mean;
  RowWrench previous = at(t0);
  for (std::size_t i = 1; i < knots.size(); ++i) {
    const RowWrench next = at(knots[i]);
    const double h = 0.5 * (knots[i] - knots[i - 1]) / (t1 - t0);
    mean.force_n += h * (previous.force_n + next.force_n);
    mean.moment_Nm += h * (previous.moment_Nm + next.moment_Nm);
    previous = next;
  }
  return mean;
}

/// Steps 1-3: sorts, checks counts and magnitudes, rejects a dead channel, drops frozen
/// force samples, repairs theta.
/// Each object pose moved from the tracked frame to the CM at `offset` in it: p + R(theta)
/// offset. After the heading's repair, before the contact geometry and the log use them.
void MoveObjectPosesToCm(const Eigen::Vector2d& offset, std::vector<MitStreamRow>* pose) {
  if (offset.isZero()) return;
  for (MitStreamRow& row : *pose) {
    const Eigen::Vector2d r = CmOffsetInWorld(offset, row[3]);
    row[1] += r.x();
    row[2] += r.y();
  }
}

Rejection PrepareStreams(const MitImportOptions& o, Streams* s, std::vector<FrozenRun>* frozen,
                         MitImportReport* r) {
  r->object_pose = Clean(&s->object);
  r->tip_pose = Clean(&s->tip);
  r->ft_wrench = Clean(&s->ft);
  for (const auto& [name, stream] :
       {std::pair{"object_pose", &r->object_pose}, std::pair{"tip_pose", &r->tip_pose},
        std::pair{"ft_wrench", &r->ft_wrench}}) {
    if (stream->rows < kMinStreamRows) {
      return std::string(name) + " has " + std::to_string(stream->rows) + " distinct times (need " +
             std::to_string(kMinStreamRows) + ")";
    }
  }
  constexpr std::array<double, 4> kPose = {kMaxAbsTimeS, kMaxAbsPositionM, kMaxAbsPositionM,
                                           kMaxAbsAngleRad};
  constexpr std::array<double, 4> kWrench = {kMaxAbsTimeS, kMaxAbsForceN, kMaxAbsForceN,
                                             kMaxAbsForceN};
  for (const std::string& implausible :
       {Implausible(s->object, "object_pose", kPose, {"t", "x", "y", "theta"}),
        Implausible(s->tip, "tip_pose", kPose, {"t", "x", "y", "yaw"}),
        Implausible(s->ft, "ft_wrench", kWrench, {"t", "fx", "fy", "tz"})}) {
    if (!implausible.empty()) return implausible;
  }
  if (const std::string dead = DeadChannel(s->ft); !dead.empty()) {
    const double value = s->ft.front()[dead == "fx" ? 1 : 2];
    return "force channel constant (dead sensor?): " + dead + Printf(" = %.6g N in all ", value) +
           std::to_string(r->ft_wrench.rows) + " samples";
  }
  *frozen = DropFrozen(&s->ft);
  r->frozen_force_samples = r->ft_wrench.rows - static_cast<int>(s->ft.size());
  if (static_cast<int>(s->ft.size()) < kMinStreamRows) {
    return "force channel frozen (dead sensor?): " + std::to_string(r->frozen_force_samples) +
           " of " + std::to_string(r->ft_wrench.rows) + " samples repeat a reading";
  }
  const int poses = static_cast<int>(s->object.size());
  r->pose_glitches = DropPoseGlitches(&s->object);
  if (r->pose_glitches > kMaxGlitchFraction * poses) {
    return "object_pose: " + std::to_string(r->pose_glitches) + " of " + std::to_string(poses) +
           Printf(
               " poses lie more than %.3g mm from their neighbours (marker swaps?): too many "
               "to drop",
               kGlitchDistanceM * 1e3);
  }
  if (r->pose_glitches > 0) {
    r->notes.push_back(std::to_string(r->pose_glitches) +
                       " object poses dropped as isolated outliers (marker swaps?)");
  }
  RepairTheta(&s->object, o.theta_jump_rad, r);
  MoveObjectPosesToCm(o.cm_offset_m, &s->object);
  return std::nullopt;
}

/// The push as found by FindPush.
struct Push {
  std::vector<ForceSample> samples;       ///< every force sample, classified
  std::vector<const ForceSample*> above;  ///< touching, moving, force above the noise
  Offset offset;
};

/// Steps 4-6: the samples of the push, the offset, the sign.
Rejection FindPush(const Streams& s, const MitImportOptions& o, Push* push, MitImportReport* r) {
  push->samples = ClassifyForceSamples(s, o);
  const ForceSample *first_active = nullptr, *last_active = nullptr;
  double closest = std::numeric_limits<double>::infinity();
  for (const ForceSample& f : push->samples) {
    if (f.known) closest = std::min(closest, f.contact.gap_m);
    if (!f.active) continue;
    if (!first_active) first_active = &f;
    last_active = &f;
  }
  if (!first_active) {
    return std::isfinite(closest)
               ? Printf(
                     "no contact: the tip never touches the object while it moves "
                     "(closest approach %.1f mm beyond the tip radius)",
                     closest * 1e3)
               : std::string("no contact: the streams do not overlap in time");
  }
  if (Rejection no =
          EstimateOffset(push->samples, first_active->t, last_active->t, o, &push->offset, r)) {
    return no;
  }
  for (const ForceSample& f : push->samples) {
    if (f.active && (f.f - push->offset.At(f.t)).norm() > r->force_threshold_n) {
      push->above.push_back(&f);
    }
  }
  if (push->above.empty()) {
    return Printf(
        "no push: the force stays below the noise threshold (%.3g N) while the tip "
        "touches the object and moves",
        r->force_threshold_n);
  }
  return CheckSign(push->above, push->offset, o, r);
}

/// The object-pose gaps longer than o.max_pose_gap_s that overlap [start, end], as
/// (last pose before, first pose after) [s, stream clock].
std::vector<std::pair<double, double>> PoseGaps(const Streams& s, double start, double end,
                                                const MitImportOptions& o, MitImportReport* r) {
  std::vector<std::pair<double, double>> gaps;
  for (std::size_t i = 1; i < s.object.size(); ++i) {
    const double t0 = s.object[i - 1][0], t1 = s.object[i][0];
    if (t1 < start || t0 > end) continue;
    r->largest_pose_gap_in_window_s = std::max(r->largest_pose_gap_in_window_s, t1 - t0);
    if (t1 - t0 > o.max_pose_gap_s) gaps.emplace_back(t0, t1);
  }
  return gaps;
}

/// How much of the push [push_start, push_end] has poses: its length less the gaps [s].
double PushOutsideGaps(double push_start, double push_end,
                       const std::vector<std::pair<double, double>>& gaps) {
  double kept = push_end - push_start;
  for (const auto& [t0, t1] : gaps) {
    kept -= std::max(0.0, std::min(t1, push_end) - std::max(t0, push_start));
  }
  return kept;
}

/// Step 7: the push plus the margins, inside every stream; rejects a short push, a frozen
/// force inside it, motion-capture gaps that leave too little of it, or an absurd number of
/// rows. Gaps longer than o.max_pose_gap_s inside the window go to `gaps`: the log is split
/// there (step 8).
Rejection ChooseWindow(const Streams& s, const Push& push, const std::vector<FrozenRun>& frozen,
                       const MitImportOptions& o, double* start, double* end,
                       std::vector<std::pair<double, double>>* gaps, MitImportReport* r) {
  const double push_start = push.above.front()->t, push_end = push.above.back()->t;
  if (push_end - push_start < o.min_push_duration_s) {
    return Printf("log too short: the push lasts %.3g s (need %.3g s, --min-push-duration)",
                  push_end - push_start, o.min_push_duration_s);
  }
  *start =
      std::max({push_start - o.margin_s, s.object.front()[0], s.tip.front()[0], s.ft.front()[0]});
  *end = std::min({push_end + o.margin_s, s.object.back()[0], s.tip.back()[0], s.ft.back()[0]});
  for (const FrozenRun& run : frozen) {
    if (run.t_last >= *start && run.t_first <= *end) {
      return std::string(run.channel) + Printf(" frozen at %.6g N for ", run.value_n) +
             std::to_string(run.samples) +
             " samples inside the push window (saturated or stalled sensor)";
    }
  }
  *gaps = PoseGaps(s, *start, *end, o, r);
  const double kept = PushOutsideGaps(push_start, push_end, *gaps);
  if (kept < o.min_push_duration_s) {
    std::string which;
    for (const auto& [t0, t1] : *gaps) {
      which += (which.empty() ? "" : ", ") +
               Printf("%.0f ms at %.3f s", (t1 - t0) * 1e3, t0 - push_start);
    }
    return Printf(
               "object_pose gaps leave %.3g s of the %.3g s push (need %.3g s, "
               "--min-push-duration; gaps over --max-pose-gap split the log): ",
               kept, push_end - push_start, o.min_push_duration_s) +
           which + " after the push starts";
  }
  if ((*end - *start) * o.rate_hz >= kMaxRows) {
    return Printf(
        "push window of %.3g s at %.3g Hz: more rows than any push needs (times "
        "not in seconds?)",
        *end - *start, o.rate_hz);
  }
  // The other end: a log of one or two rows, which no estimator can use, was accepted.
  if ((*end - *start) * o.rate_hz < kMinRows - 1) {
    return Printf(
        "push window of %.3g s at %.3g Hz: fewer than %d rows, too few to fit (--rate "
        "in Hz?)",
        *end - *start, o.rate_hz, kMinRows);
  }
  return std::nullopt;
}

/// Whether time t falls strictly inside one of `gaps`, where no pose is measured.
bool InGap(double t, const std::vector<std::pair<double, double>>& gaps) {
  return std::any_of(gaps.begin(), gaps.end(),
                     [t](const auto& g) { return t > g.first && t < g.second; });
}

/// Step 8: the rows on one clock from `start` to `end`, and their contact statistics. Rows
/// inside a pose gap are left out, and the row after one is marked `start`: a new run, so
/// that no model step spans the gap (forward_model/trajectory.h).
Trajectory BuildLog(const Streams& s, const Offset& offset, double start, double end,
                    const std::vector<std::pair<double, double>>& pose_gaps,
                    const MitImportOptions& o, MitImportReport* r) {
  const double dt = 1.0 / o.rate_hz;
  const int rows = static_cast<int>(std::floor((end - start) / dt + 1e-9)) + 1;
  const double sign = r->force_flipped ? -1.0 : 1.0;
  r->time_origin_s = start;
  r->window_start_s = 0;
  r->window_end_s = (rows - 1) * dt;
  Trajectory log;
  log.slider = o.slider;
  log.patch = ContactPatch::Parse(o.patch_spec);
  log.measured.pose = true;
  log.measured.velocity = false;
  log.measured.force = true;
  log.measured.push_point = true;
  log.measured.step_info = false;
  log.measured.mode = !pose_gaps.empty();
  log.measured.tip = true;  // the pusher's path: what `predict --drive pusher` replays
  log.tip_radius_m = o.tip_radius_m;
  std::vector<double> gaps;
  int out_of_contact = 0;
  bool after_gap = false;
  for (int u = 0; u < rows; ++u) {
    const double t = start + u * dt;
    if (InGap(t, pose_gaps)) {
      after_gap = true;
      ++r->rows_dropped_in_pose_gaps;
      continue;
    }
    const Eigen::Vector3d pose = s.PoseAt(t);
    const Contact contact = s.ContactAtTime(t);
    const RowWrench wrench = MeanWrench(s, offset, sign, t, t + dt);
    const Eigen::Vector2d f = wrench.force_n;
    TrajectorySample sample;
    sample.t_s = u * dt;
    sample.state.x = pose.x();
    sample.state.y = pose.y();
    sample.state.theta = pose.z();
    const Eigen::Vector2d arm = contact.point_world - pose.head<2>();
    sample.applied = WrenchFromForceAt(f.x(), f.y(), 0.0, arm.x(), arm.y(), 0.0);
    sample.applied.tz = wrench.moment_Nm;  // the writer keeps what r x f misses as tz
    sample.push_point_world =
        Eigen::Vector3d(contact.point_world.x(), contact.point_world.y(), o.slider.com_height_m);
    sample.tip_world = s.TipAt(t);
    sample.mode = log.samples.empty() || after_gap ? SampleMode::kStart : SampleMode::kSlide;
    after_gap = false;
    log.samples.push_back(sample);
    r->peak_force_n = std::max(r->peak_force_n, f.norm());
    if (f.norm() > r->force_threshold_n) {
      gaps.push_back(contact.gap_m);
      if (contact.gap_m > o.contact_tolerance_m) ++out_of_contact;
    }
  }
  if (!gaps.empty()) {
    r->contact_gap_median_m = Median(gaps);
    r->contact_gap_p05_m = Quantile(gaps, 0.05);
    r->contact_gap_p95_m = Quantile(gaps, 0.95);
    r->rows_out_of_contact_fraction = static_cast<double>(out_of_contact) / gaps.size();
  }
  r->rows = static_cast<int>(log.samples.size());
  r->pose_gaps_split = static_cast<int>(Runs(log).size()) - 1;
  if (r->pose_gaps_split > 0) {
    r->notes.push_back(std::to_string(r->pose_gaps_split) + " object_pose gap(s) over " +
                       Printf("%.0f ms", o.max_pose_gap_s * 1e3) +
                       " inside the window: " + std::to_string(r->rows_dropped_in_pose_gaps) +
                       " rows left out, the log split into runs there (mode 'start')");
  }
  return log;
}

/// The report row of a rejection, the log left empty.
MitImportResult Reject(MitImportResult result, const std::string& reason) {
  result.report.verdict = ImportVerdict::kRejected;
  result.report.reason = reason;
  result.file.log.samples.clear();
  return result;
}

void AddMetadata(const MitImportReport& r, const MitImportOptions& o, const std::string& source,
                 PushLogFile* file) {
  auto add = [&](const std::string& key, const std::string& value) {
    file->extra_metadata.emplace_back(key, value);
  };
  add("source", source);
  add("import_format", "mit-push");
  if (!r.object.empty()) add("object", r.object);
  add("time_origin_unix_s", ExactNumber(r.time_origin_s));
  add("rate_hz", ExactNumber(o.rate_hz));
  // Not `cm_offset`, which the reader would apply again to poses already at the CM.
  if (!o.cm_offset_m.isZero()) add("object_poses_moved_to_cm_m", Vec(o.cm_offset_m));
  add("stream_rates_hz",
      Printf("object_pose %.1f, tip_pose %.1f, ft_wrench %.1f", r.object_pose.median_rate_hz,
             r.tip_pose.median_rate_hz, r.ft_wrench.median_rate_hz));
  add("force_offset_before_n", r.offset_before_n ? Vec(*r.offset_before_n) : "none");
  add("force_offset_after_n", r.offset_after_n ? Vec(*r.offset_after_n) : "none");
  add("force_sign",
      r.force_flipped ? "flipped (the stored force is the reaction on the sensor)" : "as stored");
  add("theta_jumps_repaired", std::to_string(r.theta_jumps_repaired));
  add("pz",
      "com_height: the pusher height is not recorded; at the CM height the push has no "
      "tilting moment");
  for (const auto& [key, value] : o.extra_metadata) add(key, value);
}

bool ObjectIsValid(const MitImportOptions& o, std::string* why) {
  const SliderProperties& s = o.slider;
  const char* bad = !(std::isfinite(s.mass_kg) && s.mass_kg > 0)             ? "mass must be > 0"
                    : !(std::isfinite(s.inertia_kgm2) && s.inertia_kgm2 > 0) ? "inertia must be > 0"
                    : !(std::isfinite(s.com_height_m) && s.com_height_m >= 0)
                        ? "com_height must be >= 0"
                    : !(std::isfinite(s.gravity_mps2) && s.gravity_mps2 > 0) ? "gravity must be > 0"
                                                                             : nullptr;
  if (bad) {
    *why = bad;
    return false;
  }
  try {
    ContactPatch::Parse(o.patch_spec);
  } catch (const std::invalid_argument& e) {
    *why = std::string("patch: ") + e.what();
    return false;
  }
  return true;
}

}  // namespace

bool MitImportOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& message) {
    if (why) *why = message;
    return false;
  };
  const std::pair<const char*, double> positive[] = {{"tip_radius", tip_radius_m},
                                                     {"rate", rate_hz},
                                                     {"max_offset_drift", max_offset_drift_n},
                                                     {"max_pose_gap", max_pose_gap_s},
                                                     {"min_push_duration", min_push_duration_s},
                                                     {"theta_jump", theta_jump_rad},
                                                     {"contact_tolerance", contact_tolerance_m},
                                                     {"still_speed", still_speed_mps},
                                                     {"offset_clearance", offset_clearance_m}};
  for (const auto& [name, value] : positive) {
    if (!(std::isfinite(value) && value > 0)) return fail(std::string(name) + " must be > 0");
  }
  if (!(std::isfinite(margin_s) && margin_s >= 0)) return fail("margin must be >= 0");
  if (theta_jump_rad >= kHalfPi / 2) return fail("theta_jump must be below pi/4");
  return true;
}

MitImportResult ImportMitPush(const MitPushRecording& recording, const std::string& source,
                              const MitImportOptions& o) {
  std::string why;
  if (!o.IsValid(&why) || !ObjectIsValid(o, &why)) {
    throw std::invalid_argument("MIT import options: " + why);
  }
  MitImportResult result;
  MitImportReport& r = result.report;
  r.source = source;
  r.object = ParseMitPushFileName(source).shape;
  Streams s(recording, o);
  std::vector<FrozenRun> frozen;
  if (Rejection no = PrepareStreams(o, &s, &frozen, &r)) return Reject(result, *no);
  Push push;
  if (Rejection no = FindPush(s, o, &push, &r)) return Reject(result, *no);
  double start = 0, end = 0;
  std::vector<std::pair<double, double>> pose_gaps;
  if (Rejection no = ChooseWindow(s, push, frozen, o, &start, &end, &pose_gaps, &r)) {
    return Reject(result, *no);
  }
  result.file.log = BuildLog(s, push.offset, start, end, pose_gaps, o, &r);
  if (r.theta_jumps_unrepaired > 0) {
    r.notes.push_back(std::to_string(r.theta_jumps_unrepaired) +
                      " theta step(s) above the jump threshold not near a multiple of pi/2: "
                      "left as measured");
  }
  if (!frozen.empty()) {
    r.notes.push_back(std::to_string(r.frozen_force_samples) +
                      " frozen force samples (a repeated reading) dropped outside the push");
  }
  r.verdict = ImportVerdict::kAccepted;
  AddMetadata(r, o, source, &result.file);
  return result;
}

const char* ToString(ImportVerdict verdict) {
  switch (verdict) {
    case ImportVerdict::kAccepted:
      return "accepted";
    case ImportVerdict::kRejected:
      return "rejected";
    case ImportVerdict::kUnreadable:
      return "unreadable";
  }
  return "?";
}

const char* ToString(ForceSign sign) {
  switch (sign) {
    case ForceSign::kAuto:
      return "auto";
    case ForceSign::kApplied:
      return "applied";
    case ForceSign::kReaction:
      return "reaction";
  }
  return "?";
}

}  // namespace slideid
