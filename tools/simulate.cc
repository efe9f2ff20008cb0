// simulate: run a scene file through the forward model and write the trajectory as a
// push log (docs/log-format.md), sampled, with the columns and the noise that the
// scene's [sim] log_every, [log] and [noise] (or the options) ask for.

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>

#include "datasets/sensor_model.h"
#include "forward_model/simulator.h"
#include "io/push_log.h"
#include "io/scene_file.h"
#include "io/simulated_log.h"
#include "pipeline/log_cli_options.h"
#include "tools/tool_support.h"

namespace po = boost::program_options;
using namespace slideid;

namespace {

void PrintSummary(const SimulationResult& result, const Scene& scene, std::FILE* to) {
  const SimulationSummary& s = result.summary;
  const PlanarState& last = result.trajectory.samples.back().state;
  std::fprintf(to, "scene       %s\n", scene.source.c_str());
  std::fprintf(to, "steps       %d (%d slide, %d stick), dt = %g s\n", s.steps, s.slide_steps,
               s.stick_steps, scene.dt_s);
  if (scene.pusher) {
    std::fprintf(to,
                 "pusher      tip sticking to the edge in %d steps, sliding along it in %d, "
                 "apart in %d\n",
                 s.tip_stick_steps, s.tip_slide_steps,
                 s.steps - s.tip_stick_steps - s.tip_slide_steps);
  }
  std::fprintf(to, "final       t = %.4f s  x = %.6f m  y = %.6f m  theta = %.6f rad\n",
               result.trajectory.samples.back().t_s, last.x, last.y, last.theta);
  std::fprintf(to, "            vx = %.6f m/s  vy = %.6f m/s  wz = %.6f rad/s\n", last.vx, last.vy,
               last.wz);
  if (s.rest_time_s >= 0) {
    std::fprintf(to, "at rest     from t = %.4f s at (%.6f, %.6f) m, theta = %.6f rad\n",
                 s.rest_time_s, last.x, last.y, last.theta);
  } else {
    std::fprintf(to, "at rest     no: still moving at the end (run longer with --duration)\n");
  }
  std::fprintf(to, "ECP margin  %.3f mm inside the patch hull at its closest\n",
               -1e3 * s.max_hull_signed_distance_m);
  std::fprintf(to, "solver      max %d iterations, max relative residual %.2e\n",
               s.max_step_iterations, s.max_step_residual);
}

// `--out` names the file standard output writes to (/dev/stdout, a pipe to another tool):
// the summary then goes to standard error, and the output is the log alone.
bool IsStandardOutput(const std::string& path) {
  struct stat out, target;
  return ::fstat(STDOUT_FILENO, &out) == 0 && ::stat(path.c_str(), &target) == 0 &&
         out.st_dev == target.st_dev && out.st_ino == target.st_ino;
}

}  // namespace

int main(int argc, char** argv) {
  return tools::RunTool("simulate", [&]() -> int {
    po::options_description opts(
        "simulate: simulate a slider on a plane (Xie & Chakraborty's planar sliding model)\n"
        "and write its trajectory as a push log.\n\n"
        "Usage: simulate --scene FILE.ini [--out traj.csv] [--dt S] [--duration S]\n"
        "                [--log-every K] [--write poses|velocities|both] [--noise-pose M] ...\n\n"
        "Log options override the scene's [sim] log_every, [log] and [noise] values.\n\n"
        "Options");
    opts.add_options()("help,h", "print this help and exit")("version",
                                                             "print the version and exit")(
        "scene", po::value<std::string>()->value_name("FILE.ini"),
        "scene file (INI: [slider] [friction] [patch] [initial] [push] [push.N] [program] "
        "[sim] [log] [noise]; see datasets/README.md)")(
        "out", po::value<std::string>()->value_name("FILE.csv"),
        "write the log here; omit to only print the summary")(
        "dt", po::value<double>()->value_name("S"), "override the scene's time step [s]")(
        "duration", po::value<double>()->value_name("S"), "override the scene's duration [s]");
    cli::AddLogOptions(&opts, nullptr, /*with_seed=*/true);
    po::variables_map vm;
    po::store(po::parse_command_line(argc, argv, opts), vm);
    po::notify(vm);
    if (vm.count("help")) {
      std::cout << opts
                << "\nExit codes: 0 ok, 1 bad input, 2 usage, 3 numerical failure or "
                   "toppling, 4 file not writable.\n";
      return tools::kExitOk;
    }
    if (vm.count("version")) {
      std::cout << "simulate (slideid) " << SLIDEID_VERSION << "\n";
      return tools::kExitOk;
    }
    if (!vm.count("scene")) throw po::error("the option '--scene' is required");

    LoggedScene scene = LoadScene(vm["scene"].as<std::string>());
    if (vm.count("dt")) {
      scene.dt_s = vm["dt"].as<double>();
      if (!(scene.dt_s > 0)) throw po::error("--dt must be > 0");
    }
    if (vm.count("duration")) {
      scene.duration_s = vm["duration"].as<double>();
      if (!(scene.duration_s > 0)) throw po::error("--duration must be > 0");
    }
    cli::ApplyLogOptions(vm, &scene.log);
    std::string why;
    if (!scene.log.IsValidFor(!scene.pushes.empty(), &why)) throw po::error(why);
    const SimulationResult result = Simulate(scene);
    if (!result.summary.ok()) {
      std::cerr << "simulate: " << ToString(result.summary.status) << ": " << result.summary.message
                << "\n";
      return tools::kExitNumerical;
    }
    std::FILE* summary =
        vm.count("out") && IsStandardOutput(vm["out"].as<std::string>()) ? stderr : stdout;
    PrintSummary(result, scene, summary);
    if (vm.count("out")) {
      const Trajectory log = MakeLog(result.trajectory, scene.log);
      std::fprintf(summary, "log         %zu rows every %d steps, %s, push as %s, noise %s\n",
                   log.samples.size(), scene.log.log_every, ToString(scene.log.motion),
                   ToString(scene.log.push),
                   scene.log.noise.IsZero() && !scene.log.noise.HasDefects()
                       ? "none"
                       : scene.log.noise.Describe().c_str());
      try {
        WritePushLog(SimulatedLogFile(scene, log), vm["out"].as<std::string>());
      } catch (const std::exception& e) {
        std::cerr << "simulate: " << e.what() << "\n";
        return tools::kExitIo;
      }
      std::fprintf(summary, "wrote       %s\n", vm["out"].as<std::string>().c_str());
    }
    return tools::kExitOk;
  });
}
