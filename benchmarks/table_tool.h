#pragma once
// What the benchmark tools that write tables and CSV (coverage, error_vs_time) share: a
// number formatted for a cell, and their main.

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "estimator/ceres_logging.h"

namespace slideid {
namespace bench {

/// `v` formatted by the printf format `fmt`; "-" when it is not finite.
inline std::string Fmt(const char* fmt, double v) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

/// Runs a tool's `main`, printing an exception as "tool: what" and returning 1 for it.
inline int RunTableTool(const char* tool, int (*main)(int, char**), int argc, char** argv) {
  SetCeresLogging();  // the results record how each fit ended
  try {
    return main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", tool, e.what());
    return 1;
  }
}

}  // namespace bench
}  // namespace slideid
