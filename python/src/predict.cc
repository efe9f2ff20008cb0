// predict (one push: a path or a Log, with predict's options as keywords) and validate (logs:
// paths or Logs, with validate's options): the JSON the tools print, from the same option
// readers and the same formatting (pipeline/predict_options.h).

#include <pybind11/stl.h>

#include "core.h"
#include "io/push_log.h"
#include "pipeline/identify_files.h"
#include "pipeline/predict_options.h"

namespace slideid::python {
namespace po = boost::program_options;

namespace {

PushLogFile LogOf(py::handle item) {
  if (py::isinstance<LogHandle>(item)) return item.cast<LogPtr>()->file;
  const std::string path = item.cast<std::string>();
  PushLogFile file = ReadPushLogFile(path);
  if (file.log.source.empty()) file.log.source = path;
  return file;
}

/// predict: {"json": what predict --json prints, "predicted": the predicted log}.
py::dict PredictLog(py::object log, const py::kwargs& keywords) {
  po::options_description options;
  cli::AddPredictOptions(&options);
  options.add_options()("out", po::value<std::string>());
  const po::variables_map vm = ParseKeywords("predict", options, keywords);
  const cli::PredictRequest request = cli::ReadPredictOptions(vm);
  const PushLogFile file = LogOf(log);
  const Trajectory& trajectory = file.log;
  PredictionOptions prediction = request.options;
  prediction.drive = cli::DriveFor(request, trajectory);
  auto predicted = std::make_shared<LogHandle>();
  std::string json;
  {
    py::gil_scoped_release release;
    const Prediction p = PredictPush(trajectory, request.friction, request.mu_pusher, prediction);
    json = cli::PredictionJson(p, request.friction);
    // The source's patch text goes with it: a patch written as it was read.
    predicted->file = PushLogFile{p.predicted, file.patch_spec, {}};
  }
  if (vm.count("out")) {
    try {
      WritePushLog(predicted->file, vm["out"].as<std::string>());
    } catch (const std::exception& e) {
      throw WriteFailure(e.what());
    }
  }
  py::dict out;
  out["json"] = json;
  out["predicted"] = predicted;
  return out;
}

/// validate: what validate --json writes.
std::string ValidateLogs(const py::list& inputs, const py::kwargs& keywords) {
  po::options_description options;
  cli::AddValidateOptions(&options);
  const po::variables_map vm = ParseKeywords("validate", options, keywords);
  std::vector<Trajectory> logs;
  for (py::handle item : inputs) logs.push_back(LogOf(item).log);
  bool all_tip = true;
  for (const Trajectory& l : logs) all_tip = all_tip && l.measured.tip;
  const ValidationOptions validation = cli::ReadValidateOptions(vm, all_tip);
  py::gil_scoped_release release;
  return cli::ValidationJson(Validate(logs, validation));
}

}  // namespace

void BindPredict(py::module_& m) {
  m.def("predict", &PredictLog, py::arg("log"));
  m.def("validate", &ValidateLogs, py::arg("inputs"));
}

}  // namespace slideid::python
