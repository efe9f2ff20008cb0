#include "prediction/validate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <tuple>

#include "estimator/identify.h"
#include "estimator/parallel_for.h"
#include "estimator/pusher_friction.h"
#include "estimator/robust_statistics.h"
#include "estimator/trajectory_fit.h"

namespace slideid {
namespace {

// The grid that integrates the mean distance over a patch: this many cells a side.
constexpr int kPressureGrid = 400;

std::string NameOf(const Trajectory& log, size_t k) {
  return log.source.empty() ? "log " + std::to_string(k) : log.source;
}

/// The friction a fit found: each parameter's value, or where it was held when the logs
/// do not determine it (the value the fit used).
ReducedFriction FrictionOf(const std::array<ParameterEstimate, 3>& parameters) {
  std::array<double, 3> v{};
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = parameters[i];
    v[i] = p.identifiable ? p.value : p.held_at;
  }
  return {v[0], v[1], v[2]};
}

bool Usable(const ReducedFriction& f) {
  return std::isfinite(f.a) && f.a > 0 && std::isfinite(f.b) && f.b > 0 && std::isfinite(f.c) &&
         f.c > 0;
}

/// mu_p for a prediction from a fit: the option, the fitted value, the lower bound of a
/// sticking tip, or the textbook value; and where it came from.
std::pair<double, std::string> MuPusherOf(const EstimateResult& r, const ValidationOptions& o) {
  if (o.mu_pusher) return {*o.mu_pusher, "option"};
  if (r.mu_pusher_examined && r.mu_pusher.identifiable) return {r.mu_pusher.value, "fit"};
  if (std::isfinite(r.mu_pusher_lower_bound)) return {r.mu_pusher_lower_bound, "lower bound"};
  return {kTextbookMuPusher, "textbook"};
}

PushPrediction Predict(const Trajectory& log, size_t index, int fold, const ReducedFriction& f,
                       double mu_pusher, const PredictionOptions& options) {
  PushPrediction p;
  p.log = NameOf(log, index);
  p.fold = fold;
  p.friction = f;
  p.mu_pusher = mu_pusher;
  try {
    const Prediction prediction = PredictPush(log, f, mu_pusher, options);
    p.errors = prediction.errors;
    p.ok = prediction.summary.ok();
    if (!p.ok) p.error = prediction.summary.message;
  } catch (const std::invalid_argument& e) {
    p.error = e.what();
  }
  return p;
}

/// A push that was not predicted, and why (it counts as failed in its method's summary).
PushPrediction Unpredicted(const std::string& log, int fold, const std::string& why) {
  PushPrediction p;
  p.log = log;
  p.fold = fold;
  p.error = why;
  return p;
}

void SummariseMethod(MethodValidation* m) {
  std::vector<double> position, rotation, per_100mm, fraction;
  m->failed = 0;
  for (const PushPrediction& p : m->pushes) {
    if (!p.ok) {
      ++m->failed;
      continue;
    }
    position.push_back(p.errors.final_position_m);
    rotation.push_back(p.errors.final_rotation_rad);
    per_100mm.push_back(p.errors.final_position_per_100mm_m);
    fraction.push_back(p.errors.final_position_fraction);
  }
  m->final_position_m = slideid::Summarise(position);
  m->final_rotation_rad = slideid::Summarise(rotation);
  m->final_position_per_100mm_m = slideid::Summarise(per_100mm);
  m->final_position_fraction = slideid::Summarise(fraction);
}

}  // namespace

bool ValidationOptions::IsValid(std::string* why) const {
  auto fail = [why](const char* text) {
    if (why) *why = text;
    return false;
  };
  if (folds < 0 || folds == 1) return fail("folds must be 0 (leave-one-out) or at least 2");
  if (mu_pusher && !(*mu_pusher >= 0)) return fail("mu_pusher must be >= 0");
  if (threads < 1) return fail("threads must be >= 1");
  return prediction.IsValid(why) && identify.IsValid(why);
}

ErrorSummary Summarise(std::vector<double> values) {
  ErrorSummary s;
  s.pushes = static_cast<int>(values.size());
  if (values.empty()) return s;
  s.median = Quantile(values, 0.5);
  s.q25 = Quantile(values, 0.25);
  s.q75 = Quantile(values, 0.75);
  s.worst = *std::max_element(values.begin(), values.end());
  return s;
}

ReducedFriction TextbookFriction(const ContactPatch& patch) {
  const std::vector<Eigen::Vector2d> outline = patch.Outline();
  Eigen::Vector2d lo = outline.front(), hi = outline.front();
  for (const Eigen::Vector2d& p : outline) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double inner =
      patch.shape() == ContactPatch::Shape::kRing
          ? patch.InnerOutline().empty() ? 0.0 : patch.InnerOutline().front().norm()
          : 0.0;
  double distance = 0;
  long cells = 0;
  const Eigen::Vector2d size = (hi - lo) / kPressureGrid;
  for (int i = 0; i < kPressureGrid; ++i) {
    for (int j = 0; j < kPressureGrid; ++j) {
      const Eigen::Vector2d p = lo + Eigen::Vector2d((i + 0.5) * size.x(), (j + 0.5) * size.y());
      if (!patch.HullContains(p) || p.norm() < inner) continue;
      distance += p.norm();
      ++cells;
    }
  }
  return {0.25, 1.0, cells > 0 ? distance / cells : 0.0};
}

ValidationResult Validate(const std::vector<Trajectory>& logs, const ValidationOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("validate: " + why);
  if (logs.size() < 2) throw std::invalid_argument("validate: needs at least 2 logs");
  const auto start = std::chrono::steady_clock::now();
  const int n = static_cast<int>(logs.size());
  ValidationResult result;
  result.drive = options.prediction.drive;
  result.folds = options.folds == 0 ? n : std::min(options.folds, n);
  for (int k = 0; k < n; ++k) result.logs.push_back(NameOf(logs[k], k));
  IdentifyOptions fit_options = options.identify;
  fit_options.threads = 1;  // the folds run in parallel instead

  // With the trajectory method, one pooled fit of every log starts the folds' fits (each a
  // pooled solve from nearby: PooledTrajectoryFit) and gives every log's own fit.
  std::unique_ptr<PooledTrajectoryFit> full;
  if (fit_options.method == EstimatorMethod::kTrajectory) {
    full = std::make_unique<PooledTrajectoryFit>(logs, fit_options);
  }

  // The folds: fit on the others, predict the held-out pushes.
  result.fold_fits.resize(result.folds);
  MethodValidation folds;
  folds.method = "folds";
  folds.pushes.resize(n);
  ParallelFor(result.folds, options.threads, [&](int k) {
    FoldFit& fit = result.fold_fits[k];
    fit.fold = k;
    std::vector<Trajectory> train;
    std::vector<int> train_index;
    std::vector<const Trajectory*> train_logs;
    for (int i = 0; i < n; ++i) {
      if (i % result.folds == k) {
        fit.held_out.push_back(result.logs[i]);
      } else {
        train_index.push_back(i);
        train_logs.push_back(&logs[i]);
        if (!full) train.push_back(logs[i]);
      }
    }
    try {
      EstimateResult r;
      if (full) {
        r = full->FitSubset(train_index);
        AddPusherFriction(train_logs, &r);
      } else {
        r = Identify(train, fit_options);
      }
      fit.friction = FrictionOf(r.parameters);
      std::tie(fit.mu_pusher, fit.mu_pusher_from) = MuPusherOf(r, options);
      fit.ok = r.converged && Usable(fit.friction);
      if (!fit.ok) fit.error = "the fold's fit did not converge: " + r.message;
    } catch (const std::exception& e) {
      fit.error = e.what();
    }
    for (int i = k; i < n; i += result.folds) {
      if (fit.ok) {
        folds.pushes[i] = Predict(logs[i], i, k, fit.friction, fit.mu_pusher, options.prediction);
      } else {
        folds.pushes[i] = Unpredicted(result.logs[i], k, fit.error);
      }
    }
  });
  SummariseMethod(&folds);
  result.methods.push_back(folds);

  if (options.quasi_static && options.prediction.drive == PredictionDrive::kPusher) {
    MethodValidation quasi;
    quasi.method = "quasi-static";
    quasi.pushes.resize(n);
    PredictionOptions qs = options.prediction;
    qs.drive = PredictionDrive::kQuasiStatic;
    ParallelFor(n, options.threads, [&](int i) {
      const FoldFit& fit = result.fold_fits[i % result.folds];
      if (fit.ok) {
        quasi.pushes[i] = Predict(logs[i], i, fit.fold, fit.friction, fit.mu_pusher, qs);
      } else {
        quasi.pushes[i] = Unpredicted(result.logs[i], fit.fold, fit.error);
      }
    });
    SummariseMethod(&quasi);
    result.methods.push_back(quasi);
  }
  if (options.own_fit) {
    MethodValidation own;
    own.method = "own fit";
    own.pushes.resize(n);
    ParallelFor(n, options.threads, [&](int i) {
      try {
        // The pooled fit's own fit of each log (with its mu_p), or a fit of the log alone.
        EstimateResult r;
        if (full && i < static_cast<int>(full->result().logs.size())) {
          const LogResult& own_fit = full->result().logs[i];
          r.parameters = own_fit.parameters;
          r.converged = own_fit.status == TerminationStatus::kConverged ||
                        own_fit.status == TerminationStatus::kConvergedWithCaveats;
          r.message = own_fit.message;
          AddPusherFriction({&logs[i]}, &r);
        } else {
          r = Identify(logs[i], fit_options);
        }
        const ReducedFriction f = FrictionOf(r.parameters);
        if (!r.converged || !Usable(f)) {
          own.pushes[i] =
              Unpredicted(result.logs[i], -1, "its own fit did not converge: " + r.message);
          return;
        }
        own.pushes[i] =
            Predict(logs[i], i, -1, f, MuPusherOf(r, options).first, options.prediction);
      } catch (const std::exception& e) {
        own.pushes[i] = Unpredicted(result.logs[i], -1, e.what());
      }
    });
    SummariseMethod(&own);
    result.methods.push_back(own);
  }
  if (options.textbook) {
    MethodValidation textbook;
    textbook.method = "textbook";
    textbook.pushes.resize(n);
    ParallelFor(n, options.threads, [&](int i) {
      if (!logs[i].patch) {
        textbook.pushes[i] =
            Unpredicted(result.logs[i], -1, "no patch: the textbook c needs the outline");
        return;
      }
      const ReducedFriction f = TextbookFriction(*logs[i].patch);
      textbook.pushes[i] = Predict(logs[i], i, -1, f, options.mu_pusher.value_or(kTextbookMuPusher),
                                   options.prediction);
    });
    SummariseMethod(&textbook);
    result.methods.push_back(textbook);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace slideid
