#pragma once
// A reader of untrusted files run in a forked child process. Two third-party libraries
// crash on some damaged files (librosbag reads out of bounds through a bag's index; libhdf5
// copies to a null pointer, found by fuzz_mit_push_h5): in a child, such a crash or a hang
// is an answer the caller reports as an unreadable file, never the tool's own crash.
// Internal to io/ (io/rosbag_push.cc, io/mit_push_h5.cc).

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

namespace slideid::child_process {

/// How a child ended.
enum class Ending {
  kAnswered,  ///< `work` returned: `answer` is what it returned
  kThrew,     ///< `work` threw: `answer` is the exception's message
  kTimedOut,  ///< it was still running at the limit, and was killed
  kCrashed,   ///< a signal ended it (`signal`)
  kSilent,    ///< it exited without answering (`exit_status`)
};

struct Outcome {
  Ending ending = Ending::kSilent;
  std::string answer;
  int signal = 0;        ///< kCrashed
  int exit_status = -1;  ///< kSilent: the exit code, or -1 when unknown
};

/// A limit that only a hang reaches, for a file of `bytes`: 30 s plus 1 s per 10 MB (both
/// libraries read at 100 MB/s or more here).
std::chrono::milliseconds TimeLimitFor(std::uint64_t bytes);

/// Runs `work` in a forked child and returns what it answered, or how it ended without
/// answering within `limit`. The caller holds whatever lock keeps other threads out of the
/// library across the fork. Throws std::runtime_error when no pipe or process can be made.
Outcome Run(const std::function<std::string()>& work, std::chrono::milliseconds limit);

}  // namespace slideid::child_process
