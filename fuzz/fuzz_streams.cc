// libFuzzer target: the per-stream CSV reader (io/push_streams_csv.h) with its mappings. An
// input is three lines, the --pose, --tip and --force option texts, then the three files'
// texts separated by form feeds ('\f'). std::invalid_argument (a bad mapping) and LogError
// (a bad file) are the expected answers to bad input; any other exception, a sanitizer
// report, a non-finite accepted number, or (world frame, yaw columns) an accepted recording
// that does not round-trip exactly through the writer is a crash. The import runs on what
// is accepted, as import-log would.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "io/mit_push_import.h"
#include "io/push_log.h"
#include "io/push_streams_csv.h"

namespace {

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_streams: invariant broken: %s\n", what);
    std::abort();
  }
}

/// The next line of `in` (consumed), without its line break.
std::string_view Line(std::string_view* in) {
  const std::size_t end = in->find('\n');
  const std::string_view line = in->substr(0, end);
  in->remove_prefix(end == std::string_view::npos ? in->size() : end + 1);
  return line;
}

std::string_view Part(std::string_view* in) {
  const std::size_t end = in->find('\f');
  const std::string_view part = in->substr(0, end);
  in->remove_prefix(end == std::string_view::npos ? in->size() : end + 1);
  return part;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view in(reinterpret_cast<const char*>(data), size);
  using slideid::PushStream;
  slideid::PushStreamsCsv files;
  try {
    files.pose = slideid::ParseStreamMapping(PushStream::kPose, "--pose", std::string(Line(&in)));
    files.tip = slideid::ParseStreamMapping(PushStream::kTip, "--tip", std::string(Line(&in)));
    files.force =
        slideid::ParseStreamMapping(PushStream::kForce, "--force", std::string(Line(&in)));
  } catch (const std::invalid_argument&) {
    return 0;
  }
  const std::string_view pose = Part(&in), tip = Part(&in), force = Part(&in);
  slideid::PushStreamsRead read;
  try {
    read = slideid::ParsePushStreamsCsv(files, pose, tip, force);
  } catch (const slideid::LogError&) {
    return 0;
  }
  const slideid::MitPushRecording& r = read.recording;
  for (const auto* stream : {&r.object_pose, &r.tip_pose, &r.ft_wrench}) {
    Require(!stream->empty(), "an accepted stream has a row");
    for (const slideid::MitStreamRow& row : *stream) {
      for (double v : row) Require(std::isfinite(v), "every accepted number is finite");
    }
  }
  if (!files.force.sensor_frame && !files.pose.Quaternion() && !files.tip.Quaternion()) {
    const slideid::PushStreamsRead back = slideid::ParsePushStreamsCsv(
        files, slideid::FormatPushStreamCsv(r, files.pose),
        slideid::FormatPushStreamCsv(r, files.tip), slideid::FormatPushStreamCsv(r, files.force));
    // The tip's yaw and the force's tz are 0 when not mapped: compare what was read.
    Require(back.recording.object_pose == r.object_pose && back.recording.tip_pose == r.tip_pose &&
                back.recording.ft_wrench == r.ft_wrench,
            "an accepted recording round-trips exactly");
  }
  slideid::MitImportOptions options;
  options.slider = {0.835, 1.13e-3, 0.0065, 9.81};
  options.patch_spec = "rectangle 0.09 0.09";
  const slideid::MitImportResult result = slideid::ImportMitPush(r, "fuzz.csv", options);
  const bool accepted = result.report.verdict == slideid::ImportVerdict::kAccepted;
  Require(accepted == !result.file.log.samples.empty(), "a log exactly when accepted");
  for (std::size_t u = 1; u < result.file.log.samples.size(); ++u) {
    Require(result.file.log.samples[u].t_s > result.file.log.samples[u - 1].t_s,
            "imported t strictly increases");
  }
  return 0;
}
