#pragma once
// The command line of `advise-push` (declared and read with Boost.Program_options): what the
// tool and slideid.advise_push share, so that both give the same answer. Bad values throw
// boost::program_options::error naming the option; an unreadable or malformed result file
// std::runtime_error naming the file (and the JSON path). Never prints.

#include <boost/program_options.hpp>
#include <string>

#include "estimator/push_advice.h"
#include "forward_model/contact_patch.h"
#include "forward_model/slider.h"

namespace slideid::cli {

/// What advise-push was asked.
struct AdviseRequest {
  SliderProperties slider;
  ContactPatch patch = ContactPatch::Rectangle(0.09, 0.09);
  FrictionKnowledge knowledge;  ///< from --friction, or the prior
  PushAdviceOptions options;
  int top = 10;  ///< --candidates: how many to print (0: all)
  /// Where the pose noise and mu_p came from, for the report ("--pose-noise", "the
  /// result's residuals", "default").
  std::string noise_from, mu_pusher_from;
  /// Where the correlations of a, b, c came from: "none" (a result's standard errors
  /// alone, or the prior) or "N log(s)" (--log).
  std::string correlations_from = "none";
};

/// Every option of advise-push but --help, --version and --json.
void AddAdviseOptions(boost::program_options::options_description* options);

/// Reads them: --patch is required; --mass defaults to 1 kg, --inertia to a uniform slab
/// over the patch (datasets/dataset.h, UniformInertia).
AdviseRequest ReadAdviseOptions(const boost::program_options::variables_map& vm);

/// The advice for a request (estimator/push_advice.h, AdvisePush).
PushAdvice Advise(const AdviseRequest& request);

/// What advise-push --json prints: io/push_advice_report.h's FormatAdviceJson, top N.
std::string AdviceJson(const AdviseRequest& request, const PushAdvice& advice);

}  // namespace slideid::cli
