#pragma once
// What the seed-corpus programs (make_import_corpus, make_mcap_corpus) share: the short
// synthetic push they write in each format, and the writing of one seed file.
#include <fstream>
#include <string>

#include "datasets/mit_push_synth.h"

namespace slideid {

/// The first 12 rows of each stream of a simulated MIT recording (short seeds fuzz faster).
inline MitPushRecording ShortSeedRecording() {
  MitPushRecording rec = MakeMitPushRecording(MitSynthSpec{}).recording;
  rec.object_pose.resize(12);
  rec.tip_pose.resize(12);
  rec.ft_wrench.resize(12);
  return rec;
}

/// Writes `bytes`, as given, to `dir`/`name`.
inline void WriteSeed(const std::string& dir, const std::string& name, const std::string& bytes) {
  std::ofstream(dir + "/" + name, std::ios::binary) << bytes;
}

}  // namespace slideid
