// advise-push (estimator/push_advice.h): the information of a push two independent ways,
// the ranking, the prior, degenerate and bad input, the tool, and the advice against random
// pushes on a CI-sized race (fixtures/push_race.h).

#include "estimator/push_advice.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "datasets/dataset.h"
#include "fixtures/push_race.h"
#include "forward_model/simulator.h"
#include "io/push_advice_report.h"
#include "io/result_json.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

// Central differences of the replayed poses with steps of 1e-6 (log-parameters) and 1e-7
// (m, rad, m/s, rad/s) have truncation errors near 1e-12 and rounding errors near 1e-10
// relative to J; products of two J's keep that. 1e-6 relative leaves room for a step that
// is close to the stick/slip switch without hiding a wrong derivative (those are off by
// whole percents).
constexpr double kInformationRelativeTolerance = 1e-6;

SliderProperties Box(const ContactPatch& patch) {
  SliderProperties s;
  s.mass_kg = 0.8;
  s.inertia_kgm2 = UniformInertia(patch, s.mass_kg);
  s.com_height_m = 0.02;
  return s;
}

ReducedFriction Truth() { return {0.4, 1.3, 0.03}; }

/// The (x, y, L theta) of every row of `log` replayed from `start` with (a, b, c).
Eigen::VectorXd ReplayedPoses(Trajectory log, const PlanarState& start, const ReducedFriction& f) {
  log.samples[0].state = start;
  const SimulationResult r = ReplayLog(log, f, 1);
  EXPECT_TRUE(r.summary.ok()) << r.summary.message;
  const double length = std::sqrt(log.slider.inertia_kgm2 / log.slider.mass_kg);
  Eigen::VectorXd out(3 * log.samples.size());
  for (size_t i = 0; i < log.samples.size(); ++i) {
    const PlanarState& s = r.trajectory.samples[i].state;
    out.segment<3>(3 * i) << s.x, s.y, length * s.theta;
  }
  return out;
}

TEST(PushAdvice, InformationOfAPushAgreesWithCentralDifferences) {
  const ContactPatch patch = ContactPatch::Rectangle(0.09, 0.09);
  const SliderProperties slider = Box(patch);
  PushCandidateOptions candidates;
  candidates.contact_points = 8;
  candidates.cone_fractions = {0.5};
  candidates.lengths_m = {0.05};
  // Off the centre of an edge and at an angle: the slider slides and turns (a, b and c).
  const PushCandidate push = CandidatePushes(patch, candidates)[1];
  const Scene scene = PushScene(slider, Truth(), patch, push, candidates, 0.01);
  const SimulationResult sim = Simulate(scene);
  ASSERT_TRUE(sim.summary.ok()) << sim.summary.message;
  // The rows from just before the slider moves to just after it stops: one shooting segment
  // from a sliding start (the at-rest rows carry no information either way).
  const std::vector<TrajectorySample>& rows = sim.trajectory.samples;
  int first = -1, last = -1;
  for (int i = 0; i < static_cast<int>(rows.size()); ++i) {
    if (std::hypot(rows[i].state.vx, rows[i].state.vy) > 1e-3) {
      if (first < 0) first = i;
      last = i;
    }
  }
  ASSERT_GT(last - first, 20);
  Trajectory part = sim.trajectory;
  part.samples.assign(rows.begin() + first, rows.begin() + last + 1);
  part.samples[0].mode = SampleMode::kStart;
  TrajectoryOptions one_segment;
  one_segment.segment_steps = static_cast<int>(part.samples.size());
  const Eigen::Matrix3d h = LogInformation(part, Truth(), 1.0, one_segment);

  // The same by central differences of the replay, the start state projected out.
  const PlanarState s0 = part.samples[0].state;
  const int n = 3 * static_cast<int>(part.samples.size());
  Eigen::MatrixXd jf(n, 3), js(n, 6);
  const double log_step = 1e-6, state_step = 1e-7;
  for (int p = 0; p < 3; ++p) {
    ReducedFriction up = Truth(), down = Truth();
    double* u[3] = {&up.a, &up.b, &up.c};
    double* d[3] = {&down.a, &down.b, &down.c};
    *u[p] *= std::exp(log_step);
    *d[p] *= std::exp(-log_step);
    jf.col(p) = (ReplayedPoses(part, s0, up) - ReplayedPoses(part, s0, down)) / (2 * log_step);
  }
  for (int k = 0; k < 6; ++k) {
    PlanarState up = s0, down = s0;
    double* u[6] = {&up.x, &up.y, &up.theta, &up.vx, &up.vy, &up.wz};
    double* d[6] = {&down.x, &down.y, &down.theta, &down.vx, &down.vy, &down.wz};
    *u[k] += state_step;
    *d[k] -= state_step;
    js.col(k) =
        (ReplayedPoses(part, up, Truth()) - ReplayedPoses(part, down, Truth())) / (2 * state_step);
  }
  const Eigen::MatrixXd hss_pinv =
      (js.transpose() * js).completeOrthogonalDecomposition().pseudoInverse();
  const Eigen::MatrixXd projected = jf - js * (hss_pinv * (js.transpose() * jf));
  const Eigen::Matrix3d h_fd = projected.transpose() * projected;
  EXPECT_GT(h.diagonal().minCoeff(), 0.0) << h;
  EXPECT_LT((h - h_fd).norm(), kInformationRelativeTolerance * h.norm())
      << "sensitivities:\n"
      << h << "\ncentral differences:\n"
      << h_fd;
  // Over a pose noise sigma: the same over sigma^2, and symmetric (an in-place symmetrisation
  // once mixed scaled and unscaled entries).
  const double sigma = 3e-4;
  const Eigen::Matrix3d scaled = LogInformation(part, Truth(), sigma, one_segment);
  EXPECT_EQ((scaled - scaled.transpose()).norm(), 0.0) << scaled;
  EXPECT_LT((scaled * sigma * sigma - h).norm(), 1e-12 * h.norm());
  // And through the candidate's own evaluation: its log's information over the pose noise.
  PushAdviceOptions options;
  options.candidates = candidates;
  const CandidateAdvice c = EvaluatePush(slider, patch, Truth(), push, options);
  ASSERT_TRUE(c.simulated) << c.failure;
  EXPECT_GT(c.information_log.diagonal().minCoeff(), 0.0);
}

Eigen::Matrix3d RandomInformation(std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd j(10, 3);
  for (int i = 0; i < 10; ++i) {
    for (int k = 0; k < 3; ++k) j(i, k) = normal(*rng);
  }
  return j.transpose() * j;
}

TEST(PushAdvice, RankingIsMonotoneInTheInformation) {
  std::mt19937_64 rng(21);
  const Eigen::Matrix3d prior = Eigen::Vector3d(4.0, 1.0, 0.25).asDiagonal();
  for (AdviceCriterion criterion : {AdviceCriterion::kLeastKnown, AdviceCriterion::kDOptimal}) {
    SCOPED_TRACE(ToString(criterion));
    const Eigen::Matrix3d h0 = RandomInformation(&rng);
    const double scales[4] = {0.5, 2.0, 1.0, 4.0};
    std::vector<CandidateAdvice> candidates(4);
    for (int i = 0; i < 4; ++i) {
      candidates[i].simulated = true;
      candidates[i].push.length_m = scales[i];  // to know them again after the ranking
      candidates[i].information_log = scales[i] * h0;
    }
    RankCandidates(prior, criterion, &candidates);
    EXPECT_EQ(candidates[0].push.length_m, 4.0);
    EXPECT_EQ(candidates[1].push.length_m, 2.0);
    EXPECT_EQ(candidates[2].push.length_m, 1.0);
    EXPECT_EQ(candidates[3].push.length_m, 0.5);
    for (int i = 0; i + 1 < 4; ++i) EXPECT_LE(candidates[i].score, candidates[i + 1].score);
    // More information (in the Loewner order) never scores worse, nor any standard error.
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Matrix3d h = RandomInformation(&rng), extra = RandomInformation(&rng);
      EXPECT_LE(AdviceScore(prior + h + extra, criterion), AdviceScore(prior + h, criterion));
      const std::array<double, 3> before = RelativeStdErrors(prior + h);
      const std::array<double, 3> after = RelativeStdErrors(prior + h + extra);
      for (int p = 0; p < 3; ++p) EXPECT_LE(after[p], before[p] * (1 + 1e-12));
    }
  }
}

TEST(PushAdvice, PriorAloneGivesAFiniteRanking) {
  const ContactPatch patch = ContactPatch::Disk(0.05);
  SliderProperties slider = Box(patch);
  const FrictionKnowledge prior = KnowledgeFromPrior(FrictionPrior{}, patch);
  // The prior's centre and width: a 0.1-1 -> sqrt(0.1), log sd ln(10) / 3.92.
  EXPECT_NEAR(prior.estimate.a, std::sqrt(0.1), 1e-15);
  EXPECT_NEAR(1 / std::sqrt(prior.information_log(0, 0)), std::log(10.0) / (2 * kZ95), 1e-15);
  PushAdviceOptions options;
  options.candidates.contact_points = 4;
  options.candidates.cone_fractions = {-0.8, 0.0};
  options.candidates.lengths_m = {0.05};
  const PushAdvice advice = AdvisePush(slider, patch, prior, options);
  ASSERT_EQ(advice.ranking.size(), 8u);
  for (const CandidateAdvice& c : advice.ranking) {
    ASSERT_TRUE(c.simulated) << c.failure;
    for (int p = 0; p < 3; ++p) {
      EXPECT_TRUE(std::isfinite(c.relative_stderr_after[p]));
      EXPECT_LE(c.relative_stderr_after[p], advice.relative_stderr_now[p] * (1 + 1e-12));
    }
  }
  for (size_t i = 0; i + 1 < advice.ranking.size(); ++i) {
    EXPECT_LE(advice.ranking[i].score, advice.ranking[i + 1].score);
  }
  // Pushing teaches a far more than the prior knew.
  EXPECT_LT(advice.ranking[0].relative_stderr_after[0], 0.1 * advice.relative_stderr_now[0]);
}

TEST(PushAdvice, DegenerateInformationGivesInfinityNotNaN) {
  for (double v : RelativeStdErrors(Eigen::Matrix3d::Zero())) EXPECT_EQ(v, INFINITY);
  // Only a known: b and c unknown, a finite.
  Eigen::Matrix3d only_a = Eigen::Matrix3d::Zero();
  only_a(0, 0) = 100;
  const std::array<double, 3> se = RelativeStdErrors(only_a);
  EXPECT_NEAR(se[0], 0.1, 1e-15);
  EXPECT_EQ(se[1], INFINITY);
  EXPECT_EQ(se[2], INFINITY);
  // A singular prior (nothing known), a push that teaches nothing, a failed one and a push
  // that teaches everything: no NaN, the informative push first, the failed one last.
  std::vector<CandidateAdvice> c(3);
  c[0].simulated = true;  // zero information
  c[1].simulated = false;
  c[1].failure = "toppling";
  c[2].simulated = true;
  c[2].information_log = Eigen::Vector3d(1e4, 1e4, 1e2).asDiagonal();
  for (AdviceCriterion criterion : {AdviceCriterion::kLeastKnown, AdviceCriterion::kDOptimal}) {
    std::vector<CandidateAdvice> ranked = c;
    RankCandidates(Eigen::Matrix3d::Zero(), criterion, &ranked);
    EXPECT_EQ(ranked[0].information_log(0, 0), 1e4);
    EXPECT_FALSE(ranked[2].simulated);
    for (const CandidateAdvice& r : ranked) {
      EXPECT_FALSE(std::isnan(r.score));
      for (double v : r.relative_stderr_after) EXPECT_FALSE(std::isnan(v));
    }
    EXPECT_NEAR(ranked[0].relative_stderr_after[2], 0.1, 1e-15);
  }
  // The whole advice from nothing known at all (a singular prior): every standard error
  // now infinite, after each push finite or infinite, never NaN.
  const ContactPatch patch = ContactPatch::Rectangle(0.09, 0.09);
  FrictionKnowledge nothing;
  nothing.estimate = Truth();
  PushAdviceOptions options;
  options.candidates.contact_points = 2;
  options.candidates.cone_fractions = {0.0};
  options.candidates.lengths_m = {0.05};
  const PushAdvice advice = AdvisePush(Box(patch), patch, nothing, options);
  for (double v : advice.relative_stderr_now) EXPECT_EQ(v, INFINITY);
  for (const CandidateAdvice& a : advice.ranking) {
    EXPECT_FALSE(std::isnan(a.score));
    for (double v : a.relative_stderr_after) EXPECT_FALSE(std::isnan(v));
  }
}

TEST(PushAdvice, CorrelationsFromTheLogsKeepTheResultsStandardErrors) {
  FrictionKnowledge known;
  known.information_log = Eigen::Vector3d(1 / 0.01, 1 / 0.04, 1 / 1e-4).asDiagonal();
  // Logs that pin down log a + log b far better than either: a and b strongly anti-correlated.
  Eigen::Matrix3d logs = Eigen::Matrix3d::Zero();
  logs.topLeftCorner<2, 2>() << 1e4, 1e4, 1e4, 1e4;
  logs(2, 2) = 1e3;
  const FrictionKnowledge k = WithCorrelations(known, logs);
  const std::array<double, 3> se = RelativeStdErrors(k.information_log);
  EXPECT_NEAR(se[0], 0.1, 1e-12);
  EXPECT_NEAR(se[1], 0.2, 1e-12);
  EXPECT_NEAR(se[2], 0.01, 1e-12);
  const Eigen::Matrix3d c = k.information_log.inverse();
  EXPECT_LT(c(0, 1) / std::sqrt(c(0, 0) * c(1, 1)), -0.9);
  // A push along a + b then teaches little; one along a - b much (c, known best, is not
  // the least-known): the ranking sees it, which the standard errors alone could not.
  std::vector<CandidateAdvice> pushes(2);
  for (CandidateAdvice& p : pushes) p.simulated = true;
  const Eigen::Vector3d plus(1, 1, 0), minus(1, -1, 0);
  pushes[0].information_log = 1e3 * plus * plus.transpose();
  pushes[1].information_log = 1e3 * minus * minus.transpose();
  pushes[1].push.length_m = 1;  // to know it again
  RankCandidates(k.information_log, AdviceCriterion::kLeastKnown, &pushes);
  EXPECT_EQ(pushes[0].push.length_m, 1);
}

TEST(PushAdvice, BadInputNamesTheOptionOrThePath) {
  const auto message = [](const std::string& json) {
    try {
      ParseAdviceResult(json);
    } catch (const ResultJsonError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(message("{").find("not JSON"), std::string::npos) << message("{");
  // Nested deeper than a recursive dump goes, or a number beyond a double: an error, not a
  // crash (the message once quoted the value through nlohmann's recursive dump).
  const std::string deep = std::string(200000, '[') + std::string(200000, ']');
  EXPECT_EQ(message(deep), "advise-push: result JSON: expected an object (identify --json), got " +
                               std::string(40, '[') + "...");
  EXPECT_NE(message("{\"e_t_mu\": 1e999}").find("number overflow parsing '1e999'"),
            std::string::npos)
      << message("{\"e_t_mu\": 1e999}");
  const std::string ok_a = R"("e_t_mu": {"identifiable": true, "value": 0.4, "stderr": 0.01})";
  const std::string ok_b =
      R"("e_o_over_e_t": {"identifiable": true, "value": 1.3, "stderr": 0.02})";
  const std::string no_c = "{" + ok_a + ", " + ok_b + "}";
  EXPECT_NE(message(no_c).find("no \"e_r_over_e_t\""), std::string::npos) << message(no_c);
  const std::string bad_stderr =
      R"({"e_t_mu": {"identifiable": true, "value": 0.4, "stderr": -1}, )" + ok_b +
      R"(, "e_r_over_e_t": {"identifiable": false, "held_at": 0.03}})";
  EXPECT_NE(message(bad_stderr).find("/e_t_mu/stderr"), std::string::npos) << message(bad_stderr);
  const std::string good = "{" + ok_a + ", " + ok_b +
                           R"(, "e_r_over_e_t": {"identifiable": false, "held_at": 0.03},
                           "residual_rms": 0.0006, "mu_pusher": {"value": 0.3}})";
  const AdviceResultInput in = ParseAdviceResult(good);
  EXPECT_NEAR(*in.pose_noise_m, 0.0006 / std::sqrt(3.0), 1e-18);
  EXPECT_EQ(*in.mu_pusher, 0.3);
  const ContactPatch patch = ContactPatch::Rectangle(0.09, 0.09);
  const FrictionKnowledge prior = KnowledgeFromPrior(FrictionPrior{}, patch);
  const FrictionKnowledge k = KnowledgeFromResult(in.result, prior);
  EXPECT_EQ(k.from[0], "estimate");
  EXPECT_EQ(k.from[2], "prior");  // not identifiable: the prior's width about its held value
  EXPECT_EQ(k.estimate.c, 0.03);
  EXPECT_NEAR(k.information_log(0, 0), 1 / (0.025 * 0.025), 1e-9);

  PushAdviceOptions options;
  options.pose_noise_m = 0;
  EXPECT_THROW(AdvisePush(Box(patch), patch, prior, options), std::invalid_argument);
  FrictionKnowledge nan = prior;
  nan.information_log(1, 1) = NAN;
  try {
    AdvisePush(Box(patch), patch, nan, PushAdviceOptions{});
    ADD_FAILURE() << "no error for a NaN information";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
  }
  FrictionPrior bad_prior;
  bad_prior.b = {2.0, 0.5};
  EXPECT_THROW(KnowledgeFromPrior(bad_prior, patch), std::invalid_argument);

  // The tool: usage errors name the option (exit 2), a bad file names the file (exit 1).
  const auto expect_error = [](const std::string& args, int code, const std::string& fragment) {
    const testing::ToolRun run = testing::RunTool("advise-push", args);
    EXPECT_EQ(run.code, code) << args;
    EXPECT_NE(run.err.find(fragment), std::string::npos) << args << ": " << run.err;
  };
  expect_error("--mass 1", 2, "--patch");
  expect_error("--patch 'triangle 1'", 2, "--patch");
  expect_error("--patch 'disk 0.05' --criterion best", 2, "--criterion");
  expect_error("--patch 'disk 0.05' --lengths 0.03,x", 2, "--lengths");
  // A candidate that cannot be simulated at all (here the pushes at the edge of a cone of
  // mu_p = 1e300, whose step forces overflow) is a failed candidate ranked last; it ended
  // the whole run with exit 1 and "SolveStep: applied.fx must be finite".
  const testing::ToolRun wide_cone = testing::RunTool(
      "advise-push", "--patch 'rectangle 0.12 0.08' --mu-pusher 1e300 --candidates 0 --json");
  EXPECT_EQ(wide_cone.code, 0) << wide_cone.err;
  EXPECT_EQ(wide_cone.err, "");
  EXPECT_NE(wide_cone.out.find("\"simulated\":true"), std::string::npos) << wide_cone.out;
  EXPECT_NE(wide_cone.out.find("\"simulated\":false"), std::string::npos) << wide_cone.out;
  expect_error("--patch 'rectangle 1e300 1e300'", 2, "give --inertia");
  // A limit that keeps the run finite: a billion contact points ran for ever.
  expect_error("--patch 'disk 0.05' --contact-points 1000000000", 2,
               "--contact-points must be 1 to 1000");
  const std::string missing = testing::TempPath("no_such_result.json");
  expect_error("--patch 'disk 0.05' --friction " + missing, 1, missing);
  const std::string broken = testing::TempPath("broken_result.json");
  std::ofstream(broken) << bad_stderr;
  const testing::ToolRun bad_file =
      testing::RunTool("advise-push", "--patch 'disk 0.05' --friction " + broken);
  EXPECT_EQ(bad_file.code, 1);
  EXPECT_NE(bad_file.err.find(broken), std::string::npos) << bad_file.err;
  EXPECT_NE(bad_file.err.find("/e_t_mu/stderr"), std::string::npos) << bad_file.err;
}

TEST(PushAdvice, ToolRanksAnIdentifyResultAndWritesJson) {
  // A result as identify --json writes it.
  EstimateResult r;
  const double values[3] = {0.4, 1.3, 0.03}, stderrs[3] = {0.004, 0.05, 0.003};
  for (int i = 0; i < 3; ++i) {
    r.parameters[i].identifiable = true;
    r.parameters[i].verdict = Verdict::kOk;
    r.parameters[i].value = values[i];
    r.parameters[i].stderr_value = stderrs[i];
    r.parameters[i].ci95_lo = values[i] - 2 * stderrs[i];
    r.parameters[i].ci95_hi = values[i] + 2 * stderrs[i];
  }
  r.residual_rms = 0.0005;
  const std::string path = testing::TempPath("advise_result.json");
  std::ofstream(path) << FormatJson(r) << "\n";
  const std::string args = "--friction " + path +
                           " --patch 'rectangle 0.09 0.09' --mass 0.8 --contact-points 4 "
                           "--cone-fractions -0.5,0.5 --lengths 0.05 --candidates 3";
  const testing::ToolRun json = testing::RunTool("advise-push", args + " --json");
  ASSERT_EQ(json.code, 0) << json.err;
  const nlohmann::json j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["criterion"], "least-known");
  EXPECT_EQ(j["candidates"], 8);
  ASSERT_EQ(j["ranking"].size(), 3u);
  EXPECT_NEAR(j["pose_noise_m"].get<double>(), 0.0005 / std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(j["known"]["e_r_over_e_t"]["relative_stderr"].get<double>(), 0.1, 1e-12);
  double previous = 0;
  for (const nlohmann::json& c : j["ranking"]) {
    EXPECT_GE(c["score"].get<double>(), previous);
    previous = c["score"].get<double>();
    EXPECT_LE(c["relative_stderr_after"][2].get<double>(), 0.1);
  }
  const testing::ToolRun text = testing::RunTool("advise-push", args);
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("8 candidate pushes"), std::string::npos) << text.out;
}

TEST(PushAdviceRace, AdviceNeedsFewerPushesThanRandomOnACISizedRace) {
  // Three sliders (a box, a disk, an anisotropic box), the expected information at the
  // truth for both arms, a coarser candidate grid than the tool's default (CI time).
  RaceOptions options;
  options.max_pushes = 40;
  options.advice.candidates.contact_points = 8;
  options.advice.candidates.cone_fractions = {-0.8, 0.0, 0.8};
  options.advice.candidates.lengths_m = {0.03, 0.08};
  int advice_total = 0, random_total = 0;
  for (int i = 0; i < 3; ++i) {
    const RaceSlider s = DrawRaceSlider(2111, i);
    const RaceOutcome advice = RunRace(s, RaceArm::kAdvice, RaceMeasure::kExpected, options);
    const RaceOutcome random = RunRace(s, RaceArm::kRandom, RaceMeasure::kExpected, options);
    std::printf("race slider %d (%s): advice %d pushes, random %d\n", i, s.kind.c_str(),
                advice.pushes, random.pushes);
    EXPECT_TRUE(advice.reached) << s.kind;
    EXPECT_LE(advice.pushes, random.pushes) << s.kind;
    advice_total += advice.pushes;
    random_total += random.pushes;
  }
  EXPECT_LT(advice_total, random_total);
}

}  // namespace
}  // namespace slideid
