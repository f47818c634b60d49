// A bag's messages as its container stores them, before decoding. The ROS 1 bag (v2.0), the rosbag2 directory
// (metadata.yaml + SQLite .db3) and MCAP files are each read into this one form; the message decoders turn it into
// recording streams. Private to the importers.
#pragma once

#include <deque>
#include <string>
#include <string_view>
#include <vector>

#include "common/status.h"
#include "common/time.h"

namespace roamlab::importers::internal {

// How a message's bytes are serialized: ROS 1 (packed little-endian, u32-length strings and arrays) or CDR (ROS 2:
// a 4-byte encapsulation header, then little- or big-endian fields aligned to their size from the header's end).
enum class Encoding { kRos1, kCdr };

struct BagTopic {
  std::string name;  // "/imu/data"
  std::string type;  // "sensor_msgs/Imu": a ROS 2 type "sensor_msgs/msg/Imu" is stored without its "/msg"
  Encoding encoding = Encoding::kRos1;
};

struct BagMessage {
  std::size_t topic = 0;  // index into Bag::topics
  Time receive_time;      // when the recorder received it (ROS 1 record time, rosbag2 timestamp, MCAP log_time)
  std::string_view data;  // the serialized message (for CDR including its encapsulation header)
};

struct Bag {
  std::string format;                // "ROS 1 bag v2.0", "rosbag2 SQLite", "MCAP"
  std::vector<BagTopic> topics;      // one per topic name (several ROS 1 connections of a topic share one)
  std::vector<BagMessage> messages;  // in the order the container stores them
  std::deque<std::string> storage;   // owns the bytes the messages point into (file content, decompressed chunks)
  int chunks = 0;                    // chunks read (ROS 1, MCAP); 0 when the format has none
};

// Each reader: errors are one line "<path>: <problem>" (not the format, truncated or corrupt record, unsupported
// compression, unsupported serialization), never a crash and never a read past a declared length.
Result<Bag> ReadRos1Bag(const std::string& path);

// rosbag2: `path` is the bag directory or its metadata.yaml (every file of relative_file_paths is read, in that
// order), or one .db3 file (its own tables name its topics). storage_identifier sqlite3: each .db3 is opened
// read-only and immutable (a bag left in WAL mode is read as its main file holds it; nothing is written next to it),
// the topics and messages tables are read and each file's messages sorted by timestamp (ties in row order); only the
// cdr serialization is read. storage_identifier mcap: each file is read as ReadMcap does. compression_format zstd is
// read in both modes (FILE: each listed file is one zstd stream, decompressed in memory; MESSAGE: each message is a zstd
// frame stating its size); other compressions are refused. Topics of several files merge by name.
Result<Bag> ReadRosbag2(const std::string& path);

// MCAP: the data section is read record by record from the start (the summary section and indexes are not needed,
// the Footer and the closing magic are required, so a truncated file is refused). Schema names give the types
// ("sensor_msgs/msg/Imu" -> "sensor_msgs/Imu"); channel message encodings cdr and ros1 are read, others refused;
// channels of one topic merge. Chunks: uncompressed, zstd or lz4 (frame format), at most 1 GiB uncompressed each,
// their uncompressed size and (when not 0) CRC-32 checked; messages are views into the file or the uncompressed
// chunk, nothing is copied. Attachments, metadata records and unknown opcodes are skipped.
Result<Bag> ReadMcap(const std::string& path);

// Picks the reader by what `path` is: a directory (rosbag2), a file starting with the MCAP magic, or "#ROSBAG V".
Result<Bag> ReadAnyBag(const std::string& path);

}  // namespace roamlab::importers::internal
