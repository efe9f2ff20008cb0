#pragma once
// Files that are complete or absent (docs/robustness.md, "What happens when things fail").
// Every file a tool writes goes through here:
//  - WriteFileAtomically: the whole file is written to a unique temporary file in the same
//    directory, flushed and fsync'ed, then renamed over the path. A kill, a full disk or an
//    error at any point leaves the old file (or none) and no temporary behind (but for
//    SIGKILL, which can leave a hidden ".NAME.tmp-XXXXXX" to be deleted).
//  - StagedFile: the same for a file another program writes (gnuplot's PNG).
//  - JsonLinesFile: a stream of lines (identify --batch's results.jsonl) appended one whole
//    line per write(2), fsync'ed at a stated interval: a kill leaves whole lines only, and
//    a failed write (a full disk) is cut back to the last whole line.
// Errors throw FileWriteError naming the file and the system's reason (No space left on
// device, Permission denied, Read-only file system).

#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <string_view>

namespace slideid {

/// A file that could not be written: "cannot write WHAT 'PATH': REASON".
class FileWriteError : public std::runtime_error {
 public:
  FileWriteError(const std::string& path, const std::string& what, const std::string& reason);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// Writes `path` (described as `what`, e.g. "push log") atomically with what `write` puts
/// on the stream. An exception from `write` propagates unchanged (the temporary removed, the
/// path untouched); a failure to create, write, sync or rename throws FileWriteError. A path
/// that is a device, a pipe or a socket (/dev/stdout, a FIFO) is written in place, as the
/// stream it is: no temporary is renamed over it.
void WriteFileAtomically(const std::string& path, const std::string& what,
                         const std::function<void(std::ostream&)>& write);

/// Writes `contents` to `path` atomically (as above).
void WriteFileAtomically(const std::string& path, const std::string& what,
                         std::string_view contents);

/// A unique temporary path in the directory of `path`, for a program that writes the file
/// itself; Commit() syncs it and renames it over `path`. Destroyed uncommitted, the
/// temporary is removed. Throws FileWriteError when the directory is not writable.
class StagedFile {
 public:
  StagedFile(std::string path, std::string what);
  ~StagedFile();
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;
  /// Where the program writes.
  const std::string& temp_path() const { return temp_; }
  /// Syncs the temporary and renames it to the path; throws FileWriteError.
  void Commit();

 private:
  std::string path_, what_, temp_;
  bool committed_ = false;
};

/// How a JsonLinesFile opens and syncs.
struct JsonLinesOptions {
  bool truncate = false;  ///< start empty (else append to what is there)
  /// The most seconds between fsyncs: a line is synced at the first Append after this
  /// long, and always by Sync() and the destructor. 0 syncs every line.
  double fsync_interval_s = 1.0;
  bool IsValid(std::string* why) const;
};

/// An append-only file of lines, each written by one write(2) call.
class JsonLinesFile {
 public:
  /// Opens (creates) `path`; throws FileWriteError.
  JsonLinesFile(const std::string& path, const JsonLinesOptions& options = {});
  ~JsonLinesFile();
  JsonLinesFile(const JsonLinesFile&) = delete;
  JsonLinesFile& operator=(const JsonLinesFile&) = delete;
  /// Appends `line` (no line break in it) and a line break. On a failed write the file is
  /// cut back to its size before, and FileWriteError is thrown. Not thread-safe: one writer.
  void Append(std::string_view line);
  /// fsync now, if a line was appended since the last; throws FileWriteError.
  void Sync();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  JsonLinesOptions options_;
  int fd_ = -1;
  double last_sync_s_ = 0;
  bool unsynced_ = false;
};

}  // namespace slideid
