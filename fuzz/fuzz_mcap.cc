// libFuzzer target: the MCAP reader and the CDR decoder (io/mcap_file.h, io/ros2_cdr.h,
// io/mcap_push.h) on arbitrary bytes. The first byte chooses: 0-3 one CDR decoder on the
// rest (PoseStamped, TransformStamped, TFMessage, WrenchStamped); otherwise the whole input
// is an MCAP file, read as `import-log --format mcap` reads it (topics /object, /tf with
// child frame "tip", /ft), then imported on what it accepts. McapError, RosLogError and
// CdrError are the expected answers to bad input; any other exception, a sanitizer report,
// an accepted stream with a non-finite number, or an imported log with a non-finite number
// or non-increasing t is a crash. Seeds (fuzz/corpus/mcap/) come from our own writer, most
// without CRCs so that mutations reach the records behind them.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "io/mcap_push.h"
#include "io/mit_push_import.h"
#include "io/ros2_cdr.h"

namespace {

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_mcap: invariant broken: %s\n", what);
    std::abort();
  }
}

void Cdr(std::uint8_t which, std::string_view message) {
  try {
    switch (which) {
      case 0:
        slideid::DecodeCdrPoseStamped(message);
        break;
      case 1:
        slideid::DecodeCdrTransformStamped(message);
        break;
      case 2:
        Require(slideid::DecodeCdrTfMessage(message).size() <= message.size() / 72,
                "a TFMessage holds no more transforms than its bytes can");
        break;
      default:
        slideid::DecodeCdrWrenchStamped(message);
        break;
    }
  } catch (const slideid::CdrError&) {
  }
}

void Import(const slideid::MitPushRecording& r) {
  for (const auto* stream : {&r.object_pose, &r.tip_pose, &r.ft_wrench}) {
    Require(!stream->empty(), "an accepted stream has a row");
    for (const slideid::MitStreamRow& row : *stream) {
      for (double v : row) Require(std::isfinite(v), "every accepted number is finite");
    }
  }
  slideid::MitImportOptions options;
  options.slider = {0.835, 1.13e-3, 0.0065, 9.81};
  options.patch_spec = "rectangle 0.09 0.09";
  const slideid::MitImportResult result = slideid::ImportMitPush(r, "fuzz.mcap", options);
  const bool accepted = result.report.verdict == slideid::ImportVerdict::kAccepted;
  Require(accepted == !result.file.log.samples.empty(), "a log exactly when accepted");
  for (std::size_t u = 0; u < result.file.log.samples.size(); ++u) {
    const slideid::TrajectorySample& s = result.file.log.samples[u];
    for (double v :
         {s.t_s, s.state.x, s.state.y, s.state.theta, s.applied.fx, s.applied.fy, s.applied.tz}) {
      Require(std::isfinite(v), "every imported number is finite");
    }
    if (u > 0) Require(s.t_s > result.file.log.samples[u - 1].t_s, "imported t strictly increases");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  if (data[0] < 4) {
    Cdr(data[0], bytes.substr(1));
    return 0;
  }
  slideid::RosTopics topics;
  topics.object_topic = "/object";
  topics.tip_topic = "/tf";
  topics.tip_frame = "tip";
  topics.force_topic = "/ft";
  slideid::RosPushLog log;
  try {
    log = slideid::ParseMcapPushLog(bytes, "fuzz.mcap", topics);
  } catch (const slideid::McapError&) {
    return 0;
  } catch (const slideid::RosLogError&) {
    return 0;
  }
  Import(log.recording);
  return 0;
}
