// Import throughput of the other readers against the MIT JSON reader, measured in the same
// run: one synthetic push (datasets/mit_push_synth.h, 12 s of streams) written by our
// writers as MIT JSON, MIT HDF5 (contiguous and gzip), three stream CSVs (seconds, world
// frame), a ROS 1 bag (librosbag, uncompressed) and ROS 2 MCAP files (zstd, lz4, none), then
//  - BM_Read<format>: the file into its three streams (what each reader does);
//  - BM_Import<format>: the same plus the import into a push log (ImportMitPush), the work
//    of `import-log` per file without writing.
// Rows are the streams' rows (poses, tip poses, wrenches); main() prints each format's
// rows/s and its ratio to the JSON reader's: medians of 5 repetitions of CPU time, this
// process's and its children's (the bag is read in a child process; wall time would count
// whatever else the machine runs). Usage: import_benchmark [google benchmark flags]

#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "datasets/mit_push_synth.h"
#include "io/mcap_push.h"
#include "io/mit_push_h5.h"
#include "io/mit_push_import.h"
#include "io/mit_push_json.h"
#include "io/push_streams_csv.h"
#include "io/rosbag_push.h"

namespace slideid {
namespace {

struct Inputs {
  std::string dir;
  MitSynthSpec spec;
  MitPushRecording recording;
  RosTopics topics;
  PushStreamsCsv streams;
  double rows = 0;
};

const Inputs& Files() {
  static const Inputs inputs = [] {
    Inputs in;
    in.dir = (std::filesystem::temp_directory_path() / "slideid_import_benchmark_XXXXXX").string();
    if (mkdtemp(in.dir.data()) == nullptr) throw std::runtime_error("cannot make " + in.dir);
    in.spec.rest_after_s = 10.4;  // 12 s of streams
    in.recording = MakeMitPushRecording(in.spec).recording;
    in.rows = static_cast<double>(in.recording.object_pose.size() + in.recording.tip_pose.size() +
                                  in.recording.ft_wrench.size());
    in.topics.object_topic = "/object";
    in.topics.tip_topic = "/tip";
    in.topics.force_topic = "/ft";
    RosPushWriteSpec spec;
    spec.topics = in.topics;
    WriteMitPushJson(in.recording, in.dir + "/push.json");
    WriteMitPushH5(in.recording, in.dir + "/push.h5");
    MitPushH5WriteOptions gzip;
    gzip.deflate = true;
    WriteMitPushH5(in.recording, in.dir + "/push_gzip.h5", gzip);
    in.streams.pose = ParseStreamMapping(PushStream::kPose, "--pose", in.dir + "/pose.csv");
    in.streams.tip = ParseStreamMapping(PushStream::kTip, "--tip", in.dir + "/tip.csv:theta");
    in.streams.force = ParseStreamMapping(PushStream::kForce, "--force", in.dir + "/ft.csv:tz");
    WritePushStreamsCsv(in.recording, in.streams);
    WriteRosbagPushLog(in.recording, spec, in.dir + "/push.bag");
    for (McapCompression c :
         {McapCompression::kZstd, McapCompression::kLz4, McapCompression::kNone}) {
      McapWriterOptions o;
      o.compression = c;
      WriteMcapPushLog(in.recording, spec,
                       in.dir + "/push_" + (*ToString(c) ? ToString(c) : "none") + ".mcap", o);
    }
    return in;
  }();
  return inputs;
}

MitPushRecording Read(const std::string& format) {
  const Inputs& in = Files();
  if (format == "json") return ReadMitPushJson(in.dir + "/push.json");
  if (format == "h5") return ReadMitPushH5(in.dir + "/push.h5");
  if (format == "h5_gzip") return ReadMitPushH5(in.dir + "/push_gzip.h5");
  if (format == "streams") return ReadPushStreamsCsv(in.streams).recording;
  if (format == "rosbag") return ReadRosbagPushLog(in.dir + "/push.bag", in.topics).recording;
  return ReadMcapPushLog(in.dir + "/push_" + format.substr(5) + ".mcap", in.topics).recording;
}

/// CPU seconds of this process and its finished children: the bag is read in a child
/// process, and the machine may be shared (wall time would count the other programs).
double CpuSeconds() {
  double total = 0;
  for (int who : {RUSAGE_SELF, RUSAGE_CHILDREN}) {
    rusage u;
    getrusage(who, &u);
    total +=
        u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  }
  return total;
}

void BM_Read(benchmark::State& state, const std::string& format) {
  const Inputs& in = Files();
  for (auto _ : state) {
    const double start = CpuSeconds();
    benchmark::DoNotOptimize(Read(format));
    state.SetIterationTime(CpuSeconds() - start);
  }
  state.counters["rows/s"] =
      benchmark::Counter(in.rows, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Import(benchmark::State& state, const std::string& format) {
  const Inputs& in = Files();
  MitImportOptions options;
  options.slider = in.spec.slider;
  options.patch_spec = "rectangle 0.09 0.09";
  for (auto _ : state) {
    const double start = CpuSeconds();
    benchmark::DoNotOptimize(ImportMitPush(Read(format), "push", options));
    state.SetIterationTime(CpuSeconds() - start);
  }
  state.counters["rows/s"] =
      benchmark::Counter(in.rows, benchmark::Counter::kIsIterationInvariantRate);
}

const char* const kFormats[] = {"json",   "h5",        "h5_gzip",  "streams",
                                "rosbag", "mcap_zstd", "mcap_lz4", "mcap_none"};

/// Keeps each benchmark's median real time per iteration, to print the ratios at the end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  std::map<std::string, double> seconds;  ///< by name, e.g. "BM_Read/json"
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.aggregate_name != "median") continue;
      seconds[run.run_name.function_name] =
          run.GetAdjustedRealTime() / benchmark::GetTimeUnitMultiplier(run.time_unit);
    }
    ConsoleReporter::ReportRuns(runs);
  }
};

}  // namespace
}  // namespace slideid

int main(int argc, char** argv) {
  using namespace slideid;
  for (const char* f : kFormats) {
    benchmark::RegisterBenchmark((std::string("BM_Read/") + f).c_str(), BM_Read, f)
        ->Unit(benchmark::kMillisecond)
        ->UseManualTime()  // CpuSeconds: this process's and the bag reader's
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
  }
  for (const char* f : kFormats) {
    benchmark::RegisterBenchmark((std::string("BM_Import/") + f).c_str(), BM_Import, f)
        ->Unit(benchmark::kMillisecond)
        ->UseManualTime()
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
  }
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const double rows = Files().rows;
  std::printf("%.0f rows (three streams, 12 s); rows/s and ratio to the JSON reader:\n", rows);
  for (const char* kind : {"BM_Read/", "BM_Import/"}) {
    // Medians of the repetitions: the machine may be shared.
    const auto json = reporter.seconds.find(std::string(kind) + "json");
    for (const char* f : kFormats) {
      const auto it = reporter.seconds.find(std::string(kind) + f);
      if (it == reporter.seconds.end() || json == reporter.seconds.end()) continue;
      std::printf("%-22s %12.0f rows/s  %5.2f x json\n", (std::string(kind) + f).c_str(),
                  rows / it->second, json->second / it->second);
    }
  }
  std::filesystem::remove_all(Files().dir);
  benchmark::Shutdown();
  return 0;
}
