#pragma once
// What every reader's fuzz target asks of the importer behind it, on a recording its reader
// accepted: a log exactly when the import accepts, and in that log finite numbers and
// strictly increasing t. A broken invariant aborts, which libFuzzer reports as a crash.

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "io/mit_push_import.h"

namespace slideid::fuzz {

inline void Require(bool ok, const char* target, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "%s: invariant broken: %s\n", target, what);
    std::abort();
  }
}

/// Imports `recording` as an MIT push of rect1's size and checks the invariants above.
inline void CheckImport(const MitPushRecording& recording, const std::string& source,
                        const char* target) {
  MitImportOptions options;
  options.slider = {0.835, 1.13e-3, 0.0065, 9.81};
  options.patch_spec = "rectangle 0.09 0.09";
  const MitImportResult result = ImportMitPush(recording, source, options);
  const bool accepted = result.report.verdict == ImportVerdict::kAccepted;
  Require(accepted == !result.file.log.samples.empty(), target, "a log exactly when accepted");
  for (std::size_t u = 0; u < result.file.log.samples.size(); ++u) {
    const TrajectorySample& s = result.file.log.samples[u];
    for (double v : {s.t_s, s.state.x, s.state.y, s.state.theta, s.applied.fx, s.applied.fy}) {
      Require(std::isfinite(v), target, "every imported number is finite");
    }
    if (u > 0) {
      Require(s.t_s > result.file.log.samples[u - 1].t_s, target, "imported t strictly increases");
    }
  }
}

}  // namespace slideid::fuzz
