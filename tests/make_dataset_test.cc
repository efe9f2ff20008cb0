// Synthetic datasets: drawn from ranges, deterministic by seed, redrawn (with reasons) when
// a draw tips, written with a truth manifest; and the make-dataset tool over them.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "datasets/dataset.h"
#include "io/dataset_files.h"
#include "io/push_log.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

std::string TempDir(const std::string& name) {
  std::string pattern = ::testing::TempDir() + name + "_XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) std::abort();
  return pattern;
}

using testing::ReadText;

std::string Written(const Trajectory& t) {
  std::ostringstream out;
  WritePushLog(t, out);
  return out.str();
}

/// A small, quick dataset: 3 short pushes, logged at 100 Hz with motion-capture noise.
DatasetSpec Small() {
  DatasetSpec spec;
  spec.count = 3;
  spec.seed = 17;
  spec.program.count = 3;
  spec.log.noise.pose_m = 3e-4;
  spec.log.noise.angle_rad = 3e-3;
  return spec;
}

TEST(Dataset, SameSeedAndIndexGiveTheSameLogAndOthersDiffer) {
  const DatasetSpec spec = Small();
  Trajectory a, b, c, d;
  DrawDatasetLog(spec, 1, &a);
  DrawDatasetLog(spec, 1, &b);
  EXPECT_EQ(Written(a), Written(b));
  DrawDatasetLog(spec, 2, &c);
  EXPECT_NE(Written(a), Written(c));
  DatasetSpec other = spec;
  other.seed = 18;
  DrawDatasetLog(other, 1, &d);
  EXPECT_NE(Written(a), Written(d));
}

// A pusher-driven dataset: each log one straight push by a round tip, its path and radius
// in the log, mu_p in its range; the slider and friction drawn as the force-driven dataset of
// the same seed draws them (the pusher has a stream of its own).
TEST(Dataset, APusherDrivenDatasetLogsTheTipAndKeepsTheOtherDraws) {
  DatasetSpec force = Small();
  force.log.noise = NoiseSpec{};
  DatasetSpec pusher = force;
  pusher.pusher = PusherDraw{};
  for (int index = 0; index < 3; ++index) {
    Trajectory by_force, by_pusher;
    const DatasetEntry f = DrawDatasetLog(force, index, &by_force);
    const DatasetEntry p = DrawDatasetLog(pusher, index, &by_pusher);
    EXPECT_EQ(p.scene.slider.mass_kg, f.scene.slider.mass_kg);
    EXPECT_EQ(p.scene.friction.paper().mu, f.scene.friction.paper().mu);
    ASSERT_TRUE(p.scene.pusher.has_value());
    EXPECT_TRUE(p.scene.pushes.empty());
    EXPECT_GE(p.scene.pusher->mu, 0.1);
    EXPECT_LE(p.scene.pusher->mu, 0.6);
    EXPECT_TRUE(by_pusher.measured.tip);
    ASSERT_TRUE(by_pusher.tip_radius_m.has_value());
    int pushing = 0;
    for (const TrajectorySample& s : by_pusher.samples)
      pushing += s.applied.fx != 0 || s.applied.fy != 0;
    EXPECT_GT(pushing, 10) << "the tip meets the slider";
    // Written and read back, the tip's path is there.
    std::istringstream text(Written(by_pusher));
    EXPECT_NE(text.str().find("tip_x,tip_y"), std::string::npos);
  }
  DatasetSpec bad = pusher;
  bad.pusher->speed_mps = {0.0, 0.1};
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("tip-speed"), std::string::npos) << why;
}

TEST(Dataset, DrawsStayInTheirRangesAndInertiaFollowsThePatch) {
  DatasetSpec spec = Small();
  spec.count = 6;
  spec.patch = PatchRange::Parse("rectangle 0.05:0.1 0.08");
  for (int i = 0; i < spec.count; ++i) {
    Trajectory log;
    const DatasetEntry e = DrawDatasetLog(spec, i, &log);
    const Scene& s = e.scene;
    EXPECT_GE(s.slider.mass_kg, spec.mass_kg.lo);
    EXPECT_LE(s.slider.mass_kg, spec.mass_kg.hi);
    EXPECT_GE(s.slider.com_height_m, spec.com_height_m.lo);
    EXPECT_LE(s.slider.com_height_m, spec.com_height_m.hi);
    EXPECT_GE(s.friction.paper().mu, spec.mu.lo);
    EXPECT_LE(s.friction.paper().e_o, spec.e_o.hi);
    EXPECT_GE(s.friction.paper().e_r, spec.e_r_m.lo);
    std::istringstream patch(s.patch.Spec());
    std::string shape;
    double w = 0, l = 0;
    patch >> shape >> w >> l;
    EXPECT_EQ(shape, "rectangle");
    EXPECT_GE(w, 0.05);
    EXPECT_LE(w, 0.1);
    EXPECT_EQ(l, 0.08);
    EXPECT_NEAR(s.slider.inertia_kgm2, s.slider.mass_kg * (w * w + l * l) / 12, 1e-15);
    // The log carries the truth and the noise it was made with.
    ASSERT_TRUE(log.true_friction.has_value());
    EXPECT_EQ(log.true_friction->e_o, s.friction.paper().e_o);
    EXPECT_EQ(log.slider.mass_kg, s.slider.mass_kg);
    ASSERT_TRUE(log.patch.has_value());
    EXPECT_EQ(log.patch->Spec(), s.patch.Spec());
    EXPECT_EQ(e.rows, static_cast<int>(log.samples.size()));
  }
}

TEST(Dataset, UniformInertiaOfEachShape) {
  EXPECT_NEAR(UniformInertia(ContactPatch::Rectangle(0.1, 0.2), 2.0), 2.0 * 0.05 / 12, 1e-15);
  EXPECT_NEAR(UniformInertia(ContactPatch::Disk(0.1), 2.0), 0.01, 1e-15);
  EXPECT_NEAR(UniformInertia(ContactPatch::Ring(0.1, 0.05), 1.0), 0.00625, 1e-15);
  // A polygon computed by the polygon formula agrees with the rectangle's.
  const ContactPatch square =
      ContactPatch::Parse("polygon -0.05 -0.1 0.05 -0.1 0.05 0.1 -0.05 0.1");
  EXPECT_NEAR(UniformInertia(square, 2.0), 2.0 * 0.05 / 12, 1e-15);
}

TEST(Dataset, ADrawThatTipsIsRedrawnWithItsReasonRecorded) {
  DatasetSpec spec = Small();
  spec.count = 1;
  // Tall and narrow, pushed high and hard: many draws tip (with seed 17, the first two).
  spec.com_height_m = {0.05, 0.08};
  spec.patch = PatchRange::Parse("rectangle 0.04:0.06 0.04:0.06");
  spec.program.force_n = ValueRange{1.0, 4.0};
  spec.program.height_m = ValueRange{0.03, 0.08};
  spec.mu = {0.3, 0.6};
  Trajectory log;
  const DatasetEntry e = DrawDatasetLog(spec, 0, &log);
  ASSERT_FALSE(e.redraw_reasons.empty());
  EXPECT_NE(e.redraw_reasons[0].find("draw 0: toppling"), std::string::npos) << e.redraw_reasons[0];
  EXPECT_NE(e.redraw_reasons[0].find("ECP"), std::string::npos);
  // Deterministic, redraws included.
  Trajectory again;
  EXPECT_EQ(DrawDatasetLog(spec, 0, &again).redraw_reasons, e.redraw_reasons);
  EXPECT_EQ(Written(log), Written(again));
  // With no redraws allowed the draw fails, as NoValidDraw (the tools' numerical outcome,
  // told apart by its type), naming the log and the reason.
  spec.max_redraws = 0;
  try {
    DrawDatasetLog(spec, 0, &again);
    ADD_FAILURE() << "no error";
  } catch (const NoValidDraw& error) {
    EXPECT_NE(std::string(error.what()).find("log_0000.csv"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("toppling"), std::string::npos);
  }
}

TEST(Dataset, MakeDatasetWritesTheLogsAndATruthManifest) {
  const std::string dir = TempDir("dataset");
  const DatasetSpec spec = Small();
  const DatasetSummary summary = MakeDataset(spec, dir);
  ASSERT_EQ(summary.entries.size(), 3u);
  std::istringstream truth(ReadText(dir + "/truth.csv"));
  std::string line;
  std::getline(truth, line);
  EXPECT_EQ(line,
            "file,mass,inertia,com_height,mu,e_t,e_o,e_r,a,b,c,noise,patch,rows,redraws,mu_p");
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(std::getline(truth, line));
    std::vector<std::string> f;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) f.push_back(cell);
    ASSERT_EQ(f.size(), 15u) << line;
    const Trajectory log = ReadPushLog(dir + "/" + f[0]);
    EXPECT_EQ(std::stod(f[1]), log.slider.mass_kg);
    EXPECT_EQ(std::stod(f[2]), log.slider.inertia_kgm2);
    EXPECT_EQ(std::stod(f[3]), log.slider.com_height_m);
    EXPECT_EQ(std::stod(f[4]), log.true_friction->mu);
    EXPECT_EQ(std::stod(f[7]), log.true_friction->e_r);
    const ReducedFriction r = ReducedFriction::From(*log.true_friction);
    EXPECT_EQ(std::stod(f[8]), r.a);
    EXPECT_EQ(std::stod(f[9]), r.b);
    EXPECT_EQ(std::stod(f[10]), r.c);
    EXPECT_NE(f[11].find("pose_m=0.00029999999999999997"), std::string::npos) << f[11];
    ASSERT_TRUE(log.patch.has_value());
    EXPECT_EQ(f[12], log.patch->Spec());
    EXPECT_EQ(std::stoi(f[13]), static_cast<int>(log.samples.size()));
    EXPECT_FALSE(log.measured.velocity);  // poses only, as motion capture gives
  }
  EXPECT_FALSE(std::getline(truth, line));
}

TEST(Dataset, RangesAndPatchesParseAndReportErrors) {
  EXPECT_EQ(ParseRange("0.3:1.5", "--x").lo, 0.3);
  EXPECT_EQ(ParseRange("0.3:1.5", "--x").hi, 1.5);
  EXPECT_EQ(ParseRange("2", "--x").hi, 2.0);
  EXPECT_THROW(ParseRange("2:1", "--x"), std::invalid_argument);
  EXPECT_THROW(ParseRange("a:b", "--x"), std::invalid_argument);
  EXPECT_EQ(PatchRange::Parse("disk 0.03:0.1").sizes.size(), 1u);
  EXPECT_EQ(PatchRange::Parse("rectangle 0.05:0.1 0.08").ToString(), "rectangle 0.05:0.1 0.08");
  EXPECT_THROW(PatchRange::Parse("triangle 1"), std::invalid_argument);
  EXPECT_THROW(PatchRange::Parse("rectangle 0.1"), std::invalid_argument);
  EXPECT_THROW(PatchRange::Parse("disk -0.1"), std::invalid_argument);
  DatasetSpec spec;
  spec.mass_kg = {0.0, 1.0};
  std::string why;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("mass"), std::string::npos) << why;
}

// ---- the make-dataset tool ----

int RunTool(const std::string& tool, const std::string& args, std::string* output = nullptr) {
  const char* bin = std::getenv("SLIDEID_BIN_DIR");
  // One file per process: ctest runs the tests of this file side by side, and a shared
  // file let one test read another's output (seen under the sanitizers).
  const std::string out =
      ::testing::TempDir() + "/tool_output_" + std::to_string(getpid()) + ".txt";
  const std::string cmd =
      std::string(bin ? bin : "build/bin") + "/" + tool + " " + args + " > " + out + " 2>&1";
  const int status = std::system(cmd.c_str());
  if (output) *output = ReadText(out);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(MakeDatasetTool, SameSeedGivesIdenticalFilesAndAnotherSeedOthers) {
  const std::string a = TempDir("md_a"), b = TempDir("md_b"), c = TempDir("md_c");
  const std::string common =
      " --count 2 --pushes 2 --noise-pose 3e-4 --noise-force-relative 0.02 --quiet --out ";
  ASSERT_EQ(RunTool("make-dataset", "--seed 5" + common + a), 0);
  ASSERT_EQ(RunTool("make-dataset", "--seed 5" + common + b), 0);
  ASSERT_EQ(RunTool("make-dataset", "--seed 6" + common + c), 0);
  for (const char* f : {"/log_0000.csv", "/log_0001.csv", "/truth.csv"}) {
    EXPECT_EQ(ReadText(a + f), ReadText(b + f)) << f;
    EXPECT_NE(ReadText(a + f), ReadText(c + f)) << f;
    EXPECT_FALSE(ReadText(a + f).empty()) << f;
  }
}

TEST(MakeDatasetTool, HelpDocumentsEveryOptionAndItsDefault) {
  std::string help;
  ASSERT_EQ(RunTool("make-dataset", "--help", &help), 0);
  for (const char* option : {"--count",         "--seed",
                             "--out",           "--mass-range",
                             "--inertia-range", "--com-height-range",
                             "--patch",         "--mu-range",
                             "--e-t-range",     "--e-o-range",
                             "--e-r-range",     "--pushes",
                             "--force-range",   "--amplitude-range",
                             "--period-range",  "--push-duration-range",
                             "--rest-range",    "--height-range",
                             "--spread",        "--max-lever",
                             "--through-cm",    "--dt",
                             "--max-redraws",   "--log-every",
                             "--wrench",        "--write",
                             "--push-columns",  "--noise-pose",
                             "--noise-angle",   "--noise-velocity",
                             "--noise-spin",    "--noise-force-relative",
                             "--noise-force",   "--noise-outlier-fraction",
                             "--noise-outlier"}) {
    EXPECT_NE(help.find(option), std::string::npos) << option;
  }
  EXPECT_NE(help.find("(=0.3:1.5)"), std::string::npos) << "mass default";
  EXPECT_NE(help.find("(default: 10)"), std::string::npos) << "log-every default";
}

TEST(MakeDatasetTool, BadOptionsAreUsageErrors) {
  const std::string dir = TempDir("md_bad");
  EXPECT_EQ(RunTool("make-dataset", "--count 1"), 2);  // --out missing
  EXPECT_EQ(RunTool("make-dataset", "--count 1 --mass-range 2:1 --out " + dir), 2);
  EXPECT_EQ(RunTool("make-dataset", "--count 1 --patch hexagon --out " + dir), 2);
  EXPECT_EQ(RunTool("make-dataset", "--count 1 --seed -4 --out " + dir), 2);
  EXPECT_EQ(RunTool("make-dataset", "--count 1 --write velocities --out " + dir), 2);
  EXPECT_EQ(RunTool("make-dataset", "--count 1 --out /proc/no/such/dir"), 4);
  // A limit that keeps the run finite: a billion pushes were drawn for ever.
  std::string output;
  EXPECT_EQ(RunTool("make-dataset", "--count 1 --pushes 1000000000 --out " + dir, &output), 2);
  EXPECT_NE(output.find("count = 1000000000: must be 1 to 10000"), std::string::npos) << output;
}

// ---- simulate's log options ----

std::string Scene(const std::string& name) {
  return std::string(SLIDEID_SOURCE_DIR) + "/datasets/scenes/" + name;
}

TEST(SimulateLogOptions, SameSeedGivesIdenticalBytesAndAnotherSeedOthers) {
  const std::string dir = TempDir("sim_seed");
  const std::string args = "--scene " + Scene("example3_pushed_square.ini") +
                           " --noise-pose 3e-4 --noise-angle 3e-3 --noise-force-relative 0.02 "
                           "--noise-force 0.05 --noise-outlier-fraction 0.01 --noise-outlier 0.01";
  ASSERT_EQ(RunTool("simulate", args + " --seed 8 --out " + dir + "/a.csv"), 0);
  ASSERT_EQ(RunTool("simulate", args + " --seed 8 --out " + dir + "/b.csv"), 0);
  ASSERT_EQ(RunTool("simulate", args + " --seed 9 --out " + dir + "/c.csv"), 0);
  EXPECT_EQ(ReadText(dir + "/a.csv"), ReadText(dir + "/b.csv"));
  EXPECT_NE(ReadText(dir + "/a.csv"), ReadText(dir + "/c.csv"));
  EXPECT_NE(ReadText(dir + "/a.csv").find("# noise_seed = 8\n"), std::string::npos);
}

TEST(SimulateLogOptions, SamplingAndColumnsFollowTheOptions) {
  const std::string dir = TempDir("sim_cols");
  ASSERT_EQ(RunTool("simulate", "--scene " + Scene("example3_pushed_square.ini") +
                                    " --dt 0.001 --log-every 10 --write poses --out " + dir +
                                    "/poses.csv"),
            0);
  const Trajectory poses = ReadPushLog(dir + "/poses.csv");
  EXPECT_EQ(poses.samples.size(), 301u);  // 3 s at 100 Hz from a 1 ms simulation
  EXPECT_NEAR(poses.samples[1].t_s, 0.01, 1e-15);
  EXPECT_FALSE(poses.measured.velocity);
  EXPECT_TRUE(poses.measured.push_point);
  ASSERT_EQ(RunTool("simulate", "--scene " + Scene("example3_pushed_square.ini") +
                                    " --write velocities --push-columns moments --out " + dir +
                                    "/moments.csv"),
            0);
  const std::string text = ReadText(dir + "/moments.csv");
  EXPECT_NE(text.find("\nt,vx,vy,wz,fx,fy,tx,ty,tz,ax,ay"), std::string::npos);
  EXPECT_EQ(RunTool("simulate", "--scene " + Scene("example3_pushed_square.ini") +
                                    " --write velocities --out " + dir + "/bad.csv"),
            2);  // push points need poses
  EXPECT_EQ(RunTool("simulate", "--scene " + Scene("example1_square.ini") +
                                    " --write velocities --out " + dir + "/free.csv"),
            0);  // a free slide has no push points: velocities alone are fine
  EXPECT_EQ(RunTool("simulate", "--scene " + Scene("example1_square.ini") + " --write all"), 2);
  EXPECT_EQ(RunTool("simulate", "--scene " + Scene("example1_square.ini") + " --wrench mean"), 2);
  EXPECT_EQ(RunTool("simulate", "--scene " + Scene("example1_square.ini") + " --log-every 0"), 2);
  EXPECT_EQ(RunTool("simulate", "--scene " + Scene("example1_square.ini") + " --seed x"), 2);
  EXPECT_EQ(RunTool("simulate", "--scene " + Scene("example1_square.ini") + " --noise-pose -1"), 2);
}

TEST(SimulateLogOptions, IntervalMeanWrenchNeedsMomentsAndIsRecorded) {
  const std::string dir = TempDir("sim_wrench");
  const std::string scene = "--scene " + Scene("example3_pushed_square.ini") +
                            " --dt 0.001 --log-every 10 --wrench interval-mean";
  ASSERT_EQ(RunTool("simulate", scene + " --push-columns moments --out " + dir + "/mean.csv"), 0);
  const std::string text = ReadText(dir + "/mean.csv");
  EXPECT_NE(text.find("# log_wrench = interval-mean\n"), std::string::npos);
  EXPECT_NE(text.find("\nt,x,y,theta,vx,vy,wz,fx,fy,tx,ty,tz,"), std::string::npos);
  EXPECT_EQ(RunTool("simulate", scene + " --out " + dir + "/points.csv"), 2);  // no mean point
}

TEST(SimulateLogOptions, ForceBiasAndDelayOptionsReachTheLogAndItsMetadata) {
  const std::string dir = TempDir("sim_defects");
  const std::string scene = "--scene " + Scene("example3_pushed_square.ini") + " --write poses";
  ASSERT_EQ(RunTool("simulate", scene + " --out " + dir + "/plain.csv"), 0);
  ASSERT_EQ(RunTool("simulate", scene +
                                    " --force-bias-x 0.5 --force-bias-y -0.25 "
                                    "--force-delay 0.02 --out " +
                                    dir + "/defects.csv"),
            0);
  const Trajectory plain = ReadPushLog(dir + "/plain.csv");
  const Trajectory defects = ReadPushLog(dir + "/defects.csv");
  ASSERT_EQ(plain.samples.size(), defects.samples.size());
  const double dt = plain.samples[1].t_s - plain.samples[0].t_s;
  const size_t lag = static_cast<size_t>(std::lround(0.02 / dt));
  ASSERT_GE(lag, 1u);
  for (size_t u = lag; u < plain.samples.size(); ++u) {
    EXPECT_NEAR(defects.samples[u].applied.fx, plain.samples[u - lag].applied.fx + 0.5, 1e-9) << u;
    EXPECT_NEAR(defects.samples[u].applied.fy, plain.samples[u - lag].applied.fy - 0.25, 1e-9) << u;
  }
  const std::string text = ReadText(dir + "/defects.csv");
  EXPECT_NE(text.find("# noise_force_bias_x_n = 0.5\n"), std::string::npos);
  EXPECT_NE(text.find("# noise_force_delay_s = 0.02\n"), std::string::npos);
  EXPECT_EQ(RunTool("simulate", scene + " --force-delay nan"), 2);
}

}  // namespace
}  // namespace slideid
