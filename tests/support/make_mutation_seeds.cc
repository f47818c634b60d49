// Writes the binary seeds of the mutation campaign (tools/mutate.py): a short synthetic ATV recording (synthetic.h)
// and a small ROS 1 bag (bag_writers.h) with an IMU and a GPS topic. Usage: make_mutation_seeds OUT_DIR
// Writes OUT_DIR/rec/ and OUT_DIR/seed.bag.
#include <cstdio>
#include <fstream>
#include <string>

#include "tests/support/bag_writers.h"
#include "tests/support/message_writer.h"
#include "tests/support/synthetic.h"

namespace {

using namespace roamlab::importers::testing;

// 40 IMU messages at 100 Hz and 4 fixes at 10 Hz on /imu and /fix, in one uncompressed chunk.
std::string SeedBag() {
  std::string chunk = Connection(0, "/imu", "sensor_msgs/Imu") + Connection(1, "/fix", "sensor_msgs/NavSatFix");
  for (std::uint32_t k = 0; k < 40; ++k) {
    const std::uint32_t nsec = (k % 100) * 10000000u;
    chunk += MessageRecord(0, 100, nsec, ImuMessage(Wire::kRos1, 100, nsec, 0.01 * k));
    if (k % 10 == 0) chunk += MessageRecord(1, 100, nsec, FixMessage(Wire::kRos1, 100, nsec, 0, 45.0 + 1e-6 * k));
  }
  return BagOf(chunk);
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
  std::ofstream bag(out + "/seed.bag", std::ios::binary);
  bag << SeedBag();
  if (!bag) {
    std::fprintf(stderr, "make_mutation_seeds: %s/seed.bag: cannot write\n", out.c_str());
    return 1;
  }
  return 0;
}
