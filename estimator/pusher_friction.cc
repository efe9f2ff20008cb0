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
  return log.columns.tip && log.tip_radius_m && !log.patch_spec.empty() &&
         log.samples.size() >= 2 &&
         std::all_of(log.samples.begin(), log.samples.end(),
                     [](const TrajectorySample& s) { return s.tip_world.has_value(); });
}

/// The tip centre in the body frame of row u [m].
Eigen::Vector2d TipInBody(const TrajectorySample& s) {
  const double c = std::cos(s.state.theta), si = std::sin(s.state.theta);
  const Eigen::Vector2d d = *s.tip_world - Eigen::Vector2d(s.state.x, s.state.y);
  return {c * d.x() + si * d.y(), -si * d.x() + c * d.y()};
}

/// The contact rows of one log, in order. The slip is read in the body frame, where it is
/// the tip's drift along the edge: over rows u - k .. u + k (inside one run), whose
/// difference divides the pose noise by the window's length instead of one interval's.
std::vector<ContactRow> ContactRows(const Trajectory& log, double min_force_n,
                                    const PusherFrictionOptions& o) {
  const ContactPatch patch = ContactPatch::Parse(log.patch_spec);
  const LogDiagnostics noise = DiagnoseLog(log);
  const double pose_noise = std::isfinite(noise.pose_noise_m) ? noise.pose_noise_m : 0.0;
  const double angle_noise = std::isfinite(noise.angle_noise_rad) ? noise.angle_noise_rad : 0.0;
  std::vector<int> run_of(log.samples.size());
  int run = 0;
  for (size_t u = 0; u < log.samples.size(); ++u) run_of[u] = run += (u > 0 && StartsRun(log, u));
  const int n = static_cast<int>(log.samples.size());
  std::vector<ContactRow> rows;
  for (int u = 0; u < n; ++u) {
    const TrajectorySample& a = log.samples[u];
    const TipContact c = ContactWithTip(patch, a.state, *a.tip_world, *log.tip_radius_m);
    if (!(c.gap_m < o.contact_tolerance_m)) continue;
    const Eigen::Vector2d n_w = c.normal_world, t_w(-n_w.y(), n_w.x());
    const Eigen::Vector2d f(a.applied.fx, a.applied.fy);
    const double fn = -f.dot(n_w);  // into the slider
    if (!(fn > min_force_n)) continue;
    int lo = u, hi = u;
    while (u - lo < o.slip_half_window_rows && lo > 0 && run_of[lo - 1] == run_of[u]) --lo;
    while (hi - u < o.slip_half_window_rows && hi + 1 < n && run_of[hi + 1] == run_of[u]) ++hi;
    if (hi == lo) continue;
    const double window = log.samples[hi].t_s - log.samples[lo].t_s;
    const double ct = std::cos(a.state.theta), st = std::sin(a.state.theta);
    const Eigen::Vector2d t_body(ct * t_w.x() + st * t_w.y(), -st * t_w.x() + ct * t_w.y());
    // The slider's contact point relative to the tip, along t: minus the tip's drift.
    const double slip =
        -(TipInBody(log.samples[hi]) - TipInBody(log.samples[lo])).dot(t_body) / window;
    const double arm =
        (c.point_world - Eigen::Vector2d(a.state.x, a.state.y)).norm() + *log.tip_radius_m;
    const double slip_noise = std::sqrt(2.0) * std::hypot(pose_noise, arm * angle_noise) / window;
    const Eigen::Vector2d tip_velocity =
        (*log.samples[hi].tip_world - *log.samples[lo].tip_world) / window;
    const double threshold =
        std::max(o.slip_sigmas * slip_noise, o.min_slip_fraction * tip_velocity.norm());
    ContactRow row;
    row.ratio = f.dot(t_w) / fn;
    // Sliding: the slip beyond its noise, the friction on the slider against it.
    row.sliding = std::abs(slip) > threshold && row.ratio * slip < 0;
    rows.push_back(row);
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
  const double half = StudentT95(batches - 1) * std::sqrt(square / batches);
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
  PusherFrictionResult r;
  std::vector<double> sliding, all;
  for (const Trajectory* log : with_tip) {
    for (const ContactRow& row : ContactRows(*log, options.min_force_fraction * typical, options)) {
      all.push_back(std::abs(row.ratio));
      if (row.sliding) sliding.push_back(std::abs(row.ratio));
    }
  }
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

void AddPusherFriction(const std::vector<const Trajectory*>& logs, EstimateResult* result) {
  const std::optional<PusherFrictionResult> r = EstimatePusherFriction(logs);
  if (!r) return;
  result->mu_pusher_examined = true;
  result->mu_pusher = r->mu;
  result->mu_pusher_lower_bound = r->lower_bound;
}

}  // namespace slideid
