#include "estimator/pusher_friction.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "estimator/log_diagnostics.h"
#include "estimator/pooling.h"
#include "estimator/robust_statistics.h"
#include "forward_model/contact_patch.h"
#include "forward_model/number_format.h"
#include "forward_model/pusher.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Fewer batches than this give an interval too rough to trust: the estimate is suspect.
constexpr int kMinBatches = 4;

/// One row where the tip pushes the edge: |f_t| / f_n, and whether the tip slides.
struct ContactRow {
  double ratio = 0;  ///< f_t / f_n, signed
  bool sliding = false;
};

bool HasTip(const Trajectory& log) {
  return log.measured.tip && log.tip_radius_m && log.patch.has_value() && log.samples.size() >= 2 &&
         std::all_of(log.samples.begin(), log.samples.end(),
                     [](const TrajectorySample& s) { return s.tip_world.has_value(); });
}

/// The tip centre in the body frame of row u [m].
Eigen::Vector2d TipInBody(const TrajectorySample& s) {
  const double c = std::cos(s.state.theta), si = std::sin(s.state.theta);
  const Eigen::Vector2d d = *s.tip_world - Eigen::Vector2d(s.state.x, s.state.y);
  return {c * d.x() + si * d.y(), -si * d.x() + c * d.y()};
}

/// Row `a` as a contact row, or nullopt when the tip does not push the edge there. The slip
/// is read in the body frame, where it is the tip's drift along the edge: over rows `lo` ..
/// `hi` (around `a`, inside one run), whose difference divides the pose noise by the
/// window's length instead of one interval's.
std::optional<ContactRow> ClassifyContact(const ContactPatch& patch, double tip_radius_m,
                                          const TrajectorySample& a, const TrajectorySample& lo,
                                          const TrajectorySample& hi, double min_force_n,
                                          double pose_noise, double angle_noise,
                                          const PusherFrictionOptions& o) {
  const TipContact c = ContactWithTip(patch, a.state, *a.tip_world, tip_radius_m);
  if (!(c.gap_m < o.contact_tolerance_m)) return std::nullopt;
  const Eigen::Vector2d n_w = c.normal_world, t_w(-n_w.y(), n_w.x());
  const Eigen::Vector2d f(a.applied.fx, a.applied.fy);
  const double fn = -f.dot(n_w);  // into the slider
  if (!(fn > min_force_n)) return std::nullopt;
  const double window = hi.t_s - lo.t_s;
  if (!(window > 0)) return std::nullopt;
  const double ct = std::cos(a.state.theta), st = std::sin(a.state.theta);
  const Eigen::Vector2d t_body(ct * t_w.x() + st * t_w.y(), -st * t_w.x() + ct * t_w.y());
  // The slider's contact point relative to the tip, along t: minus the tip's drift.
  const double slip = -(TipInBody(hi) - TipInBody(lo)).dot(t_body) / window;
  const double arm = (c.point_world - Eigen::Vector2d(a.state.x, a.state.y)).norm() + tip_radius_m;
  const double slip_noise = std::sqrt(2.0) * std::hypot(pose_noise, arm * angle_noise) / window;
  const Eigen::Vector2d tip_velocity = (*hi.tip_world - *lo.tip_world) / window;
  const double threshold =
      std::max(o.slip_sigmas * slip_noise, o.min_slip_fraction * tip_velocity.norm());
  ContactRow row;
  row.ratio = f.dot(t_w) / fn;
  // Sliding: the slip beyond its noise, the friction on the slider against it.
  row.sliding = std::abs(slip) > threshold && row.ratio * slip < 0;
  return row;
}

/// The contact rows of one log, in order, each with its slip over rows u - k .. u + k.
std::vector<ContactRow> ContactRows(const Trajectory& log, double min_force_n,
                                    const PusherFrictionOptions& o) {
  const ContactPatch& patch = *log.patch;
  const LogDiagnostics noise = DiagnoseLog(log);
  const double pose_noise = std::isfinite(noise.pose_noise_m) ? noise.pose_noise_m : 0.0;
  const double angle_noise = std::isfinite(noise.angle_noise_rad) ? noise.angle_noise_rad : 0.0;
  std::vector<int> run_of(log.samples.size());
  int run = 0;
  for (size_t u = 0; u < log.samples.size(); ++u) run_of[u] = run += (u > 0 && StartsRun(log, u));
  const int n = static_cast<int>(log.samples.size());
  std::vector<ContactRow> rows;
  for (int u = 0; u < n; ++u) {
    int lo = u, hi = u;
    while (u - lo < o.slip_half_window_rows && lo > 0 && run_of[lo - 1] == run_of[u]) --lo;
    while (hi - u < o.slip_half_window_rows && hi + 1 < n && run_of[hi + 1] == run_of[u]) ++hi;
    if (hi == lo) continue;
    const std::optional<ContactRow> row =
        ClassifyContact(patch, *log.tip_radius_m, log.samples[u], log.samples[lo], log.samples[hi],
                        min_force_n, pose_noise, angle_noise, o);
    if (row) rows.push_back(*row);
  }
  return rows;
}

std::string Rounded(double v) { return Printf("%.3g", v); }

/// mu_p from the sliding rows' |ratio| (in log order): their median, and its standard error
/// from batch medians, which carries whatever correlation the rows of a log share (on
/// synthetic logs the spread of the estimates over noise draws was 1.3 times the
/// independent-row standard error of the median).
ParameterEstimate FromSliding(const std::vector<double>& ratios, const PusherFrictionOptions& o) {
  ParameterEstimate p;
  p.identifiable = true;
  p.value = Median(ratios);
  const int batches = std::clamp(static_cast<int>(ratios.size()) / o.batch_rows, 2, o.max_batches);
  std::vector<double> medians;
  for (int k = 0; k < batches; ++k) {
    const size_t lo = ratios.size() * k / batches, hi = ratios.size() * (k + 1) / batches;
    medians.push_back(Median(std::vector<double>(ratios.begin() + lo, ratios.begin() + hi)));
  }
  double mean = 0, square = 0;
  for (double m : medians) mean += m / batches;
  for (double m : medians) square += (m - mean) * (m - mean) / (batches - 1);
  p.interval_quantile = StudentT95(batches - 1);
  const double half = p.interval_quantile * std::sqrt(square / batches);
  p.stderr_value = half / kZ95;  // the interval's, as EstimateFromLog's (identifiability.h)
  p.ci95_lo = p.value - half;
  p.ci95_hi = p.value + half;
  p.note = "median |f_t| / f_n over " + std::to_string(ratios.size()) +
           " rows where the tip slides along the edge; interval from " + std::to_string(batches) +
           " batch medians, t on " + std::to_string(batches - 1) + " df";
  if (batches < kMinBatches) {
    p.verdict = Verdict::kSuspect;
    p.reason = "the tip slides in only " + std::to_string(ratios.size()) +
               " rows: the interval rests on " + std::to_string(batches) + " batches";
  } else {
    p.verdict = Verdict::kOk;
  }
  return p;
}

/// The result from the contact rows' |f_t| / f_n: of the rows where the tip slides, and of
/// all of them (in log order).
PusherFrictionResult FromContactRows(const std::vector<double>& sliding,
                                     const std::vector<double>& all,
                                     const PusherFrictionOptions& options) {
  PusherFrictionResult r;
  r.contact_rows = static_cast<int>(all.size());
  r.sliding_rows = static_cast<int>(sliding.size());
  if (r.sliding_rows >= options.min_sliding_rows) {
    r.mu = FromSliding(sliding, options);
    return r;
  }
  r.mu.verdict = Verdict::kNotIdentifiable;
  if (all.empty()) {
    r.mu.reason =
        "the tip never pushes the object's edge (no row with the tip on the outline "
        "and a force into it)";
    return r;
  }
  r.lower_bound = Quantile(all, options.sticking_quantile);
  r.mu.reason = "the tip does not slide along the edge (" + std::to_string(r.sliding_rows) +
                " of " + std::to_string(r.contact_rows) +
                " contact rows): mu_p >= " + Rounded(r.lower_bound) + ", the " +
                Rounded(100 * options.sticking_quantile) +
                "th percentile of |f_t| / f_n while it sticks";
  return r;
}

}  // namespace

double TypicalPush(const std::vector<const Trajectory*>& logs) {
  std::vector<double> pushes;
  for (const Trajectory* log : logs) {
    for (const TrajectorySample& s : log->samples) {
      const double f = std::hypot(s.applied.fx, s.applied.fy);
      if (f > 0) pushes.push_back(f);
    }
  }
  return pushes.empty() ? 0.0 : Quantile(pushes, kTypicalPushQuantile);
}

bool PusherFrictionOptions::IsValid(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (!(contact_tolerance_m >= 0)) return fail("pusher friction: contact tolerance must be >= 0");
  if (!(min_force_fraction >= 0 && min_force_fraction < 1)) {
    return fail("pusher friction: min_force_fraction must be in [0, 1)");
  }
  if (!(slip_sigmas >= 0) || !(min_slip_fraction >= 0)) {
    return fail("pusher friction: slip thresholds must be >= 0");
  }
  if (min_sliding_rows < 2 || batch_rows < 1 || max_batches < 2 || slip_half_window_rows < 1) {
    return fail(
        "pusher friction: min_sliding_rows >= 2, batch_rows >= 1, max_batches >= 2, "
        "slip_half_window_rows >= 1");
  }
  if (!(sticking_quantile > 0 && sticking_quantile <= 1)) {
    return fail("pusher friction: sticking_quantile must be in (0, 1]");
  }
  return true;
}

std::optional<PusherFrictionResult> EstimatePusherFriction(
    const std::vector<const Trajectory*>& logs, const PusherFrictionOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  std::vector<const Trajectory*> with_tip;
  for (const Trajectory* log : logs) {
    if (HasTip(*log)) with_tip.push_back(log);
  }
  if (with_tip.empty()) return std::nullopt;
  const double typical = TypicalPush(with_tip);
  std::vector<double> sliding, all;
  for (const Trajectory* log : with_tip) {
    for (const ContactRow& row : ContactRows(*log, options.min_force_fraction * typical, options)) {
      all.push_back(std::abs(row.ratio));
      if (row.sliding) sliding.push_back(std::abs(row.ratio));
    }
  }
  return FromContactRows(sliding, all, options);
}

bool PusherFrictionStream::Applies(const Trajectory& metadata) {
  return metadata.measured.tip && metadata.tip_radius_m && metadata.patch.has_value();
}

namespace {
const Trajectory& Checked(const Trajectory& metadata, const PusherFrictionOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  if (!PusherFrictionStream::Applies(metadata)) {
    throw std::invalid_argument(
        "pusher friction: the log needs the tip's path (tip_x, tip_y), '# tip_radius' and "
        "'# patch'");
  }
  return metadata;
}
}  // namespace

PusherFrictionStream::PusherFrictionStream(const Trajectory& metadata,
                                           const PusherFrictionOptions& options)
    : options_(options),
      patch_(*Checked(metadata, options).patch),
      tip_radius_m_(*metadata.tip_radius_m) {
  result_ = FromContactRows({}, {}, options_);
}

void PusherFrictionStream::Add(const TrajectorySample& row, double pose_noise_m,
                               double angle_noise_rad) {
  if (!row.tip_world) return;
  pose_noise_m_ = std::isfinite(pose_noise_m) ? pose_noise_m : 0.0;
  angle_noise_rad_ = std::isfinite(angle_noise_rad) ? angle_noise_rad : 0.0;
  const size_t k = static_cast<size_t>(options_.slip_half_window_rows);
  if (!ring_.empty() && row.mode == SampleMode::kStart) {
    // A new run: the old run's last rows are classified with what their windows have.
    while (classified_ < ring_.size()) Classify(classified_++);
    ++run_;
  }
  const double f = std::hypot(row.applied.fx, row.applied.fy);
  if (f > 0) {
    forces_.push_back(f);
    if (forces_.size() >= forces_at_recompute_ + std::max<size_t>(1, forces_at_recompute_ / 16)) {
      min_force_n_ = options_.min_force_fraction * Quantile(forces_, kTypicalPushQuantile);
      forces_at_recompute_ = forces_.size();
    }
  }
  ring_.push_back({row, run_});
  while (classified_ < ring_.size() && ring_.size() - 1 - classified_ >= k) Classify(classified_++);
  while (classified_ > k) {
    ring_.pop_front();
    --classified_;
  }
  if (all_.size() >= rows_at_recompute_ + std::max<size_t>(1, rows_at_recompute_ / 16)) Recompute();
}

void PusherFrictionStream::Classify(size_t i) {
  const int k = options_.slip_half_window_rows;
  size_t lo = i, hi = i;
  while (static_cast<int>(i - lo) < k && lo > 0 && ring_[lo - 1].run == ring_[i].run) --lo;
  while (static_cast<int>(hi - i) < k && hi + 1 < ring_.size() && ring_[hi + 1].run == ring_[i].run)
    ++hi;
  if (hi == lo) return;
  const std::optional<ContactRow> row =
      ClassifyContact(patch_, tip_radius_m_, ring_[i].row, ring_[lo].row, ring_[hi].row,
                      min_force_n_, pose_noise_m_, angle_noise_rad_, options_);
  if (!row) return;
  all_.push_back(std::abs(row->ratio));
  if (row->sliding) sliding_.push_back(std::abs(row->ratio));
}

void PusherFrictionStream::Recompute() {
  result_ = FromContactRows(sliding_, all_, options_);
  rows_at_recompute_ = all_.size();
}

void AddPusherFriction(const std::vector<const Trajectory*>& logs, EstimateResult* result) {
  const std::optional<PusherFrictionResult> r = EstimatePusherFriction(logs);
  if (!r) return;
  result->mu_pusher_examined = true;
  result->mu_pusher = r->mu;
  result->mu_pusher_lower_bound = r->lower_bound;
}

}  // namespace slideid
