// Writes the seed corpus of fuzz_mcap (fuzz/corpus/mcap/) with our own MCAP writer: short
// synthetic pushes (the first rows of each stream of a simulated MIT recording) under each
// compression, with and without CRCs, each pose message type; and one CDR message of each
// type in both byte orders, behind the target's selector byte. Run by hand when the
// format changes: build-fuzz/bin/make_mcap_corpus fuzz/corpus/mcap
#include <cstdio>
#include <fstream>
#include <string>

#include "datasets/mit_push_synth.h"
#include "fuzz/corpus_seed.h"
#include "io/mcap_push.h"
#include "io/ros2_cdr.h"

using namespace slideid;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_mcap_corpus DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  const MitPushRecording rec = ShortSeedRecording();
  auto write = [&](const std::string& name, const std::string& bytes) {
    WriteSeed(dir, name, bytes);
  };
  RosPushWriteSpec spec;
  spec.topics.object_topic = "/object";
  spec.topics.tip_topic = "/tf";
  spec.topics.tip_frame = "tip";
  spec.topics.force_topic = "/ft";
  spec.tip_type = RosMessageType::kTfMessage;
  spec.zero_stamp_every = 5;
  for (const auto& [name, compression] :
       {std::pair<const char*, McapCompression>{"none", McapCompression::kNone},
        {"zstd", McapCompression::kZstd},
        {"lz4", McapCompression::kLz4}}) {
    for (bool crcs : {false, true}) {
      McapWriterOptions o;
      o.compression = compression;
      o.crcs = crcs;
      o.chunk_bytes = 1500;
      write(std::string("push_") + name + (crcs ? "_crc" : "") + ".mcap",
            FormatMcapPushLog(rec, spec, o));
    }
  }
  McapWriterOptions plain;
  plain.compression = McapCompression::kNone;
  plain.crcs = false;
  RosPushWriteSpec transform = spec;
  transform.object_type = RosMessageType::kTransformStamped;
  write("push_transform.mcap", FormatMcapPushLog(rec, transform, plain));
  RosPose p;
  p.stamp = {1476728847, 5};
  p.frame_id = "world";
  p.child_frame_id = "tip";
  p.x = 0.3;
  p.qw = 1;
  RosWrench w;
  w.stamp = p.stamp;
  w.frame_id = "ft";
  w.fx = 1.5;
  for (bool little : {true, false}) {
    const std::string order = little ? "le" : "be";
    write("cdr_pose_" + order, '\0' + EncodeCdrPoseStamped(p, little));
    write("cdr_transform_" + order, '\1' + EncodeCdrTransformStamped(p, little));
    write("cdr_tf_" + order, '\2' + EncodeCdrTfMessage({p, p}, little));
    write("cdr_wrench_" + order, '\3' + EncodeCdrWrenchStamped(w, little));
  }
  return 0;
}
