#include "estimator/log_check.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "estimator/internal/seed_information.h"
#include "estimator/log_diagnostics.h"
#include "estimator/pusher_friction.h"
#include "estimator/robust_statistics.h"
#include "forward_model/constants.h"
#include "forward_model/number_format.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Motion is read over rows u - k .. u + k, which divides the pose noise by the window's
// length: 2 k intervals. k = 2 keeps short pushes (a few rows) visible.
constexpr int kMotionHalfWindow = 2;
// The object moves when its displacement over the window exceeds this many standard
// deviations of the displacement's noise (sqrt(2) times the pose noise), and this floor
// [m] (a noise-free log's rounding).
constexpr double kMotionSigmas = 4.0;
constexpr double kMotionFloorM = 1e-5;
// Fewest rest rows whose median force is worth reporting.
constexpr int kMinRestRows = 5;
// A force at rest larger than this fraction of the largest push is worth a sentence.
constexpr double kRestForceFraction = 0.05;
// The advice's thresholds: an estimate expected to be known to worse than this relative
// error is "identifiable but rough"; a correlation beyond this is "strongly correlated";
// a slide within this arc of directions of its own is "along one direction"; an object
// turned less than this "barely turns".
constexpr double kRoughRelativeError = 0.1;
constexpr double kStrongCorrelation = 0.95;
constexpr double kNarrowSlideArcRad = 15.0 / kRadToDeg;
constexpr double kSmallTurnRad = 5.0 / kRadToDeg;
// Beyond this condition number J^T J counts as singular: its inverse is rounding.
constexpr double kSingularCondition = 1e14;

/// The smallest arc [rad] of the circle of period `period` that holds every angle.
double SmallestArc(std::vector<double> angles, double period) {
  if (angles.size() < 2) return 0;
  for (double& a : angles) a = a - period * std::floor(a / period);
  std::sort(angles.begin(), angles.end());
  double largest_gap = angles.front() + period - angles.back();
  for (size_t i = 1; i < angles.size(); ++i) {
    largest_gap = std::max(largest_gap, angles[i] - angles[i - 1]);
  }
  return period - largest_gap;
}

/// Headings unwrapped along the log [rad].
std::vector<double> Unwrapped(const Trajectory& log) {
  std::vector<double> theta;
  for (const TrajectorySample& s : log.samples) {
    double t = s.state.theta;
    if (!theta.empty()) t = theta.back() + std::remainder(t - theta.back(), 2 * kPi);
    theta.push_back(t);
  }
  return theta;
}

/// Rotates a world vector into the object's frame at heading theta.
Eigen::Vector2d ToBody(double x, double y, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  return {c * x + s * y, -s * x + c * y};
}

void CheckSampling(const Trajectory& log, LogCheck* c) {
  const int n = static_cast<int>(log.samples.size());
  c->rows = n;
  c->has_pose = log.measured.pose;
  c->has_velocity = log.measured.velocity;
  c->has_force = log.measured.force;
  c->has_push_point = log.measured.push_point;
  c->has_tip = log.measured.tip;
  if (n < 2) return;
  c->duration_s = log.samples.back().t_s - log.samples.front().t_s;
  const double h = MedianInterval(log);
  c->rate_hz = h > 0 ? 1.0 / h : 0.0;
  for (int u = 1; u < n; ++u) {
    const double dt = log.samples[u].t_s - log.samples[u - 1].t_s;
    if (StartsRun(log, u) || dt > kGapIntervals * h) {
      ++c->gaps;
      c->longest_gap_s = std::max(c->longest_gap_s, dt);
    }
  }
}

/// Per row whether the object moves there, and its velocity direction in its own frame
/// (NaN where it rests).
struct Motion {
  std::vector<bool> moving;
  std::vector<double> body_direction;
};

Motion ReadMotion(const Trajectory& log, const LogDiagnostics& d) {
  const int n = static_cast<int>(log.samples.size());
  Motion m{std::vector<bool>(n, false), std::vector<double>(n, kNaN)};
  const double length_m = std::sqrt(log.slider.inertia_kgm2 / log.slider.mass_kg);
  std::vector<int> run_of(n, 0);
  for (int u = 1; u < n; ++u) run_of[u] = run_of[u - 1] + (StartsRun(log, u) ? 1 : 0);
  for (int u = 0; u < n; ++u) {
    const TrajectorySample& s = log.samples[u];
    double dx = 0, dy = 0, moved = 0, limit = 0;
    if (log.measured.pose) {
      int lo = u, hi = u;
      while (lo > 0 && u - lo < kMotionHalfWindow && run_of[lo - 1] == run_of[u]) --lo;
      while (hi + 1 < n && hi - u < kMotionHalfWindow && run_of[hi + 1] == run_of[u]) ++hi;
      if (hi == lo) continue;
      const PlanarState &a = log.samples[lo].state, &b = log.samples[hi].state;
      dx = b.x - a.x;
      dy = b.y - a.y;
      const double turn = length_m * std::remainder(b.theta - a.theta, 2 * kPi);
      moved = std::sqrt(dx * dx + dy * dy + turn * turn);
      const double sp = std::isfinite(d.pose_noise_m) ? d.pose_noise_m : 0.0;
      const double sa = std::isfinite(d.angle_noise_rad) ? length_m * d.angle_noise_rad : 0.0;
      limit = kMotionSigmas * std::sqrt(2.0 * (2 * sp * sp + sa * sa)) + kMotionFloorM;
    } else if (log.measured.velocity) {
      dx = s.state.vx;
      dy = s.state.vy;
      moved = std::sqrt(dx * dx + dy * dy + std::pow(length_m * s.state.wz, 2));
      const double sv = std::isfinite(d.velocity_noise_mps) ? d.velocity_noise_mps : 0.0;
      const double sw = std::isfinite(d.spin_noise_radps) ? length_m * d.spin_noise_radps : 0.0;
      limit = kMotionSigmas * std::sqrt(2 * sv * sv + sw * sw) + kMotionFloorM;
    }
    if (!(moved > limit)) continue;
    m.moving[u] = true;
    if (std::hypot(dx, dy) > limit) {
      const Eigen::Vector2d v = ToBody(dx, dy, s.state.theta);
      m.body_direction[u] = std::atan2(v.y(), v.x());
    }
  }
  return m;
}

void CheckExcitation(const Trajectory& log, const LogDiagnostics& d, LogCheck* c) {
  const int n = static_cast<int>(log.samples.size());
  c->pose_noise_m = d.pose_noise_m;
  c->angle_noise_rad = d.angle_noise_rad;
  c->max_push_n = d.max_push_n;
  if (d.dead_force_channel) c->dead_channels.push_back(*d.dead_force_channel);
  if (n < 2) return;
  if (log.measured.pose) {
    const std::vector<double> theta = Unwrapped(log);
    const auto [lo, hi] = std::minmax_element(theta.begin(), theta.end());
    c->rotation_range_rad = *hi - *lo;
  }
  const Motion motion = ReadMotion(log, d);
  double sliding_s = 0;
  std::vector<double> rest_fx, rest_fy, slide_dirs;
  for (int u = 0; u < n; ++u) {
    const TrajectorySample& s = log.samples[u];
    if (u + 1 < n && motion.moving[u]) sliding_s += log.samples[u + 1].t_s - s.t_s;
    if (motion.moving[u] && std::isfinite(motion.body_direction[u])) {
      slide_dirs.push_back(motion.body_direction[u]);
    }
    if (!motion.moving[u] && log.measured.force) {
      rest_fx.push_back(s.applied.fx);
      rest_fy.push_back(s.applied.fy);
    }
  }
  c->sliding_share = c->duration_s > 0 ? sliding_s / c->duration_s : 0.0;
  // Sliding directions as axes: b weighs the object's own x and y axes, not their signs.
  c->slide_directions_rad = SmallestArc(slide_dirs, kPi);
  c->rest_rows = static_cast<int>(rest_fx.size());
  if (c->rest_rows >= kMinRestRows) {
    c->rest_force_x_n = Median(rest_fx);
    c->rest_force_y_n = Median(rest_fy);
  }
  // A tracker whose positions carry noise but whose heading never changes by a bit has lost
  // the heading (a noise-free simulated translation keeps both exact).
  if (log.measured.pose && c->rotation_range_rad == 0 && c->sliding_share > 0 &&
      d.pose_noise_m > 0) {
    c->dead_channels.push_back(
        "theta constant on every row while the object moves (dead tracker?)");
  }
  std::vector<double> push_dirs;
  double max_offset = kNaN;
  for (const TrajectorySample& s : log.samples) {
    const double f = std::hypot(s.applied.fx, s.applied.fy);
    if (!(f > 0) || f < kPushFraction * d.max_push_n) continue;
    const Eigen::Vector2d fb = ToBody(s.applied.fx, s.applied.fy, s.state.theta);
    push_dirs.push_back(std::atan2(fb.y(), fb.x()));
    const double offset = std::abs(s.applied.tz) / f;
    max_offset = std::isnan(max_offset) ? offset : std::max(max_offset, offset);
  }
  c->push_directions_rad = SmallestArc(push_dirs, 2 * kPi);
  c->max_push_offset_m = max_offset;
}

void CheckInformation(const Trajectory& log, const IdentifyOptions& options, LogCheck* c) {
  const SeedInformation seed = TrajectoryInformationAtSeed(log, options);
  c->failure = seed.failure;
  if (!seed.failure.empty()) {
    for (ParameterOutlook& p : c->parameters) p.reason = seed.failure;
    return;
  }
  for (int i = 0; i < 3; ++i) {
    ParameterOutlook& p = c->parameters[i];
    const ParameterIdentifiability& v = seed.verdicts[i];
    p.seed = seed.seed[i];
    p.identifiable = v.identifiable;
    p.relative_stderr = v.identifiable ? std::max(v.stderr_log, v.stderr_log_partners_free) : kNaN;
    p.reason = v.note;
  }
  for (size_t i = 3; i < seed.verdicts.size(); ++i) {
    ParameterOutlook p;
    p.identifiable = seed.verdicts[i].identifiable;
    p.reason = seed.verdicts[i].note;
    c->nuisances.emplace_back(seed.names[i], p);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(seed.fisher);
  const double largest = eig.eigenvalues().maxCoeff(), smallest = eig.eigenvalues().minCoeff();
  c->condition_number = smallest > 0 ? largest / smallest : std::numeric_limits<double>::infinity();
  for (auto& row : c->correlation) row.fill(kNaN);
  if (c->condition_number < kSingularCondition) {
    const Eigen::Matrix3d cov = seed.fisher.inverse();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j)
        c->correlation[i][j] = cov(i, j) / std::sqrt(cov(i, i) * cov(j, j));
    }
  }
}

void CheckPusher(const Trajectory& log, LogCheck* c) {
  const std::optional<PusherFrictionResult> mu = EstimatePusherFriction({&log});
  if (!mu) return;
  c->mu_pusher_examined = true;
  c->tip_contact_rows = mu->contact_rows;
  c->tip_sliding_rows = mu->sliding_rows;
  ParameterOutlook& p = c->mu_pusher;
  p.identifiable = mu->mu.identifiable;
  p.seed = mu->mu.identifiable ? mu->mu.value : kNaN;
  p.relative_stderr = mu->mu.identifiable ? mu->mu.stderr_value / mu->mu.value : kNaN;
  p.reason = mu->mu.identifiable ? "" : mu->mu.reason;
}

std::string Percent(double share) { return Printf("%.0f%%", 100 * share); }

// ---- advice ------------------------------------------------------------------------------

std::string AdviceOnA(const LogCheck& c) {
  if (c.sliding_share < 0.2) {
    return "a is not identifiable: the object slides in only " + Percent(c.sliding_share) +
           " of the log; push it harder or longer so that it slides";
  }
  return "a is not identifiable (" + c.parameters[kA].reason +
         "); a longer log, or one with less noise, would help";
}

std::string AdviceOnB(const LogCheck& c) {
  if (c.slide_directions_rad < kNarrowSlideArcRad) {
    return Printf(
        "b is not identifiable: the object slides along one direction of its own only "
        "(all within %.0f deg); push it in another direction relative to the object, or turn it",
        c.slide_directions_rad * kRadToDeg);
  }
  return Printf(
      "b is not identifiable: its slides span %.0f deg of directions of its own, too little "
      "for the log's noise; push it in more directions relative to the object",
      c.slide_directions_rad * kRadToDeg);
}

std::string AdviceOnC(const LogCheck& c) {
  const double turned_deg = c.rotation_range_rad * kRadToDeg;
  if (c.rotation_range_rad < kSmallTurnRad && std::isfinite(c.max_push_offset_m)) {
    return Printf(
        "c is not identifiable: every push passes within %.0f mm of the CM and the object "
        "turns only %.1f deg; push off-centre or turn the object",
        1000 * c.max_push_offset_m, turned_deg);
  }
  if (c.rotation_range_rad < kSmallTurnRad) {
    return Printf(
        "c is not identifiable: the object turns only %.1f deg; give it spin, or push it "
        "off-centre",
        turned_deg);
  }
  return Printf(
      "c is not identifiable: the object turns %.0f deg, too little for the log's noise; "
      "more turning (pushes further off-centre) would help",
      turned_deg);
}

void Advise(LogCheck* c) {
  std::vector<std::string>& advice = c->advice;
  for (const std::string& dead : c->dead_channels) {
    advice.push_back("a channel carries nothing: " + dead + "; check the sensor");
  }
  if (!c->failure.empty()) {
    advice.push_back("nothing is identifiable: " + c->failure);
    return;
  }
  if (!c->parameters[kA].identifiable) advice.push_back(AdviceOnA(*c));
  if (!c->parameters[kB].identifiable) advice.push_back(AdviceOnB(*c));
  if (!c->parameters[kC].identifiable) advice.push_back(AdviceOnC(*c));
  for (int i = 0; i < 3; ++i) {
    const ParameterOutlook& p = c->parameters[i];
    if (p.identifiable && p.relative_stderr > kRoughRelativeError) {
      advice.push_back(
          Printf("%s is identifiable but only to about %.0f%% (one sigma); a "
                 "longer log would help",
                 ParameterName(i), 100 * p.relative_stderr));
    }
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      const double r = c->correlation[i][j];
      if (c->parameters[i].identifiable && c->parameters[j].identifiable &&
          std::abs(r) > kStrongCorrelation) {
        advice.push_back(Printf(
            "%s and %s are strongly correlated (%.3f): the log tells mostly a combination of "
            "them; pushes that translate and turn the object in different proportions would help",
            ParameterName(i), ParameterName(j), r));
      }
    }
  }
  if (c->gaps > 0) {
    advice.push_back(
        Printf("the log has %d gap%s (longest %.3g s): each one starts a new stretch of the fit",
               c->gaps, c->gaps == 1 ? "" : "s", c->longest_gap_s));
  }
  const double rest_force = std::hypot(c->rest_force_x_n, c->rest_force_y_n);
  if (rest_force > kRestForceFraction * c->max_push_n) {
    advice.push_back(Printf(
        "the force channel reads (%.3g, %.3g) N while the object rests: a sensor offset, or a "
        "push too weak to move it; if an offset, fit it (--fit-force-bias)",
        c->rest_force_x_n, c->rest_force_y_n));
  }
  if (c->mu_pusher_examined && !c->mu_pusher.identifiable) {
    advice.push_back(
        Printf("mu_pusher is not identifiable: the tip slides along the edge in %d of %d contact "
               "rows; push at an angle to the edge so that the tip slips",
               c->tip_sliding_rows, c->tip_contact_rows));
  }
}

}  // namespace

bool LogCheck::AnyIdentifiable() const {
  return std::any_of(parameters.begin(), parameters.end(),
                     [](const ParameterOutlook& p) { return p.identifiable; });
}

LogCheck CheckLog(const Trajectory& log, const IdentifyOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  if (options.method != EstimatorMethod::kTrajectory) {
    throw std::invalid_argument(std::string("the check forecasts the trajectory fit, not the ") +
                                ToString(options.method) + " method");
  }
  LogCheck c;
  c.name = log.source;
  const LogDiagnostics d = DiagnoseLog(log);
  CheckSampling(log, &c);
  CheckExcitation(log, d, &c);
  CheckInformation(log, options, &c);
  CheckPusher(log, &c);
  Advise(&c);
  return c;
}

}  // namespace slideid
