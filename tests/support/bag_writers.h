// Test and benchmark helper: bag containers built by hand from the formats' documentation, not from the readers under
// test. ROS 1 bags (format 2.0: records of a u32-length header of name=value fields and a u32-length data part),
// MCAP files (the specification's records: opcode u8, body length u64, body) and rosbag2 directories (metadata.yaml
// and one SQLite file with the tables rosbag2 writes). The messages inside are message_writer.h's.
#pragma once

#include <bzlib.h>
#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "common/check.h"
#include "common/status.h"

namespace roamlab::importers::testing {

// The bytes of `value` as the machine holds it (little-endian here, as both formats store their integers).
template <typename T>
std::string Raw(T value) {
  std::string out(sizeof(T), '\0');
  std::memcpy(out.data(), &value, sizeof(T));
  return out;
}
inline std::string U32(std::uint32_t v) { return Raw(v); }

inline std::string Zstd(const std::string& data) {
  std::string out(ZSTD_compressBound(data.size()), '\0');
  const std::size_t size = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 3);
  ROAMLAB_CHECK(!ZSTD_isError(size), "zstd compression failed");
  out.resize(size);
  return out;
}
inline std::string Lz4(const std::string& data) {
  std::string out(LZ4F_compressFrameBound(data.size(), nullptr), '\0');
  const std::size_t size = LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), nullptr);
  ROAMLAB_CHECK(!LZ4F_isError(size), "lz4 compression failed");
  out.resize(size);
  return out;
}
inline std::string Bz2(const std::string& data) {
  std::string out(data.size() + data.size() / 100 + 1000, '\0');
  unsigned int size = static_cast<unsigned int>(out.size());
  ROAMLAB_CHECK(BZ2_bzBuffToBuffCompress(out.data(), &size, const_cast<char*>(data.data()),
                                         static_cast<unsigned int>(data.size()), 9, 0, 0) == BZ_OK,
                "bz2 compression failed");
  out.resize(size);
  return out;
}

// ---- ROS 1 bag v2.0 ----

inline std::string BagField(const std::string& name, const std::string& value) {
  return U32(static_cast<std::uint32_t>(name.size() + 1 + value.size())) + name + "=" + value;
}
inline std::string BagRecord(const std::string& header, const std::string& data) {
  return U32(static_cast<std::uint32_t>(header.size())) + header + U32(static_cast<std::uint32_t>(data.size())) + data;
}
inline std::string Op(std::uint8_t op) { return BagField("op", std::string(1, static_cast<char>(op))); }

inline std::string Connection(std::uint32_t id, const std::string& topic, const std::string& type) {
  return BagRecord(
      Op(0x07) + BagField("conn", U32(id)) + BagField("topic", topic),
      BagField("topic", topic) + BagField("type", type) + BagField("md5sum", "0") + BagField("message_definition", ""));
}
// A message received at bag time (sec + 1, nsec): later than its header stamp, which the importer must keep.
inline std::string MessageRecord(std::uint32_t conn, std::uint32_t sec, std::uint32_t nsec, const std::string& data) {
  return BagRecord(Op(0x02) + BagField("conn", U32(conn)) + BagField("time", U32(sec + 1) + U32(nsec)), data);
}

// `chunk` compressed as a chunk record says: "none", "bz2" or "lz4".
inline std::string Compressed(const std::string& chunk, const std::string& compression) {
  if (compression == "bz2") return Bz2(chunk);
  if (compression == "lz4") return Lz4(chunk);
  return chunk;
}

// A chunk record holding `chunk` (connection and message records).
inline std::string ChunkRecord(const std::string& chunk, const std::string& compression) {
  return BagRecord(
      Op(0x05) + BagField("compression", compression) + BagField("size", U32(static_cast<std::uint32_t>(chunk.size()))),
      Compressed(chunk, compression));
}

// The start of a bag of `chunk_count` chunks: the version line and the bag header record, padded as rosbag does.
inline std::string BagStart(std::uint32_t chunk_count) {
  const std::string header_fields = Op(0x03) + BagField("index_pos", Raw(std::uint64_t{0})) +
                                    BagField("conn_count", U32(4)) + BagField("chunk_count", U32(chunk_count));
  const std::string padding(4096 - header_fields.size() - 8, ' ');
  return std::string("#ROSBAG V2.0\n") + BagRecord(header_fields, padding);
}

// A bag of one chunk holding `chunk`.
inline std::string BagOf(const std::string& chunk, const std::string& compression = "none") {
  return BagStart(1) + ChunkRecord(chunk, compression);
}

// ---- MCAP ----

// A u32-length string.
inline std::string Str(const std::string& s) { return Raw(static_cast<std::uint32_t>(s.size())) + s; }

// CRC-32 as MCAP specifies it (IEEE, reflected), bit by bit.
inline std::uint32_t Crc32(const std::string& data) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (const char ch : data) {
    c ^= static_cast<unsigned char>(ch);
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xFFFFFFFFu;
}

inline const std::string kMcapMagic("\x89MCAP0\r\n", 8);
inline std::string Record(std::uint8_t op, const std::string& body) {
  return std::string(1, static_cast<char>(op)) + Raw(static_cast<std::uint64_t>(body.size())) + body;
}
inline std::string McapHeader() { return Record(0x01, Str("ros2") + Str("roamlab test")); }
inline std::string McapSchema(std::uint16_t id, const std::string& name, const std::string& encoding = "ros2msg") {
  return Record(0x03, Raw(id) + Str(name) + Str(encoding) + Str("float64 x\n"));
}
inline std::string McapChannel(std::uint16_t id, std::uint16_t schema, const std::string& topic,
                               const std::string& encoding = "cdr") {
  const std::string metadata = Str("offered_qos_profiles") + Str("");
  return Record(0x04, Raw(id) + Raw(schema) + Str(topic) + Str(encoding) + Str(metadata));
}
// A message logged at `log_time_ns` and published 5 ns later.
inline std::string McapMessage(std::uint16_t channel, std::uint64_t log_time_ns, const std::string& data) {
  return Record(0x05, Raw(channel) + Raw(std::uint32_t{7}) + Raw(log_time_ns) + Raw(log_time_ns + 5) + data);
}
inline std::string McapChunk(const std::string& compression, const std::string& compressed,
                             std::uint64_t uncompressed_size, std::uint32_t crc) {
  return Record(0x06, Raw(std::uint64_t{0}) + Raw(std::uint64_t{0}) + Raw(uncompressed_size) + Raw(crc) +
                          Str(compression) + Raw(static_cast<std::uint64_t>(compressed.size())) + compressed);
}
// A zstd chunk of `records`, with their CRC.
inline std::string McapZstdChunk(const std::string& records) {
  return McapChunk("zstd", Zstd(records), records.size(), Crc32(records));
}
// The data end, an empty summary and the footer.
inline std::string McapEnd() {
  return Record(0x0F, Raw(std::uint32_t{0})) +
         Record(0x02, Raw(std::uint64_t{0}) + Raw(std::uint64_t{0}) + Raw(std::uint32_t{0})) + kMcapMagic;
}

// ---- rosbag2 (SQLite) ----

inline Status SqliteExec(sqlite3* db, const std::string& sql) {
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) return Status::Error(sql);
  return Status::Ok();
}

// One topic of a .db3 file: its name, its ROS 2 type ("sensor_msgs/msg/Imu") and its serialization format.
struct Db3Topic {
  std::string name;
  std::string type;
  std::string format = "cdr";
};
// One message of a .db3 file: the index of its topic, its timestamp [ns] and its serialized data.
struct Db3Message {
  int topic = 0;
  std::int64_t timestamp_ns = 0;
  std::string data;
};

// A .db3 file with the tables rosbag2 writes (in WAL journal mode, as rosbag2 leaves them), `topics` and `messages`.
inline Status WriteDb3(const std::string& path, const std::vector<Db3Topic>& topics,
                       const std::vector<Db3Message>& messages) {
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) {
    sqlite3_close(db);
    return Status::Error(path + ": cannot open");
  }
  std::vector<std::string> sql = {
      "PRAGMA journal_mode=WAL",
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)",
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT "
      "NULL, data BLOB NOT NULL)",
      "CREATE INDEX timestamp_idx ON messages (timestamp ASC)"};
  for (std::size_t i = 0; i < topics.size(); ++i) {
    sql.push_back("INSERT INTO topics VALUES (" + std::to_string(i + 1) + ", '" + topics[i].name + "', '" +
                  topics[i].type + "', '" + topics[i].format + "', '')");
  }
  sql.push_back("BEGIN");
  Status status = Status::Ok();
  for (const std::string& statement : sql) {
    if (status.ok()) status = SqliteExec(db, statement);
  }
  sqlite3_stmt* insert = nullptr;
  if (status.ok() && sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", -1,
                                        &insert, nullptr) != SQLITE_OK)
    status = Status::Error(path + ": cannot prepare the insert");
  for (const Db3Message& m : messages) {
    if (!status.ok()) break;
    sqlite3_bind_int(insert, 1, m.topic + 1);
    sqlite3_bind_int64(insert, 2, m.timestamp_ns);
    sqlite3_bind_blob(insert, 3, m.data.data(), static_cast<int>(m.data.size()), SQLITE_TRANSIENT);
    if (sqlite3_step(insert) != SQLITE_DONE) status = Status::Error(path + ": insert failed");
    sqlite3_reset(insert);
  }
  if (status.ok()) status = SqliteExec(db, "COMMIT");
  sqlite3_finalize(insert);
  sqlite3_close(db);
  return status;
}

// A .db3 file with topics /imu (sensor_msgs/msg/Imu, cdr) and /fix (sensor_msgs/msg/NavSatFix, `gps_format`) and
// their messages (timestamp [ns], serialized data), /imu's first.
inline Status WriteDb3(const std::string& path, const std::vector<std::pair<std::int64_t, std::string>>& imu,
                       const std::vector<std::pair<std::int64_t, std::string>>& gps,
                       const std::string& gps_format = "cdr") {
  std::vector<Db3Message> messages;
  for (const auto& [t, data] : imu) messages.push_back({0, t, data});
  for (const auto& [t, data] : gps) messages.push_back({1, t, data});
  return WriteDb3(path, {{"/imu", "sensor_msgs/msg/Imu"}, {"/fix", "sensor_msgs/msg/NavSatFix", gps_format}}, messages);
}

// metadata.yaml of a rosbag2 bag of one file.
inline std::string Rosbag2Metadata(const std::string& storage, const std::string& file,
                                   const std::string& compression = "", const std::string& mode = "") {
  return "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: " + storage +
         "\n  relative_file_paths:\n    - " + file +
         "\n  topics_with_message_count:\n    - topic_metadata:\n        name: /imu\n        type: "
         "sensor_msgs/msg/Imu\n        serialization_format: cdr\n      message_count: 3\n  compression_format: \"" +
         compression + "\"\n  compression_mode: \"" + mode + "\"\n";
}

}  // namespace roamlab::importers::testing
