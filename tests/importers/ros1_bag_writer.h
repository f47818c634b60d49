// Test helper: ROS 1 bags (format 2.0) built by hand from the format's documentation, not from the reader under test.
#pragma once

#include <bzlib.h>
#include <lz4frame.h>

#include <cstdint>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

namespace roamlab::importers::testing {

// Bag v2.0 records built by hand (the format's documentation, not our reader, is the reference).
template <typename T>
std::string Raw(T value) {
  std::string out(sizeof(T), '\0');
  std::memcpy(out.data(), &value, sizeof(T));
  return out;
}
inline std::string U32(std::uint32_t v) { return Raw(v); }
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

inline std::string Compressed(std::string chunk, const std::string& compression) {
  std::string data = chunk;
  if (compression == "bz2") {
    data.assign(chunk.size() + 1000, '\0');
    unsigned int size = static_cast<unsigned int>(data.size());
    EXPECT_EQ(
        BZ2_bzBuffToBuffCompress(data.data(), &size, chunk.data(), static_cast<unsigned int>(chunk.size()), 9, 0, 0),
        BZ_OK);
    data.resize(size);
  } else if (compression == "lz4") {
    data.assign(LZ4F_compressFrameBound(chunk.size(), nullptr), '\0');
    const std::size_t size = LZ4F_compressFrame(data.data(), data.size(), chunk.data(), chunk.size(), nullptr);
    EXPECT_FALSE(LZ4F_isError(size));
    data.resize(size);
  }
  return data;
}

// A bag of one chunk holding `chunk` (connection and message records): header record padded as rosbag does.
inline std::string BagOf(const std::string& chunk, const std::string& compression = "none") {
  const std::string chunk_record = BagRecord(
      Op(0x05) + BagField("compression", compression) + BagField("size", U32(static_cast<std::uint32_t>(chunk.size()))),
      Compressed(chunk, compression));
  const std::string header_fields = Op(0x03) + BagField("index_pos", Raw(std::uint64_t{0})) +
                                    BagField("conn_count", U32(4)) + BagField("chunk_count", U32(1));
  const std::string padding(4096 - header_fields.size() - 8, ' ');
  return std::string("#ROSBAG V2.0\n") + BagRecord(header_fields, padding) + chunk_record;
}

}  // namespace roamlab::importers::testing
