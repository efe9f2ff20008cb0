// The MIT push importer (io/mit_push_import.h) on synthetic recordings made by the
// simulator (datasets/mit_push_synth.h): each known defect of the real files is injected,
// and the importer repairs it (the log equals the clean one, or the truth within the noise)
// or rejects the file naming it. Then identify on the imported log recovers the friction
// the recording was simulated with, as it does on a native log of the same push.

#include "io/mit_push_import.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "datasets/mit_push_synth.h"
#include "datasets/sensor_model.h"
#include "estimator/identify.h"
#include "forward_model/constants.h"
#include "io/mit_push_json.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

MitImportOptions Options(const MitSynthSpec& spec) {
  MitImportOptions o;
  o.slider = spec.slider;
  o.patch_spec = "rectangle 0.09 0.09";
  o.tip_radius_m = spec.tip_radius_m;
  return o;
}

MitImportResult Import(const MitSynthSpec& spec) {
  return ImportMitPush(MakeMitPushRecording(spec).recording, "synthetic.json", Options(spec));
}

MitImportResult ImportAccepted(const MitSynthSpec& spec) {
  MitImportResult r = Import(spec);
  EXPECT_EQ(r.report.verdict, ImportVerdict::kAccepted) << r.report.reason;
  return r;
}

void ExpectRejected(const MitImportResult& r, const std::string& reason) {
  EXPECT_EQ(r.report.verdict, ImportVerdict::kRejected);
  EXPECT_NE(r.report.reason.find(reason), std::string::npos) << r.report.reason;
  EXPECT_TRUE(r.file.log.samples.empty());
}

/// The same rows, times and numbers to `tolerance`.
void ExpectSameLog(const Trajectory& a, const Trajectory& b, double tolerance) {
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t u = 0; u < a.samples.size(); ++u) {
    const TrajectorySample &p = a.samples[u], &q = b.samples[u];
    ASSERT_NEAR(p.t_s, q.t_s, tolerance) << u;
    ASSERT_NEAR(p.state.x, q.state.x, tolerance) << u;
    ASSERT_NEAR(p.state.theta, q.state.theta, tolerance) << u;
    ASSERT_NEAR(p.applied.fx, q.applied.fx, tolerance) << u;
    ASSERT_NEAR(p.applied.tz, q.applied.tz, tolerance) << u;
  }
}

/// Largest difference between a row's force and the true force on the object averaged
/// over the row's interval [N], except rows within 10 ms of the push's start or stop, where
/// the true force steps and the samples, 4 ms apart, cannot follow it.
double WorstRowForceError(const MitSynthSpec& spec, const MitSynthResult& truth,
                          const MitImportResult& imported) {
  const double row_dt = 1.0 / 100.0, sim_dt = truth.scene.dt_s;
  const double start = spec.rest_before_s, stop = spec.rest_before_s + spec.push_s;
  double worst = 0;
  for (std::size_t u = 0; u + 1 < imported.file.log.samples.size(); ++u) {
    const TrajectorySample& row = imported.file.log.samples[u];
    const double t0 = imported.report.time_origin_s + row.t_s - spec.t_epoch_s;
    if (std::abs(t0 - start) < row_dt + 0.01 || std::abs(t0 - stop) < row_dt + 0.01) continue;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int n = 0;
    for (double t = t0 + 0.5 * sim_dt; t < t0 + row_dt; t += sim_dt, ++n) {
      const AppliedWrench& f =
          truth.simulated.samples[static_cast<std::size_t>(t / sim_dt)].applied;
      sum += Eigen::Vector2d(f.fx, f.fy);
    }
    worst = std::max(worst, (Eigen::Vector2d(row.applied.fx, row.applied.fy) - sum / n).norm());
  }
  return worst;
}

// Force noise per stored sample 0.05 N; a 100 Hz row averages about 2.5 samples at 250 Hz,
// so its noise is about 0.035 N per axis. 4 sigma per axis, on the norm: 0.2 N.
constexpr double kRowForceTolN = 0.2;
// Median contact gap over a push: the outline is met exactly; pose noise (0.3 mm, 3 mrad at
// 45 mm: 0.14 mm) averages out in the median: 0.1 mm.
constexpr double kGapTolM = 1e-4;

TEST(MitPushImport, CleanPushIsImportedWithTheReactionFlipped) {
  const MitSynthSpec spec;
  const MitSynthResult truth = MakeMitPushRecording(spec);
  const MitImportResult r = ImportMitPush(truth.recording, "synthetic.json", Options(spec));
  ASSERT_EQ(r.report.verdict, ImportVerdict::kAccepted) << r.report.reason;
  EXPECT_TRUE(r.report.force_flipped);
  EXPECT_LT(*r.report.normal_alignment, -0.9);
  EXPECT_LT(*r.report.velocity_correlation, 0.0);
  EXPECT_NEAR(*r.report.contact_gap_median_m, 0.0, kGapTolM);
  EXPECT_EQ(r.report.rows_out_of_contact_fraction, 0.0);
  EXPECT_NEAR(r.report.object_pose.median_rate_hz, 200.0, 5.0);
  EXPECT_NEAR(r.report.tip_pose.median_rate_hz, 237.0, 5.0);
  EXPECT_NEAR(r.report.ft_wrench.median_rate_hz, 250.0, 5.0);
  // The window: the push (0.9 s) plus the margins.
  EXPECT_NEAR(r.report.window_end_s, spec.push_s + 2 * 0.05, 0.05);
  EXPECT_EQ(r.file.log.slider.mass_kg, spec.slider.mass_kg);
  EXPECT_EQ(PatchText(r.file), ContactPatch::Rectangle(0.09, 0.09).Spec());
  EXPECT_LT(WorstRowForceError(spec, truth, r), kRowForceTolN);
  for (const TrajectorySample& s : r.file.log.samples) {
    ASSERT_TRUE(s.push_point_world.has_value());
    EXPECT_EQ(s.push_point_world->z(), spec.slider.com_height_m);  // pz = com_height
  }
}

// A recording whose object frame is not the CM (the MIT triangles' frame is 3-14 mm off
// their centroid): with the CM's offset in that frame the importer moves each pose to the CM
// before it places the outline, and imports the recording as that of the CM's poses; without
// it the outline sits off the tip's path (the contact gap grows by millimetres).
TEST(MitPushImport, ObjectPosesOfAnOffsetFrameAreMovedToTheCm) {
  const MitSynthSpec spec;
  const MitSynthResult truth = MakeMitPushRecording(spec);
  const Eigen::Vector2d offset(0.006, -0.004);
  MitPushRecording tracked = truth.recording;
  for (MitStreamRow& row : tracked.object_pose) {
    const double c = std::cos(row[3]), sn = std::sin(row[3]);
    row[1] -= c * offset.x() - sn * offset.y();
    row[2] -= sn * offset.x() + c * offset.y();
  }
  const MitImportResult cm = ImportMitPush(truth.recording, "synthetic.json", Options(spec));
  MitImportOptions with_offset = Options(spec);
  with_offset.cm_offset_m = offset;
  const MitImportResult moved = ImportMitPush(tracked, "synthetic.json", with_offset);
  ASSERT_EQ(moved.report.verdict, ImportVerdict::kAccepted) << moved.report.reason;
  ExpectSameLog(moved.file.log, cm.file.log, 1e-12);
  EXPECT_NEAR(*moved.report.contact_gap_median_m, *cm.report.contact_gap_median_m, 1e-12);
  bool noted = false;
  for (const auto& [key, value] : moved.file.extra_metadata) {
    noted |= key == "object_poses_moved_to_cm_m";
    EXPECT_NE(key, "cm_offset");  // the reader would move the poses again
  }
  EXPECT_TRUE(noted);
  const MitImportResult unmoved = ImportMitPush(tracked, "synthetic.json", Options(spec));
  ASSERT_EQ(unmoved.report.verdict, ImportVerdict::kAccepted) << unmoved.report.reason;
  EXPECT_GT(std::abs(*unmoved.report.contact_gap_median_m), 1e-3);
  std::printf("contact gap median: CM %.3g mm, offset frame moved %.3g mm, unmoved %.3g mm\n",
              1e3 * *cm.report.contact_gap_median_m, 1e3 * *moved.report.contact_gap_median_m,
              1e3 * *unmoved.report.contact_gap_median_m);
}

TEST(MitPushImport, ForceStoredAsAppliedIsKept) {
  MitSynthSpec spec;
  spec.store_reaction = false;
  const MitSynthResult truth = MakeMitPushRecording(spec);
  const MitImportResult r = ImportMitPush(truth.recording, "synthetic.json", Options(spec));
  ASSERT_EQ(r.report.verdict, ImportVerdict::kAccepted) << r.report.reason;
  EXPECT_FALSE(r.report.force_flipped);
  EXPECT_GT(*r.report.normal_alignment, 0.9);
  EXPECT_GT(*r.report.velocity_correlation, 0.0);
  EXPECT_LT(WorstRowForceError(spec, truth, r), kRowForceTolN);
}

TEST(MitPushImport, UnsortedAndRepeatedStampsAreRepairedAndCounted) {
  MitSynthSpec spec;
  const MitImportResult clean = ImportAccepted(spec);
  MitSynthSpec defective = spec;
  defective.defects.backward_steps = 10;
  defective.defects.duplicate_rows = 7;
  const MitImportResult r = ImportAccepted(defective);
  EXPECT_EQ(r.report.object_pose.cleanup.backward_steps, 10);
  EXPECT_EQ(r.report.object_pose.cleanup.duplicates_dropped, 7);
  EXPECT_EQ(r.report.tip_pose.cleanup.duplicates_dropped, 7);
  EXPECT_EQ(r.report.object_pose.cleanup.conflicting_duplicates, 0);
  ExpectSameLog(clean.file.log, r.file.log, 0.0);
}

TEST(MitPushImport, QuarterTurnJumpsAreRepairedAndThetaUnwrapped) {
  MitSynthSpec spec;
  const MitImportResult clean = ImportAccepted(spec);
  EXPECT_EQ(clean.report.theta_wraps, 1);  // theta starts at 3.0 and turns past pi
  MitSynthSpec defective = spec;
  defective.defects.quarter_turns = {{0.5, 1}, {0.8, -2}, {1.0, 0}};
  const MitImportResult r = ImportAccepted(defective);
  EXPECT_EQ(r.report.theta_jumps_repaired, 3);  // +1, -3 and +2 quarter turns
  EXPECT_EQ(r.report.theta_jumps_unrepaired, 0);
  EXPECT_LT(r.report.largest_theta_step_rad, 0.05);
  ExpectSameLog(clean.file.log, r.file.log, 1e-12);  // only rounding of the repaired steps
}

TEST(MitPushImport, OffsetsBeforeAndAfterAreEstimatedAndRemoved) {
  MitSynthSpec spec;
  spec.offset_before_n = {0.0, 0.0};
  spec.offset_after_n = {0.0, 0.0};
  const MitImportResult zero = ImportAccepted(spec);
  MitSynthSpec drifting = spec;
  // The tip clear of the object on both sides: a drift is measured, not a pre-load.
  drifting.rest_clearance_m = 5e-3;
  drifting.offset_before_n = {-1.5, -0.5};
  drifting.offset_after_n = {-1.2, -0.3};  // 0.36 N apart: below the 0.5 N threshold
  const MitImportResult r = ImportAccepted(drifting);
  // About 70 still samples a side, 0.05 N each: the median is within 0.02 N (3 sigma).
  ASSERT_TRUE(r.report.offset_before_n && r.report.offset_after_n);
  EXPECT_LT((*r.report.offset_before_n - drifting.offset_before_n).norm(), 0.02);
  EXPECT_LT((*r.report.offset_after_n - drifting.offset_after_n).norm(), 0.02);
  EXPECT_NEAR(*r.report.offset_drift_n, 0.36, 0.03);
  EXPECT_NEAR(r.report.force_noise_n, 0.05, 0.01);
  // The linear drift is removed: the same forces as without offsets, within the estimates'
  // error (0.02 N) on both sides.
  ASSERT_EQ(r.file.log.samples.size(), zero.file.log.samples.size());
  for (std::size_t u = 0; u < r.file.log.samples.size(); ++u) {
    EXPECT_NEAR(r.file.log.samples[u].applied.fx, zero.file.log.samples[u].applied.fx, 0.04) << u;
    EXPECT_NEAR(r.file.log.samples[u].applied.fy, zero.file.log.samples[u].applied.fy, 0.04) << u;
  }
}

// A drift is a drift only where both windows measure the offset with the tip clear of the
// object (issue 17): 5 mm away before and after the push.
TEST(MitPushImport, OffsetDriftAboveTheThresholdIsRejected) {
  MitSynthSpec spec;
  spec.rest_clearance_m = 5e-3;
  spec.offset_after_n = {0.0, 0.0};  // 1.58 N from (-1.5, -0.5)
  ExpectRejected(Import(spec), "force offset drift 1.5");
  MitImportOptions lenient = Options(spec);
  lenient.max_offset_drift_n = 2.0;
  EXPECT_EQ(ImportMitPush(MakeMitPushRecording(spec).recording, "s.json", lenient).report.verdict,
            ImportVerdict::kAccepted);
}

// The MIT pushes start with the tip resting against the object and pressing it (0.4-1.9 N),
// and read a few hundredths of a newton once it leaves: that is a pre-load, a real force,
// not an offset drift. It is kept in the log (the object does not move under it), reported,
// and the offset comes from the side where the tip does not press.
TEST(MitPushImport, APreloadBeforeThePushIsARealForceNotAnOffset) {
  for (double preload : {0.4, 1.2, 1.9}) {
    MitSynthSpec spec;
    spec.preload_n = preload;
    const MitImportResult r = ImportAccepted(spec);
    ASSERT_TRUE(r.report.preload_n.has_value()) << preload;
    EXPECT_NEAR(r.report.preload_n->norm(), preload, 0.1) << preload;
    ASSERT_TRUE(r.report.offset_after_n.has_value());
    EXPECT_NEAR((*r.report.offset_after_n - spec.offset_after_n).norm(), 0.0, 0.05);
    EXPECT_FALSE(r.report.offset_before_n.has_value());
    bool noted = false;
    for (const std::string& n : r.report.notes)
      noted = noted || n.find("pressing it") != std::string::npos;
    EXPECT_TRUE(noted) << preload;
  }
}

// A tip that touches the object before the push without pressing it, and the tip clear of
// it on one side only: the offset is measured on both sides, no pre-load is reported.
TEST(MitPushImport, ATipTouchingWithoutPressingMeasuresTheOffset) {
  MitSynthSpec spec;  // rests against the object before and after, no force
  MitImportResult r = ImportAccepted(spec);
  EXPECT_FALSE(r.report.preload_n.has_value());
  ASSERT_TRUE(r.report.offset_before_n && r.report.offset_after_n);
  EXPECT_NEAR((*r.report.offset_before_n - spec.offset_before_n).norm(), 0.0, 0.05);
  spec.rest_clearance_m = 5e-3;
  r = ImportAccepted(spec);
  EXPECT_FALSE(r.report.preload_n.has_value());
  ASSERT_TRUE(r.report.offset_before_n && r.report.offset_after_n);
}

// Marker swaps: every 7th object pose 5 m off is dropped, counted, and the push imported
// as without them (identify then recovers the truth as on the clean recording); every 3rd
// is too many, and the file is rejected saying why.
TEST(MitPushImport, IsolatedPoseGlitchesAreDroppedAndTooManyRejected) {
  MitSynthSpec spec;
  const MitImportResult clean = ImportAccepted(spec);
  spec.defects.glitch_every = 7;
  const MitImportResult r = ImportAccepted(spec);
  const int poses = static_cast<int>(MakeMitPushRecording(spec).recording.object_pose.size());
  EXPECT_NEAR(r.report.pose_glitches, poses / 7, 1);
  ASSERT_EQ(r.file.log.samples.size(), clean.file.log.samples.size());
  const EstimateResult fit = Identify(r.file.log, IdentifyOptions{});
  const EstimateResult fit_clean = Identify(clean.file.log, IdentifyOptions{});
  ASSERT_TRUE(fit.converged) << fit.message;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(fit.parameters[i].identifiable)
        << ParameterName(i) << ": " << fit.parameters[i].reason;
    // Dropping one pose in 7 changes the rows' interpolation a little: within the clean
    // fit's own interval.
    EXPECT_TRUE(fit_clean.parameters[i].ci95_lo <= fit.parameters[i].value &&
                fit.parameters[i].value <= fit_clean.parameters[i].ci95_hi)
        << ParameterName(i) << " " << fit.parameters[i].value << " vs "
        << fit_clean.parameters[i].value;
  }
  spec.defects.glitch_every = 3;
  ExpectRejected(Import(spec), "marker swaps");
}

TEST(MitPushImport, OneSidedOffsetIsUsedAndNoted) {
  MitSynthSpec spec;
  spec.rest_before_s = 0.03;  // the streams start while the push starts
  const MitImportResult r = ImportAccepted(spec);
  EXPECT_FALSE(r.report.offset_before_n.has_value());
  EXPECT_TRUE(r.report.offset_after_n.has_value());
  EXPECT_FALSE(r.report.offset_drift_n.has_value());
  ASSERT_FALSE(r.report.notes.empty());
  EXPECT_NE(r.report.notes[0].find("no offset before the push"), std::string::npos);
}

TEST(MitPushImport, DeadForceChannelIsRejectedAsSuch) {
  MitSynthSpec spec;
  spec.defects.dead_force = true;
  ExpectRejected(Import(spec), "force channel constant (dead sensor?)");
}

TEST(MitPushImport, SaturatedForceDuringThePushIsRejected) {
  MitSynthSpec spec;
  spec.defects.saturation_n = 2.0;  // stored fx (minus the force, offset -1.5 N) reaches 2.4 N
  ExpectRejected(Import(spec), "inside the push window (saturated or stalled sensor)");
}

TEST(MitPushImport, FrozenSamplesOutsideThePushAreDroppedAndCounted) {
  MitSynthSpec spec;
  MitSynthResult truth = MakeMitPushRecording(spec);
  std::vector<MitStreamRow>& ft = truth.recording.ft_wrench;
  for (std::size_t i = 1; i < 20; ++i) ft[i] = {ft[i][0], 1.9e-21, -1.9e-21, 0.0};  // stalled start
  ft[0] = {ft[0][0], 1.9e-21, -1.9e-21, 0.0};
  const MitImportResult r = ImportMitPush(truth.recording, "s.json", Options(spec));
  ASSERT_EQ(r.report.verdict, ImportVerdict::kAccepted) << r.report.reason;
  EXPECT_EQ(r.report.frozen_force_samples, 20);
  EXPECT_LT((*r.report.offset_before_n - spec.offset_before_n).norm(), 0.03);  // not the zeros
}

TEST(MitPushImport, PoseGapOutsideThePushIsReportedAndLeavesTheLogWhole) {
  MitSynthSpec outside;
  outside.defects.pose_gaps = {{0.02, 0.12}};  // during the rest before
  const MitImportResult r = ImportAccepted(outside);
  EXPECT_GT(r.report.object_pose.largest_gap_s, 0.09);
  EXPECT_LT(r.report.largest_pose_gap_in_window_s, 0.01);
  EXPECT_EQ(r.report.pose_gaps_split, 0);
  EXPECT_FALSE(HasGaps(r.file.log));
}

TEST(MitPushImport, PoseGapsThatLeaveTooLittleOfThePushAreRejectedNamingThem) {
  MitSynthSpec spec;
  spec.defects.pose_gaps = {{0.35, 0.75}, {0.8, 1.15}};  // 0.15 s of the 0.9 s push left
  const MitImportResult r = Import(spec);
  ExpectRejected(r, "object_pose gaps leave 0.1");
  // Both gaps named, each as measured (a pose interval longer at most) from the push's start.
  EXPECT_NE(r.report.reason.find(" ms at 0.04"), std::string::npos) << r.report.reason;
  EXPECT_NE(r.report.reason.find(" ms at 0.49"), std::string::npos) << r.report.reason;
}

TEST(MitPushImport, PusherThatMissesTheObjectIsNoContact) {
  MitSynthSpec spec;
  spec.defects.tip_clearance_m = 0.02;
  ExpectRejected(Import(spec), "no contact: the tip never touches the object");
}

TEST(MitPushImport, ShortPushIsRejectedAsTooShort) {
  MitSynthSpec spec;
  spec.push_s = 0.12;
  spec.amplitude_ratio = 0.0;
  spec.force_ratio = 1.3;
  ExpectRejected(Import(spec), "log too short: the push lasts");
}

// A rate that leaves the push window one or two rows (--rate 1e-300, or a rate meant per
// minute) is rejected: such a log was "accepted" with one row, which nothing can fit.
TEST(MitPushImport, RateThatLeavesTooFewRowsIsRejected) {
  const MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  MitImportOptions o = Options(MitSynthSpec{});
  o.rate_hz = 1e-300;
  ExpectRejected(ImportMitPush(rec, "s.json", o), "fewer than 3 rows, too few to fit");
  o.rate_hz = 1.0;  // a push of well under 2 s
  ExpectRejected(ImportMitPush(rec, "s.json", o), "fewer than 3 rows, too few to fit");
  o.rate_hz = 100;
  EXPECT_EQ(ImportMitPush(rec, "s.json", o).report.verdict, ImportVerdict::kAccepted);
}

TEST(MitPushImport, ForceAcrossTheContactNormalIsAnInconclusiveSign) {
  MitSynthSpec spec;
  spec.defects.force_frame_rad = kPi / 2;  // a sensor frame turned by 90 degrees
  ExpectRejected(Import(spec), "sign check inconclusive");
  MitImportOptions forced = Options(spec);
  forced.force_sign = ForceSign::kReaction;
  const MitImportResult r = ImportMitPush(MakeMitPushRecording(spec).recording, "s.json", forced);
  ASSERT_EQ(r.report.verdict, ImportVerdict::kAccepted);  // the user decided; it is noted
  bool noted = false;
  for (const std::string& note : r.report.notes)
    noted |= note.find("disagrees") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(MitPushImport, MetadataRecordsTheProvenance) {
  MitImportOptions o = Options(MitSynthSpec{});
  o.extra_metadata = {{"object_source", "estimate"}};
  const MitImportResult r = ImportMitPush(MakeMitPushRecording(MitSynthSpec{}).recording,
                                          "dir/shape=rect1_v=100.json", o);
  std::map<std::string, std::string> meta(r.file.extra_metadata.begin(),
                                          r.file.extra_metadata.end());
  EXPECT_EQ(meta["source"], "dir/shape=rect1_v=100.json");
  EXPECT_EQ(meta["object"], "rect1");
  EXPECT_EQ(meta["object_source"], "estimate");
  EXPECT_EQ(meta["force_sign"].rfind("flipped", 0), 0u);
  EXPECT_FALSE(meta["time_origin_unix_s"].empty());
  EXPECT_NE(meta["pz"].find("com_height"), std::string::npos);
}

TEST(MitPushImport, InvalidSettingsAndObjectsThrow) {
  MitImportOptions o = Options(MitSynthSpec{});
  std::string why;
  EXPECT_TRUE(o.IsValid(&why));
  o.rate_hz = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("rate"), std::string::npos);
  o = Options(MitSynthSpec{});
  o.theta_jump_rad = 1.0;  // above pi/4: a quarter turn could not be told from a step
  EXPECT_FALSE(o.IsValid(&why));
  const MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  o = Options(MitSynthSpec{});
  o.patch_spec = "hexagon 1";
  EXPECT_THROW(ImportMitPush(rec, "s.json", o), std::invalid_argument);
  o = Options(MitSynthSpec{});
  o.slider.mass_kg = 0;
  EXPECT_THROW(ImportMitPush(rec, "s.json", o), std::invalid_argument);
}

TEST(MitPushImport, TooFewRowsInAStreamIsRejected) {
  MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  rec.tip_pose.resize(5);
  ExpectRejected(ImportMitPush(rec, "s.json", Options(MitSynthSpec{})),
                 "tip_pose has 5 distinct times");
}

TEST(MitPushImport, ImplausibleMagnitudesAreRejectedNotComputedWith) {
  MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  rec.object_pose[40][3] = 1e200;  // would overflow the unwrapping
  ExpectRejected(ImportMitPush(rec, "s.json", Options(MitSynthSpec{})),
                 "object_pose: theta = 1e+200 beyond any plausible value");
  rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  for (MitStreamRow& row : rec.ft_wrench) row[0] *= 1e3;  // milliseconds
  ExpectRejected(ImportMitPush(rec, "s.json", Options(MitSynthSpec{})), "ft_wrench: t = ");
}

// ---- identify on imported logs ----

// Relative error of (a, b, c) from identify (trajectory method, default settings) on the
// imported log of the default synthetic push (0.3 mm, 3 mrad, 0.05 N per force sample; with
// the defects of the test: unsorted and repeated stamps, a quarter-turn jump, an offset
// drifting by 0.36 N, the reaction stored). A sweep of seeds 1-100 gave worst errors of
// 1.84% / 4.21% / 2.76% (imported) and 3.51% / 6.82% / 3.59% (a native 100 Hz log of the
// same simulation with the same noise levels), with the adaptive segments of 20 intervals
// (5 segments: enough for a cluster-robust interval, which then covers the truth in
// 100 / 98 / 100 of the imported logs); tolerances are 1.5 times the worst. The
// imported log is no worse than the native one: its rows average 2-3 force samples and
// interpolate 2 pose samples.
constexpr double kTolImportedA = 0.028, kTolImportedB = 0.063, kTolImportedC = 0.041;
constexpr double kTolNativeA = 0.053, kTolNativeB = 0.102, kTolNativeC = 0.054;

double RelativeError(const EstimateResult& r, int i, const ReducedFriction& truth) {
  const double expected[3] = {truth.a, truth.b, truth.c};
  EXPECT_TRUE(r.parameters[i].identifiable) << ParameterName(i) << ": " << r.parameters[i].reason;
  return r.parameters[i].value / expected[i] - 1.0;
}

TEST(MitPushImport, IdentifyRecoversTheTruthFromImportedLogsAsFromNativeOnes) {
  IdentifyOptions estimator;
  estimator.method = EstimatorMethod::kTrajectory;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    MitSynthSpec spec;
    spec.seed = seed;
    spec.defects.backward_steps = 9;
    spec.defects.duplicate_rows = 3;
    spec.defects.quarter_turns = {{0.6, 1}};
    spec.offset_after_n = {-1.3, -0.4};
    const MitSynthResult truth = MakeMitPushRecording(spec);
    const ReducedFriction& friction = spec.friction;
    const MitImportResult imported = ImportMitPush(truth.recording, "s.json", Options(spec));
    ASSERT_EQ(imported.report.verdict, ImportVerdict::kAccepted) << imported.report.reason;
    const EstimateResult fit = Identify(imported.file.log, estimator);
    EXPECT_TRUE(fit.converged) << fit.message;
    EXPECT_NEAR(RelativeError(fit, kA, friction), 0.0, kTolImportedA) << "seed " << seed;
    EXPECT_NEAR(RelativeError(fit, kB, friction), 0.0, kTolImportedB) << "seed " << seed;
    EXPECT_NEAR(RelativeError(fit, kC, friction), 0.0, kTolImportedC) << "seed " << seed;

    LogSpec native_spec;
    native_spec.log_every = 10;  // 100 Hz from the 1 ms simulation
    native_spec.motion = LogMotion::kPoses;
    native_spec.noise.pose_m = spec.pose_noise_m;
    native_spec.noise.angle_rad = spec.angle_noise_rad;
    native_spec.noise.force_n = spec.force_noise_n;
    native_spec.noise.seed = seed;
    const EstimateResult native = Identify(MakeLog(truth.simulated, native_spec), estimator);
    EXPECT_NEAR(RelativeError(native, kA, friction), 0.0, kTolNativeA) << "seed " << seed;
    EXPECT_NEAR(RelativeError(native, kB, friction), 0.0, kTolNativeB) << "seed " << seed;
    EXPECT_NEAR(RelativeError(native, kC, friction), 0.0, kTolNativeC) << "seed " << seed;
  }
}

// Gaps of 60-400 ms inside the push (it runs from 0.3 s to 1.2 s): the rows inside are left
// out, the next starts a run, and the fit, whose segments end at the gap, still recovers the
// friction the recording was simulated with. The gap's own rows are lost: the tolerances are
// those of an imported log.
TEST(MitPushImport, PoseGapsInsideThePushSplitTheLogAndTheFitGoesOnAcrossThem) {
  IdentifyOptions estimator;
  estimator.method = EstimatorMethod::kTrajectory;
  const ReducedFriction truth = MitSynthSpec{}.friction;
  const std::vector<std::pair<double, double>> gaps = {
      {0.70, 0.76}, {0.50, 0.60}, {0.85, 1.05}, {0.45, 0.85}};
  for (const auto& gap : gaps) {
    SCOPED_TRACE(::testing::Message() << "gap " << gap.first << "-" << gap.second << " s");
    MitSynthSpec spec;
    spec.defects.pose_gaps = {gap};
    const MitImportResult r = ImportAccepted(spec);
    ASSERT_EQ(r.report.pose_gaps_split, 1);
    EXPECT_NEAR(r.report.largest_pose_gap_in_window_s, gap.second - gap.first, 0.011);
    // 100 Hz rows strictly inside the measured gap (the poses either side of it, up to one
    // 5 ms pose interval outside the dropped span).
    EXPECT_NEAR(r.report.rows_dropped_in_pose_gaps, 100 * (gap.second - gap.first), 2);
    const std::vector<std::pair<int, int>> runs = Runs(r.file.log);
    ASSERT_EQ(runs.size(), 2u);
    const double jump =
        r.file.log.samples[runs[1].first].t_s - r.file.log.samples[runs[0].second].t_s;
    // The rows either side are the last before the gap's last pose and the first after its
    // next one: the jump is the measured gap plus less than two 10 ms rows.
    EXPECT_GE(jump, r.report.largest_pose_gap_in_window_s - 1e-9);
    EXPECT_LT(jump, r.report.largest_pose_gap_in_window_s + 0.02);
    const EstimateResult fit = Identify(r.file.log, estimator);
    ASSERT_TRUE(fit.converged) << fit.message;
    EXPECT_NEAR(RelativeError(fit, kA, truth), 0.0, kTolImportedA);
    EXPECT_NEAR(RelativeError(fit, kB, truth), 0.0, kTolImportedB);
    EXPECT_NEAR(RelativeError(fit, kC, truth), 0.0, kTolImportedC);
  }
}

}  // namespace
}  // namespace slideid
