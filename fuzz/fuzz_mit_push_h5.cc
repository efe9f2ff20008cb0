// libFuzzer target: the MIT push dataset's HDF5 reader on arbitrary bytes (ParseMitPushH5,
// which opens the bytes in memory through HDF5's core driver: the code ReadMitPushH5 runs on
// a file's bytes), then the importer on what it accepts. MitPushH5Error is the expected
// answer to bad input; any other exception, a sanitizer report, an accepted recording that
// does not round-trip exactly through our writer, or an imported log with a non-finite
// number or non-increasing t is a crash. libhdf5 itself is Debian's build, not instrumented:
// a read out of bounds inside it shows only if it faults.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "fuzz/import_invariants.h"
#include "io/mit_push_h5.h"

namespace {

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_mit_push_h5: invariant broken: %s\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  slideid::MitPushRecording r;
  try {
    r = slideid::ParseMitPushH5(bytes, "fuzz.h5");
  } catch (const slideid::MitPushH5Error&) {
    return 0;
  }
  for (const auto* stream : {&r.object_pose, &r.tip_pose, &r.ft_wrench}) {
    Require(!stream->empty(), "an accepted stream has a row");
    for (const slideid::MitStreamRow& row : *stream) {
      for (double v : row) Require(std::isfinite(v), "every accepted number is finite");
    }
  }
  const slideid::MitPushRecording back =
      slideid::ParseMitPushH5(slideid::FormatMitPushH5(r), "roundtrip.h5");
  Require(back.object_pose == r.object_pose && back.tip_pose == r.tip_pose &&
              back.ft_wrench == r.ft_wrench,
          "an accepted recording round-trips exactly");
  slideid::fuzz::CheckImport(r, "fuzz.h5", "fuzz_mit_push_h5");
  return 0;
}
