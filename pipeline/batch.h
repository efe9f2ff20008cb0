#pragma once
// Batch identification: many logs, each fitted on its own, on a few worker threads, one JSON
// line per log written to a stream as each finishes (JSON Lines), so that memory stays
// bounded however many logs there are. A log that fails gives a line with its error and
// does not stop the batch (its line says why). Shards split the work without shared state: shard i
// of n takes the logs whose index in the sorted list is i modulo n (a Slurm job array, GNU
// parallel).
//
// Written to a file (RunBatchToFile), each line is appended by one write(2) and the file is
// fsync'ed at least once a second (io/atomic_file.h): a killed batch leaves whole lines
// only. Resumed, a batch skips the logs its results file already holds (known by path and
// SHA-256, so a changed log is fitted again) and drops a torn last line with a warning
// (docs/robustness.md, "What happens when things fail").

#include <atomic>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "io/result_json.h"
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
  /// When it turns true (a signal handler sets it), no further log is started: the fits
  /// in progress finish and their lines are written. Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
};

/// Progress as the batch goes: logs done (ok and failed) of the total, and seconds so far.
struct BatchProgress {
  int done = 0, failed = 0, total = 0;
  double seconds = 0;
};

/// Counts at the end.
struct BatchSummary {
  int total = 0, ok = 0, failed = 0;  ///< ok and failed include the logs skipped
  int skipped = 0;                    ///< already in the results (resume), not fitted again
  bool interrupted = false;           ///< options.stop ended the batch before every log
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

/// As above, each line (without its line break) handed to `write_line`, one at a time; an
/// exception from it stops the batch (after the fits in progress) and is rethrown.
BatchSummary RunBatch(const std::vector<std::string>& files, const BatchOptions& options,
                      const std::function<void(const std::string& line)>& write_line,
                      const std::function<void(const BatchProgress&)>& progress = {});

/// What a results file already holds, for a resumed batch.
struct BatchResults {
  std::vector<std::string> lines;     ///< the whole lines kept, in order
  std::vector<BatchLineKey> keys;     ///< the key of each kept line
  std::vector<std::string> warnings;  ///< what was dropped and why (naming file and line)
  bool dropped = false;               ///< a line was dropped: the file must be rewritten
};

/// Reads the results file `path` (none: empty) of a batch over `files`. Drops, with a
/// warning naming the line: a torn last line (no line break: a kill or a full disk cut it),
/// a line that is not a batch result, a second line for a file, and the line of a file in
/// `files` whose SHA-256 differs from the file's now (changed since, or unreadable then).
/// Lines of files not in `files` are kept. Throws std::runtime_error if `path` cannot be read.
BatchResults ReadBatchResults(const std::string& path, const std::vector<std::string>& files);

/// How a batch writes its results file.
struct BatchFileOptions {
  bool resume = false;            ///< keep the results there and fit only the logs they lack
  double fsync_interval_s = 1.0;  ///< the most seconds between fsyncs of the file
};

/// RunBatch into the JSON Lines file `path` (created or emptied, or with `file_options.resume`
/// read by ReadBatchResults, rewritten atomically if a line was dropped, and appended to).
/// Warnings of the resume go to `warnings`. Throws FileWriteError (io/atomic_file.h) naming
/// the file when it cannot be written: the lines written before are left whole.
BatchSummary RunBatchToFile(const std::vector<std::string>& files, const BatchOptions& options,
                            const std::string& path, const BatchFileOptions& file_options,
                            std::vector<std::string>* warnings,
                            const std::function<void(const BatchProgress&)>& progress = {});

}  // namespace slideid
