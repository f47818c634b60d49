#include "importers/rosbag.h"

#include <bzlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"

namespace roamlab::importers {
namespace {

using ::roamlab::recording::ReadRecording;
using ::roamlab::recording::Recording;
using ::roamlab::recording::Stream;
using ::roamlab::recording::StreamType;
using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;

// Bag v2.0 records built by hand (the format's documentation, not our reader, is the reference).
template <typename T>
std::string Raw(T value) {
  std::string out(sizeof(T), '\0');
  std::memcpy(out.data(), &value, sizeof(T));
  return out;
}
std::string U32(std::uint32_t v) { return Raw(v); }
std::string F64(double v) { return Raw(v); }
std::string RosString(const std::string& s) { return U32(static_cast<std::uint32_t>(s.size())) + s; }
std::string BagField(const std::string& name, const std::string& value) {
  return U32(static_cast<std::uint32_t>(name.size() + 1 + value.size())) + name + "=" + value;
}
std::string BagRecord(const std::string& header, const std::string& data) {
  return U32(static_cast<std::uint32_t>(header.size())) + header + U32(static_cast<std::uint32_t>(data.size())) + data;
}
std::string Op(std::uint8_t op) { return BagField("op", std::string(1, static_cast<char>(op))); }
std::string Stamp(std::uint32_t sec, std::uint32_t nsec) { return U32(sec) + U32(nsec); }
std::string RosHeader(std::uint32_t seq, std::uint32_t sec, std::uint32_t nsec, const std::string& frame) {
  return U32(seq) + Stamp(sec, nsec) + RosString(frame);
}
std::string Doubles(const std::vector<double>& v) {
  std::string out;
  for (double d : v) out += F64(d);
  return out;
}

std::string Connection(std::uint32_t id, const std::string& topic, const std::string& type) {
  return BagRecord(
      Op(0x07) + BagField("conn", U32(id)) + BagField("topic", topic),
      BagField("topic", topic) + BagField("type", type) + BagField("md5sum", "0") + BagField("message_definition", ""));
}
// A message received at bag time (sec + 1, nsec): later than its header stamp, which the importer must keep.
std::string MessageRecord(std::uint32_t conn, std::uint32_t sec, std::uint32_t nsec, const std::string& data) {
  return BagRecord(Op(0x02) + BagField("conn", U32(conn)) + BagField("time", Stamp(sec + 1, nsec)), data);
}

std::string Imu(std::uint32_t seq, std::uint32_t sec, std::uint32_t nsec, double wz) {
  std::vector<double> cov(9, 0.0);
  cov[0] = cov[4] = cov[8] = 0.0004;  // gyro sigma 0.02 rad/s
  std::vector<double> cov_a(9, 0.0);
  cov_a[0] = cov_a[4] = cov_a[8] = 0.01;  // accel sigma 0.1 m/s^2
  return RosHeader(seq, sec, nsec, "imu_link") + Doubles({0, 0, 0, 1}) + Doubles(std::vector<double>(9, 0.0)) +
         Doubles({0.01, wz, -0.02}) + Doubles(cov) + Doubles({0.1, 9.81, 0.2}) + Doubles(cov_a);
}
std::string Odometry(std::uint32_t seq, std::uint32_t sec, std::uint32_t nsec, double vx, double wz) {
  std::vector<double> cov(36, 0.0);
  for (int i = 0; i < 6; ++i) cov[7 * i] = 0.001 * (i + 1);
  cov[5] = cov[30] = 1e-5;  // vx-wz correlation
  return RosHeader(seq, sec, nsec, "odom") + RosString("base_link") + Doubles({1, 2, 0, 0, 0, 0, 1}) +
         Doubles(std::vector<double>(36, 0.0)) + Doubles({vx, 0, 0, 0, 0, wz}) + Doubles(cov);
}
std::string Fix(std::uint32_t seq, std::uint32_t sec, std::uint32_t nsec, std::int8_t status, double lat) {
  std::vector<double> cov(9, 0.0);
  cov[0] = 0.64;
  cov[4] = 0.81;
  cov[8] = 2.0;
  cov[1] = cov[3] = 0.1;
  return RosHeader(seq, sec, nsec, "gps") + Raw(status) + Raw(std::uint16_t{1}) + Doubles({lat, 7.5, 100.0}) +
         Doubles(cov) + Raw(std::uint8_t{2});
}

// A bag: header record (padded as rosbag does), one chunk with three connections and the messages, an unsupported
// topic, one IMU message out of order and one repeated, and a fix without a fix.
std::string TinyBag(const std::string& compression) {
  std::string chunk = Connection(0, "/imu/data", "sensor_msgs/Imu") + Connection(1, "/odom", "nav_msgs/Odometry") +
                      Connection(2, "/fix", "sensor_msgs/NavSatFix") + Connection(3, "/rosout", "rosgraph_msgs/Log");
  chunk += MessageRecord(0, 100, 0, Imu(0, 100, 0, 0.5));
  chunk += MessageRecord(0, 100, 200000000, Imu(2, 100, 200000000, 0.7));
  chunk += MessageRecord(0, 100, 100000000, Imu(1, 100, 100000000, 0.6));  // late: sorted back
  chunk += MessageRecord(0, 100, 100000000, Imu(3, 100, 100000000, 0.6));  // repeated stamp: skipped
  chunk += MessageRecord(1, 100, 50000000, Odometry(0, 100, 50000000, 1.0, 0.1));
  chunk += MessageRecord(1, 100, 150000000, Odometry(1, 100, 150000000, 1.1, 0.2));
  chunk += MessageRecord(2, 100, 0, Fix(0, 100, 0, -1, 0.0));  // no fix: skipped
  chunk += MessageRecord(2, 100, 100000000, Fix(1, 100, 100000000, 0, 48.1));
  chunk += MessageRecord(2, 100, 300000000, Fix(2, 100, 300000000, 1, 48.2));
  chunk += MessageRecord(3, 100, 0, "log text");
  std::string data = chunk;
  if (compression == "bz2") {
    data.assign(chunk.size() + 1000, '\0');
    unsigned int size = static_cast<unsigned int>(data.size());
    EXPECT_EQ(
        BZ2_bzBuffToBuffCompress(data.data(), &size, chunk.data(), static_cast<unsigned int>(chunk.size()), 9, 0, 0),
        BZ_OK);
    data.resize(size);
  }
  const std::string chunk_record = BagRecord(
      Op(0x05) + BagField("compression", compression) + BagField("size", U32(static_cast<std::uint32_t>(chunk.size()))),
      data);
  const std::string header_fields = Op(0x03) + BagField("index_pos", Raw(std::uint64_t{0})) +
                                    BagField("conn_count", U32(4)) + BagField("chunk_count", U32(1));
  const std::string padding(4096 - header_fields.size() - 8, ' ');
  return std::string("#ROSBAG V2.0\n") + BagRecord(header_fields, padding) + chunk_record;
}

struct Imported {
  Result<Recording> rec = Status::Error("not run");
  RosbagImportReport report;
};

Imported Import(const std::string& bytes, const TempDir& dir, const RosbagImportOptions& options = {}) {
  const std::string path = dir.path() + "/tiny.bag";
  WriteFile(path, bytes);
  Imported out;
  out.rec = ImportRosbag(path, options, &out.report);
  return out;
}

class ImportRosbagTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ImportRosbagTest, TinyBagRoundTripsThroughTheRecordingFormat) {
  TempDir dir;
  RosbagImportOptions options;
  options.q_body_imu = Eigen::Quaterniond(std::sqrt(0.5), std::sqrt(0.5), 0.0, 0.0);
  options.platform.kind = "skid_steer";
  options.platform.geometry["track_m"] = 0.555;
  Imported in = Import(TinyBag(GetParam()), dir, options);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  const Recording& rec = in.rec.value();
  EXPECT_EQ(in.report.chunks, 1);
  EXPECT_EQ(in.report.messages.at("/rosout"), 1);
  EXPECT_EQ(in.report.skipped.at("/imu/data: repeated header stamp"), 1);
  EXPECT_EQ(in.report.skipped.at("/fix: no fix"), 1);

  // IMU: header stamps (not bag times), sorted; values in order; mounting and noise.
  const Stream* imu = rec.Find("imu");
  ASSERT_NE(imu, nullptr);
  ASSERT_EQ(imu->t.size(), 3u);
  EXPECT_EQ(imu->t[0].nanoseconds(), 100000000000);
  EXPECT_EQ(imu->t[1].nanoseconds(), 100100000000);
  EXPECT_DOUBLE_EQ(imu->values(1, 1), 0.6);
  EXPECT_DOUBLE_EQ(imu->values(2, 4), 9.81);
  EXPECT_NEAR(imu->info.rate_hz, 10.0, 1e-9);
  EXPECT_NEAR(imu->info.noise.at("gyro_sigma_radps"), 0.02, 1e-12);
  ASSERT_TRUE(imu->info.mounting.has_value());
  EXPECT_NEAR((imu->info.mounting->q_body_sensor * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 0.0,
              1e-12);

  // Odometry: the twist and its covariance's upper triangle.
  const Stream* odo = rec.Find("odometry");
  ASSERT_NE(odo, nullptr);
  ASSERT_EQ(odo->values.cols(), 27);
  EXPECT_DOUBLE_EQ(odo->values(1, 0), 1.1);
  EXPECT_DOUBLE_EQ(odo->values(1, 5), 0.2);
  EXPECT_DOUBLE_EQ(odo->values(0, 6), 0.001);   // cov_vx_vx
  EXPECT_DOUBLE_EQ(odo->values(0, 11), 1e-5);   // cov_vx_wz
  EXPECT_DOUBLE_EQ(odo->values(0, 26), 0.006);  // cov_wz_wz

  // GPS: the kept fixes, the ENU covariance, the origin at the first kept fix.
  const Stream* gps = rec.Find("gps");
  ASSERT_NE(gps, nullptr);
  ASSERT_EQ(gps->t.size(), 2u);
  EXPECT_DOUBLE_EQ(gps->values(1, 0), 48.2);
  EXPECT_DOUBLE_EQ(gps->values(0, 3), 0.64);
  EXPECT_DOUBLE_EQ(gps->values(0, 4), 0.1);
  EXPECT_DOUBLE_EQ(gps->values(0, 6), 0.81);
  EXPECT_DOUBLE_EQ(gps->values(0, 8), 2.0);
  ASSERT_TRUE(rec.origin.has_value());
  EXPECT_DOUBLE_EQ(rec.origin->latitude_deg, 48.1);

  // Written and read back unchanged.
  ASSERT_TRUE(WriteRecording(rec, dir.path() + "/rec").ok());
  Result<Recording> back = ReadRecording(dir.path() + "/rec");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back.value().platform.kind, "skid_steer");
  EXPECT_DOUBLE_EQ(back.value().platform.geometry.at("track_m"), 0.555);
  for (const Stream& s : rec.streams) {
    const Stream* b = back.value().Find(s.info.name);
    ASSERT_NE(b, nullptr) << s.info.name;
    EXPECT_EQ(b->info.columns, s.info.columns);
    EXPECT_EQ(b->t, s.t);
    EXPECT_TRUE(b->values.isApprox(s.values, 1e-15)) << s.info.name;
  }
  EXPECT_TRUE(back.value().Find("imu")->info.mounting->q_body_sensor.isApprox(*options.q_body_imu, 1e-15));
}

TEST(ImportRosbagWheelsTest, WheelAnglesInvertTheControllersKinematics) {
  TempDir dir;
  RosbagImportOptions options;
  options.platform.geometry = {{"wheel_radius_m", 0.1}, {"baseline_m", 0.5}};
  options.wheels_from_odometry = true;
  Imported in = Import(TinyBag("none"), dir, options);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  const Stream* wheels = in.rec.value().Find("wheels");
  ASSERT_NE(wheels, nullptr);
  EXPECT_EQ(wheels->info.columns, (std::vector<std::string>{"left", "right"}));
  // Twists (1.0, 0.1) then (1.1, 0.2) 0.1 s apart: wheel rates (9.75, 10.25) and (10.5, 11.5) rad/s, trapezoid.
  EXPECT_NEAR(wheels->values(1, 0), 0.05 * (9.75 + 10.5), 1e-12);
  EXPECT_NEAR(wheels->values(1, 1), 0.05 * (10.25 + 11.5), 1e-12);
  options.platform.geometry.erase("baseline_m");
  EXPECT_THAT(Import(TinyBag("none"), dir, options).rec.status().message(), HasSubstr("baseline_m"));
}

INSTANTIATE_TEST_SUITE_P(Compression, ImportRosbagTest, ::testing::Values("none", "bz2"));

TEST(ImportRosbagErrorTest, TruncatedFileNamesTheFileAndTheProblem) {
  TempDir dir;
  const std::string bag = TinyBag("none");
  for (std::size_t cut : {bag.size() - 3, bag.size() - 200, std::size_t{4100}}) {
    Imported in = Import(bag.substr(0, cut), dir);
    ASSERT_FALSE(in.rec.ok()) << cut;
    EXPECT_THAT(in.rec.status().message(), HasSubstr("tiny.bag: "));
    EXPECT_THAT(in.rec.status().message(), HasSubstr("truncated"));
    EXPECT_EQ(in.rec.status().message().find('\n'), std::string::npos);
  }
}

TEST(ImportRosbagErrorTest, RefusesLz4ChunksOtherVersionsAndOtherFiles) {
  TempDir dir;
  // An unsupported compression name of the same length as "none", so the record stays well-formed.
  std::string lz4 = TinyBag("none");
  const std::string none = BagField("compression", "none");
  const std::size_t at = lz4.find(none);
  ASSERT_NE(at, std::string::npos);
  lz4.replace(at, none.size(), BagField("compression", "lz44"));
  EXPECT_THAT(Import(lz4, dir).rec.status().message(), HasSubstr("compressed with 'lz44'"));
  EXPECT_THAT(Import("#ROSBAG V1.2\nxxxx", dir).rec.status().message(), HasSubstr("unsupported bag version '1.2'"));
  EXPECT_THAT(Import("hello", dir).rec.status().message(), HasSubstr("not a ROS bag"));
}

// The real Husky bag (data/husky_test1 of the shared data directory): counts, span and rates.
TEST(ImportRosbagRealTest, HuskyTest1) {
  const std::string path = std::string(ROAMLAB_SHARED_DIR) + "/data/husky_test1/test1.bag";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "real data absent: " << path;
  RosbagImportReport report;
  Result<Recording> rec = ImportRosbag(path, {}, &report);
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  EXPECT_EQ(report.messages.at("/imu/data"), 11865);
  EXPECT_EQ(report.messages.at("/husky_velocity_controller/odom"), 3952);
  EXPECT_EQ(report.messages.at("/fix"), 989);
  // stream -> (topic, rate)
  const std::map<std::string, std::pair<std::string, double>> streams = {
      {"imu", {"/imu/data", 30.0}}, {"odometry", {"/husky_velocity_controller/odom", 10.0}}, {"gps", {"/fix", 2.5}}};
  for (const auto& [name, topic_rate] : streams) {
    const auto& [topic, rate] = topic_rate;
    const Stream* s = rec.value().Find(name);
    ASSERT_NE(s, nullptr) << name;
    int skipped = 0;
    for (const auto& [what, n] : report.skipped)
      if (what.rfind(topic + ":", 0) == 0) skipped += n;
    EXPECT_EQ(static_cast<int>(s->t.size()) + skipped, report.messages.at(topic)) << name;
    EXPECT_NEAR(SecondsBetween(s->t.front(), s->t.back()), 395.0, 2.0) << name;
    EXPECT_NEAR(s->info.rate_hz, rate, 0.02 * rate) << name;
  }
}

}  // namespace
}  // namespace roamlab::importers
