// What identify prints for people (io/result_report.h, pipeline/identify_files.h): notes in
// words with their detail kept for --verbose, and warnings that count what they mean.

#include "io/result_report.h"

#include <gtest/gtest.h>

#include "pipeline/identify_files.h"

namespace slideid {
namespace {

TEST(ResultReport, WithoutDetailDropsEveryDetailWithItsNestedParentheses) {
  EXPECT_EQ(WithoutDetail("words (detail: CR2 (a) over (b (c)) x); more words (kept) (detail: y)"),
            "words; more words (kept)");
  EXPECT_EQ(WithoutDetail("no detail here (at all)"), "no detail here (at all)");
  EXPECT_EQ(WithoutDetail(""), "");
}

TEST(ResultReport, TheTableHidesNoteDetailUnlessVerbose) {
  EstimateResult r;
  for (int i = 0; i < 3; ++i) {
    r.parameters[i].identifiable = true;
    r.parameters[i].verdict = Verdict::kOk;
    r.parameters[i].value = 1;
    r.parameters[i].note = "in words (detail: t quantile 2.53)";
  }
  r.message = "Ceres Solver Report: Iterations: 5, Termination: CONVERGENCE; a second start kept";
  r.iterations = 10;
  const std::string plain = FormatReport(r), verbose = FormatReport(r, std::nullopt, true);
  EXPECT_NE(plain.find("note: in words\n"), std::string::npos) << plain;
  EXPECT_EQ(plain.find("t quantile"), std::string::npos) << plain;
  EXPECT_EQ(plain.find("Iterations: 5"), std::string::npos) << plain;
  EXPECT_NE(plain.find("solver: a second start kept"), std::string::npos) << plain;
  EXPECT_NE(plain.find("fit: 10 solver iterations over all its stages"), std::string::npos)
      << plain;
  EXPECT_NE(verbose.find("note: in words (detail: t quantile 2.53)"), std::string::npos) << verbose;
  EXPECT_NE(verbose.find("solver: Ceres Solver Report: Iterations: 5"), std::string::npos)
      << verbose;
}

TEST(ResultReport, APooledWarningCountsTheLogsWithSuspectEstimates) {
  EstimateResult r;
  r.parameters[kA].verdict = Verdict::kSuspect;
  EXPECT_EQ(SuspectSummary(r), "suspect estimates (e_t_mu): see their reasons");
  for (int k = 0; k < 11; ++k) {
    LogResult log;
    log.parameters[kB].verdict = k < 3 ? Verdict::kSuspect : Verdict::kOk;
    r.logs.push_back(log);
  }
  LogResult skipped;
  skipped.skipped = true;
  r.logs.push_back(skipped);
  EXPECT_EQ(SuspectSummary(r),
            "suspect estimates of the pooled fit (e_t_mu): see their reasons; of the 11 logs, 3 "
            "have suspect estimates of their own, 8 do not");
  r.parameters[kA].verdict = Verdict::kOk;
  EXPECT_EQ(SuspectSummary(r), "");
}

}  // namespace
}  // namespace slideid
