#pragma once
// The wrench-twist pairs CSV: one slow push per row, its mean applied wrench and the
// slider's twist, for quasi-static identification (docs/real-data.md, "Wrench-twist pairs").
//
//     # slideid wrench-twist pairs ...           (prose comments are kept out of the data)
//     # mass = 1.518                              (`# key = value` metadata, as in push logs)
//     # gravity = 9.81
//     push,fx,fy,fz,mz,vx,vy,wz,duration,dx,dy,dtheta,contact_x,contact_y,peak_force,samples
//     1,3.1,0.4,0,0.13,0.0012,-0.0004,0.018,4.9,0.0059,-0.0019,0.088,-0.019,0.068,4.15,492
//
// Units SI; the frame's origin is the CM (moments about it, velocities of it). Columns are
// found by name in any order; fx, fy, mz, vx, vy, wz are required, the others optional, and
// the diagnostic ones (duration, dx, dy, dtheta, contact_x, contact_y, peak_force, samples)
// may be empty (unknown). Metadata: mass (required unless overridden), gravity (9.81),
// inertia, com_height, supports, source, and the truth mu, e_t, e_o, e_r of synthetic pairs;
// other keys are kept in order. Lines are read with fast-cpp-csv-parser's LineReader
// (io/text_lines.h); every error is a LogError naming the file, the line and the column.

#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "forward_model/wrench_twist_pair.h"
#include "io/text_lines.h"

namespace slideid {

/// What the reader noticed that is not an error (unknown columns, partial truth).
struct WrenchTwistReadReport {
  std::vector<std::string> notes;
};

/// Reads a wrench-twist file. `overrides` replace the metadata's mass, inertia, com_height
/// and gravity. Throws LogError for bad syntax, a missing mass, a row whose wrench or twist
/// is zero, whose normal force m g - fz is not positive, or whose duration is not positive.
WrenchTwistData ReadWrenchTwistCsv(const std::string& path, const SliderOverrides& overrides = {},
                                   WrenchTwistReadReport* report = nullptr);
/// Same, from text in memory; `source` names it in messages (fuzzing, tests).
WrenchTwistData ParseWrenchTwistCsv(std::string_view text, const std::string& source,
                                    const SliderOverrides& overrides = {},
                                    WrenchTwistReadReport* report = nullptr);

/// Writes `data` with its metadata and every column; unknown diagnostics as empty cells,
/// numbers as the shortest text that reads back exactly. Throws std::invalid_argument for a
/// non-finite required value or metadata that cannot be written (the message names the
/// row), std::runtime_error if the file cannot be written (temporary file, then rename).
void WriteWrenchTwistCsv(const WrenchTwistData& data, const std::string& path);
void WriteWrenchTwistCsv(const WrenchTwistData& data, std::ostream& out);

}  // namespace slideid
