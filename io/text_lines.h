#pragma once
// The lines of a text file or of text in memory, for the readers in io/. Files are read by
// fast-cpp-csv-parser's LineReader; text in memory (fuzzing, tests) by a splitter with the
// same rules. Both number lines from 1, drop the line break ("\n" or "\r\n"), skip a UTF-8
// BOM, and refuse NUL bytes and lines of 16 MiB or more with a LogError naming the line.
// Also the text helpers the readers share: trimming, whole-cell numbers, message forms.

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

// LogError (file, line, column) is the error of every reader of a file.
#include "io/push_log.h"

namespace slideid {

/// A source of numbered lines.
class TextLines {
 public:
  virtual ~TextLines() = default;
  /// The next line without its line break, or nullopt at the end. Throws LogError.
  virtual std::optional<std::string_view> Next() = 0;
  /// The number of the line Next returned last (1-based; 0 before the first).
  virtual int LineNumber() const = 0;
  /// Whether the text so far ends with a line break (a file cut short does not).
  virtual bool EndsWithLineBreak() const = 0;
  /// Whether the text is empty (known once Next has returned nullopt).
  virtual bool Empty() const = 0;
  /// The name used in messages.
  const std::string& name() const { return name_; }

  /// Opens `path`; throws LogError (line 0) if it is a directory or cannot be opened.
  static std::unique_ptr<TextLines> OpenFile(const std::string& path);
  /// Lines of `text` (which must outlive the reader); `name` names it in messages.
  static std::unique_ptr<TextLines> FromMemory(std::string_view text, const std::string& name);

 protected:
  explicit TextLines(std::string name) : name_(std::move(name)) {}

 private:
  std::string name_;
};

namespace text {

/// `s` without leading and trailing blanks (space, tab, CR).
std::string_view Trim(std::string_view s);

/// `text` without a leading UTF-8 byte-order mark (as Windows editors write one): what every
/// reader of a text skips before its first line (docs/log-format.md).
std::string_view WithoutByteOrderMark(std::string_view text);

/// A cell without surrounding blanks and without one pair of enclosing double quotes
/// (spreadsheets quote text cells, such as a header's names).
std::string_view Unquote(std::string_view cell);

/// Splits a CSV `line` at commas into unquoted cells (`cells` is cleared first, and reused
/// to spare allocations).
void SplitCells(std::string_view line, std::vector<std::string_view>& cells);

/// Whole-cell parse of a finite number, locale independent: "nan", "inf", "1.2abc", "" and
/// out-of-range values are all rejected (nullopt). A leading '+' is accepted.
std::optional<double> ParseFiniteNumber(std::string_view s);

/// Whole-cell parse of a count: decimal digits only, at most `max_value`.
std::optional<long long> ParseCount(std::string_view s, long long max_value);

/// "file:line: column 'c': what" (the column part only when `column` is not empty; "file:
/// what" when `line` is 0, a message about the file as a whole).
std::string Located(const std::string& file, int line, const std::string& column,
                    const std::string& what);

/// Whether `s` is an identifier: a letter or '_' first, then letters, digits or '_'.
bool IsIdentifier(std::string_view s);

/// At most `max_chars` of `s`, with "..." when cut (bad cells quoted in messages).
std::string Excerpt(std::string_view s, std::size_t max_chars = 40);

}  // namespace text
}  // namespace slideid
