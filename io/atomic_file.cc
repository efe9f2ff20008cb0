#include "io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ostream>
#include <streambuf>
#include <vector>

namespace slideid {
namespace {

/// The system's reason for errno `error`.
std::string Reason(int error) { return error == 0 ? "write failed" : std::strerror(error); }

/// "DIR/.NAME.tmp-XXXXXX" for `path`: hidden, in the same directory (so that rename is
/// atomic: same file system), unique (mkstemp).
std::string TempPattern(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  return dir + "." + name + ".tmp-XXXXXX";
}

/// The path exists and is a device, a pipe or a socket (/dev/stdout, a FIFO): a stream,
/// which no temporary may be renamed over (that would put a regular file in its place, as
/// root even in /dev), and which has no half-written state to keep a reader from.
bool IsStream(const std::string& path) {
  struct stat target;
  return ::stat(path.c_str(), &target) == 0 && !S_ISREG(target.st_mode) && !S_ISDIR(target.st_mode);
}

/// Creates the temporary of `path`; returns its descriptor, `temp` set to its name.
int CreateTemp(const std::string& path, const std::string& what, std::string* temp) {
  if (IsStream(path)) {
    throw FileWriteError(path, what,
                         "not a regular file (a device, a pipe or a socket), which writing "
                         "the file would replace: give the path of a file");
  }
  *temp = TempPattern(path);
  const int fd = mkstemp(temp->data());
  if (fd < 0) {
    throw FileWriteError(path, what, Reason(errno) + " (creating a temporary file beside it)");
  }
  // mkstemp makes the file 0600; a written file gets the usual 0666 less the umask.
  const mode_t mask = umask(0);
  umask(mask);
  fchmod(fd, 0666 & ~mask);
  return fd;
}

/// write(2) of all of `data`, restarting after signals and short writes; errno on failure.
int WriteAll(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    data += n;
    size -= static_cast<size_t>(n);
  }
  return 0;
}

/// A stream buffer over a file descriptor that remembers the first write error.
class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd), buffer_(1 << 16) { Reset(); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (Drain() != 0) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return Drain() == 0 ? 0 : -1; }

 private:
  void Reset() { setp(buffer_.data(), buffer_.data() + buffer_.size()); }
  int Drain() {
    if (error_ == 0) error_ = WriteAll(fd_, pbase(), static_cast<size_t>(pptr() - pbase()));
    Reset();
    return error_;
  }
  int fd_;
  std::vector<char> buffer_;
  int error_ = 0;
};

/// fsync, then rename `temp` over `path`; throws FileWriteError (the temporary is the
/// caller's to remove).
void SyncAndRename(int fd, const std::string& temp, const std::string& path,
                   const std::string& what) {
  if (fsync(fd) != 0) throw FileWriteError(path, what, Reason(errno));
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    throw FileWriteError(path, what, Reason(errno) + " (renaming its temporary into place)");
  }
}

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

FileWriteError::FileWriteError(const std::string& path, const std::string& what,
                               const std::string& reason)
    : std::runtime_error("cannot write " + what + " '" + path + "': " + reason), path_(path) {}

void WriteFileAtomically(const std::string& path, const std::string& what,
                         const std::function<void(std::ostream&)>& write) {
  const bool stream = IsStream(path);  // written in place: `--out /dev/stdout | ...`
  std::string temp;
  const int fd =
      stream ? ::open(path.c_str(), O_WRONLY | O_CLOEXEC) : CreateTemp(path, what, &temp);
  if (fd < 0) throw FileWriteError(path, what, Reason(errno));
  try {
    FdBuf buffer(fd);
    std::ostream out(&buffer);
    write(out);
    out.flush();
    if (buffer.error() != 0 || !out) throw FileWriteError(path, what, Reason(buffer.error()));
    if (!stream) SyncAndRename(fd, temp, path, what);
  } catch (...) {
    ::close(fd);
    if (!stream) std::remove(temp.c_str());
    throw;
  }
  ::close(fd);
}

void WriteFileAtomically(const std::string& path, const std::string& what,
                         std::string_view contents) {
  WriteFileAtomically(path, what, [&](std::ostream& out) { out << contents; });
}

StagedFile::StagedFile(std::string path, std::string what)
    : path_(std::move(path)), what_(std::move(what)) {
  ::close(CreateTemp(path_, what_, &temp_));
}

StagedFile::~StagedFile() {
  if (!committed_) std::remove(temp_.c_str());
}

void StagedFile::Commit() {
  const int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw FileWriteError(path_, what_, Reason(errno));
  try {
    SyncAndRename(fd, temp_, path_, what_);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  committed_ = true;
}

bool JsonLinesOptions::IsValid(std::string* why) const {
  if (!(fsync_interval_s >= 0)) {
    if (why) *why = "the fsync interval must be at least 0 s";
    return false;
  }
  return true;
}

JsonLinesFile::JsonLinesFile(const std::string& path, const JsonLinesOptions& options)
    : path_(path), options_(options), last_sync_s_(NowSeconds()) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument(why);
  const int flags = O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | (options.truncate ? O_TRUNC : 0);
  fd_ = ::open(path.c_str(), flags, 0666);
  if (fd_ < 0) throw FileWriteError(path, "the results", Reason(errno));
}

JsonLinesFile::~JsonLinesFile() {
  if (fd_ < 0) return;
  if (unsynced_) fsync(fd_);
  ::close(fd_);
}

void JsonLinesFile::Append(std::string_view line) {
  std::string whole;
  whole.reserve(line.size() + 1);
  whole.append(line).push_back('\n');
  struct stat before;
  if (fstat(fd_, &before) != 0) throw FileWriteError(path_, "the results", Reason(errno));
  if (const int error = WriteAll(fd_, whole.data(), whole.size()); error != 0) {
    // Part of the line may be on disk: cut it off, so that the file ends with a whole line.
    if (ftruncate(fd_, before.st_size) != 0) {
      throw FileWriteError(path_, "the results",
                           Reason(error) + "; a partial last line is left (" + Reason(errno) +
                               " cutting it off): --resume drops it");
    }
    throw FileWriteError(path_, "the results", Reason(error));
  }
  unsynced_ = true;
  if (NowSeconds() - last_sync_s_ >= options_.fsync_interval_s) Sync();
}

void JsonLinesFile::Sync() {
  if (!unsynced_) return;  // nothing written since the last sync
  if (fsync(fd_) != 0) throw FileWriteError(path_, "the results", Reason(errno));
  unsynced_ = false;
  last_sync_s_ = NowSeconds();
}

}  // namespace slideid
