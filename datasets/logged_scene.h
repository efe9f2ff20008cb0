#pragma once
// A scene and how its simulated trajectory is logged: what a scene file describes (its
// physics plus [sim] log_every, [log] and [noise]; io/scene_file.h) and what a dataset draws
// for each log (datasets/dataset.h). The physics alone is forward_model's Scene, which a
// LoggedScene is: pass it to Simulate as it is, then its log spec to MakeLog.

#include "datasets/log_spec.h"
#include "forward_model/scene.h"

namespace slideid {

/// A Scene plus the sampling, columns and noise of its log.
struct LoggedScene : Scene {
  LogSpec log;  ///< applied by MakeLog (datasets/sensor_model.h)
};

}  // namespace slideid
