#pragma once
// The estimators' cores: each fits a list of push logs together, and nothing else. Options
// are valid and no log has a dead force channel by the time they run: checking, the choice
// of one log or many, per-log results, heterogeneity and timing are FitOneOrMany's
// (estimator/pooling.h), reached through EstimateOneOrMany. Not installed.

#include <vector>

#include "estimator/estimate.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// The closed form of `logs` together (EstimateClosedForm, estimator/closed_form.h);
/// without its per-step residuals when `keep_residuals` is false (a seed needs none).
EstimateResult ClosedFormCore(const std::vector<const Trajectory*>& logs,
                              const IdentifyOptions& options, bool keep_residuals = true);

/// The equation error of `logs` together (EstimateEquationError), seeded by `closed_form`,
/// the closed form of the same logs; too little sliding for the closed form is the result.
EstimateResult EquationErrorCore(const std::vector<const Trajectory*>& logs,
                                 const IdentifyOptions& options, const EstimateResult& closed_form);

/// The trajectory fit of one log or many (EstimateTrajectory): a method whose pooled fit
/// starts from the logs' own fits, so it owns its FitOneOrMany.
EstimateResult TrajectoryOneOrMany(const std::vector<const Trajectory*>& logs,
                                   const IdentifyOptions& options);

/// The one way in to every push-log method: the first log with a dead force channel as a
/// result of too little excitation (naming it among several), else options.method over one
/// log or many (FitOneOrMany). Options must be valid (IsValid); the callers check them once.
EstimateResult EstimateOneOrMany(const std::vector<const Trajectory*>& logs,
                                 const IdentifyOptions& options);

/// EstimateOneOrMany of `method` with its options checked first (throws
/// std::invalid_argument naming the method): the entry of the per-method functions
/// (EstimateClosedForm, EstimateEquationError, EstimateTrajectory).
EstimateResult EstimateAs(EstimatorMethod method, const std::vector<const Trajectory*>& logs,
                          IdentifyOptions options);

}  // namespace slideid
