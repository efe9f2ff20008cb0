#include "io/mcap_file.h"

#include <lz4frame.h>
#include <zconf.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

namespace slideid {
namespace {

constexpr char kMagic[8] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::size_t kMagicBytes = 8;
constexpr std::size_t kRecordPrefixBytes = 9;  // opcode (1) and content length (8)
constexpr std::size_t kFooterContentBytes = 20;

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

std::string OpcodeName(std::uint8_t op) {
  static const char* const kNames[] = {"",           "Header",           "Footer",
                                       "Schema",     "Channel",          "Message",
                                       "Chunk",      "Message Index",    "Chunk Index",
                                       "Attachment", "Attachment Index", "Statistics",
                                       "Metadata",   "Metadata Index",   "Summary Offset",
                                       "Data End"};
  if (op >= 1 && op <= 0x0F) return kNames[op];
  char hex[8];
  std::snprintf(hex, sizeof(hex), "0x%02X", op);
  return std::string("opcode ") + hex;
}

std::uint32_t Crc32(std::string_view bytes, std::uint32_t crc = 0) {
  // zlib's crc32 takes a uInt length: feed large inputs in pieces.
  uLong c = crc;
  while (!bytes.empty()) {
    const std::size_t n = std::min<std::size_t>(bytes.size(), 1u << 30);
    c = crc32(c, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(n));
    bytes.remove_prefix(n);
  }
  return static_cast<std::uint32_t>(c);
}

/// Reads little-endian fields of one record's content; running past its end throws.
class Fields {
 public:
  Fields(std::string_view content, std::string where) : data_(content), where_(std::move(where)) {}

  template <typename T>
  T Int(const char* field) {
    Need(sizeof(T), field);
    T value = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      value |= static_cast<T>(static_cast<unsigned char>(data_[pos_ + i])) << (8 * i);
    pos_ += sizeof(T);
    return value;
  }
  std::string_view Bytes(std::uint64_t n, const char* field) {
    Need(n, field);
    const std::string_view b = data_.substr(pos_, n);
    pos_ += n;
    return b;
  }
  std::string String(const char* field) {
    const std::uint32_t n = Int<std::uint32_t>(field);
    return std::string(Bytes(n, field));
  }
  std::map<std::string, std::string> StringMap(const char* field) {
    const std::uint32_t n = Int<std::uint32_t>(field);
    Fields inner(Bytes(n, field), where_);
    std::map<std::string, std::string> map;
    while (!inner.AtEnd()) {
      std::string key = inner.String(field);
      map[std::move(key)] = inner.String(field);
    }
    return map;
  }
  std::size_t pos() const { return pos_; }
  bool AtEnd() const { return pos_ == data_.size(); }
  [[noreturn]] void Fail(const std::string& what) const { throw McapError(where_ + ": " + what); }

 private:
  void Need(std::uint64_t n, const char* field) const {
    if (n > data_.size() - pos_) {
      Fail(std::string("field '") + field + "' (" + std::to_string(n) + " bytes at byte " +
           std::to_string(pos_) + " of the record's content) runs past the record's end (" +
           std::to_string(data_.size()) + " bytes)");
    }
  }

  std::string_view data_;
  std::string where_;
  std::size_t pos_ = 0;
};

/// One record framed in a sequence of records.
struct Record {
  std::uint8_t op = 0;
  std::uint64_t offset = 0;  ///< of its opcode, in the sequence
  std::string_view content;
  std::uint64_t end = 0;  ///< offset after it
};

std::string RecordWhere(const std::string& source, const McapPlace& place, std::uint8_t op) {
  return source + ": " + place.ToString() + " (" + OpcodeName(op) + ")";
}

/// Output grows geometrically up to `limit`: a chunk that claims a huge size but holds
/// little never allocates it.
void Grow(std::string* out, std::uint64_t limit) {
  const std::size_t want = std::max<std::size_t>(2 * out->size(), 1 << 16);
  out->resize(static_cast<std::size_t>(std::min<std::uint64_t>(limit, want)));
}

[[noreturn]] void Stalled(const std::string& where, const char* codec, std::size_t pos,
                          std::size_t room, std::uint64_t size) {
  if (pos == room) {
    throw McapError(where + ": " + codec + " data decompress to more than the stated " +
                    "uncompressed_size (" + std::to_string(size) + " bytes)");
  }
  throw McapError(where + ": " + codec + " data cut short (" + std::to_string(pos) + " of " +
                  std::to_string(size) + " bytes)");
}

std::string DecompressZstd(std::string_view in, std::uint64_t size, const std::string& where) {
  std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> ctx(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!ctx) throw McapError(where + ": zstd: out of memory");
  std::string out;
  ZSTD_inBuffer input{in.data(), in.size(), 0};
  std::size_t pos = 0;
  while (true) {
    if (pos == out.size() && out.size() < size) Grow(&out, size);
    ZSTD_outBuffer output{out.data(), out.size(), pos};
    const std::size_t in_before = input.pos;
    const std::size_t left = ZSTD_decompressStream(ctx.get(), &output, &input);
    if (ZSTD_isError(left)) throw McapError(where + ": zstd: " + ZSTD_getErrorName(left));
    const bool progressed = output.pos != pos || input.pos != in_before;
    pos = output.pos;
    if (left == 0 && input.pos == input.size) break;  // every frame decoded and flushed
    if (!progressed) Stalled(where, "zstd", pos, out.size(), size);
  }
  out.resize(pos);
  return out;
}

std::string DecompressLz4(std::string_view in, std::uint64_t size, const std::string& where) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION)))
    throw McapError(where + ": lz4: out of memory");
  std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> ctx(
      raw, LZ4F_freeDecompressionContext);
  std::string out;
  std::size_t in_pos = 0, pos = 0;
  while (true) {
    if (pos == out.size() && out.size() < size) Grow(&out, size);
    std::size_t out_n = out.size() - pos, in_n = in.size() - in_pos;
    const std::size_t hint =
        LZ4F_decompress(ctx.get(), out.data() + pos, &out_n, in.data() + in_pos, &in_n, nullptr);
    if (LZ4F_isError(hint)) throw McapError(where + ": lz4: " + LZ4F_getErrorName(hint));
    pos += out_n;
    in_pos += in_n;
    if (hint == 0) break;  // the frame is complete
    if (out_n == 0 && in_n == 0) Stalled(where, "lz4", pos, out.size(), size);
  }
  if (in_pos != in.size()) {
    throw McapError(where + ": " + std::to_string(in.size() - in_pos) +
                    " bytes after the end of the lz4 frame");
  }
  out.resize(pos);
  return out;
}

class Reader {
 public:
  Reader(std::string_view file, const std::string& source, const McapMessageHandler& on_message)
      : file_(file), source_(source), on_message_(on_message) {}

  McapContents Read() {
    if (file_.size() < kMagicBytes || std::memcmp(file_.data(), kMagic, kMagicBytes) != 0) {
      const bool other_version = file_.size() >= 6 && std::memcmp(file_.data(), kMagic, 5) == 0;
      throw McapError(source_ + ": byte 0: " +
                      (other_version ? std::string("MCAP major version '") + file_[5] +
                                           "' is not supported (only '0')"
                                     : std::string("not an MCAP file (no leading magic)")));
    }
    std::uint64_t pos = kMagicBytes;
    bool first = true, data_end = false;
    std::uint64_t data_end_offset = 0;
    while (true) {
      if (pos == file_.size()) {
        throw McapError(source_ + ": byte " + std::to_string(pos) +
                        ": the file ends without a Footer record and closing magic (truncated?)");
      }
      const Record r = Frame(file_, pos, nullptr);
      McapPlace place;
      place.record_offset = r.offset;
      const std::string where = RecordWhere(source_, place, r.op);
      if (first && r.op != kHeader) throw McapError(where + ": the first record is not a Header");
      if (!first && r.op == kHeader) throw McapError(where + ": a second Header record");
      first = false;
      pos = r.end;
      if (r.op == kFooter) {
        ReadFooter(r, where, data_end_offset);
        break;
      }
      if (r.op == kDataEnd) {
        if (data_end) throw McapError(where + ": a second Data End record");
        data_end = true;
        Fields f(r.content, where);
        const std::uint32_t crc = f.Int<std::uint32_t>("data_section_crc");
        // The data section's CRC covers every byte before this record, magic included.
        if (crc != 0 && Crc32(file_.substr(0, r.offset)) != crc) {
          throw McapError(where +
                          ": the data section's CRC does not match (the file is "
                          "damaged)");
        }
        data_end_offset = r.offset;
        continue;
      }
      if (data_end) {
        SummaryRecord(r, where);
      } else {
        DataRecord(r, place, where);
      }
    }
    return std::move(contents_);
  }

 private:
  /// The record at `pos` of `bytes` (a file or a chunk's records); its end checked.
  Record Frame(std::string_view bytes, std::uint64_t pos, const McapPlace* chunk) const {
    McapPlace place;
    place.record_offset = pos;
    if (chunk) {
      place.in_chunk = true;
      place.chunk_offset = chunk->record_offset;
    }
    if (bytes.size() - pos < kRecordPrefixBytes) {
      throw McapError(source_ + ": " + place.ToString() + ": " +
                      std::to_string(bytes.size() - pos) +
                      " bytes left, too few for a record's opcode and length" +
                      (chunk ? "" : " (truncated file?)"));
    }
    Record r;
    r.op = static_cast<std::uint8_t>(bytes[pos]);
    r.offset = pos;
    std::uint64_t length = 0;
    for (int i = 0; i < 8; ++i)
      length |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[pos + 1 + i]))
                << (8 * i);
    const std::uint64_t left = bytes.size() - pos - kRecordPrefixBytes;
    if (length > left) {
      throw McapError(RecordWhere(source_, place, r.op) + ": its length " + std::to_string(length) +
                      " runs past the end of the " + (chunk ? "chunk's records" : "file") + " (" +
                      std::to_string(left) + " bytes left" + (chunk ? ")" : "; truncated file?)"));
    }
    r.content = bytes.substr(pos + kRecordPrefixBytes, length);
    r.end = pos + kRecordPrefixBytes + length;
    return r;
  }

  void DataRecord(const Record& r, const McapPlace& place, const std::string& where) {
    switch (r.op) {
      case kHeader: {
        Fields f(r.content, where);
        contents_.profile = f.String("profile");
        contents_.library = f.String("library");
        return;
      }
      case kSchema:
      case kChannel:
      case kMessage:
        return InnerRecord(r, place, where);
      case kChunk:
        return ReadChunk(r, where);
      case kAttachment:
        return CheckAttachment(r, where);
      case kMessageIndex:
      case kMetadata:
        return;  // framed; not needed for a linear read
      default:
        if (r.op >= 0x80 || r.op > kDataEnd) return;  // extensions and future records: skipped
        throw McapError(where + ": not allowed in the data section");
    }
  }

  void SummaryRecord(const Record& r, const std::string& where) {
    switch (r.op) {
      case kSchema:
        return ReadSchema(r, where);
      case kChannel:
        return ReadChannel(r, where);
      case kChunkIndex:
      case kAttachmentIndex:
      case kStatistics:
      case kMetadataIndex:
      case kSummaryOffset:
        return;  // framed; not needed for a linear read
      default:
        if (r.op >= 0x80 || r.op > kDataEnd) return;
        throw McapError(where + ": not allowed after the Data End record");
    }
  }

  void InnerRecord(const Record& r, const McapPlace& place, const std::string& where) {
    if (r.op == kSchema) return ReadSchema(r, where);
    if (r.op == kChannel) return ReadChannel(r, where);
    if (r.op != kMessage) return;
    Fields f(r.content, where);
    McapMessage m;
    m.channel_id = f.Int<std::uint16_t>("channel_id");
    m.sequence = f.Int<std::uint32_t>("sequence");
    m.log_time_ns = f.Int<std::uint64_t>("log_time");
    m.publish_time_ns = f.Int<std::uint64_t>("publish_time");
    m.data = r.content.substr(f.pos());
    const auto channel = contents_.channels.find(m.channel_id);
    if (channel == contents_.channels.end()) {
      f.Fail("a message on channel " + std::to_string(m.channel_id) +
             ", which no earlier Channel record defines");
    }
    const McapSchema* schema = nullptr;
    if (channel->second.schema_id != 0) schema = &contents_.schemas.at(channel->second.schema_id);
    ++contents_.messages;
    if (on_message_) on_message_(channel->second, schema, m, place);
  }

  void ReadSchema(const Record& r, const std::string& where) {
    Fields f(r.content, where);
    McapSchema s;
    s.id = f.Int<std::uint16_t>("id");
    s.name = f.String("name");
    s.encoding = f.String("encoding");
    const std::uint32_t n = f.Int<std::uint32_t>("data");
    s.data = std::string(f.Bytes(n, "data"));
    if (s.id == 0) return;  // invalid by the specification: ignored
    contents_.schemas.emplace(s.id, std::move(s));
  }

  void ReadChannel(const Record& r, const std::string& where) {
    Fields f(r.content, where);
    McapChannel c;
    c.id = f.Int<std::uint16_t>("id");
    c.schema_id = f.Int<std::uint16_t>("schema_id");
    c.topic = f.String("topic");
    c.message_encoding = f.String("message_encoding");
    c.metadata = f.StringMap("metadata");
    if (c.schema_id != 0 && !contents_.schemas.count(c.schema_id)) {
      f.Fail("channel " + std::to_string(c.id) + " (topic '" + c.topic + "') refers to schema " +
             std::to_string(c.schema_id) + ", which no earlier Schema record defines");
    }
    contents_.channels.emplace(c.id, std::move(c));
  }

  void ReadChunk(const Record& r, const std::string& where) {
    Fields f(r.content, where);
    f.Int<std::uint64_t>("message_start_time");
    f.Int<std::uint64_t>("message_end_time");
    const std::uint64_t size = f.Int<std::uint64_t>("uncompressed_size");
    const std::uint32_t crc = f.Int<std::uint32_t>("uncompressed_crc");
    const std::string compression = f.String("compression");
    const std::uint64_t n = f.Int<std::uint64_t>("records");
    const std::string_view stored = f.Bytes(n, "records");
    std::string decompressed;
    std::string_view records;
    if (compression.empty()) {
      if (n != size) {
        f.Fail("uncompressed records of " + std::to_string(n) + " bytes, but uncompressed_size " +
               std::to_string(size));
      }
      records = stored;
    } else if (compression == "zstd" || compression == "lz4") {
      decompressed = compression == "zstd" ? DecompressZstd(stored, size, where)
                                           : DecompressLz4(stored, size, where);
      if (decompressed.size() != size) {
        f.Fail(compression + " records decompress to " + std::to_string(decompressed.size()) +
               " bytes, but uncompressed_size is " + std::to_string(size));
      }
      records = decompressed;
    } else {
      f.Fail("unknown compression '" + compression + "' (zstd, lz4 or none)");
    }
    if (crc != 0 && Crc32(records) != crc) {
      f.Fail("the CRC of the uncompressed records does not match (the chunk is damaged)");
    }
    ++contents_.chunks;
    McapPlace chunk;
    chunk.record_offset = r.offset;
    for (std::uint64_t pos = 0; pos < records.size();) {
      const Record inner = Frame(records, pos, &chunk);
      McapPlace place = chunk;
      place.in_chunk = true;
      place.chunk_offset = r.offset;
      place.record_offset = inner.offset;
      const std::string inner_where = RecordWhere(source_, place, inner.op);
      if (inner.op == kSchema || inner.op == kChannel || inner.op == kMessage) {
        InnerRecord(inner, place, inner_where);
      } else if (inner.op < 0x80 && inner.op <= kDataEnd) {
        throw McapError(inner_where + ": not allowed inside a chunk");
      }
      pos = inner.end;
    }
  }

  void CheckAttachment(const Record& r, const std::string& where) {
    Fields f(r.content, where);
    f.Int<std::uint64_t>("log_time");
    f.Int<std::uint64_t>("create_time");
    f.String("name");
    f.String("media_type");
    const std::uint64_t n = f.Int<std::uint64_t>("data");
    f.Bytes(n, "data");
    const std::size_t covered = f.pos();
    const std::uint32_t crc = f.Int<std::uint32_t>("crc");
    if (crc != 0 && Crc32(r.content.substr(0, covered)) != crc) {
      f.Fail("the attachment's CRC does not match (the file is damaged)");
    }
  }

  void ReadFooter(const Record& r, const std::string& where, std::uint64_t data_end_offset) {
    if (r.content.size() != kFooterContentBytes) {
      throw McapError(where + ": " + std::to_string(r.content.size()) + " bytes long, not " +
                      std::to_string(kFooterContentBytes));
    }
    Fields f(r.content, where);
    const std::uint64_t summary_start = f.Int<std::uint64_t>("summary_start");
    f.Int<std::uint64_t>("summary_offset_start");
    const std::uint32_t crc = f.Int<std::uint32_t>("summary_crc");
    if (summary_start != 0 && (summary_start <= data_end_offset || summary_start > r.offset)) {
      f.Fail("summary_start " + std::to_string(summary_start) +
             " is not between the Data End record and the Footer");
    }
    if (summary_start != 0 && crc != 0) {
      // From the summary's start through the footer's summary_offset_start field.
      const std::uint64_t end = r.offset + kRecordPrefixBytes + 16;
      if (Crc32(file_.substr(summary_start, end - summary_start)) != crc) {
        f.Fail("the summary section's CRC does not match (the file is damaged)");
      }
    }
    const std::uint64_t rest = file_.size() - r.end;
    if (rest != kMagicBytes || std::memcmp(file_.data() + r.end, kMagic, kMagicBytes) != 0) {
      throw McapError(source_ + ": byte " + std::to_string(r.end) +
                      ": the Footer is not followed by the closing magic and the end of the file");
    }
  }

  std::string_view file_;
  const std::string& source_;
  const McapMessageHandler& on_message_;
  McapContents contents_;
};

void PutInt(std::string* out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}
void PutString(std::string* out, const std::string& s) {
  PutInt(out, s.size(), 4);
  *out += s;
}
void PutRecord(std::string* out, std::uint8_t op, const std::string& content) {
  out->push_back(static_cast<char>(op));
  PutInt(out, content.size(), 8);
  *out += content;
}

std::string SchemaContent(const McapSchema& s) {
  std::string c;
  PutInt(&c, s.id, 2);
  PutString(&c, s.name);
  PutString(&c, s.encoding);
  PutString(&c, s.data);
  return c;
}

std::string ChannelContent(const McapChannel& ch) {
  std::string c, map;
  PutInt(&c, ch.id, 2);
  PutInt(&c, ch.schema_id, 2);
  PutString(&c, ch.topic);
  PutString(&c, ch.message_encoding);
  for (const auto& [key, value] : ch.metadata) {
    PutString(&map, key);
    PutString(&map, value);
  }
  PutString(&c, map);
  return c;
}

std::string Compress(McapCompression compression, const std::string& in) {
  switch (compression) {
    case McapCompression::kNone:
      return in;
    case McapCompression::kZstd: {
      std::string out(ZSTD_compressBound(in.size()), '\0');
      const std::size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 3);
      if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
      out.resize(n);
      return out;
    }
    case McapCompression::kLz4: {
      LZ4F_preferences_t prefs;
      std::memset(&prefs, 0, sizeof(prefs));
      prefs.frameInfo.contentSize = in.size();
      std::string out(LZ4F_compressFrameBound(in.size(), &prefs), '\0');
      const std::size_t n =
          LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), &prefs);
      if (LZ4F_isError(n)) throw std::runtime_error(std::string("lz4: ") + LZ4F_getErrorName(n));
      out.resize(n);
      return out;
    }
  }
  return in;
}

}  // namespace

std::string McapPlace::ToString() const {
  if (!in_chunk) return "record at byte " + std::to_string(record_offset);
  return "chunk at byte " + std::to_string(chunk_offset) + ", record at byte " +
         std::to_string(record_offset) + " of its records";
}

McapContents ReadMcap(std::string_view file, const std::string& source,
                      const McapMessageHandler& on_message) {
  return Reader(file, source, on_message).Read();
}

std::string ReadFileBytes(const std::string& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (error || !std::filesystem::exists(status)) {
    throw McapError(path + ": cannot be opened for reading" +
                    (error ? ": " + error.message() : std::string()));
  }
  if (!std::filesystem::is_regular_file(status)) throw McapError(path + ": not a regular file");
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw McapError(path + ": cannot be opened for reading");
  const std::streamoff size = in.tellg();
  if (size < 0) throw McapError(path + ": cannot be read");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), size)) throw McapError(path + ": reading failed");
  return bytes;
}

const char* ToString(McapCompression compression) {
  switch (compression) {
    case McapCompression::kNone:
      return "";
    case McapCompression::kZstd:
      return "zstd";
    case McapCompression::kLz4:
      return "lz4";
  }
  return "";
}

McapWriter::McapWriter(McapWriterOptions options) : options_(std::move(options)) {
  file_.assign(kMagic, kMagicBytes);
  std::string header;
  PutString(&header, options_.profile);
  PutString(&header, options_.library);
  PutRecord(&file_, kHeader, header);
}

std::uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding,
                                    const std::string& data) {
  McapSchema s;
  s.id = static_cast<std::uint16_t>(schemas_.size() + 1);
  s.name = name;
  s.encoding = encoding;
  s.data = data;
  schemas_.push_back(std::move(s));
  schema_written_.push_back(false);
  return schemas_.back().id;
}

std::uint16_t McapWriter::AddChannel(std::uint16_t schema_id, const std::string& topic,
                                     const std::string& message_encoding,
                                     const std::map<std::string, std::string>& metadata) {
  McapChannel c;
  c.id = static_cast<std::uint16_t>(channels_.size());
  c.schema_id = schema_id;
  c.topic = topic;
  c.message_encoding = message_encoding;
  c.metadata = metadata;
  channels_.push_back(std::move(c));
  channel_written_.push_back(false);
  return channels_.back().id;
}

void McapWriter::AddMessage(const McapMessage& m) {
  const McapChannel& channel = channels_.at(m.channel_id);
  if (!channel_written_[m.channel_id]) {
    if (channel.schema_id != 0 && !schema_written_[channel.schema_id - 1]) {
      PutRecord(&chunk_, kSchema, SchemaContent(schemas_.at(channel.schema_id - 1)));
      schema_written_[channel.schema_id - 1] = true;
    }
    PutRecord(&chunk_, kChannel, ChannelContent(channel));
    channel_written_[m.channel_id] = true;
  }
  chunk_index_[m.channel_id].emplace_back(m.log_time_ns, chunk_.size());
  std::string content;
  PutInt(&content, m.channel_id, 2);
  PutInt(&content, m.sequence, 4);
  PutInt(&content, m.log_time_ns, 8);
  PutInt(&content, m.publish_time_ns, 8);
  content.append(m.data.data(), m.data.size());
  PutRecord(&chunk_, kMessage, content);
  if (chunk_index_.size() == 1 && chunk_index_.begin()->second.size() == 1) {
    chunk_start_ns_ = chunk_end_ns_ = m.log_time_ns;
  }
  chunk_start_ns_ = std::min(chunk_start_ns_, m.log_time_ns);
  chunk_end_ns_ = std::max(chunk_end_ns_, m.log_time_ns);
  first_ns_ = messages_ == 0 ? m.log_time_ns : std::min(first_ns_, m.log_time_ns);
  last_ns_ = std::max(last_ns_, m.log_time_ns);
  ++messages_;
  ++channel_counts_[m.channel_id];
  if (chunk_.size() >= options_.chunk_bytes) CloseChunk();
}

void McapWriter::CloseChunk() {
  if (chunk_.empty()) return;
  const std::uint64_t chunk_offset = file_.size();
  const std::string stored = Compress(options_.compression, chunk_);
  std::string content;
  PutInt(&content, chunk_start_ns_, 8);
  PutInt(&content, chunk_end_ns_, 8);
  PutInt(&content, chunk_.size(), 8);
  PutInt(&content, options_.crcs ? Crc32(chunk_) : 0, 4);
  PutString(&content, ToString(options_.compression));
  PutInt(&content, stored.size(), 8);
  content += stored;
  PutRecord(&file_, kChunk, content);
  const std::uint64_t chunk_length = file_.size() - chunk_offset;
  const std::uint64_t index_start = file_.size();
  std::string offsets;
  for (const auto& [channel, entries] : chunk_index_) {
    PutInt(&offsets, channel, 2);
    PutInt(&offsets, file_.size(), 8);
    std::string index, array;
    PutInt(&index, channel, 2);
    for (const auto& [time, offset] : entries) {
      PutInt(&array, time, 8);
      PutInt(&array, offset, 8);
    }
    PutString(&index, array);
    PutRecord(&file_, kMessageIndex, index);
  }
  std::string chunk_index;
  PutInt(&chunk_index, chunk_start_ns_, 8);
  PutInt(&chunk_index, chunk_end_ns_, 8);
  PutInt(&chunk_index, chunk_offset, 8);
  PutInt(&chunk_index, chunk_length, 8);
  PutString(&chunk_index, offsets);
  PutInt(&chunk_index, file_.size() - index_start, 8);
  PutString(&chunk_index, ToString(options_.compression));
  PutInt(&chunk_index, stored.size(), 8);
  PutInt(&chunk_index, chunk_.size(), 8);
  PutRecord(&chunk_indexes_, kChunkIndex, chunk_index);
  ++chunks_;
  chunk_.clear();
  chunk_index_.clear();
}

std::string McapWriter::Finish() {
  CloseChunk();
  std::string data_end;
  PutInt(&data_end, options_.crcs ? Crc32(file_) : 0, 4);
  PutRecord(&file_, kDataEnd, data_end);
  // The summary, grouped by opcode, each group found through a Summary Offset record.
  const std::uint64_t summary_start = file_.size();
  std::vector<std::tuple<std::uint8_t, std::uint64_t, std::uint64_t>> groups;
  auto group = [&](std::uint8_t op, const std::string& records) {
    if (records.empty()) return;
    groups.emplace_back(op, file_.size(), records.size());
    file_ += records;
  };
  std::string schemas, channels;
  for (const McapSchema& s : schemas_) PutRecord(&schemas, kSchema, SchemaContent(s));
  for (const McapChannel& c : channels_) PutRecord(&channels, kChannel, ChannelContent(c));
  group(kSchema, schemas);
  group(kChannel, channels);
  group(kChunkIndex, chunk_indexes_);
  std::string stats, counts;
  PutInt(&stats, messages_, 8);
  PutInt(&stats, schemas_.size(), 2);
  PutInt(&stats, channels_.size(), 4);
  PutInt(&stats, 0, 4);  // attachments
  PutInt(&stats, 0, 4);  // metadata
  PutInt(&stats, chunks_, 4);
  PutInt(&stats, first_ns_, 8);
  PutInt(&stats, last_ns_, 8);
  for (const auto& [channel, count] : channel_counts_) {
    PutInt(&counts, channel, 2);
    PutInt(&counts, count, 8);
  }
  PutString(&stats, counts);
  std::string statistics;
  PutRecord(&statistics, kStatistics, stats);
  group(kStatistics, statistics);
  const std::uint64_t summary_offset_start = file_.size();
  for (const auto& [op, start, length] : groups) {
    std::string offset;
    PutInt(&offset, op, 1);
    PutInt(&offset, start, 8);
    PutInt(&offset, length, 8);
    PutRecord(&file_, kSummaryOffset, offset);
  }
  std::string footer;
  PutInt(&footer, summary_start, 8);
  PutInt(&footer, summary_offset_start, 8);
  file_.push_back(static_cast<char>(kFooter));
  PutInt(&file_, kFooterContentBytes, 8);
  file_ += footer;
  PutInt(&file_, options_.crcs ? Crc32(std::string_view(file_).substr(summary_start)) : 0, 4);
  file_.append(kMagic, kMagicBytes);
  std::string out = std::move(file_);
  *this = McapWriter(options_);
  return out;
}

void WriteFileBytes(const std::string& bytes, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot open '" + tmp + "' for writing");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      throw std::runtime_error("writing '" + tmp + "' failed");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename '" + tmp + "' to '" + path + "'");
  }
}

}  // namespace slideid
