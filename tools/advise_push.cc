// advise-push: which push to make next. Ranks candidate pushes (contact points on the
// outline, directions within the tip's friction cone, lengths) by what each is expected to
// teach about the friction, given what is known so far (estimator/push_advice.h).

#include <iostream>

#include "io/push_advice_report.h"
#include "pipeline/advise_options.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

int main(int argc, char** argv) {
  return tools::RunTool("advise-push", [&]() -> int {
    po::options_description opts(
        "advise-push: which push next. Each candidate push (a round tip coming in from just\n"
        "outside the slider, at rest, and pushing straight on) is simulated at the current\n"
        "estimate, and the information the trajectory fit would draw from its log is added\n"
        "to what is known; the pushes are ranked by the relative standard errors of a, b, c\n"
        "expected after them.\n\n"
        "Usage: advise-push --friction RESULT.json --patch \"rectangle 0.09 0.09\" [options]\n"
        "       advise-push --patch \"disk 0.05\" --mass 0.5 (nothing known yet: the prior)\n\n"
        "Options");
    opts.add_options()("help,h", "print this help and exit")("version",
                                                             "print the version and exit")(
        "json", "print the ranking as one JSON object instead of the table");
    cli::AddAdviseOptions(&opts);
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, opts), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts
                << "\nExit codes: 0 ok, 1 bad input (the result file), 2 usage, 3 every "
                   "candidate failed to simulate.\n";
      return tools::FlushStdout("advise-push");
    }
    if (vm.count("version")) {
      std::cout << "advise-push (slideid) " << SLIDEID_VERSION << "\n";
      return tools::FlushStdout("advise-push");
    }
    const cli::AdviseRequest request = cli::ReadAdviseOptions(vm);
    const PushAdvice advice = cli::Advise(request);
    if (vm.count("json")) {
      std::cout << cli::AdviceJson(request, advice) << "\n";
    } else {
      std::cout << "advise-push: patch " << vm["patch"].as<std::string>() << ", mass "
                << request.slider.mass_kg << " kg, inertia " << request.slider.inertia_kgm2
                << " kg m^2; pose noise from " << request.noise_from << ", mu_p from "
                << request.mu_pusher_from << "; correlations from " << request.correlations_from
                << "\n";
      std::cout << FormatAdviceText(advice, request.options, request.top);
    }
    const int flushed = tools::FlushStdout("advise-push");
    if (flushed != tools::kExitOk) return flushed;
    const bool any = !advice.ranking.empty() && advice.ranking.front().simulated;
    return any ? tools::kExitOk : tools::kExitNumerical;
  });
}
