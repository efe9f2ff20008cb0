// libFuzzer target: the tripod-log reader and importer on arbitrary bytes
// (ParseZhouTripodLog, the same code as ReadZhouTripodLog on a file, then
// ImportZhouTripod). LogError is the expected answer to bad text; the importer never throws
// for a log the reader accepted (a push it cannot use is rejected in its report). Any other
// exception, a sanitizer report, an accepted log whose counts or numbers are wrong, a
// non-finite pair, or a report that does not add up is a crash. An accepted log survives a
// write/read round trip unchanged, and the imported pairs survive the wrench-twist CSV.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

#include "io/wrench_twist_csv.h"
#include "io/zhou_tripod_import.h"
#include "io/zhou_tripod_log.h"

namespace {

using namespace slideid;

void Require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_zhou_tripod: invariant broken: %s\n", what);
    std::abort();
  }
}

bool Finite(const TripodPose& p) {
  for (double v : {p.x_mm, p.y_mm, p.z_mm, p.qw, p.qx, p.qy, p.qz}) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

void CheckAccepted(const TripodLog& log) {
  Require(!log.pushes.empty(), "an accepted log has a push");
  for (const TripodPush& push : log.pushes) {
    Require(Finite(push.pre) && Finite(push.post), "poses are finite");
    for (const TripodForceSample& s : push.forces) {
      Require(std::isfinite(s.t_s) && std::isfinite(s.fx_n) && std::isfinite(s.fy_n),
              "force samples are finite");
    }
    for (const TripodRobotSample& s : push.robot) {
      Require(std::isfinite(s.t_s) && Finite(s.pose), "robot samples are finite");
    }
  }
}

void CheckRoundTrip(const TripodLog& log) {
  std::ostringstream out;
  WriteZhouTripodLog(log, out);
  const TripodLog back = ParseZhouTripodLog(out.str(), "fuzz_round_trip.txt");
  Require(back.pushes.size() == log.pushes.size(), "round trip keeps the pushes");
  for (std::size_t p = 0; p < log.pushes.size(); ++p) {
    const TripodPush &a = log.pushes[p], &b = back.pushes[p];
    Require(a.forces.size() == b.forces.size() && a.robot.size() == b.robot.size(),
            "round trip keeps the counts");
    Require(a.pre.x_mm == b.pre.x_mm && a.post.qz == b.post.qz, "round trip keeps the poses");
    for (std::size_t i = 0; i < a.forces.size(); ++i) {
      Require(a.forces[i].t_s == b.forces[i].t_s && a.forces[i].fy_n == b.forces[i].fy_n,
              "round trip keeps the forces");
    }
  }
}

void CheckImport(const TripodLog& log) {
  TripodImportReport report;
  // A folder name with a support layout, to reach that metadata too.
  const WrenchTwistData data =
      ImportZhouTripod(log, "fuzz/10_130_10_10_10_130/fuzz.txt", TripodImportOptions{}, &report);
  Require(report.pushes == static_cast<int>(log.pushes.size()), "every push is reported");
  Require(report.accepted == static_cast<int>(data.rows.size()), "accepted pushes are rows");
  for (const WrenchTwistRow& row : data.rows) {
    const WrenchTwistPair& p = row.pair;
    for (double v : {p.fx, p.fy, p.mz, p.vx, p.vy, p.wz, row.duration_s}) {
      Require(std::isfinite(v), "an imported pair is finite");
    }
    Require(row.duration_s > 0.0, "an imported pair lasts");
  }
  if (data.rows.empty()) return;
  std::ostringstream out;
  WriteWrenchTwistCsv(data, out);
  const WrenchTwistData back = ParseWrenchTwistCsv(out.str(), "fuzz_pairs.csv");
  Require(back.rows.size() == data.rows.size(), "the pairs survive the CSV");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  TripodLog log;
  try {
    log = ParseZhouTripodLog(text, "fuzz.txt");
  } catch (const LogError&) {
    return 0;
  }
  CheckAccepted(log);
  CheckRoundTrip(log);
  CheckImport(log);
  return 0;
}
