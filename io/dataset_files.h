#pragma once
// A synthetic dataset on disk: DIR/log_0000.csv, ... (push logs, io/push_log.h) and
// DIR/truth.csv, one row per log with the truth it was made with. The logs are drawn in
// memory by datasets/dataset.h; this writes them.

#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "io/push_log.h"

namespace slideid {

/// What MakeDataset wrote.
struct DatasetSummary {
  std::string directory;
  std::vector<DatasetEntry> entries;
  int redraws = 0;  ///< total over all logs
};

/// Makes the whole dataset in `directory` (created if missing): log_0000.csv, ... and
/// truth.csv. Throws std::runtime_error naming a path that cannot be written (or, with "no
/// valid draw", a log that could not be drawn), std::invalid_argument for an invalid spec.
DatasetSummary MakeDataset(const DatasetSpec& spec, const std::string& directory);

/// Log `index` of the dataset, drawn by DrawDatasetLog, as its file: the simulated log's
/// metadata (io/simulated_log.h), then dataset_seed, dataset_index and redraws.
PushLogFile DatasetLogFile(const DatasetSpec& spec, int index, const DatasetEntry& entry,
                           Trajectory log);

/// The header of truth.csv, and one of its rows (no line break).
std::string TruthCsvHeader();
std::string TruthCsvRow(const DatasetEntry& entry);

}  // namespace slideid
