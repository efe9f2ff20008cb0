#pragma once
// What the importer tests share (tests/mit_push_h5_test.cc, tests/push_streams_csv_test.cc,
// tests/ros_push_import_test.cc): the synthetic MIT push with every repairable defect, the
// object and import options that go with it, and the checks that an import failed naming
// what it should, or imported to the same log as another.

#include <gtest/gtest.h>

#include <cstddef>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>

#include "datasets/mit_push_synth.h"
#include "io/mit_push_files.h"
#include "io/mit_push_import.h"

namespace slideid::testing {

// A log row mixes interpolated poses and averaged forces of those rows: a few ulps.
constexpr double kSameLogTol = 1e-12;

/// A push log's text without its `# source = ...` line (the input file's name).
inline std::string WithoutSource(const std::string& text) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) {
    if (line.rfind("# source = ", 0) != 0) out += line + "\n";
  }
  return out;
}

/// The object of the synthetic pushes (the MIT "rect1"), as the objects table gives it.
inline MitObjectSource Rect1() {
  MitObjectSource objects;
  const MitSynthSpec spec;
  objects.mass_kg = spec.slider.mass_kg;
  objects.inertia_kgm2 = spec.slider.inertia_kgm2;
  objects.com_height_m = spec.slider.com_height_m;
  objects.patch_spec = "rectangle 0.09 0.09";
  return objects;
}

/// The import options for a synthetic push made from `spec`.
inline MitImportOptions Options(const MitSynthSpec& spec) {
  MitImportOptions o;
  o.slider = spec.slider;
  o.patch_spec = "rectangle 0.09 0.09";
  o.tip_radius_m = spec.tip_radius_m;
  return o;
}

/// Every repairable defect of the MIT tests at once: unsorted and repeated rows, quarter
/// turns, a motion-capture gap, pose glitches and a pre-load.
inline MitSynthSpec DefectiveSpec() {
  MitSynthSpec spec;
  spec.defects.backward_steps = 10;
  spec.defects.duplicate_rows = 7;
  spec.defects.quarter_turns = {{0.5, 1}, {0.8, -2}, {1.0, 0}};
  spec.defects.pose_gaps = {{0.02, 0.12}};
  spec.defects.glitch_every = 50;
  spec.preload_n = 0.6;
  return spec;
}

/// What must be thrown (an `Exception`), with its message containing every one of `parts`.
template <typename Exception = std::runtime_error, typename Fn>
void ExpectError(Fn fn, std::initializer_list<std::string> parts) {
  try {
    fn();
    ADD_FAILURE() << "no error";
  } catch (const Exception& e) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

/// Two imports with the same verdict, reason, repairs and log (times exactly, values to
/// kSameLogTol).
inline void ExpectSameImport(const MitImportResult& a, const MitImportResult& b) {
  EXPECT_EQ(a.report.verdict, b.report.verdict);
  EXPECT_EQ(a.report.reason, b.report.reason);
  EXPECT_EQ(a.report.theta_jumps_repaired, b.report.theta_jumps_repaired);
  EXPECT_EQ(a.report.force_flipped, b.report.force_flipped);
  ASSERT_EQ(a.file.log.samples.size(), b.file.log.samples.size());
  for (std::size_t u = 0; u < a.file.log.samples.size(); ++u) {
    const TrajectorySample &p = a.file.log.samples[u], &q = b.file.log.samples[u];
    ASSERT_EQ(p.t_s, q.t_s) << u;
    ASSERT_NEAR(p.state.x, q.state.x, kSameLogTol) << u;
    ASSERT_NEAR(p.state.y, q.state.y, kSameLogTol) << u;
    ASSERT_NEAR(p.state.theta, q.state.theta, kSameLogTol) << u;
    ASSERT_NEAR(p.applied.fx, q.applied.fx, kSameLogTol) << u;
    ASSERT_NEAR(p.applied.fy, q.applied.fy, kSameLogTol) << u;
    ASSERT_NEAR(p.applied.tz, q.applied.tz, kSameLogTol) << u;
  }
}

}  // namespace slideid::testing
