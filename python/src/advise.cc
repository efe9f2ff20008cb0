// advise_push (which push next, with advise-push's options as keywords): the JSON the tool
// prints with --json, from the same option reader and the same formatting
// (pipeline/advise_options.h).

#include "core.h"
#include "pipeline/advise_options.h"

namespace slideid::python {
namespace po = boost::program_options;

namespace {

/// advise_push: what advise-push --json prints.
std::string AdvisePushJson(const py::kwargs& keywords) {
  po::options_description options;
  cli::AddAdviseOptions(&options);
  const po::variables_map vm = ParseKeywords("advise_push", options, keywords);
  const cli::AdviseRequest request = cli::ReadAdviseOptions(vm);
  py::gil_scoped_release release;
  return cli::AdviceJson(request, cli::Advise(request));
}

}  // namespace

void BindAdvise(py::module_& m) { m.def("advise_push", &AdvisePushJson); }

}  // namespace slideid::python
