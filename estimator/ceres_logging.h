#pragma once
// Ceres' logging (glog, to stderr), set in one place for every tool, the Python module and
// the benchmarks.

namespace slideid {

/// Ceres logs through glog: a page per residual block that evaluates to NaN at a trial point
/// of a fit, and "Terminating: Residual and Jacobian evaluation failed" (at ERROR, after
/// glog's "Logging before InitGoogleLogging()") where a log's numbers overflow the model.
/// The results say how each fit ended in words, so by default (`quiet`) only what ends the
/// process (FATAL) is logged; not quiet, glog's own default (identify --verbose).
void SetCeresLogging(bool quiet = true);

}  // namespace slideid
