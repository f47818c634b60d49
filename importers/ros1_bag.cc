// The ROS 1 bag reader (format version 2.0, http://wiki.ros.org/Bags/Format/2.0) into the common bag form
// (internal/bag.h). Records are `header_len (u32) header data_len (u32) data`, a header being `field_len (u32)
// name=value` fields; the op codes read are 0x03 bag header, 0x05 chunk (compression "none", "bz2" or "lz4", the
// latter an LZ4 frame), 0x07 connection (topic, type) and 0x02 message data (conn, time); index (0x04) and chunk-info
// (0x06) records are skipped: every message is found by walking the chunks. A chunk may hold at most 1 GiB
// uncompressed.
#include <bzlib.h>
#include <lz4frame.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>

#include "importers/internal/bag.h"
#include "importers/internal/byte_cursor.h"

namespace roamlab::importers::internal {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::uint32_t kMaxChunkBytes = 1u << 30;
constexpr std::uint8_t kOpMessage = 0x02, kOpBagHeader = 0x03, kOpChunk = 0x05, kOpConnection = 0x07;

struct Record {
  std::map<std::string, std::string_view> fields;
  std::string_view data;
  std::size_t offset = 0;  // of the record in its buffer
};

// Reads `name=value` fields until the cursor's end; "" or the problem.
std::string ReadFields(std::string_view bytes, std::map<std::string, std::string_view>* fields) {
  ByteCursor h(bytes);
  while (!h.done()) {
    const std::string_view field = h.Bytes(h.U32());
    if (!h.ok()) return "malformed record header (a field runs past the header)";
    const std::size_t eq = field.find('=');
    if (eq == std::string_view::npos) return "malformed record header (a field without '=')";
    (*fields)[std::string(field.substr(0, eq))] = field.substr(eq + 1);
  }
  return "";
}

// Reads the next record; "" on success, else the problem.
std::string NextRecord(ByteCursor* in, Record* out) {
  out->offset = in->position();
  out->fields.clear();
  const std::string_view header = in->Bytes(in->U32());
  if (!in->ok()) return "truncated record header";
  if (std::string problem = ReadFields(header, &out->fields); !problem.empty()) return problem;
  out->data = in->Bytes(in->U32());
  if (!in->ok()) return "truncated record data";
  return "";
}

template <typename T>
bool Field(const Record& r, const std::string& name, T* value) {
  const auto it = r.fields.find(name);
  if (it == r.fields.end() || it->second.size() != sizeof(T)) return false;
  std::memcpy(value, it->second.data(), sizeof(T));
  return true;
}

std::string Text(const Record& r, const std::string& name) {
  const auto it = r.fields.find(name);
  return it == r.fields.end() ? "" : std::string(it->second);
}

struct PendingMessage {
  std::uint32_t connection = 0;
  Time receive_time;
  std::string_view data;
};

// What the walk over the records collects.
struct Walk {
  Bag* bag = nullptr;
  std::map<std::uint32_t, std::size_t> connections;  // conn id -> topic index
  std::vector<PendingMessage> messages;
  bool saw_bag_header = false;
};

// Decompresses an LZ4 frame of `size` bytes; "" or the problem.
std::string Lz4Frame(std::string_view in, std::uint32_t size, std::string* out) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) return "cannot create an lz4 context";
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> ctx(raw, LZ4F_freeDecompressionContext);
  out->assign(size, '\0');
  std::size_t written = 0, read = 0;
  while (read < in.size()) {
    std::size_t out_n = out->size() - written, in_n = in.size() - read;
    const std::size_t rc = LZ4F_decompress(ctx.get(), out->data() + written, &out_n, in.data() + read, &in_n, nullptr);
    if (LZ4F_isError(rc)) return std::string("corrupt lz4 chunk (") + LZ4F_getErrorName(rc) + ")";
    written += out_n;
    read += in_n;
    if (rc == 0) break;
    if (in_n == 0 && out_n == 0) return "corrupt lz4 chunk (no progress; larger than its declared size?)";
  }
  if (written != size) return "lz4 chunk of " + std::to_string(written) + " bytes, declared " + std::to_string(size);
  return "";
}

// The chunk's records, decompressed; "" or the problem.
std::string Unpack(const Record& r, std::string* out) {
  std::uint32_t size = 0;
  if (!Field(r, "size", &size)) return "chunk without size";
  if (size > kMaxChunkBytes) return "chunk of " + std::to_string(size) + " bytes uncompressed (more than 1 GiB)";
  const std::string compression = Text(r, "compression");
  if (compression == "none") {
    out->assign(r.data);
    return "";
  }
  if (compression == "bz2") {
    out->assign(size, '\0');
    unsigned int out_size = size;
    const int rc = BZ2_bzBuffToBuffDecompress(out->data(), &out_size, const_cast<char*>(r.data.data()),
                                              static_cast<unsigned int>(r.data.size()), 0, 0);
    if (rc != BZ_OK || out_size != size) return "corrupt bz2 chunk (bzip2 error " + std::to_string(rc) + ")";
    return "";
  }
  if (compression == "lz4") return Lz4Frame(r.data, size, out);
  return "chunk compressed with '" + compression + "', which this reader does not support (none, bz2 and lz4)";
}

std::string WalkRecords(std::string_view buffer, std::size_t base, bool in_chunk, Walk* walk);

// One record of the walk; "" or the problem (without the position).
std::string OnRecord(const Record& r, std::size_t base, bool in_chunk, Walk* walk) {
  std::uint8_t op = 0;
  if (!Field(r, "op", &op)) return "record without op";
  if (op == kOpBagHeader) {
    walk->saw_bag_header = true;
  } else if (op == kOpConnection) {
    std::uint32_t id = 0;
    if (!Field(r, "conn", &id)) return "connection record without conn";
    std::map<std::string, std::string_view> data;
    if (std::string problem = ReadFields(r.data, &data); !problem.empty()) return "connection data: " + problem;
    const std::string topic = Text(r, "topic");
    const auto type = data.find("type");
    if (topic.empty() || type == data.end()) return "connection record without topic or type";
    Bag& bag = *walk->bag;
    std::size_t index = 0;
    while (index < bag.topics.size() && bag.topics[index].name != topic) ++index;
    if (index == bag.topics.size()) bag.topics.push_back({topic, std::string(type->second), Encoding::kRos1});
    if (bag.topics[index].type != type->second)
      return "topic " + topic + " has connections of types " + bag.topics[index].type + " and " +
             std::string(type->second);
    walk->connections[id] = index;
  } else if (op == kOpMessage) {
    std::uint32_t id = 0;
    std::uint64_t stamp = 0;
    if (!Field(r, "conn", &id)) return "message record without conn";
    if (!Field(r, "time", &stamp)) return "message record without time";
    const auto sec = static_cast<std::int64_t>(stamp & 0xffffffffu), nsec = static_cast<std::int64_t>(stamp >> 32);
    walk->messages.push_back({id, Time::FromNanoseconds(sec * 1000000000 + nsec), r.data});
  } else if (op == kOpChunk && !in_chunk) {
    ++walk->bag->chunks;
    std::string unpacked;
    if (std::string problem = Unpack(r, &unpacked); !problem.empty()) return problem;
    walk->bag->storage.push_back(std::move(unpacked));
    return WalkRecords(walk->bag->storage.back(), base + r.offset, true, walk);
  }
  return "";
}

// Walks the records of `buffer` (the file after the magic line, or one chunk's data); "" or the problem. `base` is the
// buffer's offset in the file (inside a chunk: the chunk record's offset).
std::string WalkRecords(std::string_view buffer, std::size_t base, bool in_chunk, Walk* walk) {
  ByteCursor in(buffer);
  Record r;
  const auto where = [&] {
    return in_chunk ? " in the chunk at byte " + std::to_string(base) + " (record at byte " + std::to_string(r.offset) +
                          " of its data)"
                    : " at byte " + std::to_string(base + r.offset);
  };
  while (!in.done()) {
    if (std::string problem = NextRecord(&in, &r); !problem.empty()) return problem + where();
    if (std::string problem = OnRecord(r, base, in_chunk, walk); !problem.empty()) {
      // A problem inside a nested chunk already names its position.
      return problem.find(" in the chunk at byte ") != std::string::npos ? problem : problem + where();
    }
  }
  return "";
}

}  // namespace

Result<Bag> ReadRos1Bag(const std::string& path) {
  const auto fail = [&](const std::string& problem) { return Status::Error(path + ": " + problem); };
  std::ifstream file(path, std::ios::binary);
  if (!file) return fail("cannot open the file");
  Bag bag;
  bag.format = "ROS 1 bag v2.0";
  bag.storage.emplace_back((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) return fail("cannot read the file");
  const std::string& content = bag.storage.front();
  const std::size_t magic = sizeof(kMagic) - 1;
  if (content.size() < magic || content.compare(0, magic, kMagic) != 0) {
    if (content.compare(0, 9, "#ROSBAG V") == 0)
      return fail("unsupported bag version '" + content.substr(9, content.find('\n') - 9) + "' (only 2.0 is read)");
    return fail("not a ROS bag (no '#ROSBAG V2.0' line at the start)");
  }
  Walk walk;
  walk.bag = &bag;
  if (std::string problem = WalkRecords(std::string_view(content).substr(magic), magic, false, &walk); !problem.empty())
    return fail(problem);
  if (!walk.saw_bag_header) return fail("no bag header record");
  bag.messages.reserve(walk.messages.size());
  for (const PendingMessage& m : walk.messages) {
    const auto conn = walk.connections.find(m.connection);
    if (conn == walk.connections.end())
      return fail("a message refers to connection " + std::to_string(m.connection) + ", which the bag never defines");
    bag.messages.push_back({conn->second, m.receive_time, m.data});
  }
  return bag;
}

}  // namespace roamlab::importers::internal
