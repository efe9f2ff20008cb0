// libFuzzer target: the push-log reader on arbitrary bytes (ParsePushLog, the same code as
// ReadPushLog on a file). LogError and std::invalid_argument are the expected answers to
// bad input; any other exception, a sanitizer report, or a log accepted with a non-finite
// number or non-increasing t is a crash. An accepted log with known slider properties must
// survive a write/read round trip unchanged in its times and poses.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "io/push_log.h"

namespace {

using slideid::TrajectorySample;

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_push_log: invariant broken: %s\n", what);
    std::abort();
  }
}

bool Finite(const TrajectorySample& s) {
  const double values[] = {s.t_s,        s.state.x,    s.state.y,    s.state.theta, s.state.vx,
                           s.state.vy,   s.state.wz,   s.applied.fx, s.applied.fy,  s.applied.fz,
                           s.applied.tx, s.applied.ty, s.applied.tz};
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

void CheckAccepted(const slideid::Trajectory& log) {
  Require(!log.samples.empty(), "an accepted log has a row");
  for (std::size_t u = 0; u < log.samples.size(); ++u) {
    Require(Finite(log.samples[u]), "every number of an accepted log is finite");
    if (u > 0) Require(log.samples[u].t_s > log.samples[u - 1].t_s, "t strictly increases");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  slideid::LogReadOptions options;
  // Half the inputs without the slider-properties requirement, to reach the rows more often.
  options.require_slider_properties = size % 2 == 0;
  slideid::PushLogFile file;
  try {
    slideid::LogReadReport report;
    file = slideid::ParsePushLogFile(text, "fuzz.csv", options, &report);
  } catch (const slideid::LogError&) {
    return 0;
  } catch (const std::invalid_argument&) {
    return 0;
  }
  const slideid::Trajectory& log = file.log;
  CheckAccepted(log);
  // Round trip only when the slider is known: the writer always writes mass, inertia and
  // com_height, so an unknown mass would come back as SliderProperties' default.
  if (!options.require_slider_properties) return 0;

  std::ostringstream out;
  try {
    slideid::WritePushLog(file, out);
  } catch (const std::invalid_argument&) {
    return 0;  // metadata the writer refuses (documented), not a reader bug
  }
  const std::string written = out.str();
  slideid::LogReadOptions again;
  again.max_gap_ratio = 0.0;  // the gaps were judged on the first read
  const slideid::Trajectory back = slideid::ParsePushLog(written, "fuzz_round_trip.csv", again);
  Require(back.samples.size() == log.samples.size(), "round trip keeps the rows");
  for (std::size_t u = 0; u < log.samples.size(); ++u) {
    Require(back.samples[u].t_s == log.samples[u].t_s, "round trip keeps t");
    Require(back.samples[u].state.x == log.samples[u].state.x, "round trip keeps x");
  }
  return 0;
}
