#pragma once
// The row times of a recorded log: how much they vary, whether the poses follow them, and a
// regular grid for a logger that stamps each row when it arrives.
//
// The model takes each row's time as exact: one backward-Euler step across each interval,
// the row's force held over it. A logger that samples the motion regularly but stamps the
// rows on arrival (a receive time, a busy bus) gives intervals that jitter while the
// poses' steps do not; the fit then reads a short interval's ordinary step as a fast
// motion. On the bundled log, stamps 2-3 ms off at 100 Hz moved a by up to 1% (its
// standard error is 0.15%). Where the rows really were sampled at their times,
// irregularly, the model handles them, and nothing should be changed.

#include <cstddef>
#include <limits>

#include "forward_model/trajectory.h"

namespace slideid {

/// How a log's intervals vary, and whether its poses follow them.
struct RowTimesSpread {
  double median_interval_s = 0;
  /// The intervals' robust relative spread, 1.4826 MAD / median, gaps (runs' starts) left
  /// out: 0 for a regular log, about the jitter's standard deviation over the interval.
  double spread = 0;
  /// The slope of the rows' translation steps, each over its neighbours' median, against
  /// their intervals over the median one, over the rows that move well above the rest
  /// level: about 1 where the rows were sampled at their times, about 0 where the motion
  /// was sampled regularly and only the times jitter. NaN where fewer than
  /// kMinRowTimesMovingRows rows move, or the spread is too small to tell.
  double step_slope = std::numeric_limits<double>::quiet_NaN();
  int moving_rows = 0;  ///< the rows the slope is read from
};

/// Fewest moving rows to read RowTimesSpread::step_slope from.
constexpr int kMinRowTimesMovingRows = 20;
/// Intervals spreading less than this (relative) are regular enough not to matter (a 100 Hz
/// log with 0.5 ms of jitter) and the slope is not read.
constexpr double kRowTimesSpreadToCheck = 0.05;
/// A step slope under this says the times jitter around a regular sampling.
constexpr double kStampedSlope = 0.5;

/// The spread of `log`'s intervals and, where it is kRowTimesSpreadToCheck or more, the
/// slope of its translation steps on them (needs poses; NaN without).
RowTimesSpread MeasureRowTimes(const Trajectory& log);

/// Whether `s` says the rows were sampled regularly and stamped with jitter.
bool TimesLookStampedOnArrival(const RowTimesSpread& s);

/// Puts each run's rows on a regular grid: t = the run's first time + k times its mean
/// interval, so that each run keeps its start and its end (runs: forward_model/
/// trajectory.h). Velocities from poses are not recomputed here (SetVelocitiesFromPoses).
void PutRowsOnRegularTimes(Trajectory* log);

}  // namespace slideid
