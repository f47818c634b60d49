// The rosbag2 and MCAP container readers and the dispatch by path, on files written from the formats' documentation
// (tests/support/bag_writers.h: the MCAP specification's records, rosbag2's metadata.yaml and SQLite schema) and on
// real bags.
#include <sqlite3.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "importers/internal/bag.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/bag_writers.h"
#include "tests/support/real_data.h"

namespace roamlab::importers::internal {
namespace {

using ::roamlab::importers::testing::Crc32;
using ::roamlab::importers::testing::kMcapMagic;
using ::roamlab::importers::testing::Lz4;
using ::roamlab::importers::testing::McapChannel;
using ::roamlab::importers::testing::McapChunk;
using ::roamlab::importers::testing::McapEnd;
using ::roamlab::importers::testing::McapHeader;
using ::roamlab::importers::testing::McapMessage;
using ::roamlab::importers::testing::McapSchema;
using ::roamlab::importers::testing::Raw;
using ::roamlab::importers::testing::Record;
using ::roamlab::importers::testing::Rosbag2Metadata;
using ::roamlab::importers::testing::SqliteExec;
using ::roamlab::importers::testing::Str;
using ::roamlab::importers::testing::WriteDb3;
using ::roamlab::importers::testing::Zstd;
using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;

// A CDR message: the little-endian encapsulation header, then `n` bytes of a pattern seeded by `seed`.
std::string Cdr(int seed, int n = 24) {
  std::string out("\x00\x01\x00\x00", 4);
  for (int i = 0; i < n; ++i) out += static_cast<char>((seed * 31 + i * 7) & 0xFF);
  return out;
}

struct Expected {
  std::string topic;
  std::int64_t time_ns;
  std::string data;
};

// Schemas, channels and messages outside chunks, in an uncompressed chunk, a zstd chunk (with its CRC) and an lz4
// chunk; `expected` gets the messages in file order.
std::string SmallMcap(std::vector<Expected>* expected) {
  std::string file = kMcapMagic + McapHeader() + McapSchema(1, "sensor_msgs/msg/Imu") +
                     McapSchema(2, "nav_msgs/Odometry", "ros1msg") + McapChannel(3, 1, "/imu") +
                     McapChannel(4, 2, "/odom", "ros1");
  const auto add = [&](std::uint16_t channel, std::int64_t t, int seed) {
    expected->push_back({channel == 4 ? "/odom" : "/imu", t, Cdr(seed)});
    return McapMessage(channel, static_cast<std::uint64_t>(t), Cdr(seed));
  };
  // One append per statement: `expected` follows the file order.
  file += add(3, 1000, 1);
  file += add(4, 1500, 2);
  std::string plain = add(3, 2000, 3);
  plain += add(3, 2100, 4);
  file += McapChunk("", plain, plain.size(), 0);
  std::string zstd = McapChannel(5, 1, "/imu");
  zstd += add(5, 3000, 5);
  zstd += add(4, 3100, 6);
  file += McapChunk("zstd", Zstd(zstd), zstd.size(), Crc32(zstd));
  std::string lz4 = add(3, 4000, 7);
  lz4 += add(4, 4100, 8);
  lz4 += add(3, 4200, 9);
  file += McapChunk("lz4", Lz4(lz4), lz4.size(), 0);
  file += add(4, 5000, 10);
  // Records the reader has no use for: an attachment, a metadata record, an opcode the specification reserves.
  file += Record(0x09, Raw(std::uint64_t{1}) + Raw(std::uint64_t{1}) + Str("calib.txt") + Str("text/plain") +
                           Raw(std::uint64_t{2}) + "ab" + Raw(std::uint32_t{0}));
  file += Record(0x0C, Str("info") + Str(Str("k") + Str("v")));
  file += Record(0x80, "reserved");
  // The summary section repeats the schemas and channels.
  file += Record(0x0F, Raw(std::uint32_t{0})) + McapSchema(1, "sensor_msgs/msg/Imu") + McapChannel(3, 1, "/imu") +
          Record(0x02, Raw(std::uint64_t{0}) + Raw(std::uint64_t{0}) + Raw(std::uint32_t{0})) + kMcapMagic;
  return file;
}

void ExpectMessages(const Bag& bag, const std::vector<Expected>& expected) {
  ASSERT_EQ(bag.messages.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const BagMessage& m = bag.messages[i];
    ASSERT_LT(m.topic, bag.topics.size());
    EXPECT_EQ(bag.topics[m.topic].name, expected[i].topic) << "message " << i;
    EXPECT_EQ(m.receive_time.nanoseconds(), expected[i].time_ns) << "message " << i;
    EXPECT_EQ(std::string(m.data), expected[i].data) << "message " << i;
  }
}

TEST(McapReader, ReadsMessagesInAndOutsideChunksOfEachCompression) {
  TempDir dir;
  std::vector<Expected> expected;
  WriteFile(dir.File("a.mcap"), SmallMcap(&expected));
  const Result<Bag> bag = ReadMcap(dir.File("a.mcap"));
  ASSERT_TRUE(bag.ok()) << bag.status().message();
  EXPECT_EQ(bag.value().format, "MCAP");
  EXPECT_EQ(bag.value().chunks, 3);
  ASSERT_EQ(bag.value().topics.size(), 2u);  // channels 3 and 5 share the topic /imu
  EXPECT_EQ(bag.value().topics[0].name, "/imu");
  EXPECT_EQ(bag.value().topics[0].type, "sensor_msgs/Imu");
  EXPECT_EQ(bag.value().topics[0].encoding, Encoding::kCdr);
  EXPECT_EQ(bag.value().topics[1].name, "/odom");
  EXPECT_EQ(bag.value().topics[1].type, "nav_msgs/Odometry");
  EXPECT_EQ(bag.value().topics[1].encoding, Encoding::kRos1);
  ExpectMessages(bag.value(), expected);
}

TEST(McapReader, EveryTruncationIsAnErrorNamingAnOffset) {
  TempDir dir;
  std::vector<Expected> expected;
  const std::string whole = SmallMcap(&expected);
  // Every fifth byte, and every byte of the footer and closing magic (file writes are what costs here).
  for (std::size_t cut = 0; cut < whole.size(); cut += cut + 60 < whole.size() ? 5 : 1) {
    WriteFile(dir.File("cut.mcap"), whole.substr(0, cut));
    const Result<Bag> bag = ReadMcap(dir.File("cut.mcap"));
    ASSERT_FALSE(bag.ok()) << "cut at " << cut;
    EXPECT_THAT(bag.status().message(), HasSubstr(dir.File("cut.mcap") + ": ")) << "cut at " << cut;
    if (cut > kMcapMagic.size()) {
      EXPECT_THAT(bag.status().message(), HasSubstr("byte")) << "cut at " << cut;
    }
  }
}

std::string OneChunkFile(const std::string& chunk) {
  return kMcapMagic + McapHeader() + McapSchema(1, "sensor_msgs/msg/Imu") + McapChannel(1, 1, "/imu") + chunk +
         McapEnd();
}

std::string ErrorOf(const TempDir& dir, const std::string& content) {
  WriteFile(dir.File("bad.mcap"), content);
  const Result<Bag> bag = ReadMcap(dir.File("bad.mcap"));
  return bag.ok() ? "" : bag.status().message();
}

TEST(McapReader, RefusesChunksThatDisagreeWithTheirDeclaredSizeOrCrc) {
  TempDir dir;
  const std::string records = McapMessage(1, 10, Cdr(1)) + McapMessage(1, 20, Cdr(2));
  const std::size_t chunk_at = kMcapMagic.size() + McapHeader().size() + McapSchema(1, "sensor_msgs/msg/Imu").size() +
                               McapChannel(1, 1, "/imu").size();
  const std::string at = "chunk at byte " + std::to_string(chunk_at);
  // The right sizes are read (the checks below fail on what they change, not on the rest of the file).
  ASSERT_EQ(ErrorOf(dir, OneChunkFile(McapChunk("zstd", Zstd(records), records.size(), Crc32(records)))), "");
  for (const std::uint64_t size : {records.size() - 1, records.size() + 1}) {
    EXPECT_THAT(ErrorOf(dir, OneChunkFile(McapChunk("zstd", Zstd(records), size, 0))), HasSubstr(at));
    EXPECT_THAT(ErrorOf(dir, OneChunkFile(McapChunk("lz4", Lz4(records), size, 0))), HasSubstr(at));
    EXPECT_THAT(ErrorOf(dir, OneChunkFile(McapChunk("", records, size, 0))), HasSubstr(at));
  }
  EXPECT_THAT(ErrorOf(dir, OneChunkFile(McapChunk("zstd", Zstd(records), records.size(), 12345))),
              HasSubstr(at + ": the uncompressed records do not match their CRC"));
  EXPECT_THAT(ErrorOf(dir, OneChunkFile(McapChunk("lz4", records, records.size(), 0))), HasSubstr(at + ": lz4"));
  EXPECT_THAT(ErrorOf(dir, OneChunkFile(McapChunk("zstd", records, records.size(), 0))),
              HasSubstr(at + ": the zstd data is not a zstd frame"));
  EXPECT_THAT(ErrorOf(dir, OneChunkFile(McapChunk("bz2", records, records.size(), 0))),
              HasSubstr(at + ": compression 'bz2', which this reader does not support"));
}

TEST(McapReader, RefusesUnknownChannelsEncodingsAndNonMcapFiles) {
  TempDir dir;
  const std::string start = kMcapMagic + McapHeader() + McapSchema(1, "sensor_msgs/msg/Imu");
  EXPECT_THAT(ErrorOf(dir, start + McapChannel(1, 1, "/imu", "json") + McapEnd()),
              HasSubstr("channel 1 (topic /imu) has message encoding 'json'"));
  EXPECT_THAT(ErrorOf(dir, start + McapMessage(9, 1, Cdr(1)) + McapEnd()),
              HasSubstr("Message on channel id 9, not defined before it"));
  EXPECT_THAT(ErrorOf(dir, start + McapChannel(1, 4, "/imu") + McapEnd()), HasSubstr("schema id 4"));
  EXPECT_THAT(ErrorOf(dir, ""), HasSubstr("bad.mcap: empty file"));
  EXPECT_THAT(ErrorOf(dir, std::string("\x7f"
                                       "ELF\x02\x01\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00",
                                       16)),
              HasSubstr("bad.mcap: not an MCAP file"));
  EXPECT_THAT(ErrorOf(dir, kMcapMagic + McapSchema(1, "a/msg/B") + McapEnd()),
              HasSubstr("the first record is not a Header"));
  // A declared body length past the end of the file.
  EXPECT_THAT(ErrorOf(dir, start + Record(0x05, std::string(4, 'x')).substr(0, 9) + "xx"),
              HasSubstr("truncated record at byte " + std::to_string(start.size())));
  // A record whose fields claim more than its body.
  EXPECT_THAT(
      ErrorOf(dir, start + Record(0x04, Raw(std::uint16_t{1}) + Raw(std::uint16_t{1}) + Str("/imu")) + McapEnd()),
      HasSubstr("Channel record shorter than its fields"));
}

const std::vector<std::pair<std::int64_t, std::string>> kImu = {{300, Cdr(1)}, {100, Cdr(2)}, {500, Cdr(3, 3)}};
const std::vector<std::pair<std::int64_t, std::string>> kGps = {{200, Cdr(4, 60)}, {400, Cdr(5)}};
const std::vector<Expected> kInTimeOrder = {{"/imu", 100, Cdr(2)},
                                            {"/fix", 200, Cdr(4, 60)},
                                            {"/imu", 300, Cdr(1)},
                                            {"/fix", 400, Cdr(5)},
                                            {"/imu", 500, Cdr(3, 3)}};

void ExpectSmallSqliteBag(const Result<Bag>& bag) {
  ASSERT_TRUE(bag.ok()) << bag.status().message();
  EXPECT_EQ(bag.value().format, "rosbag2 SQLite");
  ASSERT_EQ(bag.value().topics.size(), 2u);
  EXPECT_EQ(bag.value().topics[0].name, "/imu");
  EXPECT_EQ(bag.value().topics[0].type, "sensor_msgs/Imu");
  EXPECT_EQ(bag.value().topics[1].type, "sensor_msgs/NavSatFix");
  EXPECT_EQ(bag.value().topics[1].encoding, Encoding::kCdr);
  ExpectMessages(bag.value(), kInTimeOrder);
}

std::string Rosbag2Error(const std::string& path) {
  const Result<Bag> bag = ReadAnyBag(path);
  return bag.ok() ? "" : bag.status().message();
}

std::string ReadBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

TEST(Rosbag2Reader, ReadsTheSqliteBagInTimestampOrderFromItsDirectoryMetadataOrFile) {
  TempDir dir;
  ASSERT_TRUE(WriteDb3(dir.File("bag_0.db3"), kImu, kGps).ok());
  WriteFile(dir.File("metadata.yaml"), Rosbag2Metadata("sqlite3", "bag_0.db3"));
  for (const std::string& path : {dir.path(), dir.File("metadata.yaml"), dir.File("bag_0.db3")}) {
    SCOPED_TRACE(path);
    ExpectSmallSqliteBag(ReadAnyBag(path));
  }
}

TEST(Rosbag2Reader, ReadsZstdCompressionByFileAndByMessage) {
  TempDir dir;
  ASSERT_TRUE(WriteDb3(dir.File("plain.db3"), kImu, kGps).ok());
  WriteFile(dir.File("bag_0.db3.zstd"), Zstd(ReadBytes(dir.File("plain.db3"))));
  std::filesystem::remove(dir.File("plain.db3"));
  WriteFile(dir.File("metadata.yaml"), Rosbag2Metadata("sqlite3", "bag_0.db3.zstd", "zstd", "FILE"));
  {
    SCOPED_TRACE("file");
    ExpectSmallSqliteBag(ReadRosbag2(dir.path()));
  }
  std::vector<std::pair<std::int64_t, std::string>> imu = kImu;
  std::vector<std::pair<std::int64_t, std::string>> gps = kGps;
  for (auto& [t, data] : imu) data = Zstd(data);
  for (auto& [t, data] : gps) data = Zstd(data);
  ASSERT_TRUE(WriteDb3(dir.File("bag_0.db3"), imu, gps).ok());
  WriteFile(dir.File("metadata.yaml"), Rosbag2Metadata("sqlite3", "bag_0.db3", "zstd", "MESSAGE"));
  {
    SCOPED_TRACE("message");
    ExpectSmallSqliteBag(ReadRosbag2(dir.path()));
  }
  // Stored uncompressed but declared compressed by message.
  std::filesystem::remove(dir.File("bag_0.db3"));
  ASSERT_TRUE(WriteDb3(dir.File("bag_0.db3"), kImu, kGps).ok());
  EXPECT_EQ(Rosbag2Error(dir.path()),
            dir.File("bag_0.db3") + ": message 0 (topic /imu): not a zstd frame that states its size");
  // A truncated compressed file.
  const std::string compressed = Zstd(ReadBytes(dir.File("bag_0.db3")));
  WriteFile(dir.File("bag_0.db3.zstd"), compressed.substr(0, compressed.size() / 2));
  WriteFile(dir.File("metadata.yaml"), Rosbag2Metadata("sqlite3", "bag_0.db3.zstd", "zstd", "FILE"));
  EXPECT_EQ(Rosbag2Error(dir.path()), dir.File("bag_0.db3.zstd") + ": the zstd data ends inside a frame (truncated)");
}

TEST(Rosbag2Reader, ReadsAnMcapStorageBag) {
  TempDir dir;
  std::vector<Expected> expected;
  WriteFile(dir.File("bag_0.mcap"), SmallMcap(&expected));
  WriteFile(dir.File("metadata.yaml"), Rosbag2Metadata("mcap", "bag_0.mcap"));
  const Result<Bag> bag = ReadRosbag2(dir.path());
  ASSERT_TRUE(bag.ok()) << bag.status().message();
  EXPECT_EQ(bag.value().format, "rosbag2 MCAP");
  EXPECT_EQ(bag.value().chunks, 3);
  ExpectMessages(bag.value(), expected);
}

TEST(Rosbag2Reader, RefusesBadBagsWithOneLineNamingTheFile) {
  TempDir dir;
  EXPECT_EQ(Rosbag2Error(dir.path()),
            dir.path() + ": no metadata.yaml (not a rosbag2 bag directory; one .db3 file of a bag is read alone)");
  WriteFile(dir.File("metadata.yaml"), Rosbag2Metadata("sqlite3", "bag_0.db3"));
  EXPECT_EQ(Rosbag2Error(dir.path()), dir.File("bag_0.db3") + ": no such file");
  WriteFile(dir.File("bag_0.db3"), std::string(4096, '\x01'));
  EXPECT_EQ(Rosbag2Error(dir.path()), dir.File("bag_0.db3") + ": not an SQLite database");
  std::filesystem::remove(dir.File("bag_0.db3"));
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(dir.File("bag_0.db3").c_str(), &db), SQLITE_OK);
  ASSERT_TRUE(SqliteExec(db, "CREATE TABLE other(x INTEGER)").ok());
  sqlite3_close(db);
  EXPECT_EQ(Rosbag2Error(dir.path()), dir.File("bag_0.db3") + ": no 'topics' table (not a rosbag2 database)");
  std::filesystem::remove(dir.File("bag_0.db3"));
  ASSERT_TRUE(WriteDb3(dir.File("bag_0.db3"), {{1, Cdr(1)}}, {{2, Cdr(2)}}, "json").ok());
  EXPECT_THAT(Rosbag2Error(dir.path()), HasSubstr("bag_0.db3: topic /fix has serialization format 'json'"));
  WriteFile(dir.File("metadata.yaml"), Rosbag2Metadata("sqlite3", "bag_0.db3", "lz4", "FILE"));
  EXPECT_THAT(Rosbag2Error(dir.path()),
              HasSubstr("metadata.yaml: compression_format 'lz4' with compression_mode 'FILE', which this reader"));
  WriteFile(dir.File("metadata.yaml"), Rosbag2Metadata("rosbag_v2", "bag_0.db3"));
  EXPECT_THAT(Rosbag2Error(dir.path()), HasSubstr("metadata.yaml: storage_identifier 'rosbag_v2'"));
  WriteFile(dir.File("metadata.yaml"), "rosbag2_bagfile_information: [1, 2\n");
  EXPECT_THAT(Rosbag2Error(dir.path()), HasSubstr("metadata.yaml:"));
  WriteFile(dir.File("metadata.yaml"), "other: 1\n");
  EXPECT_THAT(Rosbag2Error(dir.path()), HasSubstr("no 'rosbag2_bagfile_information' mapping"));
}

TEST(AnyBag, DispatchesByContentAndRefusesOtherFiles) {
  TempDir dir;
  std::vector<Expected> expected;
  WriteFile(dir.File("a.bin"), SmallMcap(&expected));  // MCAP by its magic, whatever the name
  const Result<Bag> mcap = ReadAnyBag(dir.File("a.bin"));
  ASSERT_TRUE(mcap.ok()) << mcap.status().message();
  EXPECT_EQ(mcap.value().format, "MCAP");
  WriteFile(dir.File("empty.bag"), "");
  EXPECT_EQ(Rosbag2Error(dir.File("empty.bag")), dir.File("empty.bag") + ": empty file (not a bag)");
  WriteFile(dir.File("binary.bag"), std::string("\x7f"
                                                "ELF\x02\x01\x01\x00\x00\x00",
                                                10));
  EXPECT_THAT(Rosbag2Error(dir.File("binary.bag")), HasSubstr(dir.File("binary.bag") + ": not a bag"));
  EXPECT_THAT(Rosbag2Error(dir.File("missing.bag")), HasSubstr(dir.File("missing.bag") + ": cannot open"));
}

std::string SharedFile(const std::string& relative) { return ::roamlab::testing::RealData(relative); }

TEST(RealBags, Rosbag2SqliteCarBag) {
  const std::string path = SharedFile("ros2/av1tenth_car/bag2_deadreck_data");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  const Result<Bag> bag = ReadAnyBag(path);
  ASSERT_TRUE(bag.ok()) << bag.status().message();
  std::map<std::string, std::pair<std::string, int>> topics;  // name -> type, count
  for (const BagTopic& topic : bag.value().topics) topics[topic.name].first = topic.type;
  for (const BagMessage& m : bag.value().messages) ++topics[bag.value().topics[m.topic].name].second;
  const std::map<std::string, std::pair<std::string, int>> expected = {
      {"/odometry", {"nav_msgs/Odometry", 690}},
      {"/GPSNavSat", {"sensor_msgs/NavSatFix", 220}},
      {"/GPSData", {"geometry_msgs/PoseStamped", 220}}};
  EXPECT_EQ(topics, expected);
  const auto& messages = bag.value().messages;
  ASSERT_FALSE(messages.empty());
  for (std::size_t i = 1; i < messages.size(); ++i) ASSERT_LE(messages[i - 1].receive_time, messages[i].receive_time);
  // metadata.yaml gives the duration 103.355385114 s.
  EXPECT_NEAR(SecondsBetween(messages.front().receive_time, messages.back().receive_time), 103.355385114, 1e-9);
  for (const BagMessage& m : messages) ASSERT_GE(m.data.size(), 4u);  // each at least its CDR encapsulation header
}

TEST(RealBags, McapFixtureWithEveryCommonMessageType) {
  const std::string path = SharedFile("ros2/rosbags_fixture/test_bag_mcap/test_bag_mcap.mcap");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent";
  for (const std::string& read : {path, std::filesystem::path(path).parent_path().string()}) {
    const Result<Bag> bag = ReadAnyBag(read);
    ASSERT_TRUE(bag.ok()) << bag.status().message();
    EXPECT_EQ(bag.value().topics.size(), 94u);
    std::vector<int> counts(bag.value().topics.size(), 0);
    for (const BagMessage& m : bag.value().messages) ++counts[m.topic];
    for (std::size_t i = 0; i < counts.size(); ++i) EXPECT_EQ(counts[i], 2) << bag.value().topics[i].name;
    std::map<std::string, std::string> types;
    for (const BagTopic& topic : bag.value().topics) {
      types[topic.name] = topic.type;
      EXPECT_EQ(topic.encoding, Encoding::kCdr) << topic.name;
    }
    EXPECT_EQ(types["/test/geometry_msgs/accel"], "geometry_msgs/Accel");
    EXPECT_EQ(types["/test/tf2_msgs/tf_message"], "tf2_msgs/TFMessage");
    EXPECT_EQ(types["/test/sensor_msgs/imu"], "sensor_msgs/Imu");
  }
}

}  // namespace
}  // namespace roamlab::importers::internal
