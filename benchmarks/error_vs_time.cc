// Error against run time of every estimator (issue 5): a Monte Carlo suite of synthetic push
// logs with known friction, identified by the closed form, the equation error and the
// trajectory fit at several segment lengths and substep counts.
//
// A log: a seeded scene (fixtures/seeded_scenes.h: friction, initial state and push program
// drawn per seed) is simulated at log_dt / log_every and logged by make-dataset's sensor
// model (MakeLog, datasets/sensor_model.h): every log_every-th row with the wrench averaged
// over its interval (a 100 Hz log of a finer simulation, so that substeps > 1 have something
// to gain), noise, and the pose columns only (motion capture) or the velocity columns only
// (a velocity sensor); the log is written and read back as identify reads it. The same
// simulated scene is used at every noise level and by every estimator. The time is
// steady_clock around Identify (wall) and the process CPU time around it.
//
// Output: one CSV row per (estimator, motion, noise, length, scene), plus rows pooled over
// the scenes (scene = "all"); optionally Markdown tables and one CSV row per Identify call.
// A plain program, not Google Benchmark: each run is one Identify call on a different log.

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "benchmarks/bench_args.h"
#include "benchmarks/table_tool.h"
#include "datasets/sensor_model.h"
#include "estimator/identify.h"
#include "fixtures/seeded_scenes.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"

namespace slideid {
namespace {

using testing::kSceneKinds;
using testing::SceneKind;

// A scene that fails to simulate (toppling, no convergence) is redrawn with another seed,
// at most this often; redraws are counted and reported.
constexpr int kMaxRedraws = 5;
constexpr std::uint64_t kRedrawStride = 1000003;

/// Whether the scene's motion determines parameter i: without rotation c does not matter.
bool Determines(SceneKind k, int i) { return !(k == SceneKind::kPureTranslation && i == kC); }

/// Fixed seed of a scene, distinct for every kind, length (< 10^4 steps) and index.
std::uint64_t SceneSeed(SceneKind k, int steps, int index) {
  return 100000000ull * (static_cast<int>(k) + 1) + 10000ull * steps + index;
}

/// A sensor noise level: poses-only logs get the pose and angle noise, velocities-only logs
/// the velocity and spin noise.
struct NoiseLevel {
  const char* name;
  double pose_m, angle_rad;
  double velocity_mps, spin_radps;
};
constexpr NoiseLevel kNoiseLevels[] = {
    {"none", 0, 0, 0, 0},
    {"mocap", 3e-4, 3e-3, 3e-3, 3e-2},  // typical motion capture: 0.3 mm, 3 mrad
    {"poor", 2e-3, 2e-2, 2e-2, 2e-1},   // poor tracking: 2 mm, 20 mrad
};
constexpr int kNoiseCount = static_cast<int>(std::size(kNoiseLevels));

/// One estimator configuration.
struct Variant {
  std::string name;
  IdentifyOptions options;
};

std::vector<Variant> MakeVariants(int threads) {
  std::vector<Variant> v;
  auto add = [&](const std::string& name, EstimatorMethod m, int segment, int substeps) {
    IdentifyOptions o;
    o.method = m;
    o.trajectory.segment_steps = segment;
    o.trajectory.substeps = substeps;
    o.threads = threads;
    v.push_back({name, o});
  };
  add("closed-form", EstimatorMethod::kClosedForm, 50, 1);
  add("equation-error", EstimatorMethod::kEquationError, 50, 1);
  // The default: segments sized to the log (TrajectorySegmentSteps), then fixed lengths.
  add("trajectory default", EstimatorMethod::kTrajectory, 0, 1);
  for (int segment : {25, 50, 100}) {
    add("trajectory seg" + std::to_string(segment) + " sub1", EstimatorMethod::kTrajectory, segment,
        1);
  }
  add("trajectory seg50 sub2", EstimatorMethod::kTrajectory, 50, 2);
  add("trajectory seg50 sub4", EstimatorMethod::kTrajectory, 50, 4);
  return v;
}

/// What the simulation of one scene looked like.
struct SceneStats {
  int redraws = 0;
  double slide_fraction = 0;
  double max_hull_signed_distance_m = 0;
};

/// Simulates a scene, redrawing it on failure; returns the simulated trajectory (one row per
/// simulated step). Throws std::runtime_error after kMaxRedraws.
Trajectory SimulateScene(SceneKind kind, int log_steps, int log_every, std::uint64_t seed,
                         LoggedScene* scene, SceneStats* stats) {
  for (int r = 0; r <= kMaxRedraws; ++r) {
    *scene = testing::SeededScene(kind, log_steps, log_every, seed + r * kRedrawStride);
    SimulationResult sim = Simulate(*scene);
    if (sim.summary.ok()) {
      stats->redraws = r;
      stats->slide_fraction = double(sim.summary.slide_steps) / std::max(1, sim.summary.steps);
      stats->max_hull_signed_distance_m = sim.summary.max_hull_signed_distance_m;
      return std::move(sim.trajectory);
    }
    std::fprintf(stderr, "error_vs_time: %s seed %llu: %s; redrawing\n", ToString(kind),
                 static_cast<unsigned long long>(seed + r * kRedrawStride),
                 sim.summary.message.c_str());
  }
  throw std::runtime_error(std::string("scene ") + ToString(kind) + " failed to simulate");
}

/// The log a sensor would give: the scene's log spec (MakeLog) with only the pose (or only
/// the velocity) columns and the noise of `level`, written to `path` and read back as
/// identify reads it.
Trajectory SensorLog(const Trajectory& simulated, const LogSpec& scene_log, const NoiseLevel& level,
                     bool poses, std::uint64_t seed, const std::string& path) {
  LogSpec spec = scene_log;
  spec.motion = poses ? LogMotion::kPoses : LogMotion::kVelocities;
  if (poses) {
    spec.noise.pose_m = level.pose_m;
    spec.noise.angle_rad = level.angle_rad;
  } else {
    spec.noise.velocity_mps = level.velocity_mps;
    spec.noise.spin_radps = level.spin_radps;
  }
  spec.noise.seed = seed;
  WritePushLog(MakeLog(simulated, spec), path);
  return ReadPushLog(path);
}

/// One Identify call.
struct Run {
  bool failed = false;  ///< threw (too short, too little sliding, ...)
  bool converged = false;
  ParameterEstimate p[3];
  double wall_s = 0, cpu_s = 0;
  int iterations = 0;
  std::string message;
};

double ProcessCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

Run IdentifyTimed(const Trajectory& log, const IdentifyOptions& options) {
  Run run;
  const double cpu0 = ProcessCpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  try {
    const EstimateResult r = Identify(log, options);
    if (r.status == TerminationStatus::kTooLittleExcitation) throw std::invalid_argument(r.message);
    run.converged = r.converged;
    for (int i = 0; i < 3; ++i) run.p[i] = r.parameters[i];
    run.iterations = r.iterations;
    run.message = r.message;
  } catch (const std::exception& e) {
    run.failed = true;
    run.message = e.what();
  }
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  run.cpu_s = ProcessCpuSeconds() - cpu0;
  return run;
}

/// Quantile q of `v` (linear interpolation between order statistics); NaN when empty.
double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

/// The runs of one aggregation cell. Errors and coverage count only parameters that the
/// scene determines and the estimator reported identifiable.
struct Cell {
  int runs = 0, failed = 0, not_converged = 0;
  int missed[3] = {0, 0, 0};    ///< determined by the scene, reported not identifiable
  int spurious[3] = {0, 0, 0};  ///< not determined by the scene, reported identifiable
  int covered[3] = {0, 0, 0};   ///< 95% interval contains the truth
  std::vector<double> rel_error[3];
  std::vector<double> wall_s, cpu_s;

  void Add(const Run& run, const double truth[3], SceneKind kind) {
    ++runs;
    wall_s.push_back(run.wall_s);
    cpu_s.push_back(run.cpu_s);
    if (run.failed) {
      ++failed;
      return;
    }
    not_converged += !run.converged;
    for (int i = 0; i < 3; ++i) {
      const ParameterEstimate& p = run.p[i];
      if (!Determines(kind, i)) {
        spurious[i] += p.identifiable;
      } else if (!p.identifiable) {
        ++missed[i];
      } else {
        rel_error[i].push_back(std::abs(p.value / truth[i] - 1));
        covered[i] += p.ci95_lo <= truth[i] && truth[i] <= p.ci95_hi;
      }
    }
  }
  void Merge(const Cell& o) {
    runs += o.runs;
    failed += o.failed;
    not_converged += o.not_converged;
    for (int i = 0; i < 3; ++i) {
      missed[i] += o.missed[i];
      spurious[i] += o.spurious[i];
      covered[i] += o.covered[i];
      rel_error[i].insert(rel_error[i].end(), o.rel_error[i].begin(), o.rel_error[i].end());
    }
    wall_s.insert(wall_s.end(), o.wall_s.begin(), o.wall_s.end());
    cpu_s.insert(cpu_s.end(), o.cpu_s.begin(), o.cpu_s.end());
  }
  /// Fraction of the reported intervals (all parameters) that contain the truth.
  double Coverage() const {
    int n = 0, k = 0;
    for (int i = 0; i < 3; ++i) {
      n += static_cast<int>(rel_error[i].size());
      k += covered[i];
    }
    return n ? double(k) / n : NAN;
  }
};

// (estimator, motion, noise, length, scene)
using CellKey = std::tuple<int, std::string, int, int, std::string>;

struct Config {
  bool quick = false;
  bool velocities = true;
  bool describe = false;
  int threads = 1;
  int log_every = 4;
  std::vector<int> lengths;
  std::vector<int> seeds_per_length;
  std::string csv_path = "error_vs_time.csv";
  std::string markdown_path;
  std::string runs_path;
  std::string logs_dir;    ///< when set, every log is kept there
  std::string only_scene;  ///< when set, only scenes of this kind
  bool verbose = false;    ///< print every run to stderr

  std::vector<std::string> Motions() const {
    return velocities ? std::vector<std::string>{"poses", "velocities"}
                      : std::vector<std::string>{"poses"};
  }
  bool Runs(SceneKind k) const { return only_scene.empty() || only_scene == ToString(k); }
};

using bench::Fmt;

std::string Percent(double v) {
  if (!std::isfinite(v)) return "-";
  const double p = 100 * v;
  return Fmt(p >= 10 ? "%.0f%%" : p >= 0.095 ? "%.2g%%" : "%.1g%%", p);
}

std::string Seconds(double s) {
  if (!std::isfinite(s)) return "-";
  if (s < 1e-3) return Fmt("%.3g us", s * 1e6);
  if (s < 1) return Fmt("%.3g ms", s * 1e3);
  return Fmt("%.3g s", s);
}

void WriteCsv(const std::string& path, const std::map<CellKey, Cell>& cells,
              const std::vector<Variant>& variants) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "estimator,method,segment,substeps,motion,noise,steps,scene,runs,failed,"
         "not_converged";
  for (const char* p : {"a", "b", "c"}) {
    out << ",missed_" << p << ",spurious_" << p << ",med_err_" << p << ",p90_err_" << p << ",cover_"
        << p;
  }
  out << ",coverage,med_wall_s,med_cpu_s\n";
  for (const auto& [key, c] : cells) {
    const auto& [v, motion, noise, steps, scene] = key;
    const IdentifyOptions& o = variants[v].options;
    const bool traj = o.method == EstimatorMethod::kTrajectory;
    out << variants[v].name << ',' << ToString(o.method) << ','
        << (traj ? std::to_string(o.trajectory.segment_steps) : "") << ','
        << (traj ? std::to_string(o.trajectory.substeps) : "") << ',' << motion << ','
        << kNoiseLevels[noise].name << ',' << steps << ',' << scene << ',' << c.runs << ','
        << c.failed << ',' << c.not_converged;
    for (int i = 0; i < 3; ++i) {
      const int n = static_cast<int>(c.rel_error[i].size());
      out << ',' << c.missed[i] << ',' << c.spurious[i] << ','
          << Fmt("%.4g", Quantile(c.rel_error[i], 0.5)) << ','
          << Fmt("%.4g", Quantile(c.rel_error[i], 0.9)) << ','
          << Fmt("%.3f", n ? double(c.covered[i]) / n : NAN);
    }
    out << ',' << Fmt("%.3f", c.Coverage()) << ',' << Fmt("%.4g", Quantile(c.wall_s, 0.5)) << ','
        << Fmt("%.4g", Quantile(c.cpu_s, 0.5)) << '\n';
  }
}

std::string NoiseDescription(const std::string& motion, int noise) {
  const NoiseLevel& L = kNoiseLevels[noise];
  if (noise == 0) return "noiseless";
  if (motion == "poses") {
    return std::string(L.name) + Fmt(" (pose %.2g mm, ", L.pose_m * 1e3) +
           Fmt("angle %.2g mrad)", L.angle_rad * 1e3);
  }
  return std::string(L.name) + Fmt(" (velocity %.2g mm/s, ", L.velocity_mps * 1e3) +
         Fmt("spin %.2g rad/s)", L.spin_radps);
}

std::string ErrorsABC(const Cell& c) {
  std::string s;
  for (int i = 0; i < 3; ++i) {
    s += (i ? " / " : "") + Percent(Quantile(c.rel_error[i], 0.5));
  }
  return s;
}

// Markdown: a headline table (the middle length, every noise level, per motion), then one
// table per (motion, noise) with every length, then identifiability flags by scene.
void WriteMarkdown(const std::string& path, const std::map<CellKey, Cell>& cells,
                   const std::vector<Variant>& variants, const Config& config) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  auto find = [&](int v, const std::string& m, int n, int steps, const std::string& scene) {
    const auto it = cells.find({v, m, n, steps, scene});
    return it == cells.end() ? nullptr : &it->second;
  };
  const int headline_steps = config.lengths[config.lengths.size() / 2];
  for (const std::string& motion : config.Motions()) {
    out << "\n### Headline: " << motion << "-only logs of " << headline_steps
        << " steps, all scenes pooled\n\n"
        << "Median relative error of a / b / c at each noise level; failures and missed "
           "parameters (determined by the scene but reported not identifiable) and 95% "
           "interval coverage at mocap noise; median wall time per log at mocap noise.\n\n"
        << "| estimator | noiseless | mocap | poor | mocap: failed; missed a / b / c; of "
           "runs | coverage (mocap) | time (mocap) |\n|---|---|---|---|---|---:|---:|\n";
    for (size_t v = 0; v < variants.size(); ++v) {
      const Cell* c[kNoiseCount];
      for (int n = 0; n < kNoiseCount; ++n) c[n] = find(int(v), motion, n, headline_steps, "all");
      if (!c[0] || !c[1] || !c[2]) continue;
      const Cell& m = *c[1];
      out << "| " << variants[v].name << " | " << ErrorsABC(*c[0]) << " | " << ErrorsABC(m) << " | "
          << ErrorsABC(*c[2]) << " | " << m.failed << "; " << m.missed[0] << " / " << m.missed[1]
          << " / " << m.missed[2] << "; " << m.runs << " | " << Percent(m.Coverage()) << " | "
          << Seconds(Quantile(m.wall_s, 0.5)) << " |\n";
    }
  }
  for (const std::string& motion : config.Motions()) {
    for (int noise = 0; noise < kNoiseCount; ++noise) {
      out << "\n### " << motion << "-only logs, noise: " << NoiseDescription(motion, noise)
          << "\n\n| estimator | steps | rel. error a: median / p90 | b | c | failed | missed "
             "a / b / c | spurious c | coverage | median time, wall / CPU |\n"
             "|---|---:|---|---|---|---:|---|---:|---:|---:|\n";
      for (size_t v = 0; v < variants.size(); ++v) {
        for (int steps : config.lengths) {
          const Cell* c = find(int(v), motion, noise, steps, "all");
          if (!c) continue;
          out << "| " << variants[v].name << " | " << steps;
          for (int i = 0; i < 3; ++i) {
            out << " | " << Percent(Quantile(c->rel_error[i], 0.5)) << " / "
                << Percent(Quantile(c->rel_error[i], 0.9));
          }
          out << " | " << c->failed << " | " << c->missed[0] << " / " << c->missed[1] << " / "
              << c->missed[2] << " | " << c->spurious[kC] << " | " << Percent(c->Coverage())
              << " | " << Seconds(Quantile(c->wall_s, 0.5)) << " / "
              << Seconds(Quantile(c->cpu_s, 0.5)) << " |\n";
        }
      }
    }
  }
  for (const std::string& motion : config.Motions()) {
    out << "\n### Failures and flags by scene, " << motion
        << "-only logs, all noise levels and lengths\n\n"
           "Each cell: failed, missed a / b / c (pure translation: c reported identifiable, "
           "which it is not), of runs.\n\n| estimator |";
    for (SceneKind k : kSceneKinds) out << ' ' << ToString(k) << " |";
    out << "\n|---|";
    for (size_t k = 0; k < std::size(kSceneKinds); ++k) out << "---|";
    out << '\n';
    for (size_t v = 0; v < variants.size(); ++v) {
      out << "| " << variants[v].name << " |";
      for (SceneKind k : kSceneKinds) {
        Cell sum;
        for (int noise = 0; noise < kNoiseCount; ++noise) {
          for (int steps : config.lengths) {
            if (const Cell* c = find(int(v), motion, noise, steps, ToString(k))) sum.Merge(*c);
          }
        }
        out << ' ' << sum.failed << ", " << sum.missed[0] << " / " << sum.missed[1] << " / "
            << (Determines(k, kC) ? sum.missed[kC] : sum.spurious[kC]) << " of " << sum.runs
            << " |";
      }
      out << '\n';
    }
  }
}

// Per scene kind and length: smallest slide fraction, largest hull distance, speed, spin.
void Describe(const Config& config) {
  std::printf("%-17s %6s %5s %8s %7s %10s %9s %9s %7s\n", "scene", "steps", "seeds", "redraws",
              "slide", "hull [mm]", "max |v|", "max |w|", "pushes");
  for (size_t li = 0; li < config.lengths.size(); ++li) {
    const int steps = config.lengths[li];
    for (SceneKind kind : kSceneKinds) {
      if (!config.Runs(kind)) continue;
      int redraws = 0;
      double slide = 1, hull = -1, vmax = 0, wmax = 0;
      size_t pushes = 0;
      for (int seed = 1; seed <= config.seeds_per_length[li]; ++seed) {
        LoggedScene scene;
        SceneStats stats;
        const Trajectory log = MakeLog(SimulateScene(kind, steps, config.log_every,
                                                     SceneSeed(kind, steps, seed), &scene, &stats),
                                       scene.log);
        redraws += stats.redraws;
        slide = std::min(slide, stats.slide_fraction);
        hull = std::max(hull, stats.max_hull_signed_distance_m);
        pushes = std::max(pushes, scene.pushes.size());
        for (const TrajectorySample& s : log.samples) {
          vmax = std::max(vmax, std::hypot(s.state.vx, s.state.vy));
          wmax = std::max(wmax, std::abs(s.state.wz));
        }
      }
      std::printf("%-17s %6d %5d %8d %6.0f%% %10.2f %7.2f/s %6.1f/s %7zu\n", ToString(kind), steps,
                  config.seeds_per_length[li], redraws, 100 * slide, hull * 1e3, vmax, wmax,
                  pushes);
    }
  }
  std::printf(
      "(slide: smallest fraction of sliding steps; hull: largest signed distance of the "
      "ECP to the hull, negative inside; max |v| [m/s], max |w| [rad/s]; over seeds)\n");
}

void Usage(const char* argv0) {
  std::printf(
      "usage: %s [--quick] [--poses-only] [--threads N] [--log-every K] [--csv FILE]\n"
      "          [--markdown FILE] [--runs FILE] [--write-logs DIR] [--scene KIND]\n"
      "          [--lengths L,...] [--seeds N,...] [--verbose] [--describe]\n"
      "Monte Carlo error and run time of every estimator on synthetic push logs.\n"
      "  --quick           lengths 100 and 1000 only, fewer seeds (under a minute)\n"
      "  --poses-only      skip the velocities-only logs\n"
      "  --threads N       threads per Identify call (default 1, for timings)\n"
      "  --log-every K     simulated steps per 10 ms log interval (default 4; 1: the\n"
      "                    estimators' model is exact at substeps 1)\n"
      "  --csv FILE        aggregated results (default error_vs_time.csv)\n"
      "  --markdown FILE   Markdown tables of the results\n"
      "  --runs FILE       one CSV row per Identify call\n"
      "  --write-logs DIR  keep every log as DIR/<scene>_<steps>_<seed>_<noise>_<motion>.csv\n"
      "  --scene KIND      only free-spin, pushed-rotation, pure-translation or anisotropic\n"
      "  --lengths L,...   log lengths in steps (default 100,1000,5000; quick 100,1000)\n"
      "  --seeds N,...     seeds per length (default 40,16,6; quick 6,2)\n"
      "  --verbose         print every Identify call to stderr\n"
      "  --describe        print what the simulated scenes look like, and stop\n",
      argv0);
}

int Main(int argc, char** argv) {
  Config config;
  std::vector<int> lengths, seeds;
  bench::Args args(argc, argv);
  while (args.Next()) {
    if (args.Is("--quick"))
      config.quick = true;
    else if (args.Is("--poses-only"))
      config.velocities = false;
    else if (args.Is("--describe"))
      config.describe = true;
    else if (args.Is("--threads"))
      config.threads = args.Integer();
    else if (args.Is("--log-every"))
      config.log_every = args.Integer();
    else if (args.Is("--csv"))
      config.csv_path = args.Value();
    else if (args.Is("--markdown"))
      config.markdown_path = args.Value();
    else if (args.Is("--runs"))
      config.runs_path = args.Value();
    else if (args.Is("--write-logs"))
      config.logs_dir = args.Value();
    else if (args.Is("--scene"))
      config.only_scene = args.Value();
    else if (args.Is("--lengths"))
      lengths = args.Integers();
    else if (args.Is("--seeds"))
      seeds = args.Integers();
    else if (args.Is("--verbose"))
      config.verbose = true;
    else if (args.Is("--help") || args.Is("-h")) {
      Usage(argv[0]);
      return 0;
    } else {
      std::fprintf(stderr, "error_vs_time: unknown option %s\n", args.option().c_str());
      Usage(argv[0]);
      return 2;
    }
  }
  if (config.log_every < 1 || config.threads < 1) {
    std::fprintf(stderr, "error_vs_time: --log-every and --threads must be >= 1\n");
    return 2;
  }
  if (config.quick) {
    config.lengths = {100, 1000};
    config.seeds_per_length = {6, 2};
  } else {
    config.lengths = {100, 1000, 5000};
    config.seeds_per_length = {40, 16, 6};
  }
  if (!lengths.empty()) config.lengths = lengths;
  if (!seeds.empty()) config.seeds_per_length = seeds;
  if (config.seeds_per_length.size() != config.lengths.size()) {
    std::fprintf(stderr, "error_vs_time: --seeds needs one count per length\n");
    return 2;
  }
  for (size_t li = 0; li < config.lengths.size(); ++li) {
    if (config.lengths[li] < 1 || config.lengths[li] >= 10000 || config.seeds_per_length[li] < 1 ||
        config.seeds_per_length[li] >= 10000) {
      std::fprintf(stderr, "error_vs_time: lengths and seeds must be in [1, 9999]\n");
      return 2;
    }
  }
  if (config.describe) {
    Describe(config);
    return 0;
  }

  const std::vector<Variant> variants = MakeVariants(config.threads);
  for (const Variant& v : variants) {
    std::string why;
    if (!v.options.IsValid(&why)) throw std::invalid_argument(v.name + ": " + why);
  }
  const std::string tmp_path =
      "/tmp/error_vs_time." + std::to_string(static_cast<long>(getpid())) + ".csv";
  std::map<CellKey, Cell> cells;
  std::ofstream runs_out;
  if (!config.runs_path.empty()) {
    runs_out.open(config.runs_path);
    if (!runs_out) throw std::runtime_error("cannot write " + config.runs_path);
    runs_out << "estimator,motion,noise,steps,scene,seed,failed,converged,a,b,c,true_a,true_b,"
                "true_c,ident_a,ident_b,ident_c,wall_s,cpu_s,iterations,message\n";
  }
  int total_redraws = 0;
  const auto t_start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  };
  for (size_t li = 0; li < config.lengths.size(); ++li) {
    const int steps = config.lengths[li];
    for (SceneKind kind : kSceneKinds) {
      if (!config.Runs(kind)) continue;
      for (int index = 1; index <= config.seeds_per_length[li]; ++index) {
        const std::uint64_t seed = SceneSeed(kind, steps, index);
        LoggedScene scene;
        SceneStats stats;
        const Trajectory simulated =
            SimulateScene(kind, steps, config.log_every, seed, &scene, &stats);
        total_redraws += stats.redraws;
        const ReducedFriction t = scene.friction.reduced();
        const double truth[3] = {t.a, t.b, t.c};
        for (const std::string& motion : config.Motions()) {
          for (int noise = 0; noise < kNoiseCount; ++noise) {
            const std::string path = config.logs_dir.empty()
                                         ? tmp_path
                                         : config.logs_dir + "/" + ToString(kind) + "_" +
                                               std::to_string(steps) + "_" + std::to_string(seed) +
                                               "_" + kNoiseLevels[noise].name + "_" + motion +
                                               ".csv";
            const Trajectory log = SensorLog(simulated, scene.log, kNoiseLevels[noise],
                                             motion == "poses", seed * 10 + noise, path);
            for (size_t v = 0; v < variants.size(); ++v) {
              const Run run = IdentifyTimed(log, variants[v].options);
              cells[{int(v), motion, noise, steps, ToString(kind)}].Add(run, truth, kind);
              cells[{int(v), motion, noise, steps, "all"}].Add(run, truth, kind);
              if (config.verbose) {
                std::fprintf(stderr, "run: %s %s %s %d %s %llu: %s\n", variants[v].name.c_str(),
                             motion.c_str(), kNoiseLevels[noise].name, steps, ToString(kind),
                             static_cast<unsigned long long>(seed),
                             run.failed ? run.message.c_str() : "ok");
              }
              if (!runs_out) continue;
              std::string message = run.message.substr(0, 200);
              std::replace(message.begin(), message.end(), ',', ';');
              std::replace(message.begin(), message.end(), '\n', ' ');
              runs_out << variants[v].name << ',' << motion << ',' << kNoiseLevels[noise].name
                       << ',' << steps << ',' << ToString(kind) << ',' << seed << ',' << run.failed
                       << ',' << run.converged;
              for (int i = 0; i < 3; ++i) runs_out << ',' << Fmt("%.9g", run.p[i].value);
              for (int i = 0; i < 3; ++i) runs_out << ',' << Fmt("%.9g", truth[i]);
              for (int i = 0; i < 3; ++i) runs_out << ',' << run.p[i].identifiable;
              runs_out << ',' << run.wall_s << ',' << run.cpu_s << ',' << run.iterations << ','
                       << message << '\n';
            }
          }
        }
      }
      std::fprintf(stderr, "error_vs_time: %5d steps, %-16s done (%.0f s)\n", steps, ToString(kind),
                   elapsed());
    }
  }
  if (config.logs_dir.empty()) std::remove(tmp_path.c_str());
  WriteCsv(config.csv_path, cells, variants);
  if (!config.markdown_path.empty()) WriteMarkdown(config.markdown_path, cells, variants, config);
  std::printf("error_vs_time: %zu estimators; lengths", variants.size());
  for (size_t li = 0; li < config.lengths.size(); ++li) {
    std::printf(" %d (%d seeds)", config.lengths[li], config.seeds_per_length[li]);
  }
  std::printf(
      "; %zu scene kinds; %d noise levels; %zu motions; log_every %d; %d scene "
      "redraws; %.0f s; wrote %s\n",
      std::size(kSceneKinds), kNoiseCount, config.Motions().size(), config.log_every, total_redraws,
      elapsed(), config.csv_path.c_str());
  return 0;
}

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) {
  return slideid::bench::RunTableTool("error_vs_time", slideid::Main, argc, argv);
}
