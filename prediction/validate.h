#pragma once
// Cross-validation over logs: is an identified friction good enough to plan with? Each fold
// fits a, b, c and mu_p pooled on the other logs, then predicts each of its own pushes
// (prediction/predict.h). Beside it, on the same pushes, in the same run:
//  - "own fit", an oracle: each push predicted with the friction fitted on it alone (how
//    well the model can fit that push at all);
//  - "textbook": a = 0.25, b = 1, c from a uniform pressure over the outline, mu_p = 0.25
//    (what a user without an identification would take);
//  - "quasi-static": the folds' friction through the quasi-static ellipsoid model (pusher
//    drive only; prediction/predict.h), what the pushing literature predicts with.
// The gap between the folds and the own fits is what pooling costs; the own fits' errors
// are what the model cannot explain.

#include <optional>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/contact_patch.h"
#include "prediction/predict.h"

namespace slideid {

struct ValidationOptions {
  /// Folds: the logs dealt round-robin into K folds in their order; 0 is leave-one-out.
  int folds = 0;
  PredictionOptions prediction;
  IdentifyOptions identify;  ///< the fits of the folds and the own fits
  /// mu_p for every prediction instead of the fitted one (pusher drive).
  std::optional<double> mu_pusher;
  bool own_fit = true;   ///< the oracle baseline
  bool textbook = true;  ///< the textbook baseline
  /// The pusher drive: also the folds' friction through the quasi-static model (what the
  /// pushing literature predicts with).
  bool quasi_static = true;
  int threads = 1;  ///< folds fitted and pushes predicted in parallel

  bool IsValid(std::string* why) const;
};

/// One push predicted by one method.
struct PushPrediction {
  std::string log;
  int fold = 0;
  bool ok = false;  ///< predicted to the end; else `error` says why
  std::string error;
  PredictionErrors errors;
  ReducedFriction friction;
  double mu_pusher = 0;
};

/// What one fold's pooled fit found.
struct FoldFit {
  int fold = 0;
  std::vector<std::string> held_out;
  bool ok = false;
  std::string error;
  ReducedFriction friction;
  double mu_pusher = 0;
  std::string mu_pusher_from;  ///< "fit", "lower bound", "option" or "textbook"
};

/// Median, quartiles and worst of one error over the pushes a method predicted.
struct ErrorSummary {
  int pushes = 0;
  double median = 0, q25 = 0, q75 = 0, worst = 0;
};

/// One method's predictions and their summaries (final position [m], final rotation [rad],
/// final position per 100 mm of travel [m], final position over the displacement).
struct MethodValidation {
  std::string method;  ///< "folds", "own fit", "textbook", "quasi-static"
  std::vector<PushPrediction> pushes;
  int failed = 0;
  ErrorSummary final_position_m, final_rotation_rad, final_position_per_100mm_m,
      final_position_fraction;
};

struct ValidationResult {
  std::vector<std::string> logs;
  PredictionDrive drive = PredictionDrive::kPusher;
  int folds = 0;  ///< as run (the number of logs for leave-one-out)
  std::vector<FoldFit> fold_fits;
  std::vector<MethodValidation> methods;
  double seconds = 0;
};

/// Cross-validates over `logs` (at least 2; their `source` names them). Throws
/// std::invalid_argument for invalid options or too few logs; a fold or a push that fails
/// is recorded with its reason.
ValidationResult Validate(const std::vector<Trajectory>& logs, const ValidationOptions& options);

/// The textbook friction of a patch: a = 0.25, b = 1, and c = the mean distance from the
/// CM over the patch (the ratio of the largest friction moment to the largest friction
/// force under a uniform pressure) [m].
ReducedFriction TextbookFriction(const ContactPatch& patch);
constexpr double kTextbookMuPusher = 0.25;

ErrorSummary Summarise(std::vector<double> values);

}  // namespace slideid
