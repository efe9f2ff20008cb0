#pragma once
// The file of a simulated log: what simulate, make-dataset and the Python module write beyond
// the trajectory (log-format.md). The simulator and the sensor model make physics only; how
// a log was made is said here, as the metadata its file carries.

#include <string>
#include <utility>
#include <vector>

#include "datasets/logged_scene.h"
#include "forward_model/trajectory.h"
#include "io/push_log.h"

namespace slideid {

/// The metadata of `log`, made by MakeLog(Simulate(scene).trajectory, scene.log), in order:
/// the truth's reduced form (e_t_mu, e_o_over_e_t, e_r_over_e_t), dt, the scene's name and
/// the pusher's mu_p; then log_every and log_dt when decimated, log_wrench for the interval
/// mean, and the noise's own (NoiseSpec::Metadata) when there is noise or a defect.
std::vector<std::pair<std::string, std::string>> SimulatedLogMetadata(const LoggedScene& scene,
                                                                      const Trajectory& log);

/// `log` (as above) with that metadata: the file simulate writes.
PushLogFile SimulatedLogFile(const LoggedScene& scene, Trajectory log);

}  // namespace slideid
