#pragma once
// The tip-edge friction mu_p from logs that carry the pusher tip's path (tip_x, tip_y,
// '# tip_radius', '# patch'). Its evidence is the angle between the measured force and the
// edge's normal: while the tip slides along the edge, Coulomb's law puts the force on the
// edge of its friction cone, |f_t| / f_n = mu_p, the tangential part opposing the slip;
// while it sticks, the ratio only stays inside the cone. So mu_p is the median ratio over
// the rows where the tip slides (the slip, the contact point's velocity along the edge
// relative to the tip, read in the body frame over a few rows, beyond its noise and against
// the tangential force), with an interval from the medians of consecutive batches of them. A log
// whose tip never slides gives only a lower bound, a high quantile of the ratio while it sticks,
// and says so.

#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "estimator/estimate.h"
#include "forward_model/contact_patch.h"
#include "forward_model/trajectory.h"

namespace slideid {

struct PusherFrictionOptions {
  /// The tip touches when its centre is within tip radius + this of the outline [m]
  /// (motion capture and machining: about 1-2 mm).
  double contact_tolerance_m = 2e-3;
  /// A row pushes when the force into the edge exceeds this fraction of the logs' typical
  /// push (the 90th percentile of their non-zero forces).
  double min_force_fraction = 0.1;
  /// The tip slides when the slip exceeds this many standard deviations of its noise (from
  /// the pose noise the log shows) and this fraction of the tip's speed.
  double slip_sigmas = 3.0;
  double min_slip_fraction = 0.1;
  /// The slip is the tip's drift along the edge over rows u - k .. u + k: k = 5 makes its
  /// noise from 0.2 mm of pose noise at 100 Hz 2.8 mm/s, against 28 mm/s over one row.
  int slip_half_window_rows = 5;
  /// Fewer sliding rows than this identify nothing: mu_p gets a lower bound only.
  int min_sliding_rows = 8;
  /// The interval: the sliding rows cut into consecutive batches of at least this many
  /// rows, at most max_batches of them.
  int batch_rows = 10;
  int max_batches = 10;
  /// The lower bound from a tip that sticks: this quantile of |f_t| / f_n.
  double sticking_quantile = 0.95;

  bool IsValid(std::string* why) const;
};

struct PusherFrictionResult {
  ParameterEstimate mu;  ///< identifiable when the tip slides in enough rows
  double lower_bound = std::numeric_limits<double>::quiet_NaN();  ///< when it only sticks
  int contact_rows = 0;  ///< rows where the tip pushes the edge
  int sliding_rows = 0;  ///< of which the tip slides along it
};

/// The typical push of `logs` [N]: the kTypicalPushQuantile quantile of their non-zero
/// horizontal forces, 0 without any. Not the largest: a tip that meets the object at speed
/// logs one impact row many times the push.
constexpr double kTypicalPushQuantile = 0.9;
double TypicalPush(const std::vector<const Trajectory*>& logs);

/// mu_p from the logs that have the tip's path, radius and the object's outline; nullopt
/// when none has. Throws std::invalid_argument for invalid options.
std::optional<PusherFrictionResult> EstimatePusherFriction(
    const std::vector<const Trajectory*>& logs, const PusherFrictionOptions& options = {});

/// mu_p from rows as they come (the online identifier, estimator/online_identifier.h): the
/// same contact rows and the same estimate as EstimatePusherFriction, each row classified
/// once its slip window is in, slip_half_window_rows rows later (or at the end of its run).
/// The typical push is that of the rows so far. The estimate is recomputed from the rows'
/// ratios whenever they have grown by a sixteenth (medians are O(n)): O(1) per row
/// amortised, and at most that far behind the rows.
class PusherFrictionStream {
 public:
  /// Whether a log with this metadata carries what mu_p needs: the tip's path, its radius
  /// and the object's outline.
  static bool Applies(const Trajectory& metadata);
  /// `metadata` must Apply; throws std::invalid_argument otherwise or for invalid options.
  explicit PusherFrictionStream(const Trajectory& metadata,
                                const PusherFrictionOptions& options = {});
  /// The next row (its mode kStart after a gap), with the pose noise the caller reads off
  /// the log so far [m, rad]. A row without the tip is skipped.
  void Add(const TrajectorySample& row, double pose_noise_m, double angle_noise_rad);
  const PusherFrictionResult& result() const { return result_; }

 private:
  struct Held {
    TrajectorySample row;
    int run = 0;
  };
  void Classify(size_t index_in_ring);
  void Recompute();
  PusherFrictionOptions options_;
  ContactPatch patch_;
  double tip_radius_m_ = 0;
  std::deque<Held> ring_;  // the rows whose slip window is not yet in, and k before them
  size_t classified_ = 0;  // rows of ring_ classified
  int run_ = 0;
  double pose_noise_m_ = 0, angle_noise_rad_ = 0;
  std::vector<double> forces_, sliding_, all_;
  double min_force_n_ = 0;
  size_t forces_at_recompute_ = 0, rows_at_recompute_ = 0;
  PusherFrictionResult result_;
};

/// Sets result->mu_pusher* from EstimatePusherFriction (untouched when no log has a tip).
void AddPusherFriction(const std::vector<const Trajectory*>& logs, EstimateResult* result);

}  // namespace slideid
