#include "pipeline/follow.h"

#include <cmath>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>

#include "estimator/plausibility.h"
#include "io/online_json.h"
#include "io/text_lines.h"

namespace slideid {
namespace {

constexpr double kTwoPi = 6.283185307179586;

// theta as the log reader unwraps it over a file: the branch nearest the previous row's.
double Unwrapped(double theta, double previous) {
  return theta + kTwoPi * std::round((previous - theta) / kTwoPi);
}

// A reader's message without its "source:line: column 'c': " (the row's line in the
// one-row text it parsed is not the stream's).
std::string Unlocated(const LogError& e) {
  const std::string message = e.what();
  std::string prefix = LogError(e.file(), e.line(), e.column(), "").what();
  while (!prefix.empty() && (prefix.back() == ' ' || prefix.back() == ':')) prefix.pop_back();
  if (message.compare(0, prefix.size(), prefix) != 0) return message;
  size_t start = prefix.size();
  while (start < message.size() && (message[start] == ':' || message[start] == ' ')) ++start;
  return message.substr(start);
}

// A warning of the reader on the one-row text at the stream's line `line_number`: its line
// there (after the header's) is not the stream's; the header's own lines are.
std::string AtStreamLine(const std::string& warning, const std::string& source, int header_lines,
                         int line_number) {
  const std::string prefix = source + ":";
  if (warning.compare(0, prefix.size(), prefix) != 0) return warning;
  const size_t colon = warning.find(':', prefix.size());
  if (colon == std::string::npos) return warning;
  const std::string digits = warning.substr(prefix.size(), colon - prefix.size());
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos ||
      std::stoll(digits) <= header_lines) {
    return warning;
  }
  return prefix + std::to_string(line_number) + warning.substr(colon);
}

// What makes two warnings the same over a stream: a row's by its column (each column's
// first absurd row is warned of, as the file's reader does), the header's by its text (it
// is read again with every row).
std::string WarningKey(const std::string& warning) {
  const size_t at = warning.find("column '");
  if (at == std::string::npos) return warning;
  return warning.substr(at, warning.find('\'', at + 8) - at);
}

// The reader's warnings over a stream: each passed on once; the first makes every later
// answer doubtful.
struct StreamWarnings {
  std::set<std::string> seen;
  std::string first;

  void Add(const LogReadReport& report, const std::string& source, int header_lines,
           int line_number, const FollowOptions& options) {
    for (const std::string& w : report.warnings) {
      const std::string located = AtStreamLine(w, source, header_lines, line_number);
      if (!seen.insert(WarningKey(located)).second) continue;
      if (first.empty()) first = located;
      if (options.warn) options.warn(located);
    }
  }

  // `result`'s line, its ok verdicts suspect after a warning.
  std::string Json(const OnlineResult& result) const {
    if (first.empty()) return FormatOnlineJson(result);
    OnlineResult doubted = result;
    const std::string why = "the log reader warned: " + first;
    for (ParameterEstimate& p : doubted.parameters) {
      if (p.verdict == Verdict::kOk) MarkSuspect(&p, why);
    }
    if (doubted.mu_pusher.verdict == Verdict::kOk) MarkSuspect(&doubted.mu_pusher, why);
    return FormatOnlineJson(doubted);
  }
};

}  // namespace

bool FollowOptions::IsValid(std::string* why) const {
  if (every < 1) {
    if (why) *why = "--every must be >= 1";
    return false;
  }
  return online.IsValid(why);
}

FollowSummary FollowLog(std::istream& in, const std::string& source, const FollowOptions& options,
                        const std::function<bool(const std::string&)>& emit) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  LogReadOptions read;
  read.overrides = options.overrides;
  read.max_gap_ratio = 0;  // one row at a time: no median interval to hold a gap against
  read.missing_as_gaps = read.allow_no_rows = options.missing_as_gaps;
  bool gap_before = false;  // a row was dropped since the last one filtered
  std::string header;       // the metadata and the header line, as the reader wants them
  bool have_header = false;
  int header_lines = 0;
  std::string line;
  FollowSummary summary;
  std::unique_ptr<OnlineIdentifier> identifier;
  std::optional<double> previous_theta;
  int line_number = 0;
  const OnlineResult* last = nullptr;  // the last row's answer, and whether it went out
  bool last_emitted = true;
  StreamWarnings warnings;
  while (std::getline(in, line)) {
    ++line_number;
    // A byte-order mark, as a file's reader skips it (docs/log-format.md): left in, it
    // would make the first metadata line the header.
    if (line_number == 1) line = std::string(text::WithoutByteOrderMark(line));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!have_header) {
      // Still in the metadata: comments, blank lines, then the header line.
      header += line + "\n";
      ++header_lines;
      have_header = !line.empty() && line[0] != '#';
      continue;
    }
    if (line.empty()) continue;
    const std::string text = header + line + "\n";
    Trajectory one;
    LogReadReport report;
    try {
      one = ParsePushLog(text, source, read, &report);
    } catch (const LogError& e) {
      if (e.line() <= header_lines) throw;  // about the header: its lines are the stream's
      throw LogError(source, line_number, e.column(), Unlocated(e));
    }
    if (one.samples.empty() && options.missing_as_gaps) {
      ++summary.dropped_rows;
      gap_before = true;
      continue;
    }
    if (one.samples.size() != 1) {
      throw LogError(source, line_number, "", "expected one row on the line");
    }
    warnings.Add(report, source, header_lines, line_number, options);
    TrajectorySample row = one.samples.front();
    // A lone row reads as a run's first; only the mode column can say so here.
    if (!one.measured.mode) row.mode = SampleMode::kSlide;
    // After a dropout the motion starts afresh (no step across the hole), as after a gap.
    if (gap_before && identifier) row.mode = SampleMode::kStart;
    gap_before = false;
    if (previous_theta) row.state.theta = Unwrapped(row.state.theta, *previous_theta);
    previous_theta = row.state.theta;
    if (!identifier) {
      try {
        identifier = std::make_unique<OnlineIdentifier>(one, options.online);
      } catch (const std::invalid_argument& e) {
        throw LogError(source, line_number, "", e.what());
      }
    }
    const OnlineResult* result = nullptr;
    try {
      result = &identifier->Update(row);
    } catch (const std::invalid_argument& e) {
      throw LogError(source, line_number, "", e.what());
    }
    ++summary.rows;
    last = result;
    last_emitted =
        summary.rows % options.every == 0 || result->change_detected || result->change_judged;
    if (last_emitted) {
      ++summary.lines;
      if (!emit(warnings.Json(*result))) {
        summary.reader_gone = true;
        return summary;
      }
    }
  }
  if (!have_header) {
    throw LogError(source, line_number, "", "no header line before the end of the input");
  }
  if (summary.rows == 0) {
    // As a file's reader says it: a logger that stopped after its header identified nothing.
    throw LogError(source, header_lines, "", "the header is not followed by any data row");
  }
  // The stream ended between two lines: the last row's estimate, the final one, still goes.
  if (!last_emitted) {
    ++summary.lines;
    summary.reader_gone = !emit(warnings.Json(*last));
  }
  return summary;
}

}  // namespace slideid
