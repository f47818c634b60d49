// Writes the binary seeds of the mutation campaign (tools/mutate.py): a short synthetic ATV recording (synthetic.h)
// and the same small bag (bag_writers.h, an IMU and a GPS topic) as ROS 1, MCAP and rosbag2 SQLite.
// Usage: make_mutation_seeds OUT_DIR. Writes OUT_DIR/rec/, OUT_DIR/seed.bag, OUT_DIR/seed.mcap and OUT_DIR/seed.db3.
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/bag_writers.h"
#include "tests/support/message_writer.h"
#include "tests/support/synthetic.h"

namespace {

using namespace roamlab::importers::testing;

// 40 IMU messages at 100 Hz (topic 0, /imu) and 4 fixes at 10 Hz (topic 1, /fix) from 100 s, in time order,
// serialized for `wire`.
std::vector<Db3Message> SeedMessages(Wire wire) {
  std::vector<Db3Message> messages;
  for (std::uint32_t k = 0; k < 40; ++k) {
    const std::uint32_t nsec = k * 10000000u;
    const std::int64_t stamp_ns = 100000000000ll + nsec;
    messages.push_back({0, stamp_ns, ImuMessage(wire, 100, nsec, 0.01 * k)});
    if (k % 10 == 0) messages.push_back({1, stamp_ns, FixMessage(wire, 100, nsec, 0, 45.0 + 1e-6 * k)});
  }
  return messages;
}

// The messages in a ROS 1 bag, one uncompressed chunk.
std::string SeedBag() {
  std::string chunk = Connection(0, "/imu", "sensor_msgs/Imu") + Connection(1, "/fix", "sensor_msgs/NavSatFix");
  for (const Db3Message& m : SeedMessages(Wire::kRos1))
    chunk += MessageRecord(m.topic, 100, static_cast<std::uint32_t>(m.timestamp_ns % 1000000000), m.data);
  return BagOf(chunk);
}

// The messages as MCAP (little-endian CDR), the records unchunked.
std::string SeedMcap() {
  std::string out = kMcapMagic + McapHeader() + McapSchema(1, "sensor_msgs/msg/Imu") + McapChannel(1, 1, "/imu") +
                    McapSchema(2, "sensor_msgs/msg/NavSatFix") + McapChannel(2, 2, "/fix");
  for (const Db3Message& m : SeedMessages(Wire::kCdrLittle))
    out += McapMessage(static_cast<std::uint16_t>(m.topic + 1), m.timestamp_ns, m.data);
  return out + McapEnd();
}

bool WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  if (out) return true;
  std::fprintf(stderr, "make_mutation_seeds: %s: cannot write\n", path.c_str());
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_mutation_seeds OUT_DIR\n");
    return 2;
  }
  const std::string out = argv[1];
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 4.0;
  const roamlab::Status status =
      roamlab::recording::WriteRecording(roamlab::testing::MakeAtvRecording(options).recording, out + "/rec");
  if (!status.ok()) {
    std::fprintf(stderr, "make_mutation_seeds: %s\n", status.message().c_str());
    return 1;
  }
  if (!WriteFile(out + "/seed.bag", SeedBag()) || !WriteFile(out + "/seed.mcap", SeedMcap())) return 1;
  const roamlab::Status db3 =
      WriteDb3(out + "/seed.db3", {{"/imu", "sensor_msgs/msg/Imu"}, {"/fix", "sensor_msgs/msg/NavSatFix"}},
               SeedMessages(Wire::kCdrLittle));
  if (!db3.ok()) {
    std::fprintf(stderr, "make_mutation_seeds: %s\n", db3.message().c_str());
    return 1;
  }
  return 0;
}
