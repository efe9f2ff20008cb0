// Writes the seed corpora of fuzz_mit_push_h5 (fuzz/corpus/mit_push_h5/), fuzz_streams
// (fuzz/corpus/streams/) and fuzz_rosbag (fuzz/corpus/rosbag/) with our own writers: short
// synthetic pushes (the first rows of each stream of a simulated MIT recording), as HDF5 contiguous
// and gzip-compressed, and as stream CSVs under several mappings (units, a quaternion, sensor
// frames), and as bags (PoseStamped or TransformStamped poses, some stamps zero; uncompressed, bz2
// and lz4 chunks). Run by hand when a format changes: build-fuzz/bin/make_import_corpus fuzz/corpus
#include <cstdio>
#include <fstream>
#include <string>

#include "datasets/mit_push_synth.h"
#include "fuzz/corpus_seed.h"
#include "io/mit_push_h5.h"
#include "io/push_streams_csv.h"
#include "io/rosbag_push.h"

using namespace slideid;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_import_corpus DIR (fuzz/corpus)\n");
    return 2;
  }
  const std::string dir = argv[1];
  const MitPushRecording rec = ShortSeedRecording();
  auto write = [&](const std::string& name, const std::string& bytes) {
    WriteSeed(dir, name, bytes);
  };
  MitPushH5WriteOptions gzip;
  gzip.deflate = true;
  write("mit_push_h5/push.h5", FormatMitPushH5(rec));
  write("mit_push_h5/push_gzip.h5", FormatMitPushH5(rec, gzip));
  const char* const mappings[][3] = {
      {"p.csv", "t.csv", "f.csv"},
      {"p.csv:t=stamp,x=px,y=py,theta=yaw,unit=ms", "t.csv:theta,unit=us", "f.csv:tz,unit=ns"},
      {"p.csv:qx=a,qy=b,qz=c,qw=d", "t.csv:theta", "f.csv:frame=sensor,yaw=tip"},
      {"p.csv", "t.csv", "f.csv:fx=force_x,fy=force_y,frame=sensor,yaw=0.3"}};
  int k = 0;
  for (const auto& m : mappings) {
    PushStreamsCsv files;
    files.pose = ParseStreamMapping(PushStream::kPose, "--pose", m[0]);
    files.tip = ParseStreamMapping(PushStream::kTip, "--tip", m[1]);
    files.force = ParseStreamMapping(PushStream::kForce, "--force", m[2]);
    write("streams/push_" + std::to_string(k++), std::string(m[0]) + "\n" + m[1] + "\n" + m[2] +
                                                     "\n" + FormatPushStreamCsv(rec, files.pose) +
                                                     "\f" + FormatPushStreamCsv(rec, files.tip) +
                                                     "\f" + FormatPushStreamCsv(rec, files.force));
  }
  RosPushWriteSpec bag;
  bag.topics.object_topic = "/vicon/object";  // fuzz/fuzz_rosbag.cc reads these topics
  bag.topics.tip_topic = "/tip_pose";
  bag.topics.force_topic = "/netft/wrench";
  WriteRosbagPushLog(rec, bag, dir + "/rosbag/push.bag");
  WriteRosbagPushLog(rec, bag, dir + "/rosbag/push_lz4.bag", RosbagCompression::kLz4);
  WriteRosbagPushLog(rec, bag, dir + "/rosbag/push_bz2.bag", RosbagCompression::kBz2);
  bag.object_type = RosMessageType::kTransformStamped;
  bag.zero_stamp_every = 3;
  WriteRosbagPushLog(rec, bag, dir + "/rosbag/push_transform.bag");
  return 0;
}
