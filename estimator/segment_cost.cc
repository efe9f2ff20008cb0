#include "estimator/internal/segment_cost.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include "estimator/internal/log_friction.h"
#include "estimator/step_sensitivity.h"
#include "forward_model/step_solver.h"

namespace slideid {
namespace {

using Matrix63 = Eigen::Matrix<double, 6, 3>;
using Matrix66 = Eigen::Matrix<double, 6, 6>;
// Wrench components in the order of StepSensitivity::dnu_dwrench: (f_x, f_y, t_z, t_x, t_y).
using Vector5 = Eigen::Matrix<double, 5, 1>;

constexpr int kStateBlock = 0;
constexpr int kFirstFrictionBlock = 1;
// A row whose squared residual is below this fraction of the loss scale squared takes the
// loss's expansion at zero (rho(s) / s -> rho'(0)): its exact form would divide by s.
constexpr double kTinyRowFraction = 1e-12;

Vector5 Components(const AppliedWrench& w) { return Vector5(w.fx, w.fy, w.tz, w.tx, w.ty); }

void AddScaled(AppliedWrench* w, double k, const AppliedWrench& d) {
  w->fx += k * d.fx;
  w->fy += k * d.fy;
  w->fz += k * d.fz;
  w->tx += k * d.tx;
  w->ty += k * d.ty;
  w->tz += k * d.tz;
}

// The logged (piecewise-constant) wrench at time t: row j's over [t_j, t_j+1), the first
// row's before the log, the last row's after it. `hint` is a row near t.
int RowAt(const Trajectory& log, double t, int hint) {
  const int n = static_cast<int>(log.samples.size());
  int j = std::clamp(hint, 0, n - 1);
  while (j > 0 && log.samples[j].t_s > t) --j;
  while (j + 1 < n && log.samples[j + 1].t_s <= t) ++j;
  return j;
}

// rho(s), rho'(s), rho''(s) of the loss with scale a (Ceres' definitions).
void EvaluateLoss(const RowLoss& loss, double s, double rho[3]) {
  const double a = loss.scale;
  if (loss.kind == RobustLoss::kHuber) {
    if (s <= a * a) {
      rho[0] = s;
      rho[1] = 1.0;
      rho[2] = 0.0;
    } else {
      const double r = std::sqrt(s);
      rho[0] = 2.0 * a * r - a * a;
      rho[1] = a / r;
      rho[2] = -rho[1] / (2.0 * s);
    }
    return;
  }
  // Cauchy.
  const double c2 = a * a, sum = 1.0 + s / c2, inv = 1.0 / sum;
  rho[0] = c2 * std::log(sum);
  rho[1] = inv;
  rho[2] = -inv * inv / c2;
}

}  // namespace

namespace {

// The mean over [t_row + d, t_row+1 + d) of a piecewise-constant per-row wrench
// (value(j) over [t_j, t_j+1), the first row's before the log, the last row's after it),
// and its derivative with respect to d.
template <typename RowValue>
void DelayedMean(const Trajectory& log, int row, double delay_s, RowValue value,
                 AppliedWrench* mean, AppliedWrench* d_mean_d_delay) {
  const int n = static_cast<int>(log.samples.size());
  const double t0 = log.samples[row].t_s + delay_s;
  const double t1 = log.samples[std::min(row + 1, n - 1)].t_s + delay_s;
  const double h = t1 - t0;
  *mean = AppliedWrench{};
  // Integrate the piecewise-constant rows over [t0, t1).
  int j = RowAt(log, t0, row);
  double t = t0;
  while (t < t1) {
    const double end = j + 1 < n ? std::min(t1, std::max(t, log.samples[j + 1].t_s)) : t1;
    AddScaled(mean, (end - t) / h, value(j));
    t = end;
    if (j + 1 < n) ++j;
  }
  // d/dd of the mean over [t0 + d, t1 + d): (W(t1) - W(t0)) / h.
  *d_mean_d_delay = AppliedWrench{};
  AddScaled(d_mean_d_delay, 1.0 / h, value(RowAt(log, t1, row + 1)));
  AddScaled(d_mean_d_delay, -1.0 / h, value(RowAt(log, t0, row)));
}

}  // namespace

void DelayedWrench(const Trajectory& log, int row, double delay_s, AppliedWrench* wrench,
                   AppliedWrench* d_wrench_d_delay) {
  DelayedMean(
      log, row, delay_s, [&](int j) { return log.samples[j].applied; }, wrench, d_wrench_d_delay);
}

void OffsetWrenchJacobian(const Trajectory& log, int row, AppliedWrench* d_wrench_d_ox,
                          AppliedWrench* d_wrench_d_oy) {
  const TrajectorySample& s = log.samples[row];
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  if (s.push_point_world) {
    r = *s.push_point_world - Eigen::Vector3d(s.state.x, s.state.y, log.slider.com_height_m);
  }
  *d_wrench_d_ox = WrenchFromForceAt(-1, 0, 0, r.x(), r.y(), r.z());
  *d_wrench_d_oy = WrenchFromForceAt(0, -1, 0, r.x(), r.y(), r.z());
}

void DelayedOffsetWrenchJacobian(const Trajectory& log, int row, double delay_s,
                                 AppliedWrench* d_wrench_d_ox, AppliedWrench* d_wrench_d_oy,
                                 AppliedWrench* d2_wrench_d_ox_d_delay,
                                 AppliedWrench* d2_wrench_d_oy_d_delay) {
  auto along = [&](bool x) {
    return [&log, x](int j) {
      AppliedWrench dx, dy;
      OffsetWrenchJacobian(log, j, &dx, &dy);
      return x ? dx : dy;
    };
  };
  DelayedMean(log, row, delay_s, along(true), d_wrench_d_ox, d2_wrench_d_ox_d_delay);
  DelayedMean(log, row, delay_s, along(false), d_wrench_d_oy, d2_wrench_d_oy_d_delay);
}

AppliedWrench SegmentCost::RowWrench(int row) const {
  const AppliedWrench& a = log_.samples[row].applied;
  if (!held_rows_ || !(*held_rows_)[row]) return a;
  const AppliedWrench& b = log_.samples[row + 1].applied;
  return {0.5 * (a.fx + b.fx), 0.5 * (a.fy + b.fy), 0.5 * (a.fz + b.fz),
          0.5 * (a.tx + b.tx), 0.5 * (a.ty + b.ty), 0.5 * (a.tz + b.tz)};
}

SegmentCost::SegmentCost(const Trajectory& log, int first_row, int last_row, int substeps,
                         bool use_pose, SegmentNuisances nuisances)
    : log_(log),
      first_(first_row),
      last_(last_row),
      substeps_(substeps),
      use_pose_(use_pose),
      nuisances_(nuisances),
      length_m_(std::sqrt(log.slider.inertia_kgm2 / log.slider.mass_kg)),
      warm_start_((last_row - first_row) * substeps, Eigen::Vector4d::Zero()) {
  set_num_residuals(3 * (last_row - first_row + 1));
  std::vector<int32_t>* sizes = mutable_parameter_block_sizes();
  sizes->assign({6, 1, 1, 1});
  if (nuisances.force_bias) {
    offset_block_ = static_cast<int>(sizes->size());
    sizes->push_back(2);
  }
  if (nuisances.delay) {
    delay_block_ = static_cast<int>(sizes->size());
    sizes->push_back(1);
  }
}

bool SegmentCost::Holds(const std::vector<char>& held_rows) const {
  const auto held = [](char h) { return h != 0; };
  if (delay_block_ >= 0) return std::any_of(held_rows.begin(), held_rows.end(), held);
  return std::any_of(held_rows.begin() + first_, held_rows.begin() + last_, held);
}

bool SegmentCost::RawResiduals(double const* const* params, double* residuals,
                               double** jacobians) const {
  const std::vector<int32_t>& sizes = parameter_block_sizes();
  // Compared in place: this runs for every segment on every evaluation of a fit.
  auto same_as_last = [&] {
    if (last_params_.empty()) return false;
    size_t k = 0;
    for (size_t b = 0; b < sizes.size(); ++b) {
      for (int j = 0; j < sizes[b]; ++j) {
        if (!(params[b][j] == last_params_[k++])) return false;
      }
    }
    return true;
  };
  if ((!jacobians || jacobian_kept_) && same_as_last()) {
    std::copy(last_residuals_.begin(), last_residuals_.end(), residuals);
    if (jacobians) CopyKeptJacobian(jacobians);
    return true;
  }
  last_params_.clear();
  jacobian_kept_ = false;
  try {
    if (!Simulate(params, residuals, jacobians)) return false;
  } catch (const std::exception&) {
    return false;
  }
  for (size_t b = 0; b < sizes.size(); ++b) {
    last_params_.insert(last_params_.end(), params[b], params[b] + sizes[b]);
  }
  last_residuals_.assign(residuals, residuals + num_residuals());
  return true;
}

std::vector<double*> SegmentCost::KeptBlocks() const {
  const std::vector<int32_t>& sizes = parameter_block_sizes();
  size_t total = 0;
  for (const int32_t size : sizes) total += static_cast<size_t>(num_residuals()) * size;
  kept_jacobian_.resize(total);
  std::vector<double*> blocks(sizes.size());
  double* block = kept_jacobian_.data();
  for (size_t b = 0; b < sizes.size(); ++b) {
    blocks[b] = block;
    block += static_cast<size_t>(num_residuals()) * sizes[b];
  }
  return blocks;
}

void SegmentCost::CopyKeptJacobian(double** jacobians) const {
  const std::vector<double*> kept = KeptBlocks();
  for (size_t b = 0; b < kept.size(); ++b) {
    if (!jacobians[b] || jacobians[b] == kept[b]) continue;
    std::copy(kept[b], kept[b] + static_cast<size_t>(num_residuals()) * parameter_block_sizes()[b],
              jacobians[b]);
  }
}

std::vector<const double*> SegmentCost::EvaluateKept(double const* const* params,
                                                     double* residuals) const {
  std::vector<double*> blocks = KeptBlocks();
  if (!RawResiduals(params, residuals, blocks.data())) return {};
  jacobian_kept_ = true;
  return {blocks.begin(), blocks.end()};
}

bool SegmentCost::Evaluate(double const* const* params, double* residuals,
                           double** jacobians) const {
  if (!RawResiduals(params, residuals, jacobians)) return false;
  if (loss_.active()) ApplyRowLoss(residuals, jacobians);
  return true;
}

bool SegmentCost::Residuals(double const* const* params, double* residuals,
                            bool with_row_loss) const {
  if (!RawResiduals(params, residuals, nullptr)) return false;
  if (with_row_loss && loss_.active()) {
    ApplyRowLoss(residuals, nullptr);
  }
  return true;
}

bool SegmentCost::SimulatedStates(double const* const* params,
                                  std::vector<PlanarState>* states) const {
  std::vector<double> residuals(num_residuals());
  states->clear();
  try {
    return Simulate(params, residuals.data(), nullptr, states);
  } catch (const std::exception&) {
    return false;
  }
}

bool SegmentCost::Simulate(double const* const* params, double* residuals, double** jacobians,
                           std::vector<PlanarState>* states) const {
  PlanarState s{params[0][0], params[0][1], params[0][2], params[0][3], params[0][4], params[0][5]};
  const ReducedFriction abc = FromLogBlocks(params + kFirstFrictionBlock);
  if (!(abc.a > 0 && abc.b > 0 && abc.c > 0) || !std::isfinite(abc.a * abc.b * abc.c)) {
    return false;
  }
  const double offset_x = offset_block_ >= 0 ? params[offset_block_][0] : 0.0;
  const double offset_y = offset_block_ >= 0 ? params[offset_block_][1] : 0.0;
  const double delay = delay_block_ >= 0 ? params[delay_block_][0] : 0.0;
  const bool want = jacobians != nullptr;
  const bool with_wrench = want && (offset_block_ >= 0 || delay_block_ >= 0);

  Matrix66 d_state = Matrix66::Identity();  // d(state) / d(initial state)
  Matrix63 d_param = Matrix63::Zero();      // d(state) / d(log a, log b, log c)
  Matrix63 d_nuis = Matrix63::Zero();       // d(state) / d(o_x, o_y, delay)
  auto residual = [&](int i) {
    if (states) states->push_back(s);
    const PlanarState& m = log_.samples[first_ + i].state;
    const int offset = use_pose_ ? 0 : 3;  // rows of the state the channels read
    const double got[3] = {use_pose_ ? s.x : s.vx, use_pose_ ? s.y : s.vy,
                           use_pose_ ? s.theta : s.wz};
    const double logged[3] = {use_pose_ ? m.x : m.vx, use_pose_ ? m.y : m.vy,
                              use_pose_ ? m.theta : m.wz};
    for (int c = 0; c < 3; ++c) {
      const double scale = c == 2 ? length_m_ : 1.0;
      const int r = 3 * i + c;
      residuals[r] = scale * (got[c] - logged[c]);
      if (!jacobians) continue;
      if (jacobians[kStateBlock]) {
        for (int j = 0; j < 6; ++j)
          jacobians[kStateBlock][6 * r + j] = scale * d_state(offset + c, j);
      }
      for (int p = 0; p < 3; ++p) {
        if (jacobians[kFirstFrictionBlock + p]) {
          jacobians[kFirstFrictionBlock + p][r] = scale * d_param(offset + c, p);
        }
      }
      if (offset_block_ >= 0 && jacobians[offset_block_]) {
        jacobians[offset_block_][2 * r] = scale * d_nuis(offset + c, 0);
        jacobians[offset_block_][2 * r + 1] = scale * d_nuis(offset + c, 1);
      }
      if (delay_block_ >= 0 && jacobians[delay_block_]) {
        jacobians[delay_block_][r] = scale * d_nuis(offset + c, 2);
      }
    }
  };

  residual(0);
  for (int row = first_; row < last_; ++row) {
    const double h = (log_.samples[row + 1].t_s - log_.samples[row].t_s) / substeps_;
    AppliedWrench applied = RowWrench(row);
    Eigen::Matrix<double, 5, 3> dw_dnuis = Eigen::Matrix<double, 5, 3>::Zero();
    if (delay_block_ >= 0) {
      AppliedWrench d_delay;
      if (held_rows_) {
        DelayedMean(
            log_, row, delay, [&](int j) { return RowWrench(j); }, &applied, &d_delay);
      } else {
        DelayedWrench(log_, row, delay, &applied, &d_delay);
      }
      dw_dnuis.col(2) = Components(d_delay);
    }
    if (offset_block_ >= 0) {
      AppliedWrench dx, dy;
      if (delay_block_ >= 0) {
        // The offset is part of the delayed stream: its moment arm is that of the rows the
        // delay reads, and it moves the delay's derivative.
        AppliedWrench dx_dd, dy_dd;
        DelayedOffsetWrenchJacobian(log_, row, delay, &dx, &dy, &dx_dd, &dy_dd);
        AppliedWrench d_delay = AppliedWrench{};
        AddScaled(&d_delay, offset_x, dx_dd);
        AddScaled(&d_delay, offset_y, dy_dd);
        dw_dnuis.col(2) += Components(d_delay);
      } else {
        OffsetWrenchJacobian(log_, row, &dx, &dy);
      }
      AddScaled(&applied, offset_x, dx);
      AddScaled(&applied, offset_y, dy);
      dw_dnuis.col(0) = Components(dx);
      dw_dnuis.col(1) = Components(dy);
    }
    for (int k = 0; k < substeps_; ++k) {
      // Between evaluations the parameters move little: the step's last solution is the
      // best first guess (zero, i.e. none, until the step has slid once).
      Eigen::Vector4d& warm = warm_start_[(row - first_) * substeps_ + k];
      StepOptions step_options;
      if (warm(3) > 0) step_options.initial_guess = warm;
      StepSensitivity sens;
      if (want) {
        if (!SolveStepWithSensitivity(log_.slider, abc, s, applied, h, &sens, step_options,
                                      with_wrench)) {
          return false;
        }
      } else {
        sens.step = SolveStep(log_.slider, abc, s, applied, h, step_options);
        if (!sens.step.ok()) return false;
      }
      if (sens.step.mode == StepMode::kSlide) warm = sens.step.scaled_solution;
      s = sens.step.state;
      if (want) {
        // nu' = f(nu, theta, wrench); q' = q + h nu'.
        const Eigen::Matrix<double, 3, 6> dnu_state = sens.dnu_dnu * d_state.bottomRows<3>();
        const Eigen::Matrix3d dnu_param = sens.dnu_dnu * d_param.bottomRows<3>() + sens.dnu_dlogabc;
        d_state.bottomRows<3>() = dnu_state;
        d_param.bottomRows<3>() = dnu_param;
        d_state.topRows<3>() += h * dnu_state;
        d_param.topRows<3>() += h * dnu_param;
        if (with_wrench) {
          const Eigen::Matrix3d dnu_nuis =
              sens.dnu_dnu * d_nuis.bottomRows<3>() + sens.dnu_dwrench * dw_dnuis;
          d_nuis.bottomRows<3>() = dnu_nuis;
          d_nuis.topRows<3>() += h * dnu_nuis;
        }
      }
    }
    residual(row + 1 - first_);
  }
  return true;
}

RowLossScaling RowLossScalingAt(const RowLoss& loss, double s) {
  double rho[3];
  EvaluateLoss(loss, s, rho);
  // r~ = g(s) r with g = sqrt(rho / s); near s = 0, the loss's expansion there.
  if (s < kTinyRowFraction * loss.scale * loss.scale) {
    const double g = std::sqrt(rho[1]);
    return {g, rho[2] / (4.0 * g)};
  }
  const double g = std::sqrt(rho[0] / s);
  return {g, (rho[1] * s - rho[0]) / (2.0 * g * s * s)};
}

void SegmentCost::ApplyRowLoss(double* residuals, double** jacobians) const {
  const int rows = num_residuals() / 3;
  const std::vector<int32_t>& sizes = parameter_block_sizes();
  for (int i = 0; i < rows; ++i) {
    double* r = residuals + 3 * i;
    const double s = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    const auto [g, g_prime] = RowLossScalingAt(loss_, s);
    if (jacobians) {
      for (size_t b = 0; b < sizes.size(); ++b) {
        if (!jacobians[b]) continue;
        const int m = sizes[b];
        for (int col = 0; col < m; ++col) {
          double* j0 = jacobians[b] + (3 * i) * m + col;
          const double rj = r[0] * j0[0] + r[1] * j0[m] + r[2] * j0[2 * m];
          for (int c = 0; c < 3; ++c) j0[c * m] = g * j0[c * m] + 2.0 * g_prime * r[c] * rj;
        }
      }
    }
    for (int c = 0; c < 3; ++c) r[c] *= g;
  }
}

}  // namespace slideid
