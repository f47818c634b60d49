// 8. Import speed: ~100 MB (--quick: ~10 MB) of a CSV log, a ROS 1 bag, an MCAP file and a rosbag2 SQLite
// directory, written here (tests/support/bag_writers.h, message_writer.h) and imported into a recording in memory
// (ImportCsv / ImportRosbag, one thread), beside a plain read of the same bytes (the I/O floor). Target: 10 s per
// 100 MB on one core.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench.h"
#include "importers/csv.h"
#include "importers/rosbag.h"
#include "tests/support/bag_writers.h"
#include "tests/support/message_writer.h"

namespace roamlab::bench {
namespace {

namespace fs = std::filesystem;
namespace bag = importers::testing;

constexpr double kImuRateHz = 200.0;  // bags: IMU at 200 Hz, a fix every 40th IMU message (5 Hz)
constexpr int kImuPerFix = 40;
constexpr std::int64_t kStartNs = 1'700'000'000'000'000'000;  // Unix time of the first message

// One input: what it is, the path the importer reads, the files its bytes are in, the IMU samples written.
struct ImportInput {
  std::string name;  // JSON key
  std::string label;
  std::string path;
  std::vector<std::string> files;
  std::int64_t imu_samples = 0;
  std::uintmax_t uncompressed_bytes = 0;  // MCAP: the records inside its chunks
};

// A pseudo-random IMU sample (gyro [rad/s], accel [m/s^2]): values that do not repeat, so the zstd chunks compress
// by about six rather than to nothing.
struct ImuNoise {
  std::mt19937 random{7};
  std::normal_distribution<double> normal;
  std::vector<double> Gyro() { return {0.02 * normal(random), 0.02 * normal(random), 0.3 * normal(random)}; }
  std::vector<double> Accel() { return {0.5 * normal(random), 0.5 * normal(random), 9.81 + 0.5 * normal(random)}; }
};

// Stamp of IMU message `i`.
std::int64_t ImuStampNs(std::int64_t i) { return kStartNs + std::llround(1e9 * static_cast<double>(i) / kImuRateHz); }
std::int32_t Sec(std::int64_t t_ns) { return static_cast<std::int32_t>(t_ns / 1'000'000'000); }
std::uint32_t Nsec(std::int64_t t_ns) { return static_cast<std::uint32_t>(t_ns % 1'000'000'000); }
double Latitude(std::int64_t fix) { return 45.0 + 1e-6 * static_cast<double>(fix); }

Status WriteBytes(const std::string& path, const std::string& bytes, std::ios::openmode mode = std::ios::trunc) {
  std::ofstream out(path, std::ios::binary | mode);
  out << bytes;
  return out.good() ? Status::Ok() : Status::Error(path + ": cannot write");
}

// (a) CSV: epoch milliseconds, an IMU at 100 Hz (deg/s, g) and a 1 Hz GPS fix repeated on every row.
Result<ImportInput> WriteCsv(const fs::path& dir, std::uintmax_t bytes) {
  ImportInput in{"csv", "CSV (IMU + GPS on every row)", (dir / "log.csv").string(), {}, 0};
  const std::string map = (dir / "log.yaml").string();
  in.files = {in.path, map};
  Status s = WriteBytes(map,
                        "csv: {delimiter: \",\", header: true}\n"
                        "time: {column: time_ms, unit: ms, clock: epoch}\n"
                        "streams:\n"
                        "  imu: {type: imu, columns: [gx, gy, gz, ax, ay, az], units: [deg/s, deg/s, deg/s, g, g, g]}\n"
                        "  gps: {type: gps, columns: [lat, lon, alt], collapse: by_change}\n");
  if (!s.ok()) return s;
  ImuNoise noise;
  std::string block = "time_ms,gx,gy,gz,ax,ay,az,lat,lon,alt\n";
  std::uintmax_t written = 0;
  char row[256];
  for (std::int64_t i = 0; written + block.size() < bytes; ++i) {
    const std::vector<double> w = noise.Gyro(), a = noise.Accel();
    const std::int64_t fix = i / 100;
    const int n = std::snprintf(row, sizeof(row), "%lld,%.4f,%.4f,%.4f,%.5f,%.5f,%.5f,%.9f,%.9f,%.3f\n",
                                static_cast<long long>(kStartNs / 1'000'000 + 10 * i), w[0] * 57.29578, w[1] * 57.29578,
                                w[2] * 57.29578, a[0] / 9.80665, a[1] / 9.80665, a[2] / 9.80665, Latitude(fix),
                                9.0 + 1e-6 * static_cast<double>(fix), 120.0 + 0.01 * fix);
    block.append(row, static_cast<std::size_t>(n));
    ++in.imu_samples;
    if (block.size() > (8u << 20)) {
      if (!(s = WriteBytes(in.path, block, std::ios::app)).ok()) return s;
      written += block.size();
      block.clear();
    }
  }
  if (!(s = WriteBytes(in.path, block, std::ios::app)).ok()) return s;
  return in;
}

// A message of a bag: stamp [ns], topic (0: /imu, 1: /fix) and serialized data.
struct StampedMessage {
  std::int64_t t_ns;
  int topic;
  std::string data;
};

// Gives `sink` IMU messages at 200 Hz and a fix with every 40th, in time order, until it refuses one (returns false);
// returns the IMU messages it took.
template <typename Sink>
std::int64_t EmitMessages(bag::Wire wire, Sink sink) {
  ImuNoise noise;
  for (std::int64_t i = 0;; ++i) {
    const std::int64_t t = ImuStampNs(i);
    if (!sink(StampedMessage{t, 0, bag::ImuMessage(wire, Sec(t), Nsec(t), noise.Gyro(), noise.Accel())})) return i;
    if (i % kImuPerFix == 0 && !sink(StampedMessage{t, 1, bag::FixMessage(wire, Sec(t), Nsec(t), 0, Latitude(i))}))
      return i + 1;
  }
}

// (b) ROS 1 bag: uncompressed chunks of about 768 kB (rosbag's default), sensor_msgs/Imu and NavSatFix.
Result<ImportInput> WriteRos1Bag(const fs::path& dir, std::uintmax_t bytes) {
  ImportInput in{"ros1_bag", "ROS 1 bag (uncompressed chunks)", (dir / "log.bag").string(), {}, 0};
  in.files = {in.path};
  std::vector<std::string> chunks;
  std::string chunk =
      bag::Connection(0, "/imu", "sensor_msgs/Imu") + bag::Connection(1, "/fix", "sensor_msgs/NavSatFix");
  std::uintmax_t total = 0;
  in.imu_samples = EmitMessages(bag::Wire::kRos1, [&](StampedMessage m) {
    if (total + chunk.size() >= bytes) return false;
    // Received at its stamp (MessageRecord receives at sec + 1).
    chunk += bag::MessageRecord(static_cast<std::uint32_t>(m.topic), Sec(m.t_ns) - 1, Nsec(m.t_ns), m.data);
    if (chunk.size() > 768u * 1024u) {
      total += chunk.size();
      chunks.push_back(std::exchange(chunk, std::string()));
    }
    return true;
  });
  if (!chunk.empty()) chunks.push_back(chunk);
  std::string file = bag::BagStart(static_cast<std::uint32_t>(chunks.size()));
  for (const std::string& c : chunks) file += bag::ChunkRecord(c, "none");
  if (Status s = WriteBytes(in.path, file); !s.ok()) return s;
  return in;
}

// (c) MCAP: CDR sensor_msgs/msg/Imu and NavSatFix in zstd chunks of about 4 MB uncompressed; `bytes` of file.
Result<ImportInput> WriteMcap(const fs::path& dir, std::uintmax_t bytes) {
  ImportInput in{"mcap_zstd", "MCAP (zstd chunks, CDR)", (dir / "log.mcap").string(), {}, 0};
  in.files = {in.path};
  std::string file = bag::kMcapMagic + bag::McapHeader() + bag::McapSchema(1, "sensor_msgs/msg/Imu") +
                     bag::McapSchema(2, "sensor_msgs/msg/NavSatFix") + bag::McapChannel(1, 1, "/imu") +
                     bag::McapChannel(2, 2, "/fix");
  std::string records;
  // The file grows by the compressed chunks: ask for messages until it holds `bytes`.
  in.imu_samples = EmitMessages(bag::Wire::kCdrLittle, [&](StampedMessage m) {
    if (file.size() >= bytes) return false;
    records += bag::McapMessage(static_cast<std::uint16_t>(m.topic + 1), static_cast<std::uint64_t>(m.t_ns), m.data);
    if (records.size() > (4u << 20)) {
      in.uncompressed_bytes += records.size();
      file += bag::McapZstdChunk(std::exchange(records, std::string()));
    }
    return true;
  });
  in.uncompressed_bytes += records.size();
  if (!records.empty()) file += bag::McapZstdChunk(records);
  if (Status s = WriteBytes(in.path, file + bag::McapEnd()); !s.ok()) return s;
  return in;
}

// (d) rosbag2: a directory with metadata.yaml and one SQLite file of CDR Imu and NavSatFix messages.
Result<ImportInput> WriteRosbag2(const fs::path& dir, std::uintmax_t bytes) {
  const fs::path bag_dir = dir / "rosbag2";
  fs::create_directories(bag_dir);
  ImportInput in{"rosbag2_sqlite", "rosbag2 directory (SQLite)", bag_dir.string(), {}, 0};
  in.files = {(bag_dir / "metadata.yaml").string(), (bag_dir / "bag_0.db3").string()};
  std::vector<std::pair<std::int64_t, std::string>> imu, gps;
  std::uintmax_t total = 0;
  in.imu_samples = EmitMessages(bag::Wire::kCdrLittle, [&](StampedMessage m) {
    if (total >= bytes) return false;
    total += m.data.size() + 40;  // SQLite's row, its timestamp index entry and page slack
    (m.topic == 0 ? imu : gps).emplace_back(m.t_ns, std::move(m.data));
    return true;
  });
  if (Status s = bag::WriteDb3(in.files[1], imu, gps); !s.ok()) return s;
  if (Status s = WriteBytes(in.files[0], bag::Rosbag2Metadata("sqlite3", "bag_0.db3")); !s.ok()) return s;
  return in;
}

std::uintmax_t SizeOf(const std::vector<std::string>& files) {
  std::uintmax_t size = 0;
  for (const std::string& f : files) size += fs::file_size(f);
  return size;
}

// The I/O floor: every byte of the input's files read into memory; seconds.
double ReadSeconds(const std::vector<std::string>& files) {
  const auto t0 = Clock::now();
  std::size_t read_bytes = 0;
  for (const std::string& f : files) {
    std::string bytes(fs::file_size(f), '\0');
    std::FILE* file = std::fopen(f.c_str(), "rb");
    if (file == nullptr) continue;
    read_bytes += std::fread(bytes.data(), 1, bytes.size(), file);
    std::fclose(file);
  }
  const double seconds = Since(t0);
  return read_bytes > 0 ? seconds : 0.0;
}

// Imports the input into a recording in memory: the imu stream's sample count, or an error.
Result<std::int64_t> Import(const ImportInput& in) {
  Result<recording::Recording> rec = in.name == "csv"
                                         ? importers::ImportCsv({in.path}, in.files[1], nullptr)
                                         : importers::ImportRosbag(in.path, importers::RosbagImportOptions{});
  if (!rec.ok()) return rec.status();
  const recording::Stream* imu = rec.value().Find("imu");
  if (imu == nullptr) return Status::Error(in.path + ": no imu stream imported");
  return static_cast<std::int64_t>(imu->t.size());
}

// Times the import of `in` against the floor and the target, prints a line and adds the figures to `j`.
int MeasureImport(const ImportInput& in, double target_s, Json* j) {
  const double mb = 1e-6 * static_cast<double>(SizeOf(in.files));
  const double floor_s = ReadSeconds(in.files);
  const auto t0 = Clock::now();
  const double cpu0 = ThreadCpu();
  const Result<std::int64_t> samples = Import(in);
  const double cpu_s = ThreadCpu() - cpu0;
  const double wall_s = Since(t0);
  if (!samples.ok()) return Fail(samples.status().message());
  if (samples.value() != in.imu_samples) {
    return Fail(in.path + ": " + std::to_string(samples.value()) + " IMU samples imported of " +
                std::to_string(in.imu_samples) + " written");
  }
  // One core's time: the CPU time of the importing thread (on a shared machine the wall clock also counts the
  // other processes); the wall time beside it.
  const bool met = cpu_s <= target_s;
  (*j)["import"][in.name] = {{"file_mb", mb},
                             {"cpu_s", cpu_s},
                             {"wall_s", wall_s},
                             {"mb_per_cpu_s", mb / cpu_s},
                             {"floor_s", floor_s},
                             {"over_floor", cpu_s / floor_s},
                             {"target_s", target_s},
                             {"ratio_to_target", target_s / cpu_s},
                             {"met", met}};
  std::string records;
  if (in.uncompressed_bytes > 0) {
    (*j)["import"][in.name]["uncompressed_mb"] = 1e-6 * static_cast<double>(in.uncompressed_bytes);
    records =
        "; " + std::to_string(std::lround(1e-6 * static_cast<double>(in.uncompressed_bytes))) + " MB uncompressed";
  }
  Say("  import %-31s %6.1f MB %6.2f s CPU %6.1f MB/s  target <= %.0f s   ratio %.2f   %s  (wall %.2f s; read %.3f s, "
      "%.0fx the floor%s)\n",
      in.label.c_str(), mb, cpu_s, mb / cpu_s, target_s, target_s / cpu_s, met ? "met" : "NOT MET", wall_s, floor_s,
      cpu_s / floor_s, records.c_str());
  return 0;
}

}  // namespace

// 8. Import speed of each format, ~import_mb each; target 10 s per 100 MB.
int BenchImport(const Context& ctx, Json* j) {
  const fs::path dir = ctx.tmp / "import";
  const std::uintmax_t bytes = static_cast<std::uintmax_t>(ctx.sizes.import_mb * 1e6);
  const double target_s = 10.0 * ctx.sizes.import_mb / 100.0;
  for (auto* write : {WriteCsv, WriteRos1Bag, WriteMcap, WriteRosbag2}) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    const Result<ImportInput> in = write(dir, bytes);
    if (!in.ok()) return Fail(in.status().message());
    if (int code = MeasureImport(in.value(), target_s, j)) return code;
  }
  fs::remove_all(dir);
  return 0;
}

}  // namespace roamlab::bench
