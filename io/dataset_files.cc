#include "io/dataset_files.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "forward_model/number_format.h"
#include "io/atomic_file.h"
#include "io/push_log.h"
#include "io/simulated_log.h"

namespace slideid {
std::string TruthCsvHeader() {
  return "file,mass,inertia,com_height,mu,e_t,e_o,e_r,a,b,c,noise,patch,rows,redraws,mu_p";
}

std::string TruthCsvRow(const DatasetEntry& e) {
  const SliderProperties& s = e.scene.slider;
  const FrictionParameters& f = e.scene.friction.paper();
  const ReducedFriction& r = e.scene.friction.reduced();
  std::string row = e.file;
  for (double v :
       {s.mass_kg, s.inertia_kgm2, s.com_height_m, f.mu, f.e_t, f.e_o, f.e_r, r.a, r.b, r.c}) {
    row += "," + ExactNumber(v);
  }
  // mu_p: the tip-edge friction of a pusher-driven log; empty for a force-driven one.
  return row + "," + e.scene.log.noise.Describe() + "," + e.scene.patch.Spec() + "," +
         std::to_string(e.rows) + "," + std::to_string(e.redraw_reasons.size()) + "," +
         (e.scene.pusher ? ExactNumber(e.scene.pusher->mu) : std::string());
}

PushLogFile DatasetLogFile(const DatasetSpec& spec, int index, const DatasetEntry& entry,
                           Trajectory log) {
  PushLogFile file = SimulatedLogFile(entry.scene, std::move(log));
  file.extra_metadata.emplace_back("dataset_seed", std::to_string(spec.seed));
  file.extra_metadata.emplace_back("dataset_index", std::to_string(index));
  file.extra_metadata.emplace_back("redraws", std::to_string(entry.redraw_reasons.size()));
  return file;
}

DatasetSummary MakeDataset(const DatasetSpec& spec, const std::string& directory) {
  std::string why;
  if (!spec.IsValid(&why)) throw std::invalid_argument("dataset: " + why);
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec || !std::filesystem::is_directory(directory)) {
    throw std::runtime_error(directory + ": cannot create the dataset directory" +
                             (ec ? ": " + ec.message() : ""));
  }
  DatasetSummary summary;
  summary.directory = directory;
  std::string truth = TruthCsvHeader() + "\n";
  for (int i = 0; i < spec.count; ++i) {
    Trajectory log;
    DatasetEntry entry = DrawDatasetLog(spec, i, &log);
    WritePushLog(DatasetLogFile(spec, i, entry, std::move(log)), directory + "/" + entry.file);
    truth += TruthCsvRow(entry) + "\n";
    summary.redraws += static_cast<int>(entry.redraw_reasons.size());
    summary.entries.push_back(std::move(entry));
  }
  WriteFileAtomically(directory + "/truth.csv", "the truth manifest", truth);
  return summary;
}

}  // namespace slideid
