#pragma once
// What every slideid tool shares: exit codes (documented in the README and in
// docs/robustness.md) and the translation of exceptions into messages and codes. Only tools
// include this.

#include <boost/program_options.hpp>
#include <exception>
#include <iostream>
#include <new>
#include <stdexcept>
#include <string>

#include "estimator/ceres_logging.h"
#include "forward_model/constants.h"
#include "forward_model/number_format.h"

namespace slideid::tools {

enum ExitCode : int {
  kExitOk = 0,
  kExitBadInput = 1,   ///< a file (log, scene) is malformed or physically invalid
  kExitUsage = 2,      ///< unknown, missing, invalid or conflicting command-line options
  kExitNumerical = 3,  ///< a step or a fit did not converge, or the slider would tip
  kExitIo = 4,         ///< a file could not be written
  /// identify --batch stopped by a signal after writing its last whole line: 128 + the
  /// signal's number (130 SIGINT, 143 SIGTERM), as a shell reports a process the signal
  /// ended; --resume finishes the batch.
  kExitInterruptedBase = 128,
};

/// Bad input found by a tool itself (for example a log the estimators cannot use); the
/// message names the file. Maps to kExitBadInput.
class BadInput : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `value` with `digits` decimals, for the tools' tables.
inline std::string Fixed(double value, int digits) { return Printf("%.*f", digits, value); }

/// Flushes standard output; a failed write (a full disk, a closed pipe) is kExitIo.
inline int FlushStdout(const char* tool) {
  std::cout.flush();
  if (!std::cout) {
    std::cerr << tool << ": error: cannot write to standard output\n";
    return kExitIo;
  }
  return kExitOk;
}

/// Runs `body` and maps exceptions to exit codes with a one-line message on stderr:
/// option errors are usage (2); every other error (LogError, SceneError, BadInput, ... all
/// name their file) is bad input (1). Numerical failures are statuses that `body` maps to
/// kExitNumerical itself, never exceptions.
template <typename Body>
int RunTool(const char* tool, Body body) {
  SetCeresLogging();  // every tool quiet; identify --verbose asks for Ceres' own lines
  try {
    return body();
  } catch (const boost::program_options::error& e) {
    std::cerr << tool << ": usage: " << e.what() << " (see " << tool << " --help)\n";
    return kExitUsage;
  } catch (const std::bad_alloc&) {
    std::cerr << tool << ": error: out of memory (is the input far larger than intended?)\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (...) {
    std::cerr << tool << ": error: unexpected exception of unknown type\n";
    return kExitBadInput;
  }
}

}  // namespace slideid::tools
