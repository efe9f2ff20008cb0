#include "estimator/trajectory_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "estimator/closed_form.h"
#include "estimator/equation_error.h"
#include "estimator/identifiability.h"
#include "estimator/log_diagnostics.h"
#include "estimator/plausibility.h"
#include "estimator/pooling.h"
#include "estimator/robust_statistics.h"
#include "estimator/trajectory_problem.h"

namespace slideid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Residuals below this [m or m/s] are rounding, not noise: a log whose noise is below it
// needs no robust loss (and a zero scale would make the loss degenerate).
constexpr double kNoiseFloor = 1e-10;
// The seed scan of a: log-spaced points over a factor kScanSpan either side of the
// candidates' a, then the vertex of a parabola through the best point and its neighbours.
// Each point is one forward pass without derivatives (about 2 ms at 10k rows). 5 points
// (a factor 2.3 apart when the candidates' a differ by 2.5) bracket the cost's minimum
// along a, the parabola puts the seed typically within a few percent of it, from where
// Levenberg-Marquardt converges in a few iterations.
constexpr double kScanSpan = 3.0;
constexpr int kScanPoints = 5;
// Typical table-top friction, the default seed of a.
constexpr double kDefaultA = 0.3;
// The robust loss is scaled to the noise the log shows; residuals whose robust scale sits
// above this many times that noise (model mismatch) are refitted at their own scale, so that
// the loss does not treat most rows as outliers.
constexpr double kRescaleRatio = 2.0;
// Median of chi-square with 3 degrees of freedom over its mean: a row's squared residual
// norm has median 0.789 times its mean under Gaussian noise.
constexpr double kChi3MedianOverMean = 2.365974 / 3.0;
// Fewest clusters for a cluster-robust covariance: with fewer, the sum of G outer products
// estimates the score covariance too poorly even with the t(G - 1) quantile.
constexpr int kMinClusters = 3;
// A force offset whose standard error exceeds this fraction of the log's largest push (or
// of a tenth of its weight, for a log barely pushed) is not determined by the log; a delay
// whose standard error exceeds this fraction of the delay range neither.
constexpr double kMaxOffsetStdErrFraction = 0.25;
constexpr double kMaxDelayStdErrFraction = 0.25;

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string Format(const char* fmt, double x, double y = 0, double z = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, x, y, z);
  return buf;
}

// ---- seeds -----------------------------------------------------------------------------

// Seeds of (b, c): the closed form's where it identifies them, else defaults typical of
// table-top sliding (b = 1, c = the radius of gyration). On noisy poses the closed form's a
// can be far off (0.77 for a truth of 0.35 on the benchmark log), and a fit from there
// spends its first iterations walking back; a is therefore seeded by a scan of the
// trajectory cost, with the closed form's a among the points tried. Velocities that were
// measured (not differentiated from poses) make the equation error accurate: its estimate
// is a candidate too.
struct SeedCandidates {
  std::array<double, 3> base;                // (a, b, c) to scan a around
  std::vector<std::array<double, 3>> exact;  // full candidates tried as they are
};

SeedCandidates CandidateSeeds(const Trajectory& log, const IdentifyOptions& options,
                              std::array<double, 3>* closed_form_seed) {
  const double length_m = std::sqrt(log.slider.inertia_kgm2 / log.slider.mass_kg);
  const std::array<double, 3> defaults{{kDefaultA, 1.0, length_m}};
  SeedCandidates seeds{defaults, {defaults}};
  auto take = [&](const EstimateResult& r, bool set_base) {
    std::array<double, 3> seed = defaults;
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r.parameters[i];
      if (p.identifiable && std::isfinite(p.value) && p.value > 0) seed[i] = p.value;
    }
    if (seed == defaults) return;
    seeds.exact.push_back(seed);
    if (set_base) seeds.base = {defaults[0], seed[1], seed[2]};
  };
  EstimateResult closed_form;
  try {
    closed_form = EstimateClosedForm(log, options);
    take(closed_form, true);
  } catch (const std::exception&) {
  }
  if (log.columns.velocity) {
    try {
      take(EstimateEquationError(log, options, &closed_form), false);
    } catch (const std::exception&) {
    }
  }
  *closed_form_seed = seeds.exact.size() > 1 ? seeds.exact[1] : defaults;
  return seeds;
}

// Sets the problem's friction to the seed with the lowest trajectory cost among the exact
// candidates and a scan of a (refined by a parabola) at the base's (b, c).
std::array<double, 3> SeedFriction(TrajectoryProblem* problem, const SeedCandidates& seeds) {
  double best_cost = std::numeric_limits<double>::infinity();
  std::array<double, 3> best = seeds.base;
  auto try_seed = [&](const std::array<double, 3>& seed) {
    problem->SetFriction(seed);
    const double cost = problem->RawCost();
    if (cost < best_cost) {
      best_cost = cost;
      best = seed;
    }
    return cost;
  };
  double lo = seeds.base[0], hi = seeds.base[0];
  for (const std::array<double, 3>& seed : seeds.exact) {
    try_seed(seed);
    lo = std::min(lo, seed[0]);
    hi = std::max(hi, seed[0]);
  }
  const double log_lo = std::log(lo / kScanSpan), log_hi = std::log(hi * kScanSpan);
  const double spacing = (log_hi - log_lo) / (kScanPoints - 1);
  auto at = [&](double log_a) {
    std::array<double, 3> seed = seeds.base;
    seed[0] = std::exp(log_a);
    return try_seed(seed);
  };
  int best_point = 0;
  double best_scan = std::numeric_limits<double>::infinity();
  std::vector<double> scan_cost(kScanPoints);
  for (int k = 0; k < kScanPoints; ++k) {
    const double cost = scan_cost[k] = at(log_lo + k * spacing);
    if (cost < best_scan) {
      best_scan = cost;
      best_point = k;
    }
  }
  // A parabola in log a through the best scan point and its neighbours: its vertex, once.
  if (best_point > 0 && best_point < kScanPoints - 1) {
    const double x = log_lo + best_point * spacing;
    const double f_left = scan_cost[best_point - 1], f_right = scan_cost[best_point + 1];
    const double curvature = f_left - 2 * best_scan + f_right;
    if (curvature > 0 && std::isfinite(curvature)) {
      at(x + 0.5 * spacing * (f_left - f_right) / curvature);
    }
  }
  problem->SetFriction(best);
  return best;
}

// ---- noise and loss --------------------------------------------------------------------

// Robust scale of each log's residual rows: sqrt(median |r_row|^2 / 0.789), comparable with
// RowNoise (NaN for a log without rows in segments).
std::vector<double> ResidualRowScale(const TrajectoryProblem& problem) {
  const std::vector<double> r = problem.Residuals(true);
  std::vector<std::vector<double>> per_log(problem.num_logs());
  size_t k = 0;
  for (const TrajectorySegment& seg : problem.segments()) {
    for (int row = seg.first_row; row <= seg.last_row; ++row, k += 3) {
      per_log[seg.log].push_back(r[k] * r[k] + r[k + 1] * r[k + 1] + r[k + 2] * r[k + 2]);
    }
  }
  std::vector<double> scale(problem.num_logs(), kNaN);
  for (int i = 0; i < problem.num_logs(); ++i) {
    if (!per_log[i].empty()) scale[i] = std::sqrt(Median(per_log[i]) / kChi3MedianOverMean);
  }
  return scale;
}

void SetRowLosses(TrajectoryProblem* problem, RobustLoss kind, double sigmas,
                  const std::vector<double>& row_noise) {
  for (TrajectorySegment& seg : problem->segments()) {
    RowLoss loss;
    const double noise = row_noise[seg.log];
    if (kind != RobustLoss::kNone && noise > kNoiseFloor) {
      loss.kind = kind;
      loss.scale = sigmas * noise;
    }
    seg.cost->SetRowLoss(loss);
  }
}

// ---- intervals -------------------------------------------------------------------------

struct Interval {
  double stderr_value = kNaN;
  double quantile = kZ95;
  std::string note;
};

// The widest of the white-noise and cluster-robust intervals of each free global parameter
// (see trajectory_fit.h). `free` lists the global indices.
std::vector<Interval> ChooseIntervals(const FitInformation& info, const std::vector<int>& free,
                                      int state_parameters, bool pooled) {
  const int n = static_cast<int>(free.size());
  std::vector<Interval> out(n);
  if (n == 0) return out;
  Eigen::MatrixXd H(n, n), S_seg(n, n), S_log(n, n);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      H(a, b) = info.fisher(free[a], free[b]);
      S_seg(a, b) = info.segment_score_outer(free[a], free[b]);
      S_log(a, b) = info.log_score_outer(free[a], free[b]);
    }
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success) return out;
  const Eigen::MatrixXd Hinv = ldlt.solve(Eigen::MatrixXd::Identity(n, n));
  const int dof = info.residuals - state_parameters - n;
  const double s2 = dof > 0 ? info.sum_squares / dof : 0.0;
  auto sandwich = [&](const Eigen::MatrixXd& S, int clusters) {
    return Eigen::MatrixXd(Hinv * S * Hinv * (double(clusters) / (clusters - 1)));
  };
  const bool use_segments = info.segments >= kMinClusters;
  const bool use_logs = pooled && info.logs >= 2;
  const Eigen::MatrixXd V_seg = use_segments ? sandwich(S_seg, info.segments) : Hinv;
  const Eigen::MatrixXd V_log = use_logs ? sandwich(S_log, info.logs) : Hinv;
  const double t_seg = use_segments ? StudentT95(info.segments - 1) : kZ95;
  const double t_log = use_logs ? StudentT95(info.logs - 1) : kZ95;
  for (int a = 0; a < n; ++a) {
    Interval& iv = out[a];
    iv.stderr_value = std::sqrt(std::max(0.0, s2 * Hinv(a, a)));
    const double white_half = kZ95 * iv.stderr_value;
    double half = white_half;
    if (use_segments) {
      const double se = std::sqrt(std::max(0.0, V_seg(a, a)));
      if (t_seg * se > half) {
        half = t_seg * se;
        iv = {se, t_seg,
              Format("interval widened %.2fx: residuals correlated within segments "
                     "(cluster-robust over %.0f segments, t quantile %.2f)",
                     half / white_half, info.segments, t_seg)};
      }
    }
    if (use_logs) {
      const double se = std::sqrt(std::max(0.0, V_log(a, a)));
      if (t_log * se > half) {
        half = t_log * se;
        iv = {se, t_log,
              Format("interval widened %.2fx: the logs differ by more than their noise "
                     "(cluster-robust over %.0f logs, t quantile %.2f)",
                     half / white_half, info.logs, t_log)};
      }
    }
    if (!use_segments && !pooled) {
      iv.note = Format("only %.0f segments: too few to check the residuals for correlation "
                       "(white-noise interval)",
                       info.segments);
    }
  }
  return out;
}

// ---- one fit over a set of logs ----------------------------------------------------------

struct FitOutcome {
  EstimateResult result;
  std::unique_ptr<TrajectoryProblem> problem;
};

// How the pooled fit starts: from the logs fitted on their own.
struct PooledStart {
  std::array<double, 3> friction;
  std::vector<const TrajectoryProblem*> single;  // per log, null when it has none
};

double MaxStdErr(const TrajectoryProblem& problem, int i, const std::vector<LogDiagnostics>& d,
                 const TrajectoryOptions& options) {
  if (problem.IsFriction(i)) return kMaxLogStdErr;
  if (problem.GlobalName(i) == "delay_s") return kMaxDelayStdErrFraction * options.max_delay_s;
  const int k = problem.GlobalLog(i);
  const Trajectory& log = problem.log(k);
  const double weight = log.slider.mass_kg * log.slider.gravity_mps2;
  return kMaxOffsetStdErrFraction * std::max(d[k].max_push_N, 0.1 * weight);
}

std::string LogName(const Trajectory& log, int k) {
  return log.source.empty() ? "log " + std::to_string(k) : log.source;
}

void FillResiduals(const TrajectoryProblem& problem, EstimateResult* result) {
  const std::vector<double> r = problem.Residuals(true);
  size_t k = 0;
  for (const TrajectorySegment& seg : problem.segments()) {
    const Trajectory& log = problem.log(seg.log);
    for (int row = seg.first_row; row <= seg.last_row; ++row, k += 3) {
      StepResidual sr;
      sr.log = seg.log;
      sr.row = row;
      sr.t_s = log.samples[row].t_s;
      sr.value = {r[k], r[k + 1], r[k + 2]};
      result->residuals.push_back(sr);
    }
  }
  const bool pose = problem.use_pose(0);
  result->residual_names = pose ? std::array<std::string, 3>{{"x_m", "y_m", "theta_times_L_m"}}
                                : std::array<std::string, 3>{{"vx_mps", "vy_mps", "wz_times_L_mps"}};
}

FitOutcome Fit(const std::vector<const Trajectory*>& logs, const IdentifyOptions& options,
               const PooledStart* start) {
  const auto t0 = std::chrono::steady_clock::now();
  FitOutcome out;
  EstimateResult& result = out.result;
  result.method = EstimatorMethod::kTrajectory;
  const TrajectoryOptions& topt = options.trajectory;

  std::vector<LogDiagnostics> diagnostics;
  std::vector<double> row_noise;
  for (const Trajectory* log : logs) {
    diagnostics.push_back(DiagnoseLog(*log));
    row_noise.push_back(RowNoise(diagnostics.back(), log->columns.pose,
                                 std::sqrt(log->slider.inertia_kgm2 / log->slider.mass_kg)));
    result.steps_total += std::max(0, static_cast<int>(log->samples.size()) - 1);
  }
  auto too_little = [&](const std::string& message) {
    result.status = TerminationStatus::kTooLittleExcitation;
    result.converged = false;
    result.message = message;
    result.seconds = Seconds(t0);
    return std::move(out);
  };
  for (size_t k = 0; k < logs.size(); ++k) {
    if (diagnostics[k].dead_force_channel) {
      return too_little((logs.size() > 1 ? LogName(*logs[k], int(k)) + ": " : std::string()) +
                        *diagnostics[k].dead_force_channel);
    }
  }
  try {
    out.problem = std::make_unique<TrajectoryProblem>(logs, options);
  } catch (const std::invalid_argument& e) {
    return too_little(e.what());
  }
  TrajectoryProblem& problem = *out.problem;

  // Seeds.
  std::array<double, 3> seed;
  if (start) {
    seed = start->friction;
    problem.SetFriction(seed);
    for (TrajectorySegment& seg : problem.segments()) {
      const TrajectoryProblem* single = start->single[seg.log];
      if (!single) continue;
      for (const TrajectorySegment& s : single->segments()) {
        if (s.first_row == seg.first_row && s.last_row == seg.last_row) seg.state = s.state;
      }
    }
    for (int i = 3; i < problem.num_global(); ++i) {
      const int k = problem.GlobalLog(i);
      const TrajectoryProblem* single = k >= 0 ? start->single[k] : nullptr;
      if (!single) continue;
      for (int j = 3; j < single->num_global(); ++j) {
        if (single->GlobalName(j) == problem.GlobalName(i)) problem.set_global(i, single->global(j));
      }
    }
  } else {
    std::array<double, 3> closed_form_seed;
    seed = SeedFriction(&problem, CandidateSeeds(*logs[0], options, &closed_form_seed));
  }

  // Fit: the loss scaled to each log's own noise, then, where the residuals sit well above
  // it (model mismatch), to the residuals' own scale.
  SetRowLosses(&problem, topt.loss, topt.loss_scale_sigmas, row_noise);
  std::vector<bool> free(problem.num_global(), true);
  ceres::Solver::Summary summary = problem.Solve(free);
  int iterations = static_cast<int>(summary.iterations.size());
  std::vector<double> residual_scale = ResidualRowScale(problem);
  if (topt.loss != RobustLoss::kNone) {
    bool rescale = false;
    std::vector<double> loss_noise = row_noise;
    for (size_t k = 0; k < logs.size(); ++k) {
      if (residual_scale[k] > kRescaleRatio * row_noise[k] || !(row_noise[k] > kNoiseFloor)) {
        loss_noise[k] = residual_scale[k];
        rescale = rescale || residual_scale[k] > kNoiseFloor;
      }
    }
    if (rescale) {
      SetRowLosses(&problem, topt.loss, topt.loss_scale_sigmas, loss_noise);
      summary = problem.Solve(free);
      iterations += static_cast<int>(summary.iterations.size());
      residual_scale = ResidualRowScale(problem);
    }
  }

  // Identifiability over every global parameter; hold what the logs do not determine.
  FitInformation info = problem.Information();
  const int G = problem.num_global();
  std::vector<double> max_stderr(G);
  for (int i = 0; i < G; ++i) max_stderr[i] = MaxStdErr(problem, i, diagnostics, topt);
  const int dof0 = info.residuals - problem.StateParameters() - G;
  const std::vector<ParameterIdentifiability> verdict = AssessIdentifiability(
      info.fisher, dof0 > 0 ? info.sum_squares / dof0 : 0.0, std::vector<bool>(G, true),
      max_stderr);
  for (int i = 0; i < G; ++i) free[i] = verdict[i].identifiable;
  if (!free[0] && !free[1] && !free[2]) {
    return too_little(
        "too little sliding to identify anything: the log does not determine any friction "
        "parameter (it barely slides, or its noise is too large for its length: " +
        std::to_string(problem.Rows()) + " rows in segments)");
  }
  if (std::find(free.begin(), free.end(), false) != free.end()) {
    summary = problem.Solve(free);
    iterations += static_cast<int>(summary.iterations.size());
    residual_scale = ResidualRowScale(problem);
    info = problem.Information();
  }

  // Intervals.
  std::vector<int> free_index;
  for (int i = 0; i < G; ++i) {
    if (free[i]) free_index.push_back(i);
  }
  const std::vector<Interval> intervals =
      ChooseIntervals(info, free_index, problem.StateParameters(), logs.size() > 1);
  std::vector<Interval> interval_of(G);
  for (size_t a = 0; a < free_index.size(); ++a) interval_of[free_index[a]] = intervals[a];
  for (int i = 0; i < 3; ++i) {
    const double value = std::exp(problem.global(i));
    if (!free[i]) {
      result.parameters[i] = NotIdentifiable(value, verdict[i].note);
      continue;
    }
    const Interval& iv = interval_of[i];
    result.parameters[i] = EstimateFromLog(problem.global(i), iv.stderr_value, iv.quantile);
    result.parameters[i].note = iv.note;
  }
  for (int i = 3; i < G; ++i) {
    NuisanceEstimate n;
    n.name = problem.GlobalName(i);
    n.log = problem.GlobalLog(i) >= 0 ? LogName(*logs[problem.GlobalLog(i)], problem.GlobalLog(i))
                                      : "";
    if (!free[i]) {
      n.held_at = problem.global(i);
      n.reason = verdict[i].note;
    } else {
      const Interval& iv = interval_of[i];
      n.identifiable = true;
      n.verdict = Verdict::kOk;
      n.value = problem.global(i);
      n.stderr_value = iv.stderr_value;
      n.ci95_lo = n.value - iv.quantile * iv.stderr_value;
      n.ci95_hi = n.value + iv.quantile * iv.stderr_value;
    }
    result.nuisance.push_back(n);
  }

  // Verdicts.
  PlausibilityContext context;
  double noise2 = 0, scale2 = 0;
  int rows = 0;
  std::vector<int> rows_of(logs.size(), 0);
  for (const TrajectorySegment& seg : problem.segments()) {
    rows_of[seg.log] += seg.last_row - seg.first_row + 1;
  }
  for (size_t k = 0; k < logs.size(); ++k) {
    if (rows_of[k] == 0 || !std::isfinite(row_noise[k]) || !std::isfinite(residual_scale[k])) {
      continue;
    }
    noise2 += rows_of[k] * row_noise[k] * row_noise[k];
    scale2 += rows_of[k] * residual_scale[k] * residual_scale[k];
    rows += rows_of[k];
    context.logs.push_back({logs[k]->slider.mass_kg * logs[k]->slider.gravity_mps2,
                            diagnostics[k].max_push_N});
  }
  result.log_noise = rows > 0 ? std::sqrt(noise2 / rows) : kNaN;
  result.residual_rms = rows > 0 ? std::sqrt(scale2 / rows) : kNaN;
  context.log_noise = result.log_noise;
  context.residual_rms = result.residual_rms;
  context.seed = seed;
  for (int i = 0; i < 3; ++i) {
    context.lower[i] = kFrictionLowerBound[i];
    context.upper[i] = kFrictionUpperBound[i];
  }
  JudgeEstimates(context, &result.parameters);

  int intervals_used = 0;
  for (const TrajectorySegment& seg : problem.segments()) {
    intervals_used += seg.last_row - seg.first_row;
  }
  result.steps_used = intervals_used;
  if (result.steps_total > intervals_used) {
    result.Exclude("between shooting segments", result.steps_total - intervals_used);
  }
  result.final_cost = summary.final_cost;
  result.iterations = iterations;
  result.message = summary.BriefReport();
  FillResiduals(problem, &result);
  // Usable is not converged: a solve cut off by the iteration limit is usable to Ceres.
  result.Conclude(summary.termination_type == ceres::CONVERGENCE ||
                  summary.termination_type == ceres::USER_SUCCESS);
  result.seconds = Seconds(t0);
  return out;
}

LogResult AsLogResult(const EstimateResult& r, const Trajectory& log, int k) {
  LogResult lr;
  lr.name = LogName(log, k);
  lr.rows = static_cast<int>(log.samples.size());
  lr.steps_used = r.steps_used;
  lr.status = r.status;
  lr.message = r.message;
  lr.parameters = r.parameters;
  return lr;
}

}  // namespace

EstimateResult EstimateTrajectory(const Trajectory& log, const IdentifyOptions& options) {
  std::string why;
  if (!options.trajectory.IsValid(&why)) throw std::invalid_argument(why);
  return Fit({&log}, options, nullptr).result;
}

EstimateResult EstimateTrajectory(const std::vector<Trajectory>& logs,
                                  const IdentifyOptions& options) {
  std::string why;
  if (!options.trajectory.IsValid(&why)) throw std::invalid_argument(why);
  if (logs.empty()) throw std::invalid_argument("no logs to fit");
  if (logs.size() == 1) return EstimateTrajectory(logs[0], options);
  const auto t0 = std::chrono::steady_clock::now();

  // Every log on its own: its own estimate, and the seeds of the pooled fit.
  std::vector<FitOutcome> single;
  std::vector<LogResult> log_results;
  PooledStart start;
  std::array<std::vector<double>, 3> log_values;
  for (size_t k = 0; k < logs.size(); ++k) {
    single.push_back(Fit({&logs[k]}, options, nullptr));
    log_results.push_back(AsLogResult(single.back().result, logs[k], int(k)));
    const bool fitted = single.back().problem &&
                        single.back().result.status != TerminationStatus::kTooLittleExcitation;
    start.single.push_back(fitted ? single.back().problem.get() : nullptr);
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = single.back().result.parameters[i];
      if (p.identifiable) log_values[i].push_back(std::log(p.value));
    }
  }
  std::array<double, 3> defaults{{kDefaultA, 1.0,
                                  std::sqrt(logs[0].slider.inertia_kgm2 / logs[0].slider.mass_kg)}};
  for (int i = 0; i < 3; ++i) {
    start.friction[i] = log_values[i].empty() ? defaults[i] : std::exp(Median(log_values[i]));
  }

  std::vector<const Trajectory*> pointers;
  for (const Trajectory& log : logs) pointers.push_back(&log);
  EstimateResult result = Fit(pointers, options, &start).result;
  result.logs = std::move(log_results);
  for (int i = 0; i < 3; ++i) result.heterogeneity[i] = TestHeterogeneity(result.logs, i);
  result.seconds = Seconds(t0);
  return result;
}

ceres::CostFunction* NewSegmentCost(const Trajectory& log, int first_row, int last_row,
                                    int substeps, bool use_pose, SegmentNuisances nuisances) {
  return new SegmentCost(log, first_row, last_row, substeps, use_pose, nuisances);
}

}  // namespace slideid
