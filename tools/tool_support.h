#pragma once
// What every slideid tool shares: exit codes (documented in the README) and the
// translation of exceptions into messages and codes. Only tools include this.

#include <boost/program_options.hpp>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

namespace slideid::tools {

enum ExitCode : int {
  kExitOk = 0,
  kExitBadInput = 1,   ///< a file (log, scene) is malformed or physically invalid
  kExitUsage = 2,      ///< unknown, missing or conflicting command-line options
  kExitNumerical = 3,  ///< a step or a fit did not converge, or the slider would tip
  kExitIo = 4,         ///< a file could not be read or written
};

/// Runs `body` and maps exceptions to exit codes with a one-line message on stderr.
template <typename Body>
int RunTool(const char* tool, Body body) {
  try {
    return body();
  } catch (const boost::program_options::error& e) {
    std::cerr << tool << ": " << e.what() << " (see " << tool << " --help)\n";
    return kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return kExitBadInput;
  }
}

}  // namespace slideid::tools
