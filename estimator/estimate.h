#pragma once
// What every estimator of the friction parameters returns, and the options they share.
// The identifiable parameters are a = e_t mu, b = e_o / e_t and c = e_r / e_t [m]
// (model.md, "Only three parameters matter").

#include <array>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace slideid {

enum class EstimatorMethod {
  kClosedForm,
  kEquationError,
  kTrajectory,
  kQuasiStatic,  ///< wrench-twist pairs, not a push log (estimator/quasi_static_fit.h)
};
enum class RobustLoss { kNone, kHuber, kCauchy };

/// "closed-form", "equation-error", "trajectory", "quasi-static"
const char* ToString(EstimatorMethod method);
const char* ToString(RobustLoss loss);         ///< "none", "huber", "cauchy"

/// Index of a parameter in EstimateResult::parameters.
enum ParameterIndex { kA = 0, kB = 1, kC = 2 };
/// JSON / table names: e_t_mu, e_o_over_e_t, e_r_over_e_t.
const char* ParameterName(int index);

/// One estimated parameter. value/stderr are NaN when not identifiable.
struct ParameterEstimate {
  bool identifiable = false;
  double value = std::numeric_limits<double>::quiet_NaN();
  double stderr_value = std::numeric_limits<double>::quiet_NaN();  ///< standard error
  double ci95_lo = std::numeric_limits<double>::quiet_NaN();
  double ci95_hi = std::numeric_limits<double>::quiet_NaN();
  /// The value it was held at when not identifiable (it then does not affect the fit).
  double held_at = std::numeric_limits<double>::quiet_NaN();
  std::string note;  ///< why not identifiable, or how the interval was formed
};

/// A per-step residual for --residuals: what the fit could not explain at a log row.
struct StepResidual {
  int row = 0;
  double t_s = 0;
  std::array<double, 3> value{};  ///< method-specific channels, named in residual_names
  bool used = true;
};

struct EstimateResult {
  EstimatorMethod method = EstimatorMethod::kTrajectory;
  std::array<ParameterEstimate, 3> parameters;  ///< a, b, c (ParameterIndex)
  int steps_total = 0;
  int steps_used = 0;
  /// Reasons steps were left out, with counts ("sticking", "v_t near zero", ...).
  std::vector<std::pair<std::string, int>> steps_excluded;
  double final_cost = 0;
  int iterations = 0;
  double seconds = 0;
  bool converged = true;
  std::string message;  ///< how the solve ended
  std::array<std::string, 3> residual_names{{"r0", "r1", "r2"}};
  std::vector<StepResidual> residuals;

  void Exclude(const std::string& reason, int count = 1);
};

/// Options shared by the estimators; each uses the ones that apply to it.
struct EstimatorOptions {
  EstimatorMethod method = EstimatorMethod::kTrajectory;
  RobustLoss loss = RobustLoss::kHuber;
  /// Robust loss scale in units of the residuals' estimated standard deviation.
  double loss_scale_sigmas = 3.0;
  int segment_steps = 50;  ///< trajectory: log intervals per shooting segment
  int substeps = 1;        ///< trajectory: forward-model steps per log interval
  int threads = 1;
  int max_iterations = 100;

  bool IsValid(std::string* why) const;
};

/// Student-t free quantile for a 95% interval is ~1.96 at the sample sizes of a log.
constexpr double kZ95 = 1.959963984540054;

}  // namespace slideid
