#pragma once
// The content hash that tells a log already in a batch's results from a changed one
// (identify --batch --resume, slideid.dask resume=True): SHA-256 of the file's bytes, as
// Python's hashlib.sha256 gives it.

#include <string>

namespace slideid {

/// The SHA-256 of the bytes of `path`, as 64 lowercase hex digits. Throws
/// std::runtime_error naming the file when it cannot be read.
std::string Sha256OfFile(const std::string& path);

}  // namespace slideid
