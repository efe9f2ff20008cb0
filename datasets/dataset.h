#pragma once
// Synthetic datasets: N sliders and friction parameters drawn from ranges, each pushed by a
// random push program, logged as a sensor would (datasets/sensor_model.h). Deterministic by
// seed. In memory only: io/dataset_files.h writes a dataset (logs and truth manifest), and
// the make-dataset tool is a thin front end to that.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/log_spec.h"
#include "datasets/logged_scene.h"
#include "datasets/push_program.h"
#include "forward_model/contact_patch.h"
#include "forward_model/slider.h"
#include "forward_model/trajectory.h"

namespace slideid {

/// A patch shape whose sizes are drawn from ranges: "rectangle W L", "disk R", "ring R r"
/// or "polygon x1 y1 ..." where every number may be a range "LO:HI" [m].
struct PatchRange {
  std::string shape = "rectangle";
  std::vector<ValueRange> sizes{{0.06, 0.15}, {0.06, 0.15}};

  /// Parses the text form; throws std::invalid_argument naming the bad part.
  static PatchRange Parse(const std::string& text);
  std::string ToString() const;
};

/// Parses "LO:HI" (or one number, LO = HI); throws std::invalid_argument naming `what`.
ValueRange ParseRange(const std::string& text, const std::string& what);
std::string ToString(const ValueRange& range);  ///< "LO:HI"

/// Moment of inertia about the vertical axis through the CM of a uniform slider of mass
/// `mass_kg` whose mass lies over `patch` (a box or cylinder standing on its footprint:
/// height does not change I_z) [kg m^2]. Ring: the annulus.
double UniformInertia(const ContactPatch& patch, double mass_kg);

/// A pusher-driven dataset's draws: each log one straight push by a round tip, coming in
/// from outside the slider along a random heading with a random lateral offset (so that it
/// meets the outline at a random point and angle), then pushing on.
struct PusherDraw {
  ValueRange mu{0.1, 0.6};            ///< tip-edge friction mu_p
  ValueRange speed_mps{0.02, 0.1};    ///< tip speed
  ValueRange distance_m{0.03, 0.08};  ///< pushed after touching
  /// Lateral offset of the tip's line from the CM, as a fraction of the patch's smallest
  /// half-size (so that the tip meets the slider).
  ValueRange offset_fraction{-0.6, 0.6};
  double tip_radius_m = 0.00475;
};

/// The pusher of a pusher-driven log (make-dataset --pusher): one straight push of `patch`'s
/// slider, at rest at the origin, drawn from `d` on its own stream (seeded by the dataset's
/// `seed`, the log's `index` and the draw's `attempt`), so that a dataset's other draws stay
/// those of a force-driven dataset with the same seed. Also the random arm of the push
/// advice's benchmark (fixtures/push_race.h).
Pusher DrawPusher(const PusherDraw& d, const ContactPatch& patch, std::uint64_t seed, int index,
                  int attempt);

/// What a dataset draws from, and how each log is made.
struct DatasetSpec {
  int count = 10;          ///< logs to make (>= 1)
  std::uint64_t seed = 1;  ///< everything below is drawn from it
  ValueRange mass_kg{0.3, 1.5};
  /// Unset: UniformInertia of the drawn patch and mass.
  std::optional<ValueRange> inertia_kgm2;
  ValueRange com_height_m{0.01, 0.04};
  PatchRange patch;
  ValueRange mu{0.2, 0.6};
  ValueRange e_t{0.8, 1.2};
  ValueRange e_o{0.6, 1.5};
  ValueRange e_r_m{0.01, 0.04};
  /// Push program of every log (its seed is drawn per log; unset force and height ranges
  /// scale with each drawn slider, see RandomProgramSpec).
  RandomProgramSpec program;
  double dt_s = 1e-3;  ///< simulation step [s]
  /// Sampling, columns and noise of every log (the noise seed is drawn per log).
  /// Default: log at 100 Hz (every 10th 1 ms step), poses and push points.
  LogSpec log = DefaultLog();
  /// Pushes start and stop at log sample times (RandomProgramSpec::time_grid_s = dt *
  /// log_every), as when a robot commands its pusher at its logging rate; false: anywhere,
  /// so a log row's force can be off for part of an interval at each switch.
  bool align_pushes = true;
  /// Set: every log is driven by a pusher (instead of the push program), and records the
  /// tip's path (tip_x, tip_y) and its radius.
  std::optional<PusherDraw> pusher;
  /// A draw that tips the slider (ECP outside the hull), lifts it or fails to converge is
  /// redrawn, with its reason recorded, up to this many times per log.
  int max_redraws = 50;

  static LogSpec DefaultLog();
  /// False (and why) when a range is empty or non-physical (mass <= 0, ...).
  bool IsValid(std::string* why) const;
};

/// One log of a dataset and the truth it was made with.
struct DatasetEntry {
  std::string file;   ///< "log_0000.csv" (relative to the dataset directory)
  LoggedScene scene;  ///< slider, friction, patch, pushes, log spec (with its noise seed)
  int rows = 0;       ///< rows in the log
  std::vector<std::string> redraw_reasons;  ///< one per rejected draw, in order
};

/// Every draw of a log tipped the slider, lifted it or failed to converge: the message names
/// the log and lists each draw's reason. A numerical outcome, not bad input or I/O.
class NoValidDraw : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Draws log `index` of the dataset: the scene (redrawn while it tips), simulated and
/// logged. Deterministic in (spec, index). Throws NoValidDraw when max_redraws is
/// exhausted, std::invalid_argument for an invalid spec.
DatasetEntry DrawDatasetLog(const DatasetSpec& spec, int index, Trajectory* log);

}  // namespace slideid
