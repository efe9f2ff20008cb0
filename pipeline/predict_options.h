#pragma once
// The command lines of `predict` and `validate` (declared and read with
// Boost.Program_options), and their results as JSON: what the tools and the Python module's
// predict() and validate() share, so that both give the same answer. Bad values throw
// boost::program_options::error naming the option. Never prints.

#include <boost/program_options.hpp>
#include <optional>
#include <string>

#include "forward_model/slider.h"
#include "prediction/predict.h"
#include "prediction/validate.h"

namespace slideid::cli {

/// What predict was asked: the friction (a, b, c, and mu_p when known) and how to drive.
struct PredictRequest {
  ReducedFriction friction;
  std::optional<double> mu_pusher;
  /// --drive, when given; otherwise the pusher when the log has the tip's path.
  std::optional<PredictionDrive> drive;
  PredictionOptions options;
};

/// The friction and prediction options of predict (all but --log, --out, --json).
void AddPredictOptions(boost::program_options::options_description* options);
/// Reads them; the friction from --friction RESULT.json (a file identify --json wrote), the
/// options --mu, --b, --c, --mu-pusher over it. Throws po::error for a value missing or
/// out of range, std::runtime_error naming the file for an unreadable result.
PredictRequest ReadPredictOptions(const boost::program_options::variables_map& vm);

/// The drive a request gives for `log`.
PredictionDrive DriveFor(const PredictRequest& request, const Trajectory& log);

/// One JSON object: the drive, the friction used, whether the prediction ran to the end,
/// and every error of PredictionErrors (parting_time_s null when they never part).
std::string PredictionJson(const Prediction& prediction, const ReducedFriction& friction);

/// validate's options other than --logs, --skip-bad, --json, --csv.
void AddValidateOptions(boost::program_options::options_description* options);
/// Reads them; `all_tip` says whether every log has the tip's path (the default drive).
ValidationOptions ReadValidateOptions(const boost::program_options::variables_map& vm,
                                      bool all_tip);

/// One JSON object: logs, folds, the folds' fits, and per method its summaries and pushes.
std::string ValidationJson(const ValidationResult& result);

}  // namespace slideid::cli
