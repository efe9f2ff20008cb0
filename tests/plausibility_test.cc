// The model-mismatch check of the verdicts (estimator/plausibility.h): residuals far above
// the log's own noise make an estimate suspect, but not residuals at the level of the fit's
// own discretisation on a noise-free log (issue 17: make-dataset --count 20 gave 60 of 60
// estimates "residuals 10.9 times the log's own noise").

#include "estimator/plausibility.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "datasets/dataset.h"
#include "estimator/identifiability.h"
#include "estimator/identify.h"
#include "forward_model/constants.h"

namespace slideid {
namespace {

bool SuspectForResiduals(const ParameterEstimate& p) {
  return p.verdict == Verdict::kSuspect && p.reason.find("residuals") != std::string::npos;
}

TEST(Plausibility, ResidualsAreComparedWithTheNoiseAndTheModelFloorTogether) {
  std::array<ParameterEstimate, 3> p;
  for (ParameterEstimate& e : p) e = EstimateFromLog(std::log(0.3), 0.01);
  PlausibilityContext c;
  c.residual_rms = 10.0;
  c.log_noise = 1.0;
  JudgeEstimates(c, &p);
  EXPECT_TRUE(SuspectForResiduals(p[kA])) << p[kA].reason;
  for (ParameterEstimate& e : p) e = EstimateFromLog(std::log(0.3), 0.01);
  c.model_floor = 5.0;  // 10 / hypot(1, 5) = 1.96 < 3
  JudgeEstimates(c, &p);
  EXPECT_EQ(p[kA].verdict, Verdict::kOk) << p[kA].reason;
  for (ParameterEstimate& e : p) e = EstimateFromLog(std::log(0.3), 0.01);
  c.model_floor = 2.0;  // 10 / hypot(1, 2) = 4.5 > 3
  JudgeEstimates(c, &p);
  EXPECT_TRUE(SuspectForResiduals(p[kA])) << p[kA].reason;
  EXPECT_NE(p[kA].reason.find("discretisation"), std::string::npos) << p[kA].reason;
}

// make-dataset's defaults: noise-free logs, simulated at 1 ms and logged at 100 Hz.
TEST(Plausibility, NoiseFreeLogsAreNotSuspectForTheirDiscretisation) {
  DatasetSpec spec;
  spec.log.noise = NoiseSpec{};
  for (int k = 0; k < 5; ++k) {
    Trajectory log;
    DrawDatasetLog(spec, k, &log);
    const EstimateResult r = Identify(log, IdentifyOptions{});
    ASSERT_GT(r.residual_rms, 3 * r.log_noise) << "log " << k << ": the case the floor is for";
    for (int i = 0; i < 3; ++i) {
      EXPECT_FALSE(SuspectForResiduals(r.parameters[i]))
          << "log " << k << " " << ParameterName(i) << ": " << r.parameters[i].reason;
    }
  }
}

// A noisy log whose force stream does not describe its motion (the logged force swings by
// +-60% at 2 Hz around the one applied) is still marked.
TEST(Plausibility, ALogItsModelCannotFollowIsStillSuspect) {
  DatasetSpec spec;
  spec.log.noise.pose_m = 3e-4;
  spec.log.noise.angle_rad = 3e-3;
  Trajectory log;
  DrawDatasetLog(spec, 0, &log);
  for (TrajectorySample& s : log.samples) {
    const double f = 1.0 + 0.6 * std::sin(2 * kPi * 2.0 * s.t_s);
    s.applied.fx *= f;
    s.applied.fy *= f;
    s.applied.tz *= f;
  }
  const EstimateResult r = Identify(log, IdentifyOptions{});
  bool any = false;
  for (const ParameterEstimate& p : r.parameters) any = any || SuspectForResiduals(p);
  EXPECT_TRUE(any) << "residuals " << r.residual_rms << " against noise " << r.log_noise << ": "
                   << r.parameters[0].reason << " / " << ToString(r.parameters[0].verdict);
}

}  // namespace
}  // namespace slideid
