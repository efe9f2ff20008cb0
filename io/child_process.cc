#include "io/internal/child_process.h"

#include <poll.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <stdexcept>

namespace slideid::child_process {
namespace {

// The child's first byte says what follows: its answer or its exception's message.
constexpr char kAnswerMark = 'A';
constexpr char kErrorMark = 'E';

void WriteAll(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

[[noreturn]] void AnswerAndExit(int fd, const std::function<std::string()>& work) {
  std::string out;
  try {
    out = kAnswerMark + work();
  } catch (const std::exception& e) {
    out = std::string(1, kErrorMark) + e.what();
  }
  WriteAll(fd, out);
  close(fd);
  _exit(0);
}

/// Everything the child writes until it closes the pipe; false when `limit` passed first.
bool ReadUntilClosed(int fd, std::chrono::milliseconds limit, std::string* bytes) {
  char buffer[1 << 16];
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (true) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) return false;
    if (ready < 0) return true;
    const ssize_t n = read(fd, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;
    bytes->append(buffer, static_cast<std::size_t>(n));
  }
}

}  // namespace

std::chrono::milliseconds TimeLimitFor(std::uint64_t bytes) {
  return std::chrono::milliseconds(30000 + bytes / 10000);
}

Outcome Run(const std::function<std::string()>& work, std::chrono::milliseconds limit) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  std::fflush(nullptr);  // nothing buffered is written twice, by the child too
  const pid_t child = fork();
  if (child < 0) {
    close(fds[0]);
    close(fds[1]);
    throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  }
  if (child == 0) {
    close(fds[0]);
    AnswerAndExit(fds[1], work);
  }
  close(fds[1]);
  std::string bytes;
  const bool finished = ReadUntilClosed(fds[0], limit, &bytes);
  close(fds[0]);
  if (!finished) kill(child, SIGKILL);
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  Outcome out;
  if (!finished) {
    out.ending = Ending::kTimedOut;
  } else if (WIFSIGNALED(status)) {
    out.ending = Ending::kCrashed;
    out.signal = WTERMSIG(status);
  } else if (bytes.empty() || (bytes[0] != kAnswerMark && bytes[0] != kErrorMark)) {
    out.ending = Ending::kSilent;
    out.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  } else {
    out.ending = bytes[0] == kAnswerMark ? Ending::kAnswered : Ending::kThrew;
    out.answer = bytes.substr(1);
  }
  return out;
}

}  // namespace slideid::child_process
