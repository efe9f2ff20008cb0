// libFuzzer target: the ROS 1 bag reader (ReadRosbagPushLog) on arbitrary bytes, then the
// importer on what it accepts. librosbag opens bags by file name only, so each input is
// written to a temporary file first; and it crashes inside itself on some damaged bags, so
// the reader runs it in a child process (io/internal/child_process.h): its crash or hang is
// a RosLogError, the expected answer to bad input, as is any RosLogError. Any other
// exception, a sanitizer report in this process, or an imported log with a non-finite number
// or non-increasing t is a crash. librosbag is Debian's build, not instrumented, and runs in
// the child: this target checks our side of the fork (answers, limits, the importer), about
// 100 inputs/s.

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz/import_invariants.h"
#include "io/rosbag_push.h"

namespace {

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_rosbag: invariant broken: %s\n", what);
    std::abort();
  }
}

/// The topics make_import_corpus writes the seeds' streams on.
slideid::RosTopics Topics() {
  slideid::RosTopics t;
  t.object_topic = "/vicon/object";
  t.tip_topic = "/tip_pose";
  t.force_topic = "/netft/wrench";
  return t;
}

/// A file of this process's own, written once per input.
const std::string& InputPath() {
  static const std::string path = [] {
    char name[] = "/tmp/fuzz_rosbag_XXXXXX";
    const int fd = mkstemp(name);
    Require(fd >= 0, "a temporary file can be made");
    close(fd);
    return std::string(name);
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& path = InputPath();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  Require(f != nullptr, "the input file can be written");
  Require(std::fwrite(data, 1, size, f) == size, "the input is written whole");
  std::fclose(f);
  slideid::RosPushLog read;
  try {
    read = slideid::ReadRosbagPushLog(path, Topics());
  } catch (const slideid::RosLogError&) {
    return 0;
  }
  slideid::fuzz::CheckImport(read.recording, "fuzz.bag", "fuzz_rosbag");
  return 0;
}
