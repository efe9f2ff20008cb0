#pragma once
// The poses a log describes, for the figures that draw its path (plot-log, the HTML report):
// as logged, or integrated from the velocities for a log without pose columns.

#include <vector>

#include "forward_model/planar_state.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// One pose per row: the logged ones, or, without pose columns, integrated from the
/// velocities (backward Euler, from the first row's state, usually 0).
std::vector<PlanarState> LoggedOrIntegratedPoses(const Trajectory& log);

}  // namespace slideid
