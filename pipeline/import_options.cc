#include "pipeline/import_options.h"

#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace slideid::cli {
namespace {

namespace po = boost::program_options;

std::optional<double> Physical(const po::variables_map& vm, const char* option, bool zero_ok) {
  if (!vm.count(option)) return std::nullopt;
  const double value = vm[option].as<double>();
  if (!std::isfinite(value) || value < 0.0 || (!zero_ok && value == 0.0)) {
    throw po::error(std::string("--") + option + " must be a finite number " +
                    (zero_ok ? ">= 0" : "> 0"));
  }
  return value;
}

MitImportOptions MitOptions(const po::variables_map& vm) {
  MitImportOptions o;
  o.tip_radius_m = vm["tip-radius"].as<double>();
  o.rate_hz = vm["rate"].as<double>();
  o.margin_s = vm["margin"].as<double>();
  o.max_offset_drift_n = vm["max-offset-drift"].as<double>();
  o.offset_clearance_m = vm["offset-clearance"].as<double>();
  o.max_pose_gap_s = vm["max-pose-gap"].as<double>();
  o.min_push_duration_s = vm["min-push-duration"].as<double>();
  const std::string sign = vm["force-sign"].as<std::string>();
  if (sign == "auto")
    o.force_sign = ForceSign::kAuto;
  else if (sign == "applied")
    o.force_sign = ForceSign::kApplied;
  else if (sign == "reaction")
    o.force_sign = ForceSign::kReaction;
  else
    throw po::error("--force-sign must be auto, applied or reaction");
  std::string why;
  if (!o.IsValid(&why)) throw po::error("invalid import setting: " + why);
  return o;
}

MitObjectSource Objects(const po::variables_map& vm, std::shared_ptr<const ObjectTable>* table) {
  MitObjectSource objects;
  objects.mass_kg = Physical(vm, "mass", false);
  objects.inertia_kgm2 = Physical(vm, "inertia", false);
  objects.com_height_m = Physical(vm, "com-height", true);
  if (vm.count("patch")) objects.patch_spec = vm["patch"].as<std::string>();
  if (vm.count("objects")) {
    *table = std::make_shared<const ObjectTable>(ReadObjectTable(vm["objects"].as<std::string>()));
  } else if (!objects.mass_kg || !objects.inertia_kgm2 || !objects.com_height_m ||
             !objects.patch_spec) {
    throw po::error(
        "the object is not known: give --mass, --inertia, --com-height and --patch, "
        "or an --objects table (masses are never guessed)");
  }
  return objects;
}

RosTopics RosOptions(const po::variables_map& vm) {
  RosTopics t;
  auto text = [&](const char* option, std::string* out) {
    if (vm.count(option)) *out = vm[option].as<std::string>();
  };
  text("object-topic", &t.object_topic);
  text("tip-topic", &t.tip_topic);
  text("force-topic", &t.force_topic);
  text("object-frame", &t.object_frame);
  text("tip-frame", &t.tip_frame);
  std::string why;
  if (!t.IsValid(&why)) throw po::error(why);
  return t;
}

/// The three stream files of --format streams (their mappings parsed, errors naming the
/// option).
PushStreamsCsv StreamsOptions(const po::variables_map& vm) {
  PushStreamsCsv files;
  const std::pair<const char*, PushStream> streams[] = {
      {"pose", PushStream::kPose}, {"tip", PushStream::kTip}, {"force", PushStream::kForce}};
  for (const auto& [option, stream] : streams) {
    if (!vm.count(option)) {
      throw po::error(std::string("--format streams needs --") + option +
                      " FILE[:key=column,...] (docs/real-data.md, \"Streams as CSV\")");
    }
    StreamCsvMapping m;
    try {
      m = ParseStreamMapping(stream, std::string("--") + option, vm[option].as<std::string>());
    } catch (const std::invalid_argument& e) {
      throw po::error(e.what());
    }
    (stream == PushStream::kPose  ? files.pose
     : stream == PushStream::kTip ? files.tip
                                  : files.force) = m;
  }
  if (files.force.sensor_frame && !files.force.sensor_yaw_rad &&
      !files.tip.columns.count("theta") && !files.tip.Quaternion()) {
    throw po::error(
        "--force yaw=tip needs the tip's orientation (theta= or qx, qy, qz, qw= in "
        "--tip)");
  }
  return files;
}

TripodImportOptions TripodOptions(const po::variables_map& vm) {
  TripodImportOptions o;
  o.mass_kg = Physical(vm, "mass", false);
  o.inertia_kgm2 = Physical(vm, "inertia", false);
  o.com_height_m = Physical(vm, "com-height", true);
  std::string why;
  if (!o.IsValid(&why)) throw po::error("invalid import setting: " + why);
  return o;
}

}  // namespace

void AddImportOptions(po::options_description* options, po::options_description* hidden) {
  options->add_options()("format", po::value<std::string>()->value_name("NAME"),
                         "mit-push (MIT push dataset JSON), mit-push-h5 (its HDF5 files), "
                         "streams (one CSV per stream), rosbag (ROS 1 bags), mcap (ROS 2 "
                         "MCAP files): push logs; or zhou-tripod (ICRA 2016 tripod logs: "
                         "wrench-twist pairs)")(
      "out", po::value<std::string>()->value_name("DIR"),
      "output directory: one DIR/<stem>.csv per accepted file and DIR/import_report.csv")(
      "objects", po::value<std::string>()->value_name("FILE"),
      "CSV table name,mass,inertia,com_height[,patch,source] by object name (shape=NAME)")(
      "mass", po::value<double>()->value_name("KG"), "object mass (overrides the table)")(
      "inertia", po::value<double>()->value_name("KG_M2"),
      "moment of inertia about the vertical axis through the CM (overrides the table)")(
      "com-height", po::value<double>()->value_name("M"), "CM height (overrides the table)")(
      "patch", po::value<std::string>()->value_name("SPEC"),
      "object outline = contact patch, e.g. \"rectangle 0.09 0.09\" (overrides the table)")(
      "tip-radius", po::value<double>()->default_value(0.00475)->value_name("M"), "pusher radius")(
      "rate", po::value<double>()->default_value(100.0)->value_name("HZ"), "rows per second")(
      "margin", po::value<double>()->default_value(0.05)->value_name("S"),
      "kept before and after the push")(
      "max-offset-drift", po::value<double>()->default_value(0.5)->value_name("N"),
      "reject a file whose force offsets before and after the push differ by more (only "
      "when both exist)")(
      "offset-clearance", po::value<double>()->default_value(3e-3)->value_name("M"),
      "the force offset is measured only where the tip is farther than this from the "
      "object's outline; before that, a tip resting on the object is a real pre-load")(
      "max-pose-gap", po::value<double>()->default_value(0.05)->value_name("S"),
      "a longer gap between object poses inside the push splits the log there (its rows "
      "left out, the next marked 'start'); a file whose gaps leave less of the push than "
      "--min-push-duration is rejected")("min-push-duration",
                                         po::value<double>()->default_value(0.2)->value_name("S"),
                                         "reject a shorter push")(
      "force-sign", po::value<std::string>()->default_value("auto"),
      "auto (per file, from the contact normal), applied or reaction (stored = -force)")(
      "object-topic", po::value<std::string>()->value_name("TOPIC"),
      "rosbag, mcap: the object's pose (geometry_msgs PoseStamped, TransformStamped or "
      "tf2_msgs TFMessage)")("tip-topic", po::value<std::string>()->value_name("TOPIC"),
                             "rosbag, mcap: the pusher tip's pose (same types)")(
      "force-topic", po::value<std::string>()->value_name("TOPIC"),
      "rosbag, mcap: the force (geometry_msgs WrenchStamped)")(
      "object-frame", po::value<std::string>()->value_name("FRAME"),
      "rosbag, mcap: the child frame id of the object's transform (required for a TFMessage "
      "topic)")("tip-frame", po::value<std::string>()->value_name("FRAME"),
                "rosbag, mcap: the child frame id of the tip's transform")(
      "pose", po::value<std::string>()->value_name("FILE[:MAP]"),
      "streams: the object's pose CSV, e.g. pose.csv:t=stamp,x=px,y=py,theta=yaw (or "
      "qx=..,qy=..,qz=..,qw=..), unit=s|ms|us|ns; its name names the push and the log")(
      "tip", po::value<std::string>()->value_name("FILE[:MAP]"),
      "streams: the pusher tip's CSV (t, x, y; theta or a quaternion optional)")(
      "force", po::value<std::string>()->value_name("FILE[:MAP]"),
      "streams: the force CSV (t, fx, fy; tz optional), frame=world (default) or "
      "frame=sensor with yaw=RAD or yaw=tip (the tip's logged yaw)");
  hidden->add_options()("files", po::value<std::vector<std::string>>())(
      // A check, not a converter (scripts/real_data.sh): see ImportRequest::h5_copies_dir.
      "h5-copies", po::value<std::string>()->value_name("DIR"));
}

ImportRequest ReadImportOptions(const po::variables_map& vm) {
  if (!vm.count("format")) throw po::error("the option '--format' is required");
  if (!vm.count("out")) throw po::error("the option '--out' is required");
  ImportRequest r;
  r.format = vm["format"].as<std::string>();
  r.out_dir = vm["out"].as<std::string>();
  const bool ros = r.format == "rosbag" || r.format == "mcap";
  const bool streams = r.format == "streams";
  const bool push = r.format == "mit-push" || r.format == "mit-push-h5" || ros || streams;
  if (!push && r.format != "zhou-tripod") {
    throw po::error("--format must be mit-push, mit-push-h5, streams, rosbag, mcap or zhou-tripod");
  }
  for (const char* option : {"pose", "tip", "force"}) {
    if (!streams && vm.count(option)) {
      throw po::error(std::string("--") + option + " applies to --format streams only");
    }
  }
  if (vm.count("h5-copies")) {
    if (r.format != "mit-push") throw po::error("--h5-copies applies to --format mit-push only");
    r.h5_copies_dir = vm["h5-copies"].as<std::string>();
  }
  if (streams) {
    if (vm.count("files")) {
      throw po::error(
          "--format streams reads the files of --pose, --tip and --force; no FILE "
          "argument");
    }
    r.streams = StreamsOptions(vm);
    r.files = {r.streams.pose.path};
  } else {
    if (!vm.count("files")) throw po::error("no input FILE given");
    r.files = vm["files"].as<std::vector<std::string>>();
  }
  for (const char* option :
       {"object-topic", "tip-topic", "force-topic", "object-frame", "tip-frame"}) {
    if (!ros && vm.count(option)) {
      throw po::error(std::string("--") + option + " applies to --format rosbag and mcap only");
    }
  }
  // The table is read before any import: a bad table is bad input, not I/O.
  if (push) {
    if (ros) r.ros = RosOptions(vm);
    r.objects = Objects(vm, &r.table);
    r.mit = MitOptions(vm);
  } else {
    r.tripod = TripodOptions(vm);
  }
  return r;
}

}  // namespace slideid::cli
