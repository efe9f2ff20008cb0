// The closed form and the equation error on the logs users have: rest phases, several logs
// of one slider, noisy velocities, and velocities differentiated from noisy poses. Logs are
// drawn by the datasets library (random push programs with rests), identified, and compared
// with the truth they were made with.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "datasets/dataset.h"
#include "estimator/closed_form.h"
#include "estimator/equation_error.h"
#include "estimator/identify.h"
#include "estimator/plausibility.h"

namespace slideid {
namespace {

std::array<double, 3> Truth(const DatasetEntry& e) {
  const ReducedFriction t = e.scene.friction.reduced();
  return {{t.a, t.b, t.c}};
}

/// A dataset of logs with measured velocities carrying `velocity_mps` of noise (and ten
/// times that in rad/s on the spin), 100 Hz rows of a 1 ms simulation.
DatasetSpec VelocityLogs(double velocity_mps, std::uint64_t seed) {
  DatasetSpec spec;
  spec.seed = seed;
  spec.log.motion = LogMotion::kBoth;
  spec.log.step_info = false;
  spec.log.noise.velocity_mps = velocity_mps;
  spec.log.noise.spin_radps = 10 * velocity_mps;
  return spec;
}

/// The estimate of a parameter, or the value it would have had when the method declines it.
double ValueOrHeld(const ParameterEstimate& p) { return p.identifiable ? p.value : p.held_at; }

int Excluded(const EstimateResult& r, const std::string& reason) {
  for (const auto& [what, count] : r.steps_excluded) {
    if (what == reason) return count;
  }
  return 0;
}

// ---- rest phases (issue 11: "the closed form's a drops 3x with no warning") -------------

// Rests of 1-2 s after each push: most rows are at rest. A noisy log has no mode column,
// and its resting rows read as slow motion in random directions with impulses of pure
// noise; kept as sliding steps, they pulled the closed form's a from 0.41 to 0.014 and the
// equation error's to 0.026 (this log, before rest rows were recognised). Both must now
// stay within kRestTolerance of the truth, and say why they left rows out.
constexpr double kRestTolerance = 0.03;

TEST(CheapMethods, RestPhasesDoNotPullFrictionTowardsZero) {
  DatasetSpec spec = VelocityLogs(5e-4, 7);
  spec.program.rest_s = {1.0, 2.0};
  for (int index = 0; index < 3; ++index) {
    Trajectory log;
    const DatasetEntry e = DrawDatasetLog(spec, index, &log);
    const auto truth = Truth(e);
    const EstimateResult cf = EstimateClosedForm(log, {});
    const EstimateResult ee = EstimateEquationError(log, {});
    for (const EstimateResult* r : {&cf, &ee}) {
      SCOPED_TRACE(std::string(ToString(r->method)) + " log " + std::to_string(index));
      EXPECT_NEAR(ValueOrHeld(r->parameters[kA]) / truth[kA], 1.0, kRestTolerance);
      EXPECT_GT(Excluded(*r, "at rest (speed within the noise)"), r->steps_total / 3);
      EXPECT_GT(Excluded(*r, "start of a sliding phase"), 0);
    }
    EXPECT_TRUE(ee.parameters[kA].identifiable) << ee.parameters[kA].reason;
  }
}

// ---- velocities differentiated from noisy poses ------------------------------------------

TEST(CheapMethods, NoisyMotionCaptureIsNotIdentifiableWithTheReason) {
  // 0.3 mm and 3 mrad at 100 Hz: the change of a differentiated velocity over a step
  // carries sqrt(6) 0.3 mm / 10 ms = 7 cm/s of noise, against a friction's a g h of about
  // 3 cm/s. The per-step estimates are then biased, not just noisy (the closed form said
  // a = 0.76 for 0.4 on the bundled log): neither method may report an interval.
  DatasetSpec spec;
  spec.seed = 3;
  spec.log.noise.pose_m = 3e-4;
  spec.log.noise.angle_rad = 3e-3;
  Trajectory log;
  DrawDatasetLog(spec, 0, &log);
  ASSERT_FALSE(log.measured.velocity);
  const EstimateResult cf = EstimateClosedForm(log, {});
  const EstimateResult ee = EstimateEquationError(log, {});
  for (const EstimateResult* r : {&cf, &ee}) {
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = r->parameters[i];
      SCOPED_TRACE(std::string(ToString(r->method)) + " " + ParameterName(i));
      EXPECT_FALSE(p.identifiable);
      EXPECT_NE(p.reason.find("differentiated from noisy poses"), std::string::npos) << p.reason;
    }
    EXPECT_GT(Excluded(*r, r->method == EstimatorMethod::kClosedForm
                               ? "a: impulse noise swamps the friction"
                               : "impulse noise swamps the friction"),
              0);
  }
}

// ---- honest intervals --------------------------------------------------------------------

// Over noisy logs of every kind, an identifiable parameter's interval never reaches 0 and
// never spans more than kMaxIntervalFactor (issue 11: a = 0.0042 in [2.2e-308, 0.0086]).
TEST(CheapMethods, IntervalsNeverReachZeroNorSpanOrdersOfMagnitude) {
  std::vector<DatasetSpec> specs = {VelocityLogs(2e-3, 21), VelocityLogs(2e-4, 22)};
  DatasetSpec poses;
  poses.seed = 23;
  poses.log.noise.pose_m = 2e-5;
  poses.log.noise.angle_rad = 2e-4;
  specs.push_back(poses);
  DatasetSpec short_log = VelocityLogs(4e-3, 24);
  short_log.program.count = 1;
  specs.push_back(short_log);
  for (const DatasetSpec& spec : specs) {
    for (int index = 0; index < 4; ++index) {
      Trajectory log;
      DrawDatasetLog(spec, index, &log);
      const EstimateResult cf = EstimateClosedForm(log, {});
      if (cf.status == TerminationStatus::kTooLittleExcitation) continue;
      const EstimateResult ee = EstimateEquationError(log, {});
      for (const EstimateResult* r : {&cf, &ee}) {
        for (const ParameterEstimate& p : r->parameters) {
          if (!p.identifiable) {
            EXPECT_FALSE(p.reason.empty());
            continue;
          }
          EXPECT_GT(p.ci95_lo, 0.0);
          EXPECT_LE(p.ci95_hi / p.ci95_lo, kMaxIntervalFactor);
          EXPECT_TRUE(p.ci95_lo <= p.value && p.value <= p.ci95_hi);
        }
      }
    }
  }
}

// ---- pooling (issue 10: "the closed-form and equation-error methods pool too") --------

/// Logs of one friction on sliders of different mass and size, simulated at the log rate
/// without noise: each one alone, and all together, give the truth exactly.
DatasetSpec OneSurface(std::uint64_t seed) {
  DatasetSpec spec;
  spec.seed = seed;
  spec.mu = {0.35, 0.35};
  spec.e_t = {1.0, 1.0};
  spec.e_o = {1.3, 1.3};
  spec.e_r_m = {0.03, 0.03};
  spec.dt_s = 0.01;
  spec.log.log_every = 1;
  spec.log.motion = LogMotion::kBoth;
  return spec;
}

// Exact logs simulated at the log rate: every step's Appendix A holds to rounding.
constexpr double kExactRelTol = 1e-6;

TEST(CheapMethods, PoolLogsOfDifferentSlidersAndReportEachOnItsOwn) {
  const DatasetSpec spec = OneSurface(5);
  std::vector<Trajectory> logs(3);
  std::array<double, 3> truth{};
  for (int k = 0; k < 3; ++k) truth = Truth(DrawDatasetLog(spec, k, &logs[k]));
  ASSERT_NE(logs[0].slider.mass_kg, logs[1].slider.mass_kg);
  for (EstimatorMethod method : {EstimatorMethod::kClosedForm, EstimatorMethod::kEquationError}) {
    IdentifyOptions options;
    options.method = method;
    const EstimateResult r = Identify(logs, options);
    SCOPED_TRACE(ToString(method));
    EXPECT_EQ(r.method, method);
    EXPECT_TRUE(r.converged) << r.message;
    ASSERT_EQ(r.logs.size(), 3u);
    int steps = 0;
    for (const LogResult& log : r.logs) {
      steps += log.steps_used;
      for (int i = 0; i < 3; ++i) {
        ASSERT_TRUE(log.parameters[i].identifiable) << log.name << " " << ParameterName(i);
        EXPECT_NEAR(log.parameters[i].value / truth[i], 1.0, kExactRelTol) << log.name;
      }
    }
    EXPECT_EQ(r.steps_used, steps);
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(r.parameters[i].identifiable) << ParameterName(i);
      EXPECT_NEAR(r.parameters[i].value / truth[i], 1.0, kExactRelTol) << ParameterName(i);
      EXPECT_TRUE(r.heterogeneity[i].tested);
      EXPECT_EQ(r.heterogeneity[i].logs, 3);
    }
    for (const StepResidual& res : r.residuals) EXPECT_TRUE(res.log >= 0 && res.log < 3);
  }
}

TEST(CheapMethods, PooledIntervalWidensWhenLogsDisagree) {
  // Two surfaces 20% apart in a, three logs each, 0.2 mm/s velocity noise: each log pins
  // its own a to about 0.1%, so the pooled interval must come from the spread of the logs
  // (cluster-robust over logs), hold the logs' own values, and say that it widened; the
  // heterogeneity test must call the logs inconsistent.
  std::vector<Trajectory> logs;
  std::vector<double> own;
  for (double mu : {0.3, 0.36}) {
    DatasetSpec spec = VelocityLogs(2e-4, 9);
    spec.mu = {mu, mu};
    spec.e_t = {1.0, 1.0};
    for (int k = 0; k < 3; ++k) {
      logs.emplace_back();
      DrawDatasetLog(spec, k, &logs.back());
      own.push_back(mu);
    }
  }
  IdentifyOptions options;
  options.method = EstimatorMethod::kEquationError;
  const EstimateResult r = Identify(logs, options);
  const ParameterEstimate& a = r.parameters[kA];
  ASSERT_TRUE(a.identifiable) << a.reason;
  EXPECT_NE(a.note.find("widened"), std::string::npos) << a.note;
  EXPECT_NE(a.note.find("6 logs"), std::string::npos) << a.note;
  EXPECT_LT(a.ci95_lo, 0.3);
  EXPECT_GT(a.ci95_hi, 0.36);
  EXPECT_TRUE(r.heterogeneity[kA].tested);
  EXPECT_FALSE(r.heterogeneity[kA].consistent);
  // The same six logs' own estimates recover their own surfaces.
  ASSERT_EQ(r.logs.size(), logs.size());
  for (size_t k = 0; k < logs.size(); ++k) {
    ASSERT_TRUE(r.logs[k].parameters[kA].identifiable);
    EXPECT_NEAR(r.logs[k].parameters[kA].value / own[k], 1.0, 0.01) << r.logs[k].name;
  }
}

TEST(CheapMethods, PoolingOneLogIsTheSingleLogEstimate) {
  const DatasetSpec spec = VelocityLogs(2e-3, 13);
  std::vector<Trajectory> logs(1);
  DrawDatasetLog(spec, 0, &logs[0]);
  const EstimateResult pooled = EstimateEquationError(logs, {});
  const EstimateResult single = EstimateEquationError(logs[0], {});
  EXPECT_TRUE(pooled.logs.empty());
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(pooled.parameters[i].identifiable, single.parameters[i].identifiable);
    if (single.parameters[i].identifiable) {
      EXPECT_EQ(pooled.parameters[i].value, single.parameters[i].value);
    }
  }
  EXPECT_THROW(EstimateClosedForm(std::vector<Trajectory>{}, {}), std::invalid_argument);
}

// ---- calibration (issue 11: "95% intervals cover the truth in 90-98% of cases") --------

// The equation error's intervals on noisy velocity logs, CI-sized (the full Monte Carlo over
// every condition is in the README's figures). With kLogs logs, a calibrated 95% interval
// covers at least kMinCovered of them with probability 0.99 (binomial); an interval as
// conservative as the white-noise one was (4x), or as optimistic as ignoring the shared
// samples, moves the median of |error| / half-width far from its calibrated 0.674 / 1.96
// = 0.34 (between kMinMedianRatio and kMaxMedianRatio with 30 logs and t quantiles).
constexpr int kLogs = 30;
constexpr int kMinCovered = 25;
constexpr double kMinMedianRatio = 0.15;
constexpr double kMaxMedianRatio = 0.6;

void ExpectCalibrated(const DatasetSpec& spec, const std::string& what) {
  std::array<int, 3> covered{}, reported{};
  std::array<std::vector<double>, 3> ratio;
  for (int index = 0; index < kLogs; ++index) {
    Trajectory log;
    const auto truth = Truth(DrawDatasetLog(spec, index, &log));
    const EstimateResult r = EstimateEquationError(log, {});
    for (int i = 0; i < 2; ++i) {  // a and b; c is too weakly excited in these programs
      const ParameterEstimate& p = r.parameters[i];
      if (!p.identifiable) continue;
      ++reported[i];
      covered[i] += p.ci95_lo <= truth[i] && truth[i] <= p.ci95_hi;
      const double half = 0.5 * std::log(p.ci95_hi / p.ci95_lo);
      ratio[i].push_back(std::abs(std::log(p.value / truth[i])) / half);
    }
  }
  for (int i = 0; i < 2; ++i) {
    SCOPED_TRACE(what + " " + ParameterName(i));
    ASSERT_EQ(reported[i], kLogs);
    EXPECT_GE(covered[i], kMinCovered);
    std::nth_element(ratio[i].begin(), ratio[i].begin() + kLogs / 2, ratio[i].end());
    EXPECT_GT(ratio[i][kLogs / 2], kMinMedianRatio);
    EXPECT_LT(ratio[i][kLogs / 2], kMaxMedianRatio);
  }
}

TEST(CheapMethods, EquationErrorIntervalsAreCalibratedOnNoisyVelocities) {
  DatasetSpec matched = VelocityLogs(2e-3, 31);
  matched.dt_s = 0.01;
  matched.log.log_every = 1;
  ExpectCalibrated(matched, "logged at the simulation rate");
  DatasetSpec forces = VelocityLogs(2e-3, 32);
  forces.log.noise.force_relative = 0.03;
  forces.log.noise.outlier_fraction = 0.01;
  forces.log.noise.outlier_m = 0.01;
  ExpectCalibrated(forces, "3% force noise and outliers, simulated finer than logged");
}

// ---- the full Monte Carlo (docs/identify.md, "Which estimator"; run on demand)
// ---------------------

/// One condition of the coverage table.
struct Condition {
  std::string name;
  DatasetSpec spec;
};

std::vector<Condition> CoverageConditions() {
  DatasetSpec velocities = VelocityLogs(2e-3, 11);  // 1 ms simulation logged at 100 Hz
  velocities.log.noise.pose_m = 3e-4;               // moves the push point's moment arm
  velocities.log.noise.angle_rad = 3e-3;
  std::vector<Condition> out{{"velocities 2 mm/s", velocities}};
  auto with = [&](const std::string& name, auto change) {
    DatasetSpec s = velocities;
    change(&s);
    out.push_back({name, s});
  };
  with("+ force noise 1%", [](DatasetSpec* s) { s->log.noise.force_relative = 0.01; });
  with("+ force noise 3%", [](DatasetSpec* s) { s->log.noise.force_relative = 0.03; });
  with("300 rows", [](DatasetSpec* s) { s->program.count = 4; });
  with("3000 rows", [](DatasetSpec* s) { s->program.count = 40; });
  with("logged at the simulation rate", [](DatasetSpec* s) {
    s->dt_s = 0.01;
    s->log.log_every = 1;
  });
  with("+ outliers 1% of 1 cm", [](DatasetSpec* s) {
    s->log.noise.outlier_fraction = 0.01;
    s->log.noise.outlier_m = 0.01;
  });
  with("rests of 1-2 s", [](DatasetSpec* s) { s->program.rest_s = {1.0, 2.0}; });
  with("velocities 0.2 mm/s", [](DatasetSpec* s) {
    s->log.noise.velocity_mps = 2e-4;
    s->log.noise.spin_radps = 2e-3;
  });
  DatasetSpec poses = velocities;
  poses.log.motion = LogMotion::kPoses;
  poses.log.noise.velocity_mps = poses.log.noise.spin_radps = 0;
  out.push_back({"poses 0.3 mm, 3 mrad", poses});
  poses.log.noise.pose_m = 2e-5;
  poses.log.noise.angle_rad = 2e-4;
  out.push_back({"poses 0.02 mm, 0.2 mrad", poses});
  poses.log.noise.outlier_fraction = 0.01;
  poses.log.noise.outlier_m = 5e-3;
  out.push_back({"poses 0.02 mm + outliers", poses});
  return out;
}

// SLIDEID_COVERAGE_LOGS=100 build/bin/slideid_tests --gtest_filter='*FullMonteCarlo*'
// prints, per condition, method and parameter: how many logs it was reported for (and how
// many of those suspect), how many of their 95% intervals hold the truth, the mean relative
// error, and the median relative standard error. Skipped unless asked (minutes, not seconds).
TEST(CheapMethodsCoverage, FullMonteCarlo) {
  const char* logs_env = std::getenv("SLIDEID_COVERAGE_LOGS");
  if (!logs_env) GTEST_SKIP() << "set SLIDEID_COVERAGE_LOGS to run";
  const int logs = std::atoi(logs_env);
  std::printf(
      "| condition | method | parameter | reported | suspect | coverage | bias | "
      "median rel. stderr |\n|---|---|---|---|---|---|---|---|\n");
  for (const Condition& c : CoverageConditions()) {
    std::array<std::array<std::vector<double>, 3>, 2> error, stderr_rel;
    std::array<std::array<int, 3>, 2> covered{}, suspect{};
    for (int index = 0; index < logs; ++index) {
      Trajectory log;
      const auto truth = Truth(DrawDatasetLog(c.spec, index, &log));
      const EstimateResult cf = EstimateClosedForm(log, {});
      const EstimateResult ee = EstimateEquationError(log, {});
      const EstimateResult* results[2] = {&cf, &ee};
      for (int m = 0; m < 2; ++m) {
        for (int i = 0; i < 3; ++i) {
          const ParameterEstimate& p = results[m]->parameters[i];
          if (!p.identifiable) continue;
          error[m][i].push_back(p.value / truth[i] - 1);
          stderr_rel[m][i].push_back(p.stderr_value / p.value);
          covered[m][i] += p.ci95_lo <= truth[i] && truth[i] <= p.ci95_hi;
          suspect[m][i] += p.verdict == Verdict::kSuspect;
        }
      }
    }
    for (int m = 0; m < 2; ++m) {
      for (int i = 0; i < 3; ++i) {
        const int n = static_cast<int>(error[m][i].size());
        std::printf("| %s | %s | %s | %d/%d | %d |", c.name.c_str(),
                    m == 0 ? "closed-form" : "equation-error", ParameterName(i), n, logs,
                    suspect[m][i]);
        if (n == 0) {
          std::printf(" - | - | - |\n");
          continue;
        }
        double bias = 0;
        for (double e : error[m][i]) bias += e / n;
        std::vector<double>& se = stderr_rel[m][i];
        std::nth_element(se.begin(), se.begin() + n / 2, se.end());
        std::printf(" %.0f%% | %+.2f%% | %.2f%% |\n", 100.0 * covered[m][i] / n, 100 * bias,
                    100 * se[n / 2]);
      }
    }
    std::fflush(stdout);
  }
}

}  // namespace
}  // namespace slideid
