// Writes the synthetic part of the fuzzers' seed corpora: small bags of every supported message type in each container
// (tests/support/bag_writers.h, message_writer.h) and small OptiOdom and CSV inputs (fuzz_input.h). scripts/fuzz.sh
// adds simulated recordings, the repository's YAML files and excerpts of real recordings.
//
//   fuzz_seeds CORPUS_DIR      writes CORPUS_DIR/<harness>/<seed> (the folders are created)
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz/fuzz_input.h"
#include "tests/support/bag_writers.h"
#include "tests/support/message_writer.h"

namespace roamlab::fuzz {
namespace {

namespace fs = std::filesystem;
using importers::testing::Wire;
namespace bw = importers::testing;

struct TopicMessages {
  std::string topic;
  std::string ros1_type;  // "sensor_msgs/Imu"; the ROS 2 type inserts "/msg"
  std::vector<std::string> messages;
};

std::string Ros2Type(const std::string& ros1_type) {
  const std::size_t slash = ros1_type.find('/');
  return ros1_type.substr(0, slash) + "/msg" + ros1_type.substr(slash);
}

// Three messages of every supported type, serialized for `wire`.
std::vector<TopicMessages> AllTopics(Wire wire) {
  std::vector<TopicMessages> topics = {{"/imu", "sensor_msgs/Imu", {}},
                                       {"/fix", "sensor_msgs/NavSatFix", {}},
                                       {"/mag", "sensor_msgs/MagneticField", {}},
                                       {"/joints", "sensor_msgs/JointState", {}},
                                       {"/scan", "sensor_msgs/LaserScan", {}},
                                       {"/image", "sensor_msgs/Image", {}},
                                       {"/jpeg", "sensor_msgs/CompressedImage", {}},
                                       {"/odom", "nav_msgs/Odometry", {}},
                                       {"/twist", "geometry_msgs/TwistStamped", {}},
                                       {"/pose", "geometry_msgs/PoseStamped", {}},
                                       {"/pose_cov", "geometry_msgs/PoseWithCovarianceStamped", {}}};
  for (std::uint32_t k = 0; k < 3; ++k) {
    const std::int32_t sec = 100;
    const std::uint32_t nsec = 100000000u * k;
    const double x = 0.1 * (k + 1);
    topics[0].messages.push_back(bw::ImuMessage(wire, sec, nsec, x));
    topics[1].messages.push_back(bw::FixMessage(wire, sec, nsec, 0, 45.0 + 1e-6 * k));
    topics[2].messages.push_back(bw::MagneticFieldMessage(wire, sec, nsec, 2e-5 + 1e-7 * k));
    topics[3].messages.push_back(bw::JointStateMessage(wire, sec, nsec, x, 1.0));
    topics[4].messages.push_back(bw::LaserScanMessage(wire, sec, nsec, static_cast<float>(1.0 + x)));
    topics[5].messages.push_back(bw::ImageMessage(wire, sec, nsec, "mono8", static_cast<char>('a' + k)));
    topics[6].messages.push_back(bw::CompressedImageMessage(wire, sec, nsec, "\xFF\xD8\xFF jpeg"));
    topics[7].messages.push_back(bw::OdometryMessage(wire, sec, nsec, "odom", "base_link", {0, 0, 0, 1}, x, 0, 0.1));
    topics[8].messages.push_back(bw::TwistStampedMessage(wire, sec, nsec, x, 0.1));
    topics[9].messages.push_back(bw::PoseStampedMessage(wire, sec, nsec, x));
    topics[10].messages.push_back(bw::PoseWithCovarianceMessage(wire, sec, nsec, x));
  }
  return topics;
}

void Write(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  WriteBytes(path.string(), bytes);
}

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

void WriteRos1Bags(const fs::path& dir) {
  std::string chunk;
  std::uint32_t conn = 0;
  for (const TopicMessages& topic : AllTopics(Wire::kRos1)) {
    chunk += bw::Connection(conn, topic.topic, topic.ros1_type);
    for (std::uint32_t k = 0; k < topic.messages.size(); ++k) {
      chunk += bw::MessageRecord(conn, 100, 100000000u * k, topic.messages[k]);
    }
    ++conn;
  }
  for (const std::string compression : {"none", "bz2", "lz4"}) Write(dir / compression, bw::BagOf(chunk, compression));
}

void WriteMcaps(const fs::path& dir) {
  std::string definitions, messages;
  std::uint16_t id = 1;
  for (const TopicMessages& topic : AllTopics(Wire::kCdrLittle)) {
    definitions += bw::McapSchema(id, Ros2Type(topic.ros1_type)) + bw::McapChannel(id, id, topic.topic);
    for (std::size_t k = 0; k < topic.messages.size(); ++k) {
      messages += bw::McapMessage(id, 100000000000ull + 100000000ull * k, topic.messages[k]);
    }
    ++id;
  }
  const std::string start = bw::kMcapMagic + bw::McapHeader() + definitions;
  Write(dir / "plain", start + messages + bw::McapEnd());
  Write(dir / "zstd_chunk", start + bw::McapZstdChunk(messages) + bw::McapEnd());
}

void WriteDb3s(const fs::path& dir, const fs::path& scratch) {
  for (const auto& [name, wire] : {std::pair{"little", Wire::kCdrLittle}, std::pair{"big", Wire::kCdrBig}}) {
    std::vector<bw::Db3Topic> topics;
    std::vector<bw::Db3Message> messages;
    for (const TopicMessages& topic : AllTopics(wire)) {
      for (std::size_t k = 0; k < topic.messages.size(); ++k) {
        messages.push_back({static_cast<int>(topics.size()),
                            static_cast<std::int64_t>(100000000000ll + 100000000ll * k), topic.messages[k]});
      }
      topics.push_back({topic.topic, Ros2Type(topic.ros1_type)});
    }
    const fs::path db3 = scratch / (std::string(name) + ".db3");
    const Status status = bw::WriteDb3(db3.string(), topics, messages);
    if (!status.ok()) {
      std::cerr << "fuzz_seeds: " << status.message() << "\n";
      std::exit(1);
    }
    Write(dir / name, ReadAll(db3));
  }
}

void WriteTextSeeds(const fs::path& root) {
  Write(root / "optiodom_fuzz" / "diff",
        "0,0,0,0,0,0\n0.05,0.001,0,0.01,40,38\n0.1,0.002,0.0005,0.02,41,39\n"
        "%%%% set_metadata.csv\ntype,diff\nngear,43.7,\nencRes,64,\nLi,0.2,\nDi,0.084,0.084\nThi,,\nN,2,\n");
  Write(root / "optiodom_fuzz" / "tricycle",
        "0,0,0,0,0,0\n0.05,0.001,0,0.01,40,0.1\n0.1,0.002,0.0005,0.02,41,-0.2\n"
        "%%%% set_metadata.csv\ntype,tricyc,\nngear,1,\nencRes,1600,\nLi,0.15,\nDi,0.065,\nThi,-0.02,\nN,2,\n");
  Write(root / "csv_fuzz" / "imu_gps",
        "time: {column: t, unit: ms, clock: relative}\n"
        "csv: {delimiter: \",\", header: true, comment: \"#\", non_numeric: skip_row}\n"
        "streams:\n"
        "  imu: {type: imu, columns: [gx, gy, gz, ax, ay, az], units: [deg/s, deg/s, deg/s, g, g, g],"
        " axes: [x, -z, y]}\n"
        "  gps: {type: gps, columns: [lat, lon, alt], collapse: by_change}\n"
        "  wheels: {type: wheel_encoders, columns: [l, r], names: [left, right], units: km/h}\n"
        "%%%% a.csv\n# comment\nt,gx,gy,gz,ax,ay,az,lat,lon,alt,l,r\n"
        "0,1,2,3,0,0,1,45,9,100,1,1\n10,1,2,3,0,0,1,45,9,100,1.1,1\n20,1,2,3,0,0,1,45.00001,9,100,1.2,1.1\n");
}

}  // namespace
}  // namespace roamlab::fuzz

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (argc != 2) {
    std::cerr << "usage: fuzz_seeds CORPUS_DIR\n";
    return 2;
  }
  const fs::path root = argv[1];
  const fs::path scratch = root / ".scratch";
  fs::remove_all(scratch);
  fs::create_directories(scratch);
  roamlab::fuzz::WriteRos1Bags(root / "ros1_bag_fuzz");
  roamlab::fuzz::WriteMcaps(root / "mcap_fuzz");
  roamlab::fuzz::WriteDb3s(root / "rosbag2_fuzz", scratch);
  roamlab::fuzz::WriteTextSeeds(root);
  fs::remove_all(scratch);
  return 0;
}
