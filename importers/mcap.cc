// The MCAP reader: the data section read record by record (the summary is not needed), chunks uncompressed, zstd or
// lz4 (frame format), every declared length checked against its record.
#include <lz4frame.h>
#include <zstd.h>

#include <array>
#include <cstdint>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <utility>

#include "importers/internal/bag.h"
#include "importers/internal/byte_cursor.h"
#include "importers/internal/mcap_reader.h"
#include "importers/internal/rosbag2_topics.h"

namespace roamlab::importers::internal {
namespace {

constexpr std::string_view kMagic("\x89MCAP0\r\n", 8);
constexpr std::size_t kRecordHeaderBytes = 9;                     // opcode u8 + body length u64
constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;  // writers use chunks of a few MB

enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
};

// CRC-32 (IEEE 802.3, reflected, as the MCAP chunk's uncompressed_crc), four table lookups per 4 bytes.
class Crc32 {
 public:
  Crc32() {
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      table_[0][i] = c;
    }
    for (std::uint32_t i = 0; i < 256; ++i)
      for (int t = 1; t < 4; ++t) table_[t][i] = (table_[t - 1][i] >> 8) ^ table_[0][table_[t - 1][i] & 0xFFu];
  }
  std::uint32_t Of(std::string_view data) const {
    std::uint32_t c = 0xFFFFFFFFu;
    const auto* p = reinterpret_cast<const unsigned char*>(data.data());
    std::size_t n = data.size();
    for (; n >= 4; n -= 4, p += 4) {
      c ^= static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
           static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
      c = table_[3][c & 0xFFu] ^ table_[2][(c >> 8) & 0xFFu] ^ table_[1][(c >> 16) & 0xFFu] ^ table_[0][c >> 24];
    }
    for (; n > 0; --n, ++p) c = table_[0][(c ^ *p) & 0xFFu] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
  }

 private:
  std::array<std::array<std::uint32_t, 256>, 4> table_{};
};

std::string_view String32(ByteCursor* c) { return c->Bytes(c->U32()); }

struct Schema {
  std::string name;
  std::string encoding;
};

// One file's records, appended to a Bag. Problems are returned as text naming the byte offset; "" is fine.
class McapParser {
 public:
  explicit McapParser(Bag* bag) : bag_(bag) {}

  std::string ParseFile(std::string_view content) {
    if (content.size() < kMagic.size() || content.substr(0, kMagic.size()) != kMagic)
      return content.empty() ? "empty file (not MCAP)" : "not an MCAP file (no magic at the start)";
    return ParseRecords(content, kMagic.size(), /*chunk_at=*/npos);
  }

 private:
  static constexpr std::size_t npos = std::string_view::npos;

  // Records of `data` from `start`; offsets in messages are bytes of the file, or of the uncompressed records of the
  // chunk at file byte `chunk_at`.
  std::string ParseRecords(std::string_view data, std::size_t start, std::size_t chunk_at) {
    const bool top = chunk_at == npos;
    ByteCursor cursor(data);
    cursor.Seek(start);
    bool first = true;
    while (!cursor.done()) {
      const std::size_t at = cursor.position();
      const auto where = [&] {
        return top ? "record at byte " + std::to_string(at)
                   : "chunk at byte " + std::to_string(chunk_at) + ", record at byte " + std::to_string(at) +
                         " of its uncompressed records";
      };
      if (cursor.remaining() < kRecordHeaderBytes)
        return "truncated " + where() + " (the data ends inside its opcode and length)";
      const auto op = cursor.Read<std::uint8_t>();
      const std::uint64_t length = cursor.U64();
      if (length > cursor.remaining())
        return "truncated " + where() + ": opcode 0x" + Hex(op) + " declares " + std::to_string(length) +
               " bytes, only " + std::to_string(cursor.remaining()) + " remain";
      const std::string_view body = cursor.Bytes(static_cast<std::size_t>(length));
      if (top && first && op != kHeader) return where() + ": the first record is not a Header (opcode 0x01)";
      first = false;
      if (top && op == kFooter) return CheckEnd(data, cursor.position(), at);
      if (op == kChunk) {
        if (!top) return where() + ": a Chunk inside a chunk";
        if (std::string problem = ParseChunk(body, at); !problem.empty()) return problem;
        continue;
      }
      if (std::string problem = ParseRecord(op, body); !problem.empty()) return where() + ": " + problem;
    }
    if (top) return "truncated: the file ends at byte " + std::to_string(data.size()) + " without a Footer record";
    return "";
  }

  static std::string CheckEnd(std::string_view data, std::size_t end_of_footer, std::size_t footer_at) {
    if (data.size() - end_of_footer != kMagic.size() || data.substr(end_of_footer) != kMagic)
      return "the Footer at byte " + std::to_string(footer_at) + " is not followed by the closing magic and the end";
    return "";
  }

  static std::string Hex(std::uint8_t op) {
    static const char kDigits[] = "0123456789abcdef";
    return {kDigits[op >> 4], kDigits[op & 0xF]};
  }

  std::string ParseRecord(std::uint8_t op, std::string_view body) {
    switch (op) {
      case kSchema:
        return ParseSchema(body);
      case kChannel:
        return ParseChannel(body);
      case kMessage:
        return ParseMessage(body);
      default:
        return "";  // Header, indexes, attachments, metadata, statistics, data end and unknown opcodes: not needed
    }
  }

  std::string ParseSchema(std::string_view body) {
    ByteCursor c(body);
    const auto id = c.Read<std::uint16_t>();
    Schema schema{std::string(String32(&c)), std::string(String32(&c))};
    String32(&c);  // the message definition
    if (!c.ok()) return "Schema record shorter than its fields";
    if (id == 0) return "Schema with the reserved id 0";
    const auto [it, added] = schemas_.emplace(id, schema);
    if (!added && (it->second.name != schema.name || it->second.encoding != schema.encoding))
      return "Schema id " + std::to_string(id) + " defined twice differently";
    return "";
  }

  std::string ParseChannel(std::string_view body) {
    ByteCursor c(body);
    const auto id = c.Read<std::uint16_t>();
    const auto schema_id = c.Read<std::uint16_t>();
    const std::string topic(String32(&c));
    const std::string_view message_encoding = String32(&c);
    String32(&c);  // metadata map: u32 byte length + entries
    if (!c.ok()) return "Channel record shorter than its fields";
    const std::string channel = "channel " + std::to_string(id) + " (topic " + topic + ")";
    BagTopic bag_topic{topic, "", Encoding::kCdr};
    if (message_encoding == "ros1") {
      bag_topic.encoding = Encoding::kRos1;
    } else if (message_encoding != "cdr") {
      return channel + " has message encoding '" + std::string(message_encoding) +
             "', which this reader does not decode (only cdr and ros1)";
    }
    if (schema_id != 0) {
      const auto schema = schemas_.find(schema_id);
      if (schema == schemas_.end())
        return channel + " refers to schema id " + std::to_string(schema_id) + ", not defined before it";
      bag_topic.type = TypeWithoutMsg(schema->second.name);
    }
    std::size_t index = 0;
    if (std::string problem = FindOrAddTopic(bag_topic, bag_, &index); !problem.empty()) return problem;
    const auto [it, added] = channels_.emplace(id, index);
    if (!added && it->second != index) return channel + ": channel id defined twice with different topics";
    return "";
  }

  std::string ParseMessage(std::string_view body) {
    ByteCursor c(body);
    const auto channel_id = c.Read<std::uint16_t>();
    c.U32();  // sequence
    const std::uint64_t log_time_ns = c.U64();
    c.U64();  // publish_time
    if (!c.ok()) return "Message record shorter than its fields";
    const auto channel = channels_.find(channel_id);
    if (channel == channels_.end())
      return "Message on channel id " + std::to_string(channel_id) + ", not defined before it";
    if (log_time_ns > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      return "Message log_time " + std::to_string(log_time_ns) + " ns out of range";
    bag_->messages.push_back(
        {channel->second, Time::FromNanoseconds(static_cast<std::int64_t>(log_time_ns)), body.substr(c.position())});
    return "";
  }

  std::string ParseChunk(std::string_view body, std::size_t at) {
    ByteCursor c(body);
    c.U64();  // message_start_time
    c.U64();  // message_end_time
    const std::uint64_t uncompressed_size = c.U64();
    const std::uint32_t uncompressed_crc = c.U32();
    const std::string compression(String32(&c));
    const std::string_view records = c.Bytes(c.U64());
    const std::string where = "chunk at byte " + std::to_string(at) + ": ";
    if (!c.ok()) return where + "the record is shorter than its fields (or its records' declared length)";
    if (uncompressed_size > kMaxChunkBytes)
      return where + "declares " + std::to_string(uncompressed_size) + " uncompressed bytes, more than the " +
             std::to_string(kMaxChunkBytes) + " this reader holds per chunk";
    std::string_view uncompressed;
    if (std::string problem = Uncompress(records, uncompressed_size, compression, &uncompressed); !problem.empty())
      return where + problem;
    if (uncompressed_crc != 0 && crc_.Of(uncompressed) != uncompressed_crc)
      return where + "the uncompressed records do not match their CRC";
    ++bag_->chunks;
    return ParseRecords(uncompressed, 0, at);
  }

  // The chunk's records uncompressed into `out` (a view of the file or of a new bag->storage entry).
  std::string Uncompress(std::string_view records, std::uint64_t size, const std::string& compression,
                         std::string_view* out) {
    if (compression.empty()) {
      if (records.size() != size)
        return "uncompressed records of " + std::to_string(records.size()) + " bytes, declared " + std::to_string(size);
      *out = records;
      return "";
    }
    if (compression != "zstd" && compression != "lz4")
      return "compression '" + compression + "', which this reader does not support (only none, zstd and lz4)";
    if (compression == "zstd") {
      const unsigned long long frame_size = ZSTD_getFrameContentSize(records.data(), records.size());
      if (frame_size == ZSTD_CONTENTSIZE_ERROR) return "the zstd data is not a zstd frame";
      if (frame_size != ZSTD_CONTENTSIZE_UNKNOWN && frame_size != size)
        return "zstd frame of " + std::to_string(frame_size) + " bytes, declared uncompressed size " +
               std::to_string(size);
    }
    std::string* buffer = &bag_->storage.emplace_back(static_cast<std::size_t>(size), '\0');
    std::string problem = compression == "zstd" ? Zstd(records, buffer) : Lz4(records, buffer);
    if (!problem.empty()) return problem;
    *out = *buffer;
    return "";
  }

  static std::string Zstd(std::string_view records, std::string* buffer) {
    const std::size_t n = ZSTD_decompress(buffer->data(), buffer->size(), records.data(), records.size());
    if (ZSTD_isError(n))
      return "zstd data does not decompress to the declared " + std::to_string(buffer->size()) + " bytes (" +
             ZSTD_getErrorName(n) + ")";
    if (n != buffer->size())
      return "zstd data decompresses to " + std::to_string(n) + " bytes, declared " + std::to_string(buffer->size());
    return "";
  }

  static std::string Lz4(std::string_view records, std::string* buffer) {
    LZ4F_dctx* dctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&dctx, LZ4F_VERSION))) return "cannot start lz4 decompression";
    std::size_t in = 0;
    std::size_t produced = 0;
    std::size_t hint = 1;
    std::string problem;
    while (hint != 0 && problem.empty()) {
      std::size_t out_size = buffer->size() - produced;
      std::size_t in_size = records.size() - in;
      hint = LZ4F_decompress(dctx, buffer->data() + produced, &out_size, records.data() + in, &in_size, nullptr);
      if (LZ4F_isError(hint)) {
        problem = std::string("lz4 frame does not decompress (") + LZ4F_getErrorName(hint) + ")";
      } else if (in_size == 0 && out_size == 0 && hint != 0) {
        problem = produced == buffer->size()
                      ? "lz4 frame decompresses to more than the declared " + std::to_string(buffer->size()) + " bytes"
                      : "lz4 frame ends early, after " + std::to_string(produced) + " of the declared " +
                            std::to_string(buffer->size()) + " bytes";
      }
      in += in_size;
      produced += out_size;
    }
    LZ4F_freeDecompressionContext(dctx);
    if (problem.empty() && produced != buffer->size())
      problem = "lz4 frame decompresses to " + std::to_string(produced) + " bytes, declared " +
                std::to_string(buffer->size());
    return problem;
  }

  Bag* bag_;
  Crc32 crc_;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, std::size_t> channels_;  // channel id -> index into bag_->topics
};

}  // namespace

std::string ReadFileBytes(const std::string& path, std::string* content) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) return path + ": cannot open the file";
  const std::streamoff size = file.tellg();
  if (size < 0) return path + ": cannot read the file";
  try {
    content->assign(static_cast<std::size_t>(size), '\0');
  } catch (const std::exception&) {
    return path + ": too large to read into memory";
  }
  file.seekg(0);
  if (!file.read(content->data(), size)) return path + ": cannot read the file";
  return "";
}

std::string AppendMcap(const std::string& name, std::string content, Bag* bag) {
  const std::string_view view = bag->storage.emplace_back(std::move(content));
  McapParser parser(bag);
  if (std::string problem = parser.ParseFile(view); !problem.empty()) return name + ": " + problem;
  return "";
}

Result<Bag> ReadMcap(const std::string& path) {
  std::string content;
  if (std::string problem = ReadFileBytes(path, &content); !problem.empty()) return Status::Error(problem);
  Bag bag;
  bag.format = "MCAP";
  if (std::string problem = AppendMcap(path, std::move(content), &bag); !problem.empty()) return Status::Error(problem);
  return bag;
}

}  // namespace roamlab::importers::internal
