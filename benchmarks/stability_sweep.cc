// Stability sweep (issue 5, docs/stability.md): the forward step and the estimators over
// extreme grids.
//
//   stability_sweep [--quick] [--csv PATH] [--markdown PATH] [--failures N]
//
// Step grid: the cartesian product of mu, c = e_r/e_t, b = e_o/e_t, step h, mass (inertia
// matched to a 0.1 m square patch), CM height (0 .. the toppling limit), speed and spin, each
// point solved free and pushed (tilting moments when q_z > 0), with the default options and
// with the general Newton forced, plus a free energy run (kinetic energy must never rise).
// Boundary grid: starts whose stopping impulse lies on the friction ellipsoid, scaled by
// 1 +- a few ulps .. 1e-4. Estimator grid: one axis at a time from a base and the corners
// of the box; the tests' free slide with spin and pushed slider simulated at those
// parameters (dynamically similar, and as in the tests: fixtures/scaled_scenes.h), logged
// exactly by make-dataset's sensor model (MakeLog) and identified by the trajectory and
// equation-error methods, held to the tests' tolerances (fixtures/tolerances.h). Domain
// probes: single steps at the limits of double.
// Prints the per-axis Markdown table, the failures and the verdicts; --csv writes one row
// per case. Exit code 0 when nothing failed, 3 otherwise (2: usage, 4: a file not written).
//
// A benchmark program, not a tool: it is longer than a tool's 150 lines because the grids
// and their bookkeeping are the program; nothing here is library logic.

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "benchmarks/bench_args.h"
#include "datasets/sensor_model.h"
#include "estimator/ceres_logging.h"
#include "estimator/identify.h"
#include "fixtures/scaled_scenes.h"
#include "fixtures/synthetic_scenes.h"
#include "fixtures/tolerances.h"
#include "forward_model/scene.h"
#include "forward_model/simulator.h"
#include "forward_model/step_solver.h"

namespace slideid {
namespace {

// The tests' plate and scenes (fixtures/); a case fails by the tests' own tolerances,
// testing::k*Tolerance and testing::kExactRelTol (fixtures/tolerances.h).
using testing::kGravity_mps2;
using testing::kPlateHalfSide_m;
using testing::SceneScaling;
using testing::SquarePlate;
using testing::TopplingLimit;

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Boundary starts this far (relative) from the ellipsoid must stick / slide as constructed;
// closer, rounding may decide either way (both are then correct to rounding).
constexpr double kClearOfBoundary = 1e-10;
// Converged steps that took more Newton iterations than this (over all first guesses) are
// listed apart: not failures, but where the solver works hardest.
constexpr int kManyIterations = 40;

std::string Sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1e", v);
  return buf;
}

struct Axis {
  std::string name;
  std::vector<double> values;
};

// One axis value a case belongs to, for the per-axis table.
using Tags = std::vector<std::pair<std::string, double>>;

struct Row {  // one aggregate line of the table
  long step_cases = 0, converged = 0, nonfinite = 0, energy_runs = 0, energy_violations = 0;
  long residual_fail = 0;
  double max_residual = 0, max_independent = 0;
  int max_iterations = 0;
  long est_cases = 0, est_ok = 0, est_verdict = 0, est_fail = 0;
  double est_max_rel_traj = 0, est_max_rel_ee = 0;  // over identifiable parameters
};

struct Failure {
  std::string what;
};

class Sweep {
 public:
  explicit Sweep(std::ostream* csv, int max_failures) : csv_(csv), max_failures_(max_failures) {
    if (csv_) {
      *csv_ << "kind,family,solver,mu,c,b,h,mass,qz,speed,spin,factor,status,mode,path,"
               "residual,independent_residual,iterations,nonfinite,energy_steps,"
               "energy_violations,max_energy_rise,method,rel_err_a,rel_err_b,rel_err_c,"
               "verdict\n";
    }
  }

  std::map<std::pair<std::string, double>, Row>& rows() { return rows_; }
  const std::vector<Failure>& failures() const { return failures_; }
  long total_failures() const { return total_failures_; }
  Row& total() { return total_; }

  // Solves one step and books it; returns the result.
  StepResult Step(const char* kind, const char* family, bool general_only, const Tags& tags,
                  double factor, const SliderProperties& slider, const FrictionParameters& f,
                  const PlanarState& state, const AppliedWrench& applied, double h) {
    StepOptions options;
    options.use_special_cases = !general_only;
    StepResult r;
    std::string status;
    try {
      r = SolveStep(slider, f, state, applied, h, options);
      status = r.ok()                             ? "converged"
               : r.status == StepStatus::kLiftOff ? "lift-off"
                                                  : "no-convergence";
    } catch (const std::exception& e) {
      r.status = StepStatus::kNoConvergence;
      r.message = std::string("exception: ") + e.what();
      status = "exception";
    }
    double independent = 0;
    bool nonfinite = false;
    if (r.ok()) {
      const PlanarState& s = r.state;
      const double out[] = {s.x,
                            s.y,
                            s.theta,
                            s.vx,
                            s.vy,
                            s.wz,
                            r.pt,
                            r.po,
                            r.pr,
                            r.sigma,
                            r.ecp_world.x(),
                            r.ecp_world.y(),
                            r.residual};
      for (double v : out) nonfinite |= !std::isfinite(v);
      if (r.mode == StepMode::kSlide) {
        independent = SlidingEquationResiduals(slider, f, state, applied, h,
                                               Eigen::Vector4d(r.pt, r.po, r.pr, r.sigma))
                          .cwiseAbs()
                          .maxCoeff();
        nonfinite |= !std::isfinite(independent);
      }
    }
    const bool residual_bad = r.ok() && (!(r.residual <= testing::kStepTolerance) ||
                                         !(independent <= testing::kIndependentTolerance));
    auto book = [&](Row& row) {
      ++row.step_cases;
      row.converged += r.ok();
      row.nonfinite += nonfinite;
      row.residual_fail += residual_bad;
      if (r.ok()) {
        row.max_residual = std::max(row.max_residual, r.residual);
        row.max_independent = std::max(row.max_independent, independent);
      }
      row.max_iterations = std::max(row.max_iterations, r.iterations);
    };
    for (const auto& t : tags) book(rows_[t]);
    book(total_);
    const ReducedFriction abc = ReducedFriction::From(f);
    if (csv_) {
      *csv_ << kind << ',' << family << ',' << (general_only ? "general" : "default") << ','
            << Csv(tags, f.mu, abc.c, abc.b, h, slider.mass_kg, slider.com_height_m, state, factor)
            << ',' << status << ',' << (r.ok() ? ToString(r.mode) : "") << ','
            << (r.ok() ? ToString(r.path) : "") << ',' << r.residual << ',' << independent << ','
            << r.iterations << ',' << nonfinite << ",,,,,,,," << '"' << (r.ok() ? "" : r.message)
            << "\"\n";
    }
    if (!r.ok() || nonfinite || residual_bad || r.iterations > kManyIterations) {
      std::ostringstream msg;
      msg.precision(17);
      msg << kind << '/' << family << (general_only ? "/general" : "") << ": " << status
          << " residual " << r.residual << " independent " << independent << " iterations "
          << r.iterations << (nonfinite ? " NONFINITE" : "") << " | " << r.message << " | mass "
          << slider.mass_kg << " I " << slider.inertia_kgm2 << " qz " << slider.com_height_m
          << " mu " << f.mu << " b " << abc.b << " c " << abc.c << " h " << h << " state ("
          << state.vx << ", " << state.vy << ", " << state.wz << ") applied (" << applied.fx << ", "
          << applied.fy << ", " << applied.fz << ", " << applied.tx << ", " << applied.ty << ", "
          << applied.tz << ")";
      if (!r.ok() || nonfinite || residual_bad) {
        Fail(msg.str());
      } else if (static_cast<int>(slow_.size()) < max_failures_) {
        slow_.push_back(msg.str());
      }
    }
    return r;
  }

  // Free slide from `state` for up to `steps` steps: energy must never rise.
  void Energy(const Tags& tags, const SliderProperties& slider, const FrictionParameters& f,
              PlanarState state, double h, int steps) {
    auto energy = [&](const PlanarState& s) {
      return 0.5 * slider.mass_kg * (s.vx * s.vx + s.vy * s.vy) +
             0.5 * slider.inertia_kgm2 * s.wz * s.wz;
    };
    const PlanarState start = state;
    double e = energy(state), worst_rise = 0;
    int violations = 0, done = 0, first_violation = -1;
    bool nonfinite = false;
    std::string status = "converged", message;
    for (; done < steps; ++done) {
      StepResult r;
      try {
        r = SolveStep(slider, f, state, {}, h);
      } catch (const std::exception& ex) {
        status = "exception";
        message = ex.what();
        break;
      }
      if (!r.ok()) {
        status = "no-convergence";
        message = r.message;
        break;
      }
      const double e_next = energy(r.state);
      if (!std::isfinite(e_next)) {
        nonfinite = true;
        break;
      }
      if (e_next > e * (1 + testing::kEnergyTolerance)) {
        ++violations;
        if (first_violation < 0) first_violation = done;
        worst_rise = std::max(worst_rise, e_next / e - 1);
      }
      e = e_next;
      state = r.state;
      // Without push, rest is absorbing: the stopping impulse is zero.
      if (r.mode == StepMode::kStick) {
        ++done;
        break;
      }
    }
    auto book = [&](Row& row) {
      ++row.energy_runs;
      row.energy_violations += violations > 0;
      row.nonfinite += nonfinite;
    };
    for (const auto& t : tags) book(rows_[t]);
    book(total_);
    const ReducedFriction abc = ReducedFriction::From(f);
    if (csv_) {
      *csv_ << "energy,free,default,"
            << Csv(tags, f.mu, abc.c, abc.b, h, slider.mass_kg, slider.com_height_m, start, 1)
            << ',' << status << ",,,,,," << nonfinite << ',' << done << ',' << violations << ','
            << worst_rise << ",,,,,\"" << message << "\"\n";
    }
    if (violations > 0 || nonfinite || status != "converged") {
      std::ostringstream msg;
      msg.precision(17);
      msg << "energy: " << status << " violations " << violations << " (first at step "
          << first_violation << ", worst relative rise " << worst_rise << ")"
          << (nonfinite ? " NONFINITE" : "") << " | " << message << " | mass " << slider.mass_kg
          << " I " << slider.inertia_kgm2 << " qz " << slider.com_height_m << " mu " << f.mu
          << " b " << abc.b << " c " << abc.c << " h " << h << " start (" << start.vx << ", "
          << start.vy << ", " << start.wz << ")";
      Fail(msg.str());
    }
  }

  void Estimator(const Tags& tags, const std::string& family, const char* method,
                 const ReducedFriction& truth, const Trajectory* log,
                 const std::string& sim_error) {
    std::array<double, 3> rel{{NAN, NAN, NAN}};
    std::string verdict;
    bool error = false, unidentifiable = false, ok = true;
    double worst = 0;
    if (!sim_error.empty()) {
      error = true;
      verdict = "simulation: " + sim_error;
    } else {
      IdentifyOptions options;
      options.method = std::strcmp(method, "trajectory") == 0 ? EstimatorMethod::kTrajectory
                                                              : EstimatorMethod::kEquationError;
      try {
        const EstimateResult r = Identify(*log, options);
        if (r.status == TerminationStatus::kTooLittleExcitation) {
          throw std::invalid_argument(r.message);
        }
        const double t[] = {truth.a, truth.b, truth.c};
        for (int i = 0; i < 3; ++i) {
          const ParameterEstimate& p = r.parameters[i];
          if (!p.identifiable) {
            unidentifiable = true;
            verdict += std::string(verdict.empty() ? "" : "; ") + ParameterName(i) +
                       " not identifiable: " + p.reason;
            continue;
          }
          rel[i] = std::abs(p.value / t[i] - 1);
          worst = std::max(worst, std::isfinite(rel[i]) ? rel[i] : INFINITY);
          if (rel[i] <= testing::kExactRelTol) continue;
          // Off the truth by more than 1e-6 but inside its own 95% interval: the log
          // determines it only that well, and the estimator says so (a verdict).
          if (t[i] >= p.ci95_lo && t[i] <= p.ci95_hi) {
            unidentifiable = true;
            char buf[160];
            std::snprintf(buf, sizeof buf,
                          "%s off by %.2g relative, inside its 95%% interval "
                          "[%.6g, %.6g]",
                          ParameterName(i), rel[i], p.ci95_lo, p.ci95_hi);
            verdict += std::string(verdict.empty() ? "" : "; ") + buf;
          } else {
            ok = false;
            char buf[160];
            std::snprintf(buf, sizeof buf,
                          "%s = %.9g, 95%% interval [%.9g, %.9g] excludes "
                          "the truth",
                          ParameterName(i), p.value, p.ci95_lo, p.ci95_hi);
            verdict += std::string(verdict.empty() ? "" : "; ") + buf;
          }
        }
        if (!r.converged) {
          ok = false;
          verdict += std::string(verdict.empty() ? "" : "; ") + "not converged: " + r.message;
        }
      } catch (const std::exception& e) {
        error = true;
        verdict = std::string("error: ") + e.what();
      }
    }
    // An error is a verdict when it is one of the documented ones (README: too little
    // sliding, a log too short; the simulator's toppling or lift-off); any other is a
    // failure, as is an identifiable parameter off the truth or a fit that did not converge.
    const bool documented = error && (verdict.find("too little sliding") != std::string::npos ||
                                      verdict.find("too short") != std::string::npos ||
                                      verdict.find("simulation: ") == 0);
    const bool failed = (error && !documented) || (!error && !ok);
    const bool is_verdict = !failed && (error || unidentifiable);
    auto book = [&](Row& row) {
      ++row.est_cases;
      row.est_fail += failed;
      row.est_verdict += is_verdict;
      row.est_ok += !failed && !is_verdict;
      if (error) return;
      double& m =
          std::strcmp(method, "trajectory") == 0 ? row.est_max_rel_traj : row.est_max_rel_ee;
      m = std::max(m, worst);
    };
    for (const auto& t : tags) book(rows_[t]);
    book(total_);
    if (csv_) {
      std::string v = verdict;
      std::replace(v.begin(), v.end(), '"', '\'');
      *csv_ << "estimator," << family << ",," << Csv(tags, 0, 0, 0, 0, 0, 0, {}, 1) << ','
            << (failed       ? "fail"
                : is_verdict ? "verdict"
                             : "ok")
            << ",,,,,,,,,," << method << ',' << rel[0] << ',' << rel[1] << ',' << rel[2] << ",\""
            << v << "\"\n";
    }
    if (failed) {
      std::ostringstream msg;
      msg << "estimator/" << family << '/' << method << ":";
      for (const auto& t : tags) msg << ' ' << t.first << '=' << t.second;
      msg << " rel err " << rel[0] << ' ' << rel[1] << ' ' << rel[2] << " | " << verdict;
      Fail(msg.str());
    } else if (is_verdict) {
      std::ostringstream msg;
      msg << "estimator/" << family << '/' << method << " (verdict):";
      for (const auto& t : tags) msg << ' ' << t.first << '=' << t.second;
      msg << " | " << verdict;
      verdicts_.push_back(msg.str());
    }
  }

  // A step far outside the grids, at the limits of double: it must converge with finite
  // outputs, or say why not (a status with a message, or std::invalid_argument).
  void Probe(const std::string& name, const SliderProperties& slider, const FrictionParameters& f,
             const PlanarState& state, const AppliedWrench& applied, double h) {
    std::string outcome;
    bool bad = false;
    try {
      const StepResult r = SolveStep(slider, f, state, applied, h);
      if (r.ok()) {
        const PlanarState& x = r.state;
        bool finite = true;
        for (double v : {x.x, x.y, x.theta, x.vx, x.vy, x.wz, r.pt, r.po, r.pr, r.sigma,
                         r.ecp_world.x(), r.ecp_world.y(), r.residual}) {
          finite &= std::isfinite(v);
        }
        bad = !finite || !(r.residual <= testing::kStepTolerance);
        std::ostringstream o;
        o << "converged (" << ToString(r.mode) << ", " << r.iterations << " iterations, residual "
          << Sci(r.residual) << (finite ? "" : ", NON-FINITE OUTPUT") << ")";
        outcome = o.str();
      } else {
        bad = r.message.empty();
        outcome = "status: " + r.message;
      }
    } catch (const std::invalid_argument& e) {
      outcome = std::string("std::invalid_argument: ") + e.what();
    }
    probes_.push_back({name, outcome});
    if (bad) Fail("probe " + name + ": " + outcome);
  }
  const std::vector<std::pair<std::string, std::string>>& probes() const { return probes_; }

  const std::vector<std::string>& verdicts() const { return verdicts_; }
  const std::vector<std::string>& slow() const { return slow_; }
  /// A failure found by a check outside the step (e.g. the stick decision at the boundary).
  void Flag(const std::string& what) { Fail(what); }

 private:
  // The parameter columns; axis tags override (estimator rows carry only tags).
  static std::string Csv(const Tags& tags, double mu, double c, double b, double h, double mass,
                         double qz, const PlanarState& s, double factor) {
    std::map<std::string, double> v{{"mu", mu},
                                    {"c", c},
                                    {"b", b},
                                    {"h", h},
                                    {"mass", mass},
                                    {"qz", qz},
                                    {"speed", std::hypot(s.vx, s.vy)},
                                    {"spin", s.wz},
                                    {"factor", factor}};
    for (const auto& t : tags) {
      if (v.count(t.first) && t.first != "qz" && t.first != "factor") v[t.first] = t.second;
    }
    std::ostringstream out;
    out.precision(6);
    bool first = true;
    for (const char* k : {"mu", "c", "b", "h", "mass", "qz", "speed", "spin", "factor"}) {
      out << (first ? "" : ",") << v[k];
      first = false;
    }
    return out.str();
  }

  void Fail(const std::string& what) {
    ++total_failures_;
    if (static_cast<int>(failures_.size()) < max_failures_) failures_.push_back({what});
  }

  std::ostream* csv_;
  int max_failures_;
  std::map<std::pair<std::string, double>, Row> rows_;
  Row total_;
  std::vector<Failure> failures_;
  std::vector<std::string> verdicts_;
  std::vector<std::pair<std::string, std::string>> probes_;
  std::vector<std::string> slow_;  // converged, but with more than kManyIterations
  long total_failures_ = 0;
};

struct Grids {
  std::vector<double> mu, c, b, h, mass, qz_fraction, speed, spin;
  std::vector<double> boundary;
  int energy_steps;
  bool quick;
};

Grids MakeGrids(bool quick) {
  Grids g;
  g.quick = quick;
  const double e = kEps;
  g.boundary = {1 - 1e-4, 1 - 1e-8,  1 - 4 * e, 1 - e,    1,
                1 + e,    1 + 4 * e, 1 + 1e-12, 1 + 1e-8, 1 + 1e-4};
  if (quick) {
    g.mu = {1e-3, 0.3, 2};
    g.c = {1e-4, 0.5};
    g.b = {0.1, 10};
    g.h = {1e-5, 0.1};
    g.mass = {1e-3, 1e3};
    g.qz_fraction = {0, 1};
    g.speed = {1e-8, 1, 1e2};
    g.spin = {0, 1e3};
    g.energy_steps = 100;
  } else {
    g.mu = {1e-3, 1e-2, 0.1, 0.3, 2};
    g.c = {1e-4, 1e-3, 1e-2, 0.1, 0.5};
    g.b = {0.1, 0.3, 1, 3, 10};
    g.h = {1e-5, 1e-4, 1e-3, 1e-2, 0.1};
    g.mass = {1e-3, 1e-1, 1, 1e1, 1e3};
    g.qz_fraction = {0, 0.5, 1};
    g.speed = {1e-8, 1e-5, 1e-2, 1, 1e2};
    g.spin = {0, 1, 30, 1e3};
    g.energy_steps = 300;
  }
  return g;
}

void StepGrid(const Grids& g, Sweep* sweep) {
  std::mt19937_64 rng(20240605);  // directions; fixed seed
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  for (double mu : g.mu)
    for (double c : g.c)
      for (double b : g.b)
        for (double h : g.h)
          for (double mass : g.mass)
            for (double qf : g.qz_fraction)
              for (double speed : g.speed)
                for (double spin : g.spin) {
                  const FrictionParameters f{mu, 1.0, b, c};
                  const double qz = qf * TopplingLimit(mu, b);
                  const SliderProperties slider = SquarePlate(mass, qz);
                  const double dir = angle(rng), push_dir = angle(rng);
                  const double spin_sign = angle(rng) > 0 ? 1 : -1;
                  const PlanarState state{0.1,
                                          -0.2,
                                          0.3,
                                          speed * std::cos(dir),
                                          speed * std::sin(dir),
                                          spin_sign * spin};
                  const Tags tags{{"mu", mu},       {"c", c},       {"b", b},
                                  {"h", h},         {"mass", mass}, {"cm height", qf},
                                  {"speed", speed}, {"spin", spin}};
                  // Push 1.5 mu m g at a patch corner-ish point, at ground level: tilting
                  // moments whenever q_z > 0.
                  const double force = 1.5 * mu * mass * kGravity_mps2;
                  const AppliedWrench push = WrenchFromForceAt(
                      force * std::cos(push_dir), force * std::sin(push_dir), 0.0,
                      -kPlateHalfSide_m * std::cos(dir), 0.4 * kPlateHalfSide_m, -qz);
                  for (bool general : {false, true}) {
                    sweep->Step("step", "free", general, tags, 1, slider, f, state, {}, h);
                    sweep->Step("step", "pushed", general, tags, 1, slider, f, state, push, h);
                  }
                  sweep->Energy(tags, slider, f, state, h, g.energy_steps);
                }
}

// Starts whose stopping impulse is `factor` times a point of the ellipsoid (model.md,
// "Sticking"): a moving slider without push, and a resting one pushed (tilting moments).
void BoundaryGrid(const Grids& g, Sweep* sweep) {
  std::mt19937_64 rng(777);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  // The ends of every axis, and its middle value in the full sweep.
  auto ends = [&](const std::vector<double>& v) {
    std::vector<double> out{v.front()};
    if (!g.quick && v.size() > 2) out.push_back(v[v.size() / 2]);
    out.push_back(v.back());
    return out;
  };
  const std::vector<double> mus = ends(g.mu), cs = ends(g.c), bs = ends(g.b), hs = ends(g.h);
  const std::vector<double> masses = ends(g.mass), qfs = ends(g.qz_fraction);
  const std::vector<double> spin_share{0.0, 0.5, 1.0};  // tau_r of the direction
  for (double factor : g.boundary)
    for (double mu : mus)
      for (double c : cs)
        for (double b : bs)
          for (double h : hs)
            for (double mass : masses)
              for (double qf : qfs)
                for (double share : spin_share)
                  for (bool pushed : {false, true}) {
                    const FrictionParameters f{mu, 1.0, b, c};
                    const double qz = qf * TopplingLimit(mu, b);
                    const SliderProperties slider = SquarePlate(mass, qz);
                    const double P = mu * h * mass * kGravity_mps2;
                    const double phi = angle(rng);
                    Eigen::Vector3d tau(std::cos(phi) * std::sqrt(1 - share * share),
                                        std::sin(phi) * std::sqrt(1 - share * share),
                                        angle(rng) > 0 ? share : -share);
                    const Eigen::Vector3d p_stop =
                        factor * P * Eigen::Vector3d(tau(0), b * tau(1), c * tau(2));
                    PlanarState state{0, 0, 0, 0, 0, 0};
                    AppliedWrench applied;
                    if (!pushed) {  // k = M nu = -p_stop (no tilting moments)
                      state.vx = -p_stop(0) / mass;
                      state.vy = -p_stop(1) / mass;
                      state.wz = -p_stop(2) / slider.inertia_kgm2;
                    } else {  // at rest, pushed at ground level: k = h f
                      applied.fx = -p_stop(0) / h;
                      applied.fy = -p_stop(1) / h;
                      applied.tx = qz * applied.fy;
                      applied.ty = -qz * applied.fx;
                      const double pn = h * mass * kGravity_mps2;
                      const double k2 =
                          -p_stop(2) -
                          (p_stop(0) * h * applied.tx + p_stop(1) * h * applied.ty) / pn;
                      applied.tz = k2 / h;
                    }
                    const Tags tags{
                        {"boundary", factor}, {"mu", mu},       {"c", c}, {"b", b}, {"h", h},
                        {"mass", mass},       {"cm height", qf}};
                    for (bool general : {false, true}) {
                      const StepResult r =
                          sweep->Step("boundary", pushed ? "pushed-from-rest" : "moving", general,
                                      tags, factor, slider, f, state, applied, h);
                      // Clear of rounding, the stick test must decide as the construction.
                      const bool must_stick = factor <= 1 - kClearOfBoundary;
                      const bool must_slide = factor >= 1 + kClearOfBoundary;
                      if (r.ok() && ((must_stick && r.mode != StepMode::kStick) ||
                                     (must_slide && r.mode != StepMode::kSlide))) {
                        std::ostringstream msg;
                        msg << "boundary: factor " << factor << " gave " << ToString(r.mode)
                            << " | mu " << mu << " b " << b << " c " << c << " h " << h << " mass "
                            << mass << " qz " << qz;
                        sweep->Flag(msg.str());
                      }
                    }
                  }
}

void EstimatorGrid(bool quick, Sweep* sweep) {
  const std::array<double, 5> base{0.3, 0.03, 1.0, 1.0, 0.01};  // mu, c, b, mass, h
  std::vector<Axis> axes;
  if (quick) {
    axes = {{"mu", {1e-3, 2}},
            {"c", {1e-4, 0.5}},
            {"b", {0.1, 10}},
            {"mass", {1e-3, 1e3}},
            {"h", {1e-4, 0.1}}};
  } else {
    axes = {{"mu", {1e-3, 1e-2, 1, 2}},
            {"c", {1e-4, 1e-3, 0.1, 0.5}},
            {"b", {0.1, 0.3, 3, 10}},
            {"mass", {1e-3, 1e-1, 10, 1e3}},
            {"h", {1e-5, 1e-4, 1e-3, 0.1}}};
  }
  // The base point, then every axis value with the others at the base (both scalings);
  // in the full sweep also the 32 corners of the box (similar scaling only).
  std::vector<std::pair<std::array<double, 5>, bool>> points{{base, true}, {base, false}};
  for (size_t a = 0; a < axes.size(); ++a) {
    for (double v : axes[a].values) {
      std::array<double, 5> p = base;
      p[a] = v;
      points.push_back({p, true});
      points.push_back({p, false});
    }
  }
  if (!quick) {
    for (int corner = 0; corner < 32; ++corner) {
      std::array<double, 5> p;
      for (int a = 0; a < 5; ++a) {
        p[a] = (corner >> a) & 1 ? axes[a].values.back() : axes[a].values.front();
      }
      points.push_back({p, true});
    }
  }
  for (const auto& [p, similar] : points) {
    const Tags tags{{"mu", p[0]},   {"c", p[1]}, {"b", p[2]},
                    {"mass", p[3]}, {"h", p[4]}, {"estimator scene", similar ? 0.0 : 1.0}};
    for (bool pushed : {false, true}) {
      const LoggedScene scene =
          testing::ScaledScene(pushed, similar ? SceneScaling::kSimilar : SceneScaling::kAsInTests,
                               {p[0], p[2], p[1], p[3], p[4]});
      const SimulationResult sim = Simulate(scene);
      const std::string error = sim.summary.ok() ? "" : sim.summary.message;
      const Trajectory log = sim.summary.ok() ? MakeLog(sim.trajectory, scene.log) : Trajectory{};
      for (const char* method : {"trajectory", "equation-error"}) {
        sweep->Estimator(
            tags, std::string(pushed ? "pushed" : "free-spin") + (similar ? "" : " (as in tests)"),
            method, scene.friction.reduced(), &log, error);
      }
    }
  }
}

// Steps at the limits of double, far outside the grids (docs/stability.md, domain limits).
void DomainProbes(Sweep* sweep) {
  const SliderProperties s = SquarePlate(1.0, 0.03);
  const FrictionParameters f{0.3, 1.0, 1.0, 0.03};
  const PlanarState moving{0, 0, 0, 0.6, 0.8, 10};
  const AppliedWrench tilt{1, 2, 0, 0.05, -0.03, 0.01};
  auto with_mass = [](double m) { return SquarePlate(m, 0.03); };
  auto friction = [&](double mu, double b, double c) { return FrictionParameters{mu, 1, b, c}; };
  sweep->Probe("h = 1e-300 s", s, f, moving, {}, 1e-300);
  sweep->Probe("h = 1e-200 s, tilting moments", s, f, moving, tilt, 1e-200);
  sweep->Probe("h = 1e300 s", s, f, moving, {}, 1e300);
  sweep->Probe("h = 1e200 s, tilting moments", s, f, moving, tilt, 1e200);
  sweep->Probe("mass = 1e300 kg", with_mass(1e300), f, moving, {}, 0.01);
  sweep->Probe("mass = 1e-300 kg", with_mass(1e-300), f, moving, {}, 0.01);
  sweep->Probe("mass = 1e-300 kg, tilting moments", with_mass(1e-300), f, moving, tilt, 0.01);
  sweep->Probe("mass = 1e-300 kg, h = 1e-10 s (p_n subnormal)", with_mass(1e-300), f, moving, {},
               1e-10);
  sweep->Probe("mass = 1e-300 kg, h = 1e-30 s (p_n underflows to 0)", with_mass(1e-300), f, moving,
               {}, 1e-30);
  sweep->Probe("mass = 1e-300 kg, h = 1e-30 s, at rest", with_mass(1e-300), f, {}, {}, 1e-30);
  sweep->Probe("mu = 1e-300", s, friction(1e-300, 1, 0.03), moving, {}, 0.01);
  sweep->Probe("mu = 1e300", s, friction(1e300, 1, 0.03), moving, {}, 0.01);
  sweep->Probe("c = 1e-300 m", s, friction(0.3, 1, 1e-300), moving, {}, 0.01);
  sweep->Probe("c = 1e300 m", s, friction(0.3, 1, 1e300), moving, {}, 0.01);
  sweep->Probe("b = 1e-300", s, friction(0.3, 1e-300, 0.03), moving, {}, 0.01);
  sweep->Probe("b = 1e300", s, friction(0.3, 1e300, 0.03), moving, {}, 0.01);
  sweep->Probe("speed 1e200 m/s, spin 1e200 rad/s", s, f, {0, 0, 0, 1e200, 1e200, 1e200}, {}, 0.01);
  sweep->Probe("speed 1e300 m/s", s, f, {0, 0, 0, 1e300, -1e300, 0}, {}, 0.01);
  sweep->Probe("speed 1e-300 m/s, tilting moments", s, f, {0, 0, 0, 1e-300, 1e-300, 1e-300}, tilt,
               0.01);
  sweep->Probe("subnormal speed 4e-320 m/s, spin 1e3", s, f, {0, 0, 0, 4e-320, 0, 1e3}, {}, 0.01);
  sweep->Probe("force 1e300 N", s, f, moving, {1e300, 1e300, 0, 1e300, 1e300, 1e300}, 0.01);
  sweep->Probe("f_z = -1e308 N (pressed down)", s, f, moving, {0, 0, -1e308, 0, 0, 0}, 0.01);
  sweep->Probe("f_z = m g (weightless)", s, f, moving, {0, 0, 9.81, 0, 0, 0}, 0.01);
  sweep->Probe("CM height 1e300 m", SquarePlate(1.0, 1e300), f, moving, tilt, 0.01);
  sweep->Probe("state.vx = NaN", s, f, {0, 0, 0, NAN, 0, 0}, {}, 0.01);
  sweep->Probe("state.wz = Inf", s, f, {0, 0, 0, 0, 0, INFINITY}, {}, 0.01);
  sweep->Probe("applied.fx = NaN", s, f, moving, {NAN, 0, 0, 0, 0, 0}, 0.01);
}

std::string Value(const std::string& axis, double v) {
  char buf[32];
  if (axis == "estimator scene") return v == 0 ? "similar" : "as in tests";
  if (axis == "cm height") {
    std::snprintf(buf, sizeof buf, "%g x limit", v);
  } else if (axis == "boundary") {
    if (v == 1.0) return "1";
    std::snprintf(buf, sizeof buf, "1 %c %.3g", v > 1 ? '+' : '-', std::abs(v - 1));
  } else {
    std::snprintf(buf, sizeof buf, "%g", v);
  }
  return buf;
}

std::string Table(Sweep& sweep, const std::vector<std::string>& axis_order) {
  std::ostringstream out;
  out << "| axis | value | step cases | converged | max residual | max indep. residual | "
         "max iterations | NaN/Inf | energy runs | energy violations | estimator runs | "
         "ok / verdict / fail | max rel. error, trajectory | max rel. error, equation-error |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  auto line = [&](const std::string& axis, const std::string& value, const Row& r) {
    out << "| " << axis << " | " << value << " | " << r.step_cases << " | " << r.converged << " | "
        << (r.step_cases ? Sci(r.max_residual) : "-") << " | "
        << (r.step_cases ? Sci(r.max_independent) : "-") << " | " << r.max_iterations << " | "
        << r.nonfinite << " | " << r.energy_runs << " | " << r.energy_violations << " | "
        << r.est_cases << " | ";
    if (r.est_cases) {
      out << r.est_ok << " / " << r.est_verdict << " / " << r.est_fail << " | "
          << Sci(r.est_max_rel_traj) << " | " << Sci(r.est_max_rel_ee);
    } else {
      out << "- | - | -";
    }
    out << " |\n";
  };
  for (const std::string& axis : axis_order) {
    for (const auto& [key, row] : sweep.rows()) {
      if (key.first == axis) line(axis, Value(axis, key.second), row);
    }
  }
  line("all", "", sweep.total());
  return out.str();
}

struct Options {
  bool quick = false;
  bool help = false;
  std::string csv_path, md_path;
  int max_failures = 200;
};

/// The command line; throws std::invalid_argument naming a bad option or value.
Options ParseOptions(int argc, char** argv) {
  Options o;
  bench::Args args(argc, argv);
  while (args.Next()) {
    if (args.Is("--quick"))
      o.quick = true;
    else if (args.Is("--csv"))
      o.csv_path = args.Value();
    else if (args.Is("--markdown"))
      o.md_path = args.Value();
    else if (args.Is("--failures"))
      o.max_failures = args.Integer();
    else if (args.Is("--help")) {
      o.help = true;
      break;  // what follows --help is not read: the help is the answer
    } else {
      throw std::invalid_argument("unknown option " + args.option());
    }
  }
  return o;
}

int Main(int argc, char** argv) {
  SetCeresLogging();  // Ceres' covariance warnings are not results
  Options options;
  try {
    options = ParseOptions(argc, argv);
  } catch (const std::invalid_argument& e) {
    std::cerr << "stability_sweep: " << e.what() << " (see --help)\n";
    return 2;
  }
  if (options.help) {
    std::cout << "stability_sweep [--quick] [--csv PATH] [--markdown PATH] [--failures N]\n"
                 "  --quick       small grids (seconds); default: the full sweep (minutes)\n"
                 "  --csv PATH    one row per case\n"
                 "  --markdown P  the per-axis table and the failures found\n"
                 "  --failures N  list at most N failing cases (default 200)\n";
    return 0;
  }
  std::ofstream csv_file;
  if (!options.csv_path.empty()) {
    csv_file.open(options.csv_path);
    if (!csv_file) {
      std::cerr << "stability_sweep: cannot write " << options.csv_path << "\n";
      return 4;
    }
    csv_file.precision(6);
  }
  Sweep sweep(options.csv_path.empty() ? nullptr : &csv_file, options.max_failures);
  const Grids grids = MakeGrids(options.quick);
  const auto start = std::chrono::steady_clock::now();
  auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  StepGrid(grids, &sweep);
  const double t_step = seconds();
  BoundaryGrid(grids, &sweep);
  const double t_boundary = seconds();
  EstimatorGrid(options.quick, &sweep);
  const double t_est = seconds();
  DomainProbes(&sweep);

  std::ostringstream md;
  md << "Stability sweep (" << (options.quick ? "quick" : "full") << "): step grid " << t_step
     << " s, boundary grid " << t_boundary - t_step << " s, estimator grid " << t_est - t_boundary
     << " s.\n\n"
     << Table(sweep, {"mu", "c", "b", "h", "mass", "cm height", "speed", "spin", "boundary",
                      "estimator scene"})
     << "\nDomain probes (steps at the limits of double):\n\n| probe | outcome |\n|---|---|\n";
  for (const auto& [name, outcome] : sweep.probes())
    md << "| " << name << " | " << outcome << " |\n";
  md << "\nFailing cases: " << sweep.total_failures() << "\n";
  for (const Failure& f : sweep.failures()) md << "- " << f.what << "\n";
  md << "\nEstimator verdicts (a parameter the log cannot identify, or a documented error): "
     << sweep.verdicts().size() << "\n";
  for (const std::string& v : sweep.verdicts()) md << "- " << v << "\n";
  md << "\nConverged steps with more than " << kManyIterations
     << " iterations (listed up to --failures): " << sweep.slow().size() << "\n";
  for (const std::string& v : sweep.slow()) md << "- " << v << "\n";
  std::cout << md.str();
  if (!options.md_path.empty()) {
    std::ofstream out(options.md_path);
    out << md.str();
    if (!out) {
      std::cerr << "stability_sweep: cannot write " << options.md_path << "\n";
      return 4;
    }
  }
  return sweep.total_failures() == 0 ? 0 : 3;
}

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) { return slideid::Main(argc, argv); }
