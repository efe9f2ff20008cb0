#pragma once
// Batch identification: many logs, each fitted on its own, on a few worker threads, one JSON
// line per log written to a stream as each finishes (JSON Lines), so that memory stays
// bounded however many logs there are. A log that fails gives a line with its error and
// does not stop the batch (its line says why). Shards split the work without shared state: shard i
// of n takes the logs whose index in the sorted list is i modulo n (a Slurm job array, GNU
// parallel).

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "pipeline/identify_files.h"

namespace slideid {

/// Which part of the sorted list a process takes.
struct Shard {
  int index = 0;  ///< 0 <= index < count
  int count = 1;
  /// Parses "I/N" (0 <= I < N); throws std::invalid_argument naming the text.
  static Shard Parse(const std::string& text);
  /// The files of this shard, in order.
  std::vector<std::string> Select(const std::vector<std::string>& sorted_files) const;
};

/// How a batch runs.
struct BatchOptions {
  FileIdentifyOptions identify;  ///< each log on its own (skip_bad does not apply)
  int jobs = 1;                  ///< worker threads, each fitting one log at a time
};

/// Progress as the batch goes: logs done (ok and failed) of the total, and seconds so far.
struct BatchProgress {
  int done = 0, failed = 0, total = 0;
  double seconds = 0;
};

/// Counts at the end.
struct BatchSummary {
  int total = 0, ok = 0, failed = 0;
  double seconds = 0;
  long long rows = 0;  ///< rows of the logs fitted
};

/// Identifies every file on options.jobs threads, writing one line per file to `out` as it
/// finishes (flushed each time; the order is the order of completion), as FormatBatchLine
/// (io/result_json.h) writes it. A file fails when it cannot be read or identified, when it
/// determines no parameter, or when its fit failed numerically (NumericalFailure): the
/// identify tool's exit codes 1 and 3 for one file. `progress`, when set,
/// is called (from one thread at a time) after each file. Throws std::runtime_error if
/// `out` fails.
BatchSummary RunBatch(const std::vector<std::string>& files, const BatchOptions& options,
                      std::ostream& out,
                      const std::function<void(const BatchProgress&)>& progress = {});

}  // namespace slideid
