#include "io/text_lines.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#include <libfccp/csv.h>
#pragma GCC diagnostic pop

namespace slideid {
namespace {

// fccp's LineReader refuses lines of its block length (16 MiB) or more; text in memory is
// held to the same limit, so both sources accept the same texts.
constexpr std::size_t kMaxLineBytes = std::size_t{1} << 24;

/// `line` (its CRLF's CR already removed), or a LogError when a carriage return is left
/// inside it: a file with old Mac line ends (CR only) read as one line, and the error then
/// quoted the whole file as one metadata value (93 KB of message for a 600-row log).
std::string_view WithoutBareCr(const std::string& name, int line_no, std::string_view line) {
  if (line.find('\r') != std::string_view::npos) {
    throw LogError(name, line_no, "",
                   "a carriage return inside the line: the file seems to end its lines with CR "
                   "alone (old Mac line ends); lines must end with LF or CRLF");
  }
  return line;
}

/// What CheckedByteSource has seen. Kept outside it: fccp destroys its byte source as soon
/// as a read reaches the end of a short file.
struct ByteCount {
  long long lines = 0;
  long long bytes = 0;
  bool ends_with_newline = false;
};

/// A byte source that owns its FILE.
class FileByteSource : public io::ByteSourceBase {
 public:
  explicit FileByteSource(std::FILE* file) : file_(file) {}
  ~FileByteSource() override { std::fclose(file_); }
  int read(char* buffer, int size) override {
    const std::size_t n = std::fread(buffer, 1, static_cast<std::size_t>(size), file_);
    if (n == 0 && std::ferror(file_)) {
      throw std::runtime_error(std::string("read error: ") + std::strerror(errno));
    }
    return static_cast<int>(n);
  }

 private:
  std::FILE* file_;
};

/// fccp's byte source, checked: a NUL byte (a binary file, or the zero-filled tail a crash
/// leaves) is an error naming its line, since fccp would silently cut the line short there.
class CheckedByteSource : public io::ByteSourceBase {
 public:
  CheckedByteSource(std::unique_ptr<io::ByteSourceBase> inner, const std::string& path,
                    ByteCount* count)
      : inner_(std::move(inner)), path_(path), count_(count) {}

  int read(char* buffer, int size) override {
    const int n = inner_->read(buffer, size);
    if (n <= 0) return n;
    const char* const begin = buffer;
    const char* const end = buffer + n;
    const char* nul = static_cast<const char*>(std::memchr(begin, '\0', n));
    count_->lines += std::count(begin, nul ? nul : end, '\n');
    if (nul) {
      throw LogError(path_, static_cast<int>(count_->lines + 1), "",
                     "NUL byte at offset " + std::to_string(count_->bytes + (nul - begin)) +
                         ": not a text file (or one cut short by a crash)");
    }
    count_->bytes += n;
    count_->ends_with_newline = end[-1] == '\n';
    return n;
  }

 private:
  std::unique_ptr<io::ByteSourceBase> inner_;
  std::string path_;
  ByteCount* count_;
};

class FileLines : public TextLines {
 public:
  FileLines(const std::string& path, std::FILE* file)
      : TextLines(path),
        reader_(path, std::make_unique<CheckedByteSource>(std::make_unique<FileByteSource>(file),
                                                          path, &count_)) {}

  std::optional<std::string_view> Next() override {
    try {
      const char* line = reader_.next_line();
      if (line == nullptr) return std::nullopt;
      return WithoutBareCr(name(), LineNumber(), line);
    } catch (const LogError&) {
      throw;
    } catch (const io::error::base& e) {  // a line longer than fccp's 16 MiB block
      // fccp counts the line before reading it: LineNumber() is the line it refused.
      throw LogError(name(), LineNumber(), "", e.what());
    } catch (const std::runtime_error& e) {  // a read error on fccp's helper thread
      throw LogError(name(), LineNumber(), "", std::string("cannot read: ") + e.what());
    }
  }
  int LineNumber() const override { return static_cast<int>(reader_.get_file_line()); }
  bool EndsWithLineBreak() const override { return count_.ends_with_newline; }
  bool Empty() const override { return count_.bytes == 0; }

 private:
  ByteCount count_;  // before reader_: the reader's first read writes it
  io::LineReader reader_;
};

class MemoryLines : public TextLines {
 public:
  MemoryLines(std::string_view text, const std::string& name)
      : TextLines(name),
        rest_(text::WithoutByteOrderMark(text)),
        empty_(text.empty()),
        ends_with_newline_(!text.empty() && text.back() == '\n') {}

  std::optional<std::string_view> Next() override {
    if (rest_.empty()) return std::nullopt;
    ++line_;
    const std::size_t end = rest_.find('\n');
    std::string_view line = rest_.substr(0, end);
    rest_.remove_prefix(end == std::string_view::npos ? rest_.size() : end + 1);
    if (line.size() + 1 > kMaxLineBytes) {
      throw LogError(name(), line_, "",
                     "line longer than " + std::to_string(kMaxLineBytes - 1) + " bytes");
    }
    if (line.find('\0') != std::string_view::npos) {
      throw LogError(name(), line_, "", "NUL byte: not a text file (or one cut short by a crash)");
    }
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return WithoutBareCr(name(), line_, line);
  }
  int LineNumber() const override { return line_; }
  bool EndsWithLineBreak() const override { return ends_with_newline_; }
  bool Empty() const override { return empty_; }

 private:
  std::string_view rest_;
  bool empty_;
  bool ends_with_newline_;
  int line_ = 0;
};

}  // namespace

std::unique_ptr<TextLines> TextLines::OpenFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw LogError(path, 0, "", "cannot read: it is a directory, not a file");
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw LogError(path, 0, "", std::string("cannot read: ") + std::strerror(errno));
  }
  try {
    return std::make_unique<FileLines>(path, file);
  } catch (const LogError&) {
    throw;
  } catch (const std::exception& e) {  // the first read happens in the constructor
    throw LogError(path, 0, "", std::string("cannot read: ") + e.what());
  }
}

std::unique_ptr<TextLines> TextLines::FromMemory(std::string_view text, const std::string& name) {
  return std::make_unique<MemoryLines>(text, name);
}

namespace text {

std::string_view WithoutByteOrderMark(std::string_view text) {
  return text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text;
}

std::string_view Trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::string_view Unquote(std::string_view cell) {
  cell = Trim(cell);
  if (cell.size() >= 2 && cell.front() == '"' && cell.back() == '"') {
    cell = Trim(cell.substr(1, cell.size() - 2));
  }
  return cell;
}

void SplitCells(std::string_view line, std::vector<std::string_view>& cells) {
  cells.clear();
  for (;;) {
    const auto comma = line.find(',');
    cells.push_back(Unquote(line.substr(0, comma)));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

std::optional<double> ParseFiniteNumber(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);  // from_chars rejects '+'
  if (s.empty() || s.front() == '+') return std::nullopt;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::optional<long long> ParseCount(std::string_view s, long long max_value) {
  if (s.empty() || s.size() > 18) return std::nullopt;
  long long value = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return std::nullopt;
    value = 10 * value + (c - '0');
  }
  if (value > max_value) return std::nullopt;
  return value;
}

std::string Located(const std::string& file, int line, const std::string& column,
                    const std::string& what) {
  // No line (0): the file as a whole, as "file: what" (a "file:0:" reads as a line number).
  std::string message = line > 0 ? file + ":" + std::to_string(line) + ": " : file + ": ";
  if (!column.empty()) message += "column '" + column + "': ";
  return message + what;
}

bool IsIdentifier(std::string_view s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s.front()))) return false;
  for (char c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  }
  return true;
}

std::string Excerpt(std::string_view s, std::size_t max_chars) {
  if (s.size() <= max_chars) return std::string(s);
  return std::string(s.substr(0, max_chars)) + "...";
}

}  // namespace text
}  // namespace slideid
