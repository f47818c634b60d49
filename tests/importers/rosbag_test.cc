#include "importers/rosbag.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"
#include "tests/support/bag_writers.h"
#include "tests/support/message_writer.h"
#include "tests/support/real_data.h"

namespace roamlab::importers {
namespace {

using ::roamlab::importers::testing::BagField;
using ::roamlab::importers::testing::BagOf;
using ::roamlab::importers::testing::Connection;
using ::roamlab::importers::testing::MessageRecord;
using ::roamlab::importers::testing::Wire;
using ::roamlab::recording::ReadRecording;
using ::roamlab::recording::Recording;
using ::roamlab::recording::Stream;
using ::roamlab::recording::StreamType;
using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::Contains;
using ::testing::HasSubstr;

constexpr Wire kRos1 = Wire::kRos1;

// Three connections and an unsupported topic, one IMU message out of order and one repeated, and a fix without a fix.
std::string TinyChunk() {
  std::string chunk = Connection(0, "/imu/data", "sensor_msgs/Imu") + Connection(1, "/odom", "nav_msgs/Odometry") +
                      Connection(2, "/fix", "sensor_msgs/NavSatFix") + Connection(3, "/rosout", "rosgraph_msgs/Log");
  const std::vector<double> q = {0, 0, 0, 1};
  chunk += MessageRecord(0, 100, 0, testing::ImuMessage(kRos1, 100, 0, 0.5));
  chunk += MessageRecord(0, 100, 200000000, testing::ImuMessage(kRos1, 100, 200000000, 0.7));
  chunk += MessageRecord(0, 100, 100000000, testing::ImuMessage(kRos1, 100, 100000000, 0.6));  // late: sorted back
  chunk += MessageRecord(0, 100, 100000000, testing::ImuMessage(kRos1, 100, 100000000, 0.6));  // repeated: skipped
  chunk += MessageRecord(1, 100, 50000000,
                         testing::OdometryMessage(kRos1, 100, 50000000, "odom", "base_link", q, 1.0, 0.0, 0.1));
  chunk += MessageRecord(1, 100, 150000000,
                         testing::OdometryMessage(kRos1, 100, 150000000, "odom", "base_link", q, 1.1, 0.0, 0.2));
  chunk += MessageRecord(2, 100, 0, testing::FixMessage(kRos1, 100, 0, -1, 0.0));  // no fix: skipped
  chunk += MessageRecord(2, 100, 100000000, testing::FixMessage(kRos1, 100, 100000000, 0, 48.1));
  chunk += MessageRecord(2, 100, 300000000, testing::FixMessage(kRos1, 100, 300000000, 1, 48.2));
  chunk += MessageRecord(3, 100, 0, "log text");
  return chunk;
}
std::string TinyBag(const std::string& compression) { return BagOf(TinyChunk(), compression); }

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
  EXPECT_EQ(in.report.format, "ROS 1 bag v2.0");
  ASSERT_NE(in.report.Find("/rosout"), nullptr);
  EXPECT_EQ(in.report.Find("/rosout")->messages, 1);
  EXPECT_TRUE(in.report.Find("/rosout")->streams.empty());
  EXPECT_EQ(in.report.Find("/imu/data")->skipped.at("repeated header stamp"), 1);
  EXPECT_EQ(in.report.Find("/imu/data")->stamps_back, 1);
  EXPECT_EQ(in.report.Find("/fix")->skipped.at("no fix"), 1);
  EXPECT_EQ(in.report.Find("/odom")->streams, (std::vector<std::string>{"odom", "odom_pose"}));

  // IMU: header stamps (not bag times), sorted; values in order; mounting and noise.
  const Stream* imu = rec.Find("imu_data");
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

  // Odometry: the twist and its covariance's upper triangle; the pose beside it.
  const Stream* odo = rec.Find("odom");
  ASSERT_NE(odo, nullptr);
  ASSERT_EQ(odo->values.cols(), 27);
  EXPECT_DOUBLE_EQ(odo->values(1, 0), 1.1);
  EXPECT_DOUBLE_EQ(odo->values(1, 5), 0.2);
  EXPECT_DOUBLE_EQ(odo->values(0, 6), 0.001);   // cov_vx_vx
  EXPECT_DOUBLE_EQ(odo->values(0, 11), 1e-5);   // cov_vx_wz
  EXPECT_DOUBLE_EQ(odo->values(0, 26), 0.006);  // cov_wz_wz
  const Stream* pose = rec.Find("odom_pose");
  ASSERT_NE(pose, nullptr);
  EXPECT_EQ(pose->info.type, StreamType::kPose);
  EXPECT_EQ(pose->values.row(0), (Eigen::RowVectorXd(7) << 1, 2, 0, 0, 0, 0, 1).finished());

  // GPS: the kept fixes, the ENU covariance, the origin at the first kept fix.
  const Stream* gps = rec.Find("fix");
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
  EXPECT_TRUE(back.value().Find("imu_data")->info.mounting->q_body_sensor.isApprox(*options.q_body_imu, 1e-15));
}

INSTANTIATE_TEST_SUITE_P(Compression, ImportRosbagTest, ::testing::Values("none", "bz2", "lz4"));

// Receive times 1 s after the header stamps: the clock offset, its sign and size, in the report and a warning.
TEST(ImportRosbagChecksTest, ClockOffsetIsReportedWithItsSign) {
  TempDir dir;
  Imported in = Import(TinyBag("none"), dir);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  EXPECT_NEAR(in.report.Find("/imu/data")->clock_offset_s, -1.0, 1e-9);
  EXPECT_THAT(in.report.warnings,
              Contains("/imu/data (imu_data): header stamps are 1000 ms earlier than the bag's receive times"));
  EXPECT_THAT(
      in.report.warnings,
      Contains("/imu/data (imu_data): 1 header stamps jump back from the previous message's (sorted by stamp)"));
}

// A fix whose latitude or longitude is not an angle on the Earth (a corrupted message) is skipped and counted; the
// others are kept and the origin is the first valid one.
TEST(ImportRosbagChecksTest, FixOutsideTheEarthsAnglesIsSkippedAndCounted) {
  TempDir dir;
  std::string chunk = Connection(0, "/fix", "sensor_msgs/NavSatFix");
  chunk += MessageRecord(0, 100, 0, testing::FixMessage(kRos1, 100, 0, 0, 400.0));
  chunk += MessageRecord(0, 100, 100000000, testing::FixMessage(kRos1, 100, 100000000, 0, 48.1));
  chunk += MessageRecord(0, 100, 200000000, testing::FixMessage(kRos1, 100, 200000000, 0, -90.5));
  chunk += MessageRecord(0, 100, 300000000, testing::FixMessage(kRos1, 100, 300000000, 0, 48.2));
  Imported in = Import(BagOf(chunk, "none"), dir);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  EXPECT_EQ(in.report.Find("/fix")->skipped.at("latitude or longitude outside the Earth's range"), 2);
  const Stream* gps = in.rec.value().Find("fix");
  ASSERT_NE(gps, nullptr);
  ASSERT_EQ(gps->t.size(), 2u);
  EXPECT_DOUBLE_EQ(gps->values(0, 0), 48.1);
}

// Progress: the fraction of the selected topics' messages decoded, every kProgressMessages messages and at the end;
// here 2500 IMU messages (the /rosout log is not a selected topic) and one odometry message.
TEST(ImportRosbagProgressTest, ReportsTheFractionOfMessagesDecoded) {
  std::string chunk = Connection(0, "/imu", "sensor_msgs/Imu") + Connection(1, "/odom", "nav_msgs/Odometry") +
                      Connection(2, "/rosout", "rosgraph_msgs/Log");
  const int imu = 2500;
  for (int k = 0; k < imu; ++k) {
    const std::uint32_t sec = 100 + static_cast<std::uint32_t>(k / 100), nsec = 10000000u * (k % 100);
    chunk += MessageRecord(0, sec, nsec, testing::ImuMessage(kRos1, sec, nsec, 0.001 * k));
    chunk += MessageRecord(2, sec, nsec, "log text");
  }
  chunk += MessageRecord(1, 100, 0,
                         testing::OdometryMessage(kRos1, 100, 0, "odom", "base_link", {0, 0, 0, 1}, 1.0, 0.0, 0.1));
  std::vector<double> fractions;
  RosbagImportOptions options;
  options.progress = [&fractions](double fraction) { fractions.push_back(fraction); };
  TempDir dir;
  Imported in = Import(BagOf(chunk, "none"), dir, options);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  const double total = imu + 1;
  EXPECT_THAT(fractions, ::testing::ElementsAre(::testing::DoubleEq(1024 / total), ::testing::DoubleEq(2048 / total),
                                                ::testing::DoubleEq(1.0)));
}

// An odometry twist in the parent frame (empty child_frame_id), heading 90 deg: rotated into the body frame, so the
// parent's vy is the body's vx (and the variances swap); the same twist in the child frame is kept.
TEST(ImportRosbagOdometryTest, ParentFrameTwistIsRotatedIntoTheBodyFrame) {
  TempDir dir;
  const std::vector<double> heading_90 = {0, 0, std::sqrt(0.5), std::sqrt(0.5)};
  std::string chunk = Connection(0, "/parent", "nav_msgs/Odometry") + Connection(1, "/child", "nav_msgs/Odometry");
  for (std::uint32_t k = 0; k < 3; ++k) {
    const std::uint32_t nsec = 100000000 * k;
    chunk += MessageRecord(0, 10, nsec, testing::OdometryMessage(kRos1, 10, nsec, "odom", "", heading_90, 0, 1, 0.5));
    chunk += MessageRecord(1, 10, nsec,
                           testing::OdometryMessage(kRos1, 10, nsec, "odom", "base_link", heading_90, 0, 1, 0.5));
  }
  Imported in = Import(BagOf(chunk), dir);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  const Stream* parent = in.rec.value().Find("parent");
  ASSERT_NE(parent, nullptr);
  EXPECT_NEAR(parent->values(0, 0), 1.0, 1e-12);     // vx <- parent vy
  EXPECT_NEAR(parent->values(0, 1), 0.0, 1e-12);     // vy
  EXPECT_NEAR(parent->values(0, 5), 0.5, 1e-12);     // wz about the same vertical
  EXPECT_NEAR(parent->values(0, 6), 0.002, 1e-15);   // cov_vx_vx <- parent cov_vy_vy
  EXPECT_NEAR(parent->values(0, 12), 0.001, 1e-15);  // cov_vy_vy <- parent cov_vx_vx
  const Stream* child = in.rec.value().Find("child");
  ASSERT_NE(child, nullptr);
  EXPECT_EQ(child->values(0, 0), 0.0);
  EXPECT_EQ(child->values(0, 1), 1.0);
  EXPECT_EQ(child->values(0, 6), 0.001);

  // Neither frame named, or a parent-frame twist without a usable orientation: refused, naming topic and message.
  chunk = Connection(0, "/odom", "nav_msgs/Odometry");
  chunk += MessageRecord(0, 10, 0, testing::OdometryMessage(kRos1, 10, 0, "odom", "", heading_90, 0, 1, 0));
  chunk += MessageRecord(0, 11, 0, testing::OdometryMessage(kRos1, 11, 0, "", "", heading_90, 0, 1, 0));
  in = Import(BagOf(chunk), dir);
  ASSERT_FALSE(in.rec.ok());
  EXPECT_THAT(in.rec.status().message(),
              HasSubstr("tiny.bag: /odom message 1 (counting from 0): neither child_frame_id nor header.frame_id"));
  chunk = Connection(0, "/odom", "nav_msgs/Odometry");
  chunk += MessageRecord(0, 10, 0, testing::OdometryMessage(kRos1, 10, 0, "odom", "", {0, 0, 0, 0}, 0, 1, 0));
  in = Import(BagOf(chunk), dir);
  ASSERT_FALSE(in.rec.ok());
  EXPECT_THAT(in.rec.status().message(), HasSubstr("/odom message 0 (counting from 0): child_frame_id is empty"));
}

// Every other type from a ROS 1 bag, three messages each (the second TwistStamped 20 s late: a gap).
std::string AllTypesBag() {
  std::string chunk =
      Connection(0, "/mag", "sensor_msgs/MagneticField") + Connection(1, "/joints", "sensor_msgs/JointState") +
      Connection(2, "/scan", "sensor_msgs/LaserScan") + Connection(3, "/mono", "sensor_msgs/Image") +
      Connection(4, "/color", "sensor_msgs/Image") + Connection(5, "/jpeg", "sensor_msgs/CompressedImage") +
      Connection(6, "/cmd", "geometry_msgs/TwistStamped") + Connection(7, "/pose", "geometry_msgs/PoseStamped") +
      Connection(8, "/amcl", "geometry_msgs/PoseWithCovarianceStamped");
  for (std::uint32_t k = 0; k < 3; ++k) {
    const std::uint32_t s = 10 + k, late = 10 + 20 * k;
    chunk += MessageRecord(0, s, 0, testing::MagneticFieldMessage(kRos1, s, 0, 1e-5 * (k + 1)));
    chunk += MessageRecord(1, s, 0, testing::JointStateMessage(kRos1, s, 0, 0.5 * k, -1.0 * k));
    chunk += MessageRecord(2, s, 0, testing::LaserScanMessage(kRos1, s, 0, 1.0f + static_cast<float>(k)));
    chunk += MessageRecord(3, s, 0, testing::ImageMessage(kRos1, s, 0, "mono8", static_cast<char>(10 * k)));
    chunk += MessageRecord(4, s, 0, testing::ImageMessage(kRos1, s, 0, "bgr8", static_cast<char>(10 * k)));
    chunk +=
        MessageRecord(5, s, 0, testing::CompressedImageMessage(kRos1, s, 0, "\xff\xd8\xff" + std::string(1 + k, 'j')));
    chunk += MessageRecord(6, late, 0, testing::TwistStampedMessage(kRos1, late, 0, 0.0, 0.0));
    chunk += MessageRecord(7, s, 0, testing::PoseStampedMessage(kRos1, s, 0, 1.0 * k));
    chunk += MessageRecord(8, s, 0, testing::PoseWithCovarianceMessage(kRos1, s, 0, 2.0 * k));
  }
  return BagOf(chunk);
}

TEST(ImportRosbagTypesTest, EveryTypeFromARos1Bag) {
  TempDir dir;
  RosbagImportOptions options;
  options.joints = {"right_wheel", "left_wheel"};
  options.platform.kind = "unknown";
  Imported in = Import(AllTypesBag(), dir, options);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  const Recording& rec = in.rec.value();
  const Stream* mag = rec.Find("mag");
  ASSERT_NE(mag, nullptr);
  EXPECT_EQ(mag->info.units, "uT");
  EXPECT_NEAR(mag->values(2, 0), 30.0, 1e-9);
  EXPECT_NEAR(mag->values(0, 2), 40.0, 1e-9);
  const Stream* joints = rec.Find("joints");
  ASSERT_NE(joints, nullptr);
  EXPECT_EQ(joints->info.type, StreamType::kWheelEncoders);
  EXPECT_EQ(joints->info.columns, (std::vector<std::string>{"right_wheel", "left_wheel"}));
  EXPECT_EQ(joints->info.units, "rad");
  EXPECT_EQ(joints->values.row(2), Eigen::RowVector2d(2.0, 1.0));
  const Stream* scan = rec.Find("scan");
  ASSERT_NE(scan, nullptr);
  EXPECT_EQ(scan->info.columns, recording::LaserScanColumns(3));
  EXPECT_EQ(scan->values.row(1), (Eigen::RowVectorXd(7) << -0.5, 0.5, 0.1f, 10.0, 2.0, -1.0, 3.0).finished());
  const Stream* cmd = rec.Find("cmd");
  ASSERT_NE(cmd, nullptr);
  EXPECT_EQ(cmd->info.type, StreamType::kOdometry);
  EXPECT_TRUE(in.report.Find("/cmd")->all_zero);
  EXPECT_THAT(in.report.warnings, Contains("/cmd (cmd): all values are zero"));
  EXPECT_EQ(in.report.Find("/cmd")->gaps, 2);
  EXPECT_THAT(in.report.warnings,
              Contains("/cmd (cmd): 2 gaps of more than 10 s between header stamps (largest 20 s)"));
  EXPECT_FALSE(in.report.Find("/pose")->all_zero);
  EXPECT_FALSE(in.report.Find("/pose")->constant);
  const Stream* pose = rec.Find("pose");
  ASSERT_NE(pose, nullptr);
  EXPECT_EQ(pose->values.row(2), (Eigen::RowVectorXd(7) << 2, 2, 3, 0, 0, 0.6, 0.8).finished());
  const Stream* amcl = rec.Find("amcl");
  ASSERT_NE(amcl, nullptr);
  EXPECT_DOUBLE_EQ(amcl->values(1, 0), 2.0);
  EXPECT_DOUBLE_EQ(amcl->info.noise.at("sigma_m"), 0.5);

  // Camera streams: one file per frame; PGM / PPM (bgr swapped to rgb, row padding dropped), JPEG bytes as given.
  const Stream* mono = rec.Find("mono");
  ASSERT_NE(mono, nullptr);
  EXPECT_EQ(mono->info.type, StreamType::kCamera);
  EXPECT_EQ(mono->text, (std::vector<std::string>{"mono/000000.pgm", "mono/000001.pgm", "mono/000002.pgm"}));
  ASSERT_EQ(in.report.frames.size(), 9u);
  const auto frame = [&](const std::string& file) {
    for (const CameraFrame& f : in.report.frames)
      if (f.file == file) return f.bytes;
    return std::string("missing");
  };
  EXPECT_EQ(frame("mono/000001.pgm"), std::string("P5\n2 2\n255\n") + "\x0a\x0b\x0d\x0e");
  EXPECT_EQ(frame("color/000000.ppm"),
            std::string("P6\n2 2\n255\n") + std::string("\x02\x01\x00\x05\x04\x03", 6) + "\x09\x08\x07\x0c\x0b\x0a");
  EXPECT_EQ(frame("jpeg/000002.jpg"), "\xff\xd8\xffjjj");
  const Status written = WriteRecording(rec, dir.path() + "/rec");
  ASSERT_TRUE(written.ok()) << written.message();
  ASSERT_TRUE(WriteCameraFrames(in.report.frames, dir.path() + "/rec").ok());
  Result<Recording> back = ReadRecording(dir.path() + "/rec");
  ASSERT_TRUE(back.ok()) << back.status().message();
  std::ifstream file(dir.path() + "/rec/" + back.value().Find("jpeg")->text[1], std::ios::binary);
  std::stringstream bytes;
  bytes << file.rdbuf();
  EXPECT_EQ(bytes.str(), "\xff\xd8\xffjj");
}

// Every type as ROS 2 stores it (CDR, little-endian), three messages each: the topics and the messages of a bag.
struct Ros2Bag {
  std::vector<testing::Db3Topic> topics;
  std::vector<testing::Db3Message> messages;
};
Ros2Bag AllTypesRos2() {
  Ros2Bag bag;
  bag.topics = {{"/imu", "sensor_msgs/msg/Imu"},
                {"/fix", "sensor_msgs/msg/NavSatFix"},
                {"/mag", "sensor_msgs/msg/MagneticField"},
                {"/joints", "sensor_msgs/msg/JointState"},
                {"/scan", "sensor_msgs/msg/LaserScan"},
                {"/mono", "sensor_msgs/msg/Image"},
                {"/jpeg", "sensor_msgs/msg/CompressedImage"},
                {"/odom", "nav_msgs/msg/Odometry"},
                {"/cmd", "geometry_msgs/msg/TwistStamped"},
                {"/pose", "geometry_msgs/msg/PoseStamped"},
                {"/amcl", "geometry_msgs/msg/PoseWithCovarianceStamped"}};
  const Wire cdr = Wire::kCdrLittle;
  for (std::int32_t k = 0; k < 3; ++k) {
    const std::int32_t s = 10 + k;
    const std::int64_t t_ns = 1000000000LL * (s + 1);  // received a second after the header stamp
    const std::vector<std::string> data = {
        testing::ImuMessage(cdr, s, 0, 0.5 + k),
        testing::FixMessage(cdr, s, 0, 0, 48.1 + 0.001 * k),
        testing::MagneticFieldMessage(cdr, s, 0, 1e-5 * (k + 1)),
        testing::JointStateMessage(cdr, s, 0, 0.5 * k, -1.0 * k),
        testing::LaserScanMessage(cdr, s, 0, 1.0f + static_cast<float>(k)),
        testing::ImageMessage(cdr, s, 0, "mono8", static_cast<char>(10 * k)),
        testing::CompressedImageMessage(cdr, s, 0, "\xff\xd8\xff" + std::string(1 + static_cast<std::size_t>(k), 'j')),
        testing::OdometryMessage(cdr, s, 0, "odom", "base_link", {0, 0, 0, 1}, 1.0 + k, 0.0, 0.1),
        testing::TwistStampedMessage(cdr, s, 0, 0.3 * (k + 1), 0.2),
        testing::PoseStampedMessage(cdr, s, 0, 1.0 * k),
        testing::PoseWithCovarianceMessage(cdr, s, 0, 2.0 * k)};
    for (std::size_t i = 0; i < data.size(); ++i) bag.messages.push_back({static_cast<int>(i), t_ns, data[i]});
  }
  return bag;
}

// Writes the bag as a rosbag2 SQLite directory ("sqlite") or an MCAP file with one zstd chunk ("mcap"); its path.
std::string WriteRos2Bag(const Ros2Bag& bag, const std::string& container, const TempDir& dir) {
  if (container == "sqlite") {
    const std::string bag_dir = dir.path() + "/bag2";
    std::filesystem::create_directories(bag_dir);
    EXPECT_TRUE(testing::WriteDb3(bag_dir + "/bag2_0.db3", bag.topics, bag.messages).ok());
    WriteFile(bag_dir + "/metadata.yaml", testing::Rosbag2Metadata("sqlite3", "bag2_0.db3"));
    return bag_dir;
  }
  std::string records;
  for (std::size_t i = 0; i < bag.topics.size(); ++i) {
    const auto id = static_cast<std::uint16_t>(i + 1);
    records += testing::McapSchema(id, bag.topics[i].type) + testing::McapChannel(id, id, bag.topics[i].name);
  }
  for (const testing::Db3Message& m : bag.messages) {
    records += testing::McapMessage(static_cast<std::uint16_t>(m.topic + 1), static_cast<std::uint64_t>(m.timestamp_ns),
                                    m.data);
  }
  const std::string path = dir.path() + "/bag.mcap";
  WriteFile(path, testing::kMcapMagic + testing::McapHeader() + testing::McapZstdChunk(records) + testing::McapEnd());
  return path;
}

class ImportRos2TypesTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ImportRos2TypesTest, EveryTypeFromARos2Bag) {
  TempDir dir;
  RosbagImportOptions options;
  options.joints = {"right_wheel", "left_wheel"};
  RosbagImportReport report;
  Result<Recording> imported = ImportRosbag(WriteRos2Bag(AllTypesRos2(), GetParam(), dir), options, &report);
  ASSERT_TRUE(imported.ok()) << imported.status().message();
  const Recording& rec = imported.value();
  const auto stream = [&](const std::string& name, StreamType type) {
    const Stream* s = rec.Find(name);
    EXPECT_NE(s, nullptr) << name;
    if (s) {
      EXPECT_EQ(s->info.type, type) << name;
    }
    return s;
  };
  const Stream* imu = stream("imu", StreamType::kImu);
  ASSERT_NE(imu, nullptr);
  EXPECT_EQ(imu->values.row(2), (Eigen::RowVectorXd(6) << 0.01, 2.5, -0.02, 0.1, 9.81, 0.2).finished());
  EXPECT_EQ(imu->t[0], Time::FromNanoseconds(10000000000LL));  // the header stamp, not the receive time
  const Stream* fix = stream("fix", StreamType::kGps);
  ASSERT_NE(fix, nullptr);
  EXPECT_DOUBLE_EQ(fix->values(1, 0), 48.101);
  const Stream* mag = stream("mag", StreamType::kMagnetometer);
  ASSERT_NE(mag, nullptr);
  EXPECT_NEAR(mag->values(2, 0), 30.0, 1e-9);
  const Stream* joints = stream("joints", StreamType::kWheelEncoders);
  ASSERT_NE(joints, nullptr);
  EXPECT_EQ(joints->values.row(2), Eigen::RowVector2d(2.0, 1.0));
  const Stream* scan = stream("scan", StreamType::kLaserScan);
  ASSERT_NE(scan, nullptr);
  EXPECT_EQ(scan->values.row(1), (Eigen::RowVectorXd(7) << -0.5, 0.5, 0.1f, 10.0, 2.0, -1.0, 3.0).finished());
  const Stream* mono = stream("mono", StreamType::kCamera);
  ASSERT_NE(mono, nullptr);
  EXPECT_EQ(mono->text.size(), 3u);
  const Stream* jpeg = stream("jpeg", StreamType::kCamera);
  ASSERT_NE(jpeg, nullptr);
  EXPECT_EQ(jpeg->text.size(), 3u);
  const Stream* odom = stream("odom", StreamType::kOdometry);
  ASSERT_NE(odom, nullptr);
  EXPECT_DOUBLE_EQ(odom->values(2, 0), 3.0);
  EXPECT_DOUBLE_EQ(odom->values(2, 5), 0.1);
  const Stream* odom_pose = stream("odom_pose", StreamType::kPose);
  ASSERT_NE(odom_pose, nullptr);
  EXPECT_DOUBLE_EQ(odom_pose->values(0, 1), 2.0);
  const Stream* cmd = stream("cmd", StreamType::kOdometry);
  ASSERT_NE(cmd, nullptr);
  EXPECT_DOUBLE_EQ(cmd->values(1, 0), 0.6);
  const Stream* pose = stream("pose", StreamType::kPose);
  ASSERT_NE(pose, nullptr);
  EXPECT_EQ(pose->values.row(2), (Eigen::RowVectorXd(7) << 2, 2, 3, 0, 0, 0.6, 0.8).finished());
  const Stream* amcl = stream("amcl", StreamType::kPose);
  ASSERT_NE(amcl, nullptr);
  EXPECT_DOUBLE_EQ(amcl->values(1, 0), 2.0);
  EXPECT_DOUBLE_EQ(amcl->info.noise.at("sigma_m"), 0.5);
  // The receive times are a second after the header stamps: a clock offset, reported with its sign.
  ASSERT_NE(report.Find("/imu"), nullptr);
  EXPECT_NEAR(report.Find("/imu")->clock_offset_s, -1.0, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Containers, ImportRos2TypesTest, ::testing::Values("sqlite", "mcap"));

TEST(ImportRosbagTopicsTest, TopicSelectsAndNamesStreams) {
  TempDir dir;
  RosbagImportOptions options;
  options.topics = {{"/fix", "gps"}, {"/imu/data", "imu"}};
  Imported in = Import(TinyBag("none"), dir, options);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  ASSERT_EQ(in.rec.value().streams.size(), 2u);
  EXPECT_NE(in.rec.value().Find("gps"), nullptr);
  EXPECT_NE(in.rec.value().Find("imu"), nullptr);
  EXPECT_TRUE(in.report.Find("/odom")->streams.empty());
  options.topics = {{"/nowhere", "x"}};
  EXPECT_THAT(Import(TinyBag("none"), dir, options).rec.status().message(),
              HasSubstr("tiny.bag: no topic '/nowhere' in the bag"));
  options.topics = {{"/rosout", "log"}};
  EXPECT_THAT(Import(TinyBag("none"), dir, options).rec.status().message(),
              HasSubstr("topic /rosout has type rosgraph_msgs/Log, which is not imported"));
  options.topics = {{"/fix", "gps"}, {"/fix", "gps2"}};
  EXPECT_THAT(Import(TinyBag("none"), dir, options).rec.status().message(), HasSubstr("topic /fix is selected twice"));
  options.topics = {{"/fix", "bad name"}};
  EXPECT_THAT(Import(TinyBag("none"), dir, options).rec.status().message(), HasSubstr("is not [A-Za-z0-9_]+"));
}

TEST(ImportRosbagListTest, ListsEveryTopicWithTypeCountRateAndSpan) {
  TempDir dir;
  const std::string path = dir.path() + "/tiny.bag";
  WriteFile(path, TinyBag("bz2"));
  Result<std::vector<RosbagTopicListing>> rows = ListRosbag(path);
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows.value().size(), 4u);
  const RosbagTopicListing& imu = rows.value()[0];
  EXPECT_EQ(imu.topic, "/imu/data");
  EXPECT_EQ(imu.type, "sensor_msgs/Imu");
  EXPECT_TRUE(imu.supported);
  EXPECT_EQ(imu.messages, 4);
  EXPECT_EQ(imu.first.nanoseconds(), 101000000000);
  EXPECT_EQ(imu.last.nanoseconds(), 101200000000);
  EXPECT_NEAR(imu.rate_hz, 15.0, 1e-9);
  EXPECT_EQ(rows.value()[3].topic, "/rosout");
  EXPECT_FALSE(rows.value()[3].supported);
  EXPECT_EQ(rows.value()[3].rate_hz, 0.0);
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
  EXPECT_EQ(wheels->info.attributes.at("wheel_separation_m"), 0.5);
  // A skid steer's controller divides by its effective separation, here 1.0 m: the rate differences double.
  options.odometry_wheel_separation_m = 1.0;
  Imported skid = Import(TinyBag("none"), dir, options);
  ASSERT_TRUE(skid.rec.ok()) << skid.rec.status().message();
  const Stream* effective = skid.rec.value().Find("wheels");
  EXPECT_NEAR(effective->values(1, 0), 0.05 * (9.5 + 10.0), 1e-12);
  EXPECT_NEAR(effective->values(1, 1), 0.05 * (10.5 + 12.0), 1e-12);
  EXPECT_EQ(effective->info.attributes.at("wheel_separation_m"), 1.0);
  options.odometry_wheel_separation_m = -1.0;
  EXPECT_THAT(Import(TinyBag("none"), dir, options).rec.status().message(),
              HasSubstr("wheel separation must be a positive number"));
  options.odometry_wheel_separation_m.reset();
  options.platform.geometry.erase("baseline_m");
  EXPECT_THAT(Import(TinyBag("none"), dir, options).rec.status().message(), HasSubstr("baseline_m"));
}

TEST(ImportRosbagWheelsTest, OdometryTopicChoosesAmongSeveral) {
  TempDir dir;
  std::string chunk = TinyChunk() + Connection(4, "/cmd", "geometry_msgs/TwistStamped");
  chunk += MessageRecord(4, 100, 0, testing::TwistStampedMessage(kRos1, 100, 0, 2.0, 0.0));
  chunk += MessageRecord(4, 100, 500000000, testing::TwistStampedMessage(kRos1, 100, 500000000, 2.0, 0.0));
  RosbagImportOptions options;
  options.platform.geometry = {{"wheel_radius_m", 0.1}, {"baseline_m", 0.5}};
  options.wheels_from_odometry = true;
  EXPECT_THAT(Import(BagOf(chunk), dir, options).rec.status().message(),
              HasSubstr("several odometry topics (/cmd, /odom); choose one with --odometry-topic"));
  options.odometry_topic = "/cmd";
  Imported in = Import(BagOf(chunk), dir, options);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  EXPECT_NEAR(in.rec.value().Find("wheels")->values(1, 0), 0.5 * 2.0 / 0.1, 1e-12);
  options.odometry_topic = "/fix";
  EXPECT_THAT(Import(BagOf(chunk), dir, options).rec.status().message(),
              HasSubstr("--odometry-topic /fix is no imported odometry"));
}

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

// A message shorter than its fields, or with a count past its record, is refused naming the topic and its index.
TEST(ImportRosbagErrorTest, ShortMessagesAndLongCountsNameTopicAndIndex) {
  TempDir dir;
  std::string chunk =
      Connection(0, "/imu/data", "sensor_msgs/Imu") + Connection(1, "/joints", "sensor_msgs/JointState");
  chunk += MessageRecord(0, 10, 0, testing::ImuMessage(kRos1, 10, 0, 0.1));
  chunk += MessageRecord(0, 11, 0, testing::ImuMessage(kRos1, 11, 0, 0.1));
  const std::string imu = testing::ImuMessage(kRos1, 12, 0, 0.1);
  Imported in = Import(BagOf(chunk + MessageRecord(0, 12, 0, imu.substr(0, imu.size() - 1))), dir);
  ASSERT_FALSE(in.rec.ok());
  EXPECT_EQ(in.rec.status().message(), dir.path() +
                                           "/tiny.bag: /imu/data message 2 (counting from 0): the message ends before "
                                           "its last field");
  testing::MessageWriter joints(kRos1);
  joints.Header(12, 0, "").Count(2).String("left").String("right").Count(2).Doubles({1, 2}).Count(70000).Count(0);
  in = Import(BagOf(chunk + MessageRecord(1, 12, 0, joints.bytes())), dir);
  ASSERT_FALSE(in.rec.ok());
  EXPECT_THAT(in.rec.status().message(),
              HasSubstr("/joints message 0 (counting from 0): a sequence of 70000 velocities runs past the message"));
}

TEST(ImportRosbagErrorTest, RefusesOtherCompressionsVersionsFilesAndDirectories) {
  TempDir dir;
  // An unsupported compression name of the same length as "none", so the record stays well-formed.
  std::string other = TinyBag("none");
  const std::string none = BagField("compression", "none");
  const std::size_t at = other.find(none);
  ASSERT_NE(at, std::string::npos);
  other.replace(at, none.size(), BagField("compression", "zstd"));
  EXPECT_THAT(Import(other, dir).rec.status().message(), HasSubstr("compressed with 'zstd'"));
  EXPECT_THAT(Import("#ROSBAG V1.2\nxxxx", dir).rec.status().message(), HasSubstr("unsupported bag version '1.2'"));
  EXPECT_THAT(Import("hello", dir).rec.status().message(), HasSubstr("not a bag"));
  // A directory that is no rosbag2 bag: one line, no exception.
  Result<Recording> rec = ImportRosbag(dir.path(), {});
  ASSERT_FALSE(rec.ok());
  EXPECT_EQ(rec.status().message().find('\n'), std::string::npos);
}

// Connections of one topic share one topic (rosbag opens one per publisher); a second type on a topic is refused.
TEST(ImportRosbagErrorTest, ConnectionsOfOneTopicMerge) {
  TempDir dir;
  std::string chunk = Connection(0, "/imu", "sensor_msgs/Imu") + Connection(5, "/imu", "sensor_msgs/Imu");
  chunk += MessageRecord(0, 10, 0, testing::ImuMessage(kRos1, 10, 0, 0.1));
  chunk += MessageRecord(5, 11, 0, testing::ImuMessage(kRos1, 11, 0, 0.2));
  Imported in = Import(BagOf(chunk), dir);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  EXPECT_EQ(in.report.topics.size(), 1u);
  EXPECT_EQ(in.rec.value().Find("imu")->t.size(), 2u);
  chunk += Connection(6, "/imu", "sensor_msgs/MagneticField");
  EXPECT_THAT(Import(BagOf(chunk), dir).rec.status().message(),
              HasSubstr("topic /imu has connections of types sensor_msgs/Imu and sensor_msgs/MagneticField"));
}

// No cut and no corrupted byte makes the import crash or read past a buffer: each gives a recording or one line.
TEST(ImportRosbagErrorTest, CutsAndCorruptionsNeverCrash) {
  TempDir dir;
  for (const std::string compression : {"none", "bz2", "lz4"}) {
    const std::string bag = TinyBag(compression);
    // The bag header record fills the first 4096 bytes; cuts in it are sampled, those after it taken at a stride.
    for (std::size_t cut = 0; cut < bag.size(); cut += cut < 4096 ? 97 : 7) {
      Imported in = Import(bag.substr(0, cut), dir);
      ASSERT_FALSE(in.rec.ok()) << compression << " cut " << cut;
      EXPECT_EQ(in.rec.status().message().find('\n'), std::string::npos);
    }
    for (std::size_t at = 4096; at < bag.size(); at += 11) {
      std::string corrupt = bag;
      corrupt[at] = static_cast<char>(corrupt[at] ^ 0xa5);
      Imported in = Import(corrupt, dir);
      if (!in.rec.ok()) {
        EXPECT_EQ(in.rec.status().message().find('\n'), std::string::npos) << at;
      }
    }
  }
}

TEST(ImportRosbagTypesTest, JointVelocitiesAndUnknownJoints) {
  TempDir dir;
  RosbagImportOptions options;
  options.joint_velocities = true;
  Imported in = Import(AllTypesBag(), dir, options);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  const Stream* joints = in.rec.value().Find("joints");
  ASSERT_NE(joints, nullptr);
  EXPECT_EQ(joints->info.columns, (std::vector<std::string>{"left_wheel", "right_wheel", "arm"}));
  EXPECT_EQ(joints->info.units, "rad/s");
  EXPECT_EQ(joints->values.row(2), Eigen::RowVector3d(-2.0, -1.0, 0.0));
  options.joints = {"left_wheel", "caster"};
  in = Import(AllTypesBag(), dir, options);
  ASSERT_TRUE(in.rec.ok()) << in.rec.status().message();
  EXPECT_EQ(in.rec.value().Find("joints"), nullptr);
  EXPECT_EQ(in.report.Find("/joints")->skipped.at("joint 'caster' without a velocity"), 3);
  EXPECT_THAT(in.report.warnings, Contains("/joints (joints): not imported (fewer than two usable messages)"));
}

// The real Husky bag (data/husky_test1 of the shared data directory): counts, span, rates and the IMU's clock offset.
TEST(ImportRosbagRealTest, HuskyTest1) {
  const std::string path = ::roamlab::testing::RealData("husky_test1/test1.bag");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "real data absent: " << path;
  RosbagImportReport report;
  Result<Recording> rec = ImportRosbag(path, {}, &report);
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  EXPECT_EQ(report.Find("/imu/data")->messages, 11865);
  EXPECT_EQ(report.Find("/husky_velocity_controller/odom")->messages, 3952);
  EXPECT_EQ(report.Find("/fix")->messages, 989);
  // stream -> (topic, rate)
  const std::map<std::string, std::pair<std::string, double>> streams = {
      {"imu_data", {"/imu/data", 30.0}},
      {"husky_velocity_controller_odom", {"/husky_velocity_controller/odom", 10.0}},
      {"husky_velocity_controller_odom_pose", {"/husky_velocity_controller/odom", 10.0}},
      {"fix", {"/fix", 2.5}}};
  for (const auto& [name, topic_rate] : streams) {
    const auto& [topic, rate] = topic_rate;
    const Stream* s = rec.value().Find(name);
    ASSERT_NE(s, nullptr) << name;
    int skipped = 0;
    const std::string prefix = name.size() > 5 && name.substr(name.size() - 5) == "_pose" ? "pose: " : "";
    for (const auto& [what, n] : report.Find(topic)->skipped)
      if (what.rfind("pose: ", 0) == 0 ? !prefix.empty() : prefix.empty()) skipped += n;
    EXPECT_EQ(static_cast<int>(s->t.size()) + skipped, report.Find(topic)->messages) << name;
    EXPECT_NEAR(SecondsBetween(s->t.front(), s->t.back()), 395.0, 2.0) << name;
    EXPECT_NEAR(s->info.rate_hz, rate, 0.02 * rate) << name;
  }
  // The IMU's header stamps are exact 30 Hz ticks about 26 ms behind the bag's receive times.
  EXPECT_NEAR(report.Find("/imu/data")->clock_offset_s, -0.026, 0.005);
  EXPECT_EQ(DescribeClockOffset(report.Find("/imu/data")->clock_offset_s).find("header stamps are 2"), 0u);
  EXPECT_NEAR(report.Find("/fix")->clock_offset_s, 0.0, 0.01);
}

// A real rosbag2 (SQLite, CDR) bag of a 1/10-scale car (data/ros2/av1tenth_car of the shared data directory).
TEST(ImportRosbagRealTest, Av1tenthRosbag2) {
  const std::string path = ::roamlab::testing::RealData("ros2/av1tenth_car/bag2_deadreck_data");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "real data absent: " << path;
  RosbagImportReport report;
  RosbagImportOptions options;
  options.platform.kind = "ackermann";
  Result<Recording> rec = ImportRosbag(path, options, &report);
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  EXPECT_EQ(report.format, "rosbag2 SQLite");
  EXPECT_EQ(report.Find("/odometry")->messages, 690);
  EXPECT_EQ(report.Find("/GPSNavSat")->messages, 220);
  EXPECT_EQ(report.Find("/GPSData")->messages, 220);
  const Stream* odometry = rec.value().Find("odometry");
  const Stream* heading = rec.value().Find("odometry_pose");
  const Stream* fix = rec.value().Find("GPSNavSat");
  const Stream* utm = rec.value().Find("GPSData");
  ASSERT_TRUE(odometry && heading && fix && utm);
  EXPECT_EQ(odometry->t.size(), 690u);
  EXPECT_EQ(heading->t.size(), 690u);
  EXPECT_NEAR(SecondsBetween(odometry->t.front(), odometry->t.back()), 103.0, 1.0);
  // Every orientation decoded is a unit quaternion about the vertical (a planar car): the CDR alignment is right.
  for (Eigen::Index i = 0; i < heading->values.rows(); ++i) {
    ASSERT_NEAR(heading->values.row(i).tail<4>().norm(), 1.0, 1e-6) << i;
    ASSERT_EQ(heading->values(i, 3), 0.0) << i;
  }
  // The fix: the campus in Gainesville, Florida; its pose topic carries UTM (zone 17) easting and northing.
  EXPECT_NEAR(fix->values(0, 0), 29.6, 0.1);
  EXPECT_NEAR(fix->values(0, 1), -82.3, 0.1);
  EXPECT_NEAR(utm->values(0, 0), 369375.0, 1000.0);
  EXPECT_NEAR(utm->values(0, 1), 3280343.0, 1000.0);
  // Its header stamps precede the bag's receive times by a few tens of milliseconds.
  EXPECT_LT(report.Find("/GPSNavSat")->clock_offset_s, -0.02);
  EXPECT_GT(report.Find("/GPSNavSat")->clock_offset_s, -0.05);
}

// The MCAP format fixture (data/ros2/rosbags_fixture): every supported type decoded from CDR, with the fixture's
// values.
TEST(ImportRosbagRealTest, McapFixtureEveryType) {
  const std::string path = ::roamlab::testing::RealData("ros2/rosbags_fixture/test_bag_mcap");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "data absent: " << path;
  RosbagImportReport report;
  RosbagImportOptions options;
  options.platform.kind = "unknown";
  Result<Recording> rec = ImportRosbag(path, options, &report);
  ASSERT_TRUE(rec.ok()) << rec.status().message();
  EXPECT_EQ(report.topics.size(), 94u);
  const auto row = [&](const std::string& name) {
    const Stream* s = rec.value().Find("test_" + name);
    EXPECT_NE(s, nullptr) << name;
    return s ? Eigen::RowVectorXd(s->values.row(1)) : Eigen::RowVectorXd();
  };
  EXPECT_TRUE(row("sensor_msgs_imu").isApprox((Eigen::RowVectorXd(6) << 0.01, 0.02, 0.03, 0.1, 0.2, 9.8).finished()));
  EXPECT_NEAR(row("sensor_msgs_nav_sat_fix")[0], 37.7749, 1e-9);
  EXPECT_NEAR(row("sensor_msgs_nav_sat_fix")[1], -122.4194, 1e-9);
  EXPECT_EQ(rec.value().Find("test_sensor_msgs_joint_state")->info.columns,
            (std::vector<std::string>{"joint1", "joint2", "joint3"}));
  EXPECT_TRUE(row("sensor_msgs_joint_state").isApprox(Eigen::RowVector3d(0.1, 0.2, 0.3)));
  EXPECT_NEAR(row("sensor_msgs_laser_scan")[4], 1.0, 1e-6);
  EXPECT_NEAR(row("sensor_msgs_laser_scan")[8], 5.0, 1e-6);
  EXPECT_TRUE(row("sensor_msgs_magnetic_field").isApprox(Eigen::RowVector3d(1e5, 2e5, 3e5)));
  EXPECT_TRUE(row("nav_msgs_odometry").head<6>().isApprox((Eigen::RowVectorXd(6) << 1, 0, 0, 0, 0, 0.1).finished()));
  EXPECT_TRUE(row("nav_msgs_odometry_pose").isApprox((Eigen::RowVectorXd(7) << 1, 2, 0, 0, 0, 0, 1).finished()));
  EXPECT_TRUE(row("geometry_msgs_twist_stamped").isApprox((Eigen::RowVectorXd(6) << 1, 0, 0, 0, 0, 0.5).finished()));
  EXPECT_TRUE(row("geometry_msgs_pose_stamped").isApprox((Eigen::RowVectorXd(7) << 1, 2, 3, 0, 0, 0, 1).finished()));
  EXPECT_EQ(rec.value().Find("test_sensor_msgs_compressed_image")->text.size(), 2u);
  // The fixture's raw image declares 640 x 480 pixels but holds a few bytes: skipped and counted, not imported.
  EXPECT_EQ(report.Find("/test/sensor_msgs/image")->skipped.at("image data shorter than height x step"), 2);
  EXPECT_TRUE(report.Find("/test/sensor_msgs/image")->streams.empty());
  EXPECT_TRUE(report.Find("/test/sensor_msgs/imu")->constant);
}

}  // namespace
}  // namespace roamlab::importers
