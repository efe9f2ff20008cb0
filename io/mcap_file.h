#pragma once
// MCAP files (the ROS 2 default bag format), read and written after the published
// specification (mcap.dev/spec, format version 0). Debian packages no C++ MCAP library
// (`apt-cache search mcap` finds none in bookworm), so this is a small implementation of
// just what the ROS log import needs, linking Debian's libzstd, liblz4 and zlib (CRC-32):
//  - the reader checks both magics, the Header first and the Footer last, and every
//    record's length against its container; it decompresses chunks (zstd, lz4 frame format
//    or none) into at most their stated size, checks every CRC that is present (chunk,
//    data section, summary, attachment) and hands over the messages in file order;
//    Schema and Channel records are kept, the index and summary records only framed and
//    skipped (the messages are read by a linear scan, so a file without an index reads too).
//  - the writer (tests, benchmarks and fuzz seeds) writes chunked files with message
//    indexes, a summary (schemas, channels, chunk indexes, statistics), summary offsets and
//    every CRC, with zstd, lz4 or no compression.
// Bad input throws McapError naming the file and the place: the record's byte offset and
// opcode, and for a record inside a chunk, the chunk's offset.

#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace slideid {

/// A bad MCAP file: "file: record at byte N (Chunk): what".
class McapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A Schema record: how a channel's messages are described.
struct McapSchema {
  std::uint16_t id = 0;
  std::string name;      ///< e.g. "geometry_msgs/msg/PoseStamped"
  std::string encoding;  ///< e.g. "ros2msg"
  std::string data;      ///< the schema text
};

/// A Channel record: one publisher's stream of messages on a topic.
struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  ///< 0: no schema
  std::string topic;
  std::string message_encoding;  ///< e.g. "cdr"
  std::map<std::string, std::string> metadata;
};

/// A Message record; `data` points into the file or a decompressed chunk, valid only during
/// the callback.
struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0, publish_time_ns = 0;
  std::string_view data;
};

/// Where a message was: its record's byte offset in the file, or, inside a chunk, the
/// chunk's offset in the file and the record's offset in the chunk's decompressed records.
struct McapPlace {
  std::uint64_t record_offset = 0;
  bool in_chunk = false;
  std::uint64_t chunk_offset = 0;
  /// "record at byte N" or "chunk at byte C, record at byte N of its records".
  std::string ToString() const;
};

/// What a file holds besides its messages.
struct McapContents {
  std::string profile, library;  ///< of the Header record
  std::map<std::uint16_t, McapSchema> schemas;
  std::map<std::uint16_t, McapChannel> channels;
  int chunks = 0;
  std::uint64_t messages = 0;
};

/// Called for every message, in file order, with its channel and schema (null for
/// schema id 0). May throw; the exception goes through ReadMcap unchanged.
using McapMessageHandler = std::function<void(const McapChannel& channel, const McapSchema* schema,
                                              const McapMessage& message, const McapPlace& place)>;

/// Reads the bytes of a whole MCAP file; `source` names it in messages. Throws McapError.
McapContents ReadMcap(std::string_view file, const std::string& source,
                      const McapMessageHandler& on_message);

/// The contents of the file at `path`. Throws McapError (also when it cannot be read).
std::string ReadFileBytes(const std::string& path);

enum class McapCompression { kNone, kZstd, kLz4 };
const char* ToString(McapCompression compression);  ///< "", "zstd", "lz4" as in the file

struct McapWriterOptions {
  McapCompression compression = McapCompression::kZstd;
  /// A chunk is closed once its records reach this many bytes, uncompressed.
  std::size_t chunk_bytes = 64 * 1024;
  /// Whether the chunk, data-section and summary CRCs are written (0 otherwise: "not
  /// available"); the fuzz seeds leave them out so that mutations reach the records.
  bool crcs = true;
  std::string profile = "ros2";
  std::string library = "slideid";
};

/// Builds an MCAP file in memory.
class McapWriter {
 public:
  explicit McapWriter(McapWriterOptions options = {});
  /// Registers a schema; returns its id (1, 2, ...).
  std::uint16_t AddSchema(const std::string& name, const std::string& encoding,
                          const std::string& data);
  /// Registers a channel (schema 0: none); returns its id (0, 1, ...).
  std::uint16_t AddChannel(std::uint16_t schema_id, const std::string& topic,
                           const std::string& message_encoding,
                           const std::map<std::string, std::string>& metadata = {});
  /// Appends a message; its channel's (and schema's) records go into the chunk first.
  void AddMessage(const McapMessage& message);
  /// Closes the last chunk and writes the data end, the summary and the footer; returns the
  /// file's bytes. The writer is then empty.
  std::string Finish();

 private:
  void CloseChunk();

  McapWriterOptions options_;
  std::vector<McapSchema> schemas_;
  std::vector<McapChannel> channels_;
  std::vector<bool> schema_written_, channel_written_;
  std::string file_;   ///< written so far
  std::string chunk_;  ///< records of the open chunk, uncompressed
  std::uint64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0;
  /// Per channel of the open chunk: (log time, offset in the chunk's records).
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::string chunk_indexes_;  ///< Chunk Index records for the summary
  std::uint64_t messages_ = 0, first_ns_ = 0, last_ns_ = 0;
  std::uint32_t chunks_ = 0;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
};

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename.
/// Throws std::runtime_error naming the path.
void WriteFileBytes(const std::string& bytes, const std::string& path);

}  // namespace slideid
