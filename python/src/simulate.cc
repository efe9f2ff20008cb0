// simulate (a scene file or scene text, with the simulate tool's log options) and
// make_dataset (make-dataset's options; on disk or in memory).

#include <pybind11/stl.h>

#include <filesystem>
#include <optional>
#include <utility>

#include "core.h"
#include "datasets/sensor_model.h"
#include "forward_model/simulator.h"
#include "io/dataset_files.h"
#include "io/scene_file.h"
#include "io/simulated_log.h"
#include "pipeline/log_cli_options.h"

namespace slideid::python {
namespace po = boost::program_options;

namespace {

py::dict Summary(const SimulationSummary& s) {
  py::dict d;
  d["steps"] = s.steps;
  d["slide_steps"] = s.slide_steps;
  d["stick_steps"] = s.stick_steps;
  d["rest_time"] = s.rest_time_s >= 0 ? py::object(py::float_(s.rest_time_s)) : py::none();
  d["ecp_margin"] = -s.max_hull_signed_distance_m;
  d["max_step_residual"] = s.max_step_residual;
  d["max_step_iterations"] = s.max_step_iterations;
  return d;
}

/// Simulates the scene of a file (`is_path`) or of INI text named `source`; returns the log
/// (as the simulate tool writes it) and the simulation's summary.
std::pair<LogPtr, py::dict> SimulateScene(const std::string& scene_text, bool is_path,
                                          const std::string& source, std::optional<double> dt,
                                          std::optional<double> duration,
                                          const py::kwargs& keywords) {
  po::options_description log_options;
  cli::AddLogOptions(&log_options, nullptr, /*with_seed=*/true);
  const po::variables_map vm = ParseKeywords("simulate", log_options, keywords);
  LoggedScene scene = is_path ? LoadScene(scene_text) : ParseScene(scene_text, source);
  if (dt) {
    if (!(*dt > 0)) throw po::error("--dt must be > 0");
    scene.dt_s = *dt;
  }
  if (duration) {
    if (!(*duration > 0)) throw po::error("--duration must be > 0");
    scene.duration_s = *duration;
  }
  cli::ApplyLogOptions(vm, &scene.log);
  std::string why;
  if (!scene.log.IsValidFor(!scene.pushes.empty(), &why)) throw po::error(why);
  auto handle = std::make_shared<LogHandle>();
  SimulationSummary summary;
  {
    py::gil_scoped_release release;
    const SimulationResult result = Simulate(scene);
    summary = result.summary;
    if (!summary.ok()) {
      throw NumericalError(std::string(ToString(summary.status)) + ": " + summary.message);
    }
    handle->file = SimulatedLogFile(scene, MakeLog(result.trajectory, scene.log));
  }
  handle->file.log.source =
      is_path ? std::filesystem::path(scene_text).filename().string() : source;
  return {handle, Summary(summary)};
}

/// One log of a dataset, as a row of truth.csv holds it.
py::dict Entry(const DatasetEntry& e) {
  const SliderProperties& s = e.scene.slider;
  const FrictionParameters& f = e.scene.friction.paper();
  const ReducedFriction& r = e.scene.friction.reduced();
  py::dict d;
  d["file"] = e.file;
  d["mass"] = s.mass_kg;
  d["inertia"] = s.inertia_kgm2;
  d["com_height"] = s.com_height_m;
  d["mu"] = f.mu;
  d["e_t"] = f.e_t;
  d["e_o"] = f.e_o;
  d["e_r"] = f.e_r;
  d["e_t_mu"] = r.a;
  d["e_o_over_e_t"] = r.b;
  d["e_r_over_e_t"] = r.c;
  d["noise"] = e.scene.log.noise.Describe();
  d["patch"] = e.scene.patch.Spec();
  d["rows"] = e.rows;
  d["redraw_reasons"] = e.redraw_reasons;
  return d;
}

/// make-dataset's work: with `out`, the files (each entry with its "path"); without, the
/// logs in memory (each entry with its "log").
py::list MakeDatasetEntries(const py::kwargs& keywords) {
  po::options_description options;
  cli::AddDatasetOptions(&options, DatasetSpec{});
  const po::variables_map vm = ParseKeywords("make_dataset", options, keywords);
  const DatasetSpec spec = cli::DatasetSpecFromOptions(vm);
  py::list entries;
  if (vm.count("out")) {
    const std::string dir = vm["out"].as<std::string>();
    DatasetSummary summary;
    try {
      py::gil_scoped_release release;
      summary = MakeDataset(spec, dir);
    } catch (const NoValidDraw& e) {
      throw NumericalError(e.what());
    } catch (const std::runtime_error& e) {
      throw WriteFailure(e.what());
    }
    for (const DatasetEntry& e : summary.entries) {
      py::dict d = Entry(e);
      d["path"] = (std::filesystem::path(dir) / e.file).string();
      entries.append(d);
    }
    return entries;
  }
  for (int i = 0; i < spec.count; ++i) {
    auto handle = std::make_shared<LogHandle>();
    DatasetEntry entry;
    try {
      py::gil_scoped_release release;
      Trajectory log;
      entry = DrawDatasetLog(spec, i, &log);
      handle->file = DatasetLogFile(spec, i, entry, std::move(log));
    } catch (const NoValidDraw& e) {
      throw NumericalError(e.what());
    }
    handle->file.log.source = entry.file;
    py::dict d = Entry(entry);
    d["log"] = handle;
    entries.append(d);
  }
  return entries;
}

}  // namespace

void BindSimulate(py::module_& m) {
  m.def("simulate", &SimulateScene, py::arg("scene"), py::arg("is_path"), py::arg("source"),
        py::arg("dt"), py::arg("duration"));
  m.def("make_dataset", &MakeDatasetEntries);
}

}  // namespace slideid::python
