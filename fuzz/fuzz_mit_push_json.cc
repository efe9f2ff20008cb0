// libFuzzer target: the MIT push-dataset JSON reader on arbitrary bytes (ParseMitPushJson,
// the same code as ReadMitPushJson on a file), then the importer on what it accepts.
// MitPushError is the expected answer to bad input; any other exception, a sanitizer
// report, an accepted recording that does not round-trip exactly, or an imported log with a
// non-finite number or non-increasing t is a crash.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "io/mit_push_import.h"
#include "io/mit_push_json.h"

namespace {

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_mit_push_json: invariant broken: %s\n", what);
    std::abort();
  }
}

void CheckRecording(const slideid::MitPushRecording& r) {
  for (const auto* stream : {&r.object_pose, &r.tip_pose, &r.ft_wrench}) {
    Require(!stream->empty(), "an accepted stream has a row");
    for (const slideid::MitStreamRow& row : *stream) {
      for (double v : row) Require(std::isfinite(v), "every accepted number is finite");
    }
  }
  const slideid::MitPushRecording back =
      slideid::ParseMitPushJson(slideid::FormatMitPushJson(r), "roundtrip.json");
  Require(back.object_pose == r.object_pose && back.tip_pose == r.tip_pose &&
              back.ft_wrench == r.ft_wrench,
          "an accepted recording round-trips exactly");
}

void CheckImport(const slideid::MitPushRecording& r) {
  slideid::MitImportOptions options;
  options.slider = {0.835, 1.13e-3, 0.0065, 9.81};
  options.patch_spec = "rectangle 0.09 0.09";
  const slideid::MitImportResult result = slideid::ImportMitPush(r, "fuzz.json", options);
  const bool accepted = result.report.verdict == slideid::ImportVerdict::kAccepted;
  Require(accepted == !result.file.log.samples.empty(), "a log exactly when accepted");
  Require(accepted == result.report.reason.empty(), "a reason exactly when rejected");
  for (std::size_t u = 0; u < result.file.log.samples.size(); ++u) {
    const slideid::TrajectorySample& s = result.file.log.samples[u];
    const double values[] = {s.t_s,
                             s.state.x,
                             s.state.y,
                             s.state.theta,
                             s.applied.fx,
                             s.applied.fy,
                             s.applied.tz,
                             s.push_point_world->x(),
                             s.push_point_world->y()};
    for (double v : values) Require(std::isfinite(v), "every imported number is finite");
    if (u > 0) Require(s.t_s > result.file.log.samples[u - 1].t_s, "imported t strictly increases");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  slideid::MitPushRecording recording;
  try {
    recording = slideid::ParseMitPushJson(text, "fuzz.json");
  } catch (const slideid::MitPushError&) {
    return 0;
  }
  CheckRecording(recording);
  CheckImport(recording);
  return 0;
}
