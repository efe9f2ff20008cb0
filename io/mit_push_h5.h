#pragma once
// The MIT push dataset as HDF5 (`.h5`): the three streams of io/mit_push_recording.h as
// the datasets `/object_pose`, `/tip_pose` and `/ft_wrench`, each N x 4 floating-point
// values laid out like the JSON rows (t, x, y, theta / t, x, y, yaw / t, fx, fy, tz). Read
// and written with the HDF5 C++ API (Debian's libhdf5-dev); the HDF5 headers stay in the
// .cc. Bad files throw MitPushH5Error naming the file and the dataset; HDF5's own printing
// of its error stack is switched off (the message carries what it said).

#include <stdexcept>
#include <string>
#include <string_view>

#include "io/mit_push_recording.h"

namespace slideid {

/// Bad HDF5 push file: "file: dataset '/ft_wrench': what", or "file: what" for the file as
/// a whole (not HDF5, truncated, cannot be opened).
class MitPushH5Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads the file at `path`. Each dataset must exist, be two-dimensional with 4 columns and
/// at least one row, and hold floating-point values (32- or 64-bit: read as doubles), all
/// finite. Rows are kept in file order; other datasets and attributes are ignored. Throws
/// MitPushH5Error. libhdf5 crashes on some damaged files (it trusts their sizes), so it
/// reads in a child process (fork): its crash, or a hang past a limit that grows with the
/// file's size, is such an error too. Thread-safe (the library is serialised behind one
/// lock: Debian's HDF5 is not built thread-safe).
MitPushRecording ReadMitPushH5(const std::string& path);
/// Same, from the bytes of a file in memory (HDF5's core driver); `source` names it.
MitPushRecording ParseMitPushH5(std::string_view bytes, const std::string& source);

/// How the writer stores the datasets.
struct MitPushH5WriteOptions {
  /// Chunked and gzip-compressed (level 4), as h5py's `compression="gzip"` writes; else
  /// contiguous.
  bool deflate = false;
};

/// The bytes of an HDF5 file of `recording` (64-bit little-endian floats), built in memory.
/// Throws std::runtime_error if HDF5 fails.
std::string FormatMitPushH5(const MitPushRecording& recording,
                            const MitPushH5WriteOptions& options = {});
/// Writes FormatMitPushH5 to `path` atomically (io/atomic_file.h). Throws FileWriteError.
void WriteMitPushH5(const MitPushRecording& recording, const std::string& path,
                    const MitPushH5WriteOptions& options = {});

}  // namespace slideid
