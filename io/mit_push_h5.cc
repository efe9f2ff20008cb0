#include "io/mit_push_h5.h"

#include <H5Cpp.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <mutex>
#include <vector>

#include "io/atomic_file.h"
#include "io/internal/child_process.h"

namespace slideid {
namespace {

/// Debian's libhdf5 is built without its thread-safety option: every use of the library
/// (its error stack and open-file list are global) goes through this lock.
std::mutex& Hdf5Lock() {
  static std::mutex lock;
  return lock;
}

constexpr std::array<const char*, 3> kDatasets = {"object_pose", "tip_pose", "ft_wrench"};

/// A dataset holding more values than this many times the file's size (plus a floor) is a
/// damaged header, not data: gzip does not shrink measured doubles 1000-fold, and reading
/// such a size would allocate far beyond any push.
constexpr double kMaxExpansion = 1024.0;
constexpr double kMinValuesAllowed = 1 << 20;

/// The most specific message on HDF5's error stack (what it found wrong), or "".
std::string InnermostHdf5Message() {
  std::string message;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,  // the innermost function first
      [](unsigned n, const H5E_error2_t* err, void* out) -> herr_t {
        if (n == 0 && err && err->desc) *static_cast<std::string*>(out) = err->desc;
        return 0;
      },
      &message);
  return message;
}

/// What an HDF5 exception says: its own text and the innermost reason on the stack.
std::string Describe(const H5::Exception& e) {
  std::string why = InnermostHdf5Message();
  std::string detail = e.getDetailMsg();
  if (why.empty()) return detail;
  if (detail.empty()) return why;
  return why + " (" + detail + ")";
}

bool HasHdf5Signature(std::string_view bytes) {
  // The superblock sits at 0, 512, 1024, 2048, ... (a user block may precede it).
  static const char kSignature[] = "\x89HDF\r\n\x1a\n";
  for (std::size_t at = 0; at + 8 <= bytes.size(); at = at == 0 ? 512 : 2 * at) {
    if (bytes.compare(at, 8, kSignature, 8) == 0) return true;
  }
  return false;
}

std::string DatasetPlace(const std::string& source, const char* name) {
  return source + ": dataset '/" + name + "': ";
}

std::string TypeName(const H5::DataSet& ds) {
  switch (ds.getTypeClass()) {
    case H5T_INTEGER:
      return "integers";
    case H5T_STRING:
      return "strings";
    case H5T_COMPOUND:
      return "compound values";
    case H5T_ARRAY:
      return "arrays";
    case H5T_ENUM:
      return "enumerations";
    default:
      return "values of another type";
  }
}

std::string ShapeText(const std::vector<hsize_t>& dims) {
  if (dims.empty()) return "a scalar";
  std::string s;
  for (std::size_t i = 0; i < dims.size(); ++i) s += (i ? " x " : "") + std::to_string(dims[i]);
  return s;
}

std::vector<MitStreamRow> ReadStream(const H5::H5File& file, const std::string& source,
                                     const char* name, std::size_t file_bytes) {
  const std::string place = DatasetPlace(source, name);
  if (H5Lexists(file.getId(), name, H5P_DEFAULT) <= 0) {
    std::string present;
    for (hsize_t i = 0; i < file.getNumObjs(); ++i) {
      present += (present.empty() ? "/" : ", /") + std::string(file.getObjnameByIdx(i));
    }
    throw MitPushH5Error(place +
                         "missing (the file needs object_pose, tip_pose and "
                         "ft_wrench; it holds " +
                         (present.empty() ? std::string("nothing") : present) + ")");
  }
  if (file.childObjType(name) != H5O_TYPE_DATASET) {
    throw MitPushH5Error(place + "is a group, not a dataset");
  }
  const H5::DataSet ds = file.openDataSet(name);
  const H5::DataSpace space = ds.getSpace();
  const int rank = space.getSimpleExtentNdims();
  std::vector<hsize_t> dims(rank > 0 ? rank : 0);
  if (rank > 0) space.getSimpleExtentDims(dims.data());
  const bool shape_ok = rank == 2 && dims[1] == 4;
  const bool type_ok = ds.getTypeClass() == H5T_FLOAT;
  if (!shape_ok || !type_ok) {
    throw MitPushH5Error(place + "expected N x 4 doubles, found " + ShapeText(dims) +
                         (type_ok ? "" : " " + TypeName(ds)));
  }
  if (dims[0] == 0) throw MitPushH5Error(place + "empty (no rows)");
  const double values = 4.0 * static_cast<double>(dims[0]);
  if (values > kMinValuesAllowed + kMaxExpansion * static_cast<double>(file_bytes)) {
    throw MitPushH5Error(place + ShapeText(dims) + " values in a file of " +
                         std::to_string(file_bytes) +
                         " bytes: a damaged header (more than 1024 times the file's size)");
  }
  std::vector<MitStreamRow> rows(dims[0]);
  ds.read(rows.data(), H5::PredType::NATIVE_DOUBLE);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (int c = 0; c < 4; ++c) {
      if (!std::isfinite(rows[r][c])) {
        throw MitPushH5Error(place + "row " + std::to_string(r) + ", column " + std::to_string(c) +
                             " (from 0): not a finite number");
      }
    }
  }
  return rows;
}

/// The name under which HDF5 opens an image in memory. Its core driver refuses an image
/// whose name exists on disk ("file already exists"), so it is one that cannot.
std::string InMemoryName(const std::string& source) { return "slideid-in-memory:/" + source; }

/// The streams of an HDF5 image, read in this process (the child's work, below).
MitPushRecording ParseInThisProcess(std::string_view bytes, const std::string& source) {
  H5::Exception::dontPrint();
  H5::FileAccPropList access;
  access.setCore(1 << 16, false);  // in memory, never written back
  // HDF5 copies the image; it never writes to it (read-only open).
  if (H5Pset_file_image(access.getId(), const_cast<char*>(bytes.data()), bytes.size()) < 0) {
    throw MitPushH5Error(source + ": HDF5 refused the file image");
  }
  const std::string name = InMemoryName(source);
  std::unique_ptr<H5::H5File> file;
  try {
    file =
        std::make_unique<H5::H5File>(name, H5F_ACC_RDONLY, H5::FileCreatPropList::DEFAULT, access);
  } catch (const H5::Exception& e) {
    // The C++ wrapper leaves only "H5Fopen failed"; the C call again keeps HDF5's reason
    // (e.g. "truncated file: eof = 1000, ...") on its error stack.
    std::string why = e.getDetailMsg();
    const hid_t id = H5Fopen(name.c_str(), H5F_ACC_RDONLY, access.getId());
    if (id >= 0) {
      H5Fclose(id);
    } else if (const std::string inner = InnermostHdf5Message(); !inner.empty()) {
      why = inner;
    }
    throw MitPushH5Error(source +
                         ": cannot be opened as HDF5 (truncated or damaged file?): " + why);
  }
  MitPushRecording r;
  std::vector<MitStreamRow>* streams[] = {&r.object_pose, &r.tip_pose, &r.ft_wrench};
  for (std::size_t k = 0; k < kDatasets.size(); ++k) {
    try {
      *streams[k] = ReadStream(*file, source, kDatasets[k], bytes.size());
    } catch (const H5::Exception& e) {
      throw MitPushH5Error(DatasetPlace(source, kDatasets[k]) +
                           "cannot be read (truncated or damaged file?): " + Describe(e));
    }
  }
  return r;
}

// libhdf5 trusts a file's sizes and addresses: on a damaged file it can copy to a null
// pointer (H5F__accum_read after a failed allocation of what a header claims, found by
// fuzz_mit_push_h5). So the file is read in a child process, which sends the streams (or its
// error) back through a pipe: a crash or hang inside the library becomes an unreadable
// file, never a crash of import-log. As io/rosbag_push.cc does for librosbag.

void PutBytes(std::string* out, const void* data, std::size_t n) {
  out->append(static_cast<const char*>(data), n);
}

/// 'R' and the three streams (a count and the rows each).
std::string Serialize(const MitPushRecording& r) {
  std::string out = "R";
  for (const auto* rows : {&r.object_pose, &r.tip_pose, &r.ft_wrench}) {
    const std::uint64_t n = rows->size();
    PutBytes(&out, &n, sizeof(n));
    PutBytes(&out, rows->data(), rows->size() * sizeof(MitStreamRow));
  }
  return out;
}

MitPushRecording Deserialize(const std::string& bytes, const std::string& source) {
  MitPushRecording r;
  std::size_t at = 1;
  for (auto* rows : {&r.object_pose, &r.tip_pose, &r.ft_wrench}) {
    std::uint64_t n = 0;
    if (bytes.size() - at < sizeof(n))
      throw MitPushH5Error(source + ": short answer from the reader");
    std::memcpy(&n, bytes.data() + at, sizeof(n));
    at += sizeof(n);
    if (n > (bytes.size() - at) / sizeof(MitStreamRow)) {
      throw MitPushH5Error(source + ": short answer from the reader");
    }
    rows->resize(n);
    std::memcpy(rows->data(), bytes.data() + at, n * sizeof(MitStreamRow));
    at += n * sizeof(MitStreamRow);
  }
  return r;
}

}  // namespace

MitPushRecording ParseMitPushH5(std::string_view bytes, const std::string& source) {
  if (bytes.empty()) throw MitPushH5Error(source + ": empty file (expected HDF5)");
  if (!HasHdf5Signature(bytes)) {
    throw MitPushH5Error(source + ": not an HDF5 file (no HDF5 signature)");
  }
  // Held across the fork: no other thread is inside HDF5 when the child is made, and the
  // child (whose copy of the lock stays taken) uses HDF5 alone.
  const std::lock_guard<std::mutex> lock(Hdf5Lock());
  const std::chrono::milliseconds limit = child_process::TimeLimitFor(bytes.size());
  const child_process::Outcome out =
      child_process::Run([&] { return Serialize(ParseInThisProcess(bytes, source)); }, limit);
  switch (out.ending) {
    case child_process::Ending::kAnswered:
      return Deserialize(out.answer, source);
    case child_process::Ending::kThrew:
      throw MitPushH5Error(out.answer);
    case child_process::Ending::kTimedOut:
      throw MitPushH5Error(source + ": HDF5 did not finish reading it in " +
                           std::to_string(limit.count() / 1000) + " s (a damaged file?)");
    case child_process::Ending::kCrashed:
      throw MitPushH5Error(source + ": libhdf5 crashed reading it (signal " +
                           std::to_string(out.signal) + "): a damaged file");
    case child_process::Ending::kSilent:
      break;
  }
  throw MitPushH5Error(source + ": the HDF5 reader ended without an answer");
}

MitPushRecording ReadMitPushH5(const std::string& path) {
  struct stat info;
  if (stat(path.c_str(), &info) != 0) {
    throw MitPushH5Error(path + ": cannot be opened for reading: " + std::strerror(errno));
  }
  if (!S_ISREG(info.st_mode)) throw MitPushH5Error(path + ": not a regular file");
  // The whole file in memory, opened by HDF5's core driver: one path for files and fuzz
  // inputs, and no HDF5 file lock (which fails on some network file systems).
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MitPushH5Error(path + ": cannot be opened for reading");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw MitPushH5Error(path + ": read error");
  return ParseMitPushH5(bytes, path);
}

std::string FormatMitPushH5(const MitPushRecording& recording,
                            const MitPushH5WriteOptions& options) {
  const std::lock_guard<std::mutex> lock(Hdf5Lock());
  H5::Exception::dontPrint();
  try {
    H5::FileAccPropList access;
    access.setCore(1 << 16, false);  // built in memory: no file on disk
    std::string bytes;
    {
      H5::H5File file(InMemoryName("push.h5"), H5F_ACC_TRUNC, H5::FileCreatPropList::DEFAULT,
                      access);
      const std::vector<MitStreamRow>* streams[] = {&recording.object_pose, &recording.tip_pose,
                                                    &recording.ft_wrench};
      for (std::size_t k = 0; k < kDatasets.size(); ++k) {
        const std::vector<MitStreamRow>& rows = *streams[k];
        const hsize_t dims[2] = {rows.size(), 4};
        const H5::DataSpace space(2, dims);
        H5::DSetCreatPropList create;
        if (options.deflate && !rows.empty()) {
          const hsize_t chunk[2] = {std::min<hsize_t>(rows.size(), 1024), 4};
          create.setChunk(2, chunk);
          create.setDeflate(4);
        }
        H5::DataSet ds = file.createDataSet(kDatasets[k], H5::PredType::IEEE_F64LE, space, create);
        if (!rows.empty()) ds.write(rows.data(), H5::PredType::NATIVE_DOUBLE);
      }
      file.flush(H5F_SCOPE_GLOBAL);
      const ssize_t n = H5Fget_file_image(file.getId(), nullptr, 0);
      if (n <= 0) throw std::runtime_error("HDF5 gave no file image");
      bytes.resize(static_cast<std::size_t>(n));
      if (H5Fget_file_image(file.getId(), bytes.data(), bytes.size()) != n) {
        throw std::runtime_error("HDF5 gave a file image of another size");
      }
    }
    return bytes;
  } catch (const H5::Exception& e) {
    throw std::runtime_error("cannot build the HDF5 push file: " + Describe(e));
  }
}

void WriteMitPushH5(const MitPushRecording& recording, const std::string& path,
                    const MitPushH5WriteOptions& options) {
  WriteFileAtomically(path, "HDF5 push file", FormatMitPushH5(recording, options));
}

}  // namespace slideid
