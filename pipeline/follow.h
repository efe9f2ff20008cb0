#pragma once
// identify --follow: a push log read from a stream as a logger writes it (metadata and the
// header first, then one row per line), each row given to the online identifier
// (estimator/online_identifier.h) as it comes, and a JSON line (io/online_json.h) handed
// on after every `every` rows.

#include <functional>
#include <istream>
#include <string>

#include "estimator/online_identifier.h"
#include "io/push_log.h"

namespace slideid {

struct FollowOptions {
  OnlineOptions online;
  /// A line after every this many rows, after a row with a change, and after the last row
  /// where the stream ends between two such lines.
  int every = 1;
  SliderOverrides overrides;
  /// Drop a row with an empty or NaN cell (a motion-capture dropout) and start the motion
  /// afresh at the next row (LogReadOptions::missing_as_gaps), instead of failing.
  bool missing_as_gaps = false;
  /// Gets each of the log reader's warnings (LogReadReport::warnings: absurd magnitudes, a
  /// unit error?) once, located at the stream's line; none when empty.
  std::function<void(const std::string&)> warn;
  bool IsValid(std::string* why) const;
};

/// How a follow ended.
struct FollowSummary {
  int rows = 0;              ///< rows read
  int lines = 0;             ///< lines handed on
  int dropped_rows = 0;      ///< rows dropped for a missing cell (missing_as_gaps)
  bool reader_gone = false;  ///< `emit` said the reader went away; the rest was not read
};

/// Reads `in` (named `source` in messages) line by line: `# key = value` metadata and the
/// header (docs/log-format.md), then rows, each parsed as the log reader parses a row of a
/// file. `emit` gets each JSON line (no newline) and returns false when it could not be
/// written (the reader went away): reading stops there. After the reader's first warning
/// every ok verdict handed on is suspect, its reason that warning: a heading of 1e17 rad
/// reads as a slider that never turns, which the file's fit calls not identifiable. Throws LogError
/// for bad input (naming the stream's line), std::invalid_argument for invalid options.
FollowSummary FollowLog(std::istream& in, const std::string& source, const FollowOptions& options,
                        const std::function<bool(const std::string&)>& emit);

}  // namespace slideid
