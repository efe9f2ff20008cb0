#include "pipeline/follow.h"

#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>

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
  std::string header;      // the metadata and the header line, as the reader wants them
  bool have_header = false;
  int header_lines = 0;
  std::string line;
  FollowSummary summary;
  std::unique_ptr<OnlineIdentifier> identifier;
  std::optional<double> previous_theta;
  int line_number = 0;
  const OnlineResult* last = nullptr;  // the last row's answer, and whether it went out
  bool last_emitted = true;
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
    try {
      one = ParsePushLog(text, source, read);
    } catch (const LogError& e) {
      if (e.line() <= header_lines) throw;  // about the header: its lines are the stream's
      throw LogError(source, line_number, e.column(), Unlocated(e));
    }
    if (one.samples.size() != 1) {
      throw LogError(source, line_number, "", "expected one row on the line");
    }
    TrajectorySample row = one.samples.front();
    // A lone row reads as a run's first; only the mode column can say so here.
    if (!one.measured.mode) row.mode = SampleMode::kSlide;
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
    last_emitted = summary.rows % options.every == 0 || result->change_detected;
    if (last_emitted) {
      ++summary.lines;
      if (!emit(FormatOnlineJson(*result))) {
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
    summary.reader_gone = !emit(FormatOnlineJson(*last));
  }
  return summary;
}

}  // namespace slideid
