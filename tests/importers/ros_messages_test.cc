#include "importers/internal/ros_messages.h"

#include <cmath>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/support/message_writer.h"

namespace roamlab::importers::internal {
namespace {

using ::testing::HasSubstr;
using testing::MessageWriter;
using testing::Wire;

Encoding EncodingOf(Wire wire) { return wire == Wire::kRos1 ? Encoding::kRos1 : Encoding::kCdr; }

// Every wire form: ROS 1, little-endian CDR, big-endian CDR.
class RosMessagesTest : public ::testing::TestWithParam<Wire> {
 protected:
  template <typename T>
  T Decode(const std::string& type, const std::string& bytes, RosHeader* header = nullptr) {
    Result<RosMessage> m = DecodeRosMessage(type, bytes, EncodingOf(GetParam()));
    EXPECT_TRUE(m.ok()) << m.status().message();
    if (!m.ok()) return T{};
    if (header) *header = m.value().header;
    const T* body = std::get_if<T>(&m.value().body);
    EXPECT_NE(body, nullptr) << type;
    return body ? *body : T{};
  }
  // Every strict prefix of `bytes` is refused (the message then lacks a declared field), none crashes.
  void ExpectPrefixesRefused(const std::string& type, const std::string& bytes) {
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      Result<RosMessage> m = DecodeRosMessage(type, bytes.substr(0, n), EncodingOf(GetParam()));
      EXPECT_FALSE(m.ok()) << type << " cut to " << n << " of " << bytes.size() << " bytes";
    }
  }
};

TEST_P(RosMessagesTest, ImuAndItsHeader) {
  RosHeader h;
  const std::string bytes = testing::ImuMessage(GetParam(), 100, 250000000, 0.7);
  const RosImu m = Decode<RosImu>("sensor_msgs/Imu", bytes, &h);
  EXPECT_EQ(h.stamp.nanoseconds(), 100250000000);
  EXPECT_EQ(h.frame_id, "imu_link");
  EXPECT_EQ(m.orientation_xyzw[3], 1.0);
  EXPECT_EQ(m.angular_velocity[1], 0.7);
  EXPECT_EQ(m.angular_velocity_covariance[4], 0.0004);
  EXPECT_EQ(m.linear_acceleration[1], 9.81);
  EXPECT_EQ(m.linear_acceleration_covariance[8], 0.01);
  ExpectPrefixesRefused("sensor_msgs/Imu", bytes);
}

TEST_P(RosMessagesTest, NavSatFix) {
  const std::string bytes = testing::FixMessage(GetParam(), 5, 0, -1, 48.1);
  const RosNavSatFix m = Decode<RosNavSatFix>("sensor_msgs/NavSatFix", bytes);
  EXPECT_EQ(m.status, -1);
  EXPECT_EQ(m.service, 1);
  EXPECT_EQ(m.latitude_deg, 48.1);
  EXPECT_EQ(m.longitude_deg, 7.5);
  EXPECT_EQ(m.altitude_m, 100.0);
  EXPECT_EQ(m.position_covariance[1], 0.1);
  EXPECT_EQ(m.position_covariance[8], 2.0);
  EXPECT_EQ(m.position_covariance_type, 2);
  ExpectPrefixesRefused("sensor_msgs/NavSatFix", bytes);
}

TEST_P(RosMessagesTest, MagneticField) {
  const std::string bytes = testing::MagneticFieldMessage(GetParam(), 5, 0, 3e-5);
  const RosMagneticField m = Decode<RosMagneticField>("sensor_msgs/MagneticField", bytes);
  EXPECT_EQ(m.field_t[0], 3e-5);
  EXPECT_EQ(m.field_t[2], 4e-5);
  EXPECT_EQ(m.covariance[8], 1e-12);
  ExpectPrefixesRefused("sensor_msgs/MagneticField", bytes);
}

TEST_P(RosMessagesTest, JointState) {
  const std::string bytes = testing::JointStateMessage(GetParam(), 5, 0, 1.5, -0.5);
  const RosJointState m = Decode<RosJointState>("sensor_msgs/JointState", bytes);
  EXPECT_EQ(m.name, (std::vector<std::string>{"left_wheel", "right_wheel", "arm"}));
  EXPECT_EQ(m.position, (std::vector<double>{1.5, 2.5, 3.5}));
  EXPECT_EQ(m.velocity, (std::vector<double>{-0.5, 0.5, 1.5}));
  EXPECT_TRUE(m.effort.empty());
  ExpectPrefixesRefused("sensor_msgs/JointState", bytes);
}

TEST_P(RosMessagesTest, LaserScan) {
  const std::string bytes = testing::LaserScanMessage(GetParam(), 5, 0, 2.5f);
  const RosLaserScan m = Decode<RosLaserScan>("sensor_msgs/LaserScan", bytes);
  EXPECT_EQ(m.angle_min, -0.5f);
  EXPECT_EQ(m.angle_increment, 0.5f);
  EXPECT_EQ(m.range_min, 0.1f);
  EXPECT_EQ(m.range_max, 10.0f);
  ASSERT_EQ(m.ranges.size(), 3u);
  EXPECT_EQ(m.ranges[0], 2.5f);
  EXPECT_TRUE(std::isinf(m.ranges[1]));
  EXPECT_EQ(m.intensities, (std::vector<float>{5.0f, 6.0f}));
  ExpectPrefixesRefused("sensor_msgs/LaserScan", bytes);
}

TEST_P(RosMessagesTest, ImageAndCompressedImage) {
  const std::string bytes = testing::ImageMessage(GetParam(), 5, 0, "rgb8", 10);
  const RosImage m = Decode<RosImage>("sensor_msgs/Image", bytes);
  EXPECT_EQ(m.width, 2u);
  EXPECT_EQ(m.height, 2u);
  EXPECT_EQ(m.encoding, "rgb8");
  EXPECT_EQ(m.step, 7u);
  ASSERT_EQ(m.data.size(), 14u);
  EXPECT_EQ(m.data[13], 23);
  ExpectPrefixesRefused("sensor_msgs/Image", bytes);
  const std::string jpeg = "\xff\xd8\xff\xe0 jpeg bytes";
  const std::string compressed = testing::CompressedImageMessage(GetParam(), 5, 0, jpeg);
  const RosCompressedImage c = Decode<RosCompressedImage>("sensor_msgs/CompressedImage", compressed);
  EXPECT_EQ(c.format, "jpeg");
  EXPECT_EQ(c.data, jpeg);
  ExpectPrefixesRefused("sensor_msgs/CompressedImage", compressed);
}

TEST_P(RosMessagesTest, Odometry) {
  const std::string bytes =
      testing::OdometryMessage(GetParam(), 5, 0, "odom", "base_link", {0, 0, 0.6, 0.8}, 1.1, 0.2, 0.3);
  RosHeader h;
  const RosOdometry m = Decode<RosOdometry>("nav_msgs/Odometry", bytes, &h);
  EXPECT_EQ(h.frame_id, "odom");
  EXPECT_EQ(m.child_frame_id, "base_link");
  EXPECT_EQ(m.pose.position[1], 2.0);
  EXPECT_EQ(m.pose.orientation_xyzw[2], 0.6);
  EXPECT_EQ(m.twist[0], 1.1);
  EXPECT_EQ(m.twist[1], 0.2);
  EXPECT_EQ(m.twist[5], 0.3);
  EXPECT_EQ(m.twist_covariance[5], 1e-5);
  EXPECT_EQ(m.twist_covariance[35], 0.006);
  ExpectPrefixesRefused("nav_msgs/Odometry", bytes);
}

TEST_P(RosMessagesTest, TwistAndPoses) {
  const std::string twist = testing::TwistStampedMessage(GetParam(), 5, 0, 0.4, -0.1);
  const RosTwistStamped t = Decode<RosTwistStamped>("geometry_msgs/TwistStamped", twist);
  EXPECT_EQ(t.twist[0], 0.4);
  EXPECT_EQ(t.twist[5], -0.1);
  ExpectPrefixesRefused("geometry_msgs/TwistStamped", twist);
  const std::string pose = testing::PoseStampedMessage(GetParam(), 5, 0, 1.25);
  const RosPoseStamped p = Decode<RosPoseStamped>("geometry_msgs/PoseStamped", pose);
  EXPECT_EQ(p.pose.position[0], 1.25);
  EXPECT_EQ(p.pose.orientation_xyzw[3], 0.8);
  ExpectPrefixesRefused("geometry_msgs/PoseStamped", pose);
  const std::string pose_cov = testing::PoseWithCovarianceMessage(GetParam(), 5, 0, -1.5);
  const RosPoseWithCovarianceStamped pc =
      Decode<RosPoseWithCovarianceStamped>("geometry_msgs/PoseWithCovarianceStamped", pose_cov);
  EXPECT_EQ(pc.pose.position[0], -1.5);
  EXPECT_EQ(pc.covariance[7], 0.25);
  ExpectPrefixesRefused("geometry_msgs/PoseWithCovarianceStamped", pose_cov);
}

// A count or string length that runs past the message is refused with what it is, never read.
TEST_P(RosMessagesTest, OverLongCountsAreRefused) {
  MessageWriter joints(GetParam());
  joints.Header(5, 0, "").Count(1).String("left").Count(1000000).Doubles({1.0});
  Result<RosMessage> m = DecodeRosMessage("sensor_msgs/JointState", joints.bytes(), EncodingOf(GetParam()));
  ASSERT_FALSE(m.ok());
  EXPECT_THAT(m.status().message(), HasSubstr("a sequence of 1000000 positions runs past the message"));
  // A header whose frame_id claims 4e9 bytes.
  MessageWriter long_string(GetParam());
  if (GetParam() == Wire::kRos1) long_string.Put(std::uint32_t{7});  // seq
  long_string.Put(std::int32_t{5}).Put(std::uint32_t{0});
  long_string.Put(std::uint32_t{4000000000u}).Raw("frame");
  m = DecodeRosMessage("geometry_msgs/TwistStamped", long_string.bytes(), EncodingOf(GetParam()));
  ASSERT_FALSE(m.ok());
  EXPECT_THAT(m.status().message(), HasSubstr("a string of 4000000000 bytes runs past the message"));
}

// A string-length prefix changed inside the message (longer or shorter than the string) misaligns every field after
// it: the decoder refuses the message (it runs past the end, or leaves bytes unread) instead of importing shifted
// values.
TEST_P(RosMessagesTest, ChangedStringLengthPrefixIsRefused) {
  const std::string bytes = testing::ImuMessage(GetParam(), 100, 250000000, 0.7);
  // The frame_id length: after seq, sec, nsec (ROS 1) or the 4-byte encapsulation, sec, nsec (CDR).
  const std::size_t at = 12;
  const std::uint32_t declared = GetParam() == Wire::kCdrBig
                                     ? (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + 3])))
                                     : static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at]));
  ASSERT_EQ(declared, GetParam() == Wire::kRos1 ? 8u : 9u);  // "imu_link" (CDR counts the NUL)
  for (std::uint32_t length = 0; length < 40; ++length) {
    if (length == declared) continue;
    std::string changed = bytes;
    changed[GetParam() == Wire::kCdrBig ? at + 3 : at] = static_cast<char>(length);
    Result<RosMessage> m = DecodeRosMessage("sensor_msgs/Imu", changed, EncodingOf(GetParam()));
    EXPECT_FALSE(m.ok()) << "frame_id length " << length << " instead of " << declared << " was accepted";
  }
}

INSTANTIATE_TEST_SUITE_P(Wires, RosMessagesTest, ::testing::Values(Wire::kRos1, Wire::kCdrLittle, Wire::kCdrBig),
                         [](const ::testing::TestParamInfo<Wire>& info) {
                           return info.param == Wire::kRos1        ? std::string("Ros1")
                                  : info.param == Wire::kCdrLittle ? std::string("CdrLittleEndian")
                                                                   : std::string("CdrBigEndian");
                         });

// CDR aligns each primitive to its size from the byte after the encapsulation header: a uint8 then a double leaves
// seven padding bytes, which a packed reading would take as the double's first bytes.
TEST(CdrTest, AlignmentIsCountedFromTheEncapsulationHeader) {
  const std::string bytes = testing::FixMessage(Wire::kCdrLittle, 5, 0, 0, 48.1);
  // header: sec 4, nsec 4, frame_id length 4 + "gps\0" 4 = 16 bytes; status at 16, service at 18 (aligned to 2),
  // latitude at 24 (aligned to 8): 4 + 24 from the start of the buffer.
  double latitude = 0.0;
  std::memcpy(&latitude, bytes.data() + 4 + 24, sizeof(double));
  EXPECT_EQ(latitude, 48.1);
  Result<RosMessage> m = DecodeRosMessage("sensor_msgs/NavSatFix", bytes, Encoding::kCdr);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(std::get<RosNavSatFix>(m.value().body).latitude_deg, 48.1);
}

TEST(CdrTest, RefusesOtherEncapsulations) {
  std::string bytes = testing::ImuMessage(Wire::kCdrLittle, 5, 0, 0.1);
  bytes[1] = 0x03;  // PL_CDR_LE
  Result<RosMessage> m = DecodeRosMessage("sensor_msgs/Imu", bytes, Encoding::kCdr);
  ASSERT_FALSE(m.ok());
  EXPECT_THAT(m.status().message(), HasSubstr("unsupported CDR encapsulation 0x0003"));
  EXPECT_FALSE(DecodeRosMessage("sensor_msgs/Imu", "\x00\x01", Encoding::kCdr).ok());
  EXPECT_THAT(DecodeRosMessage("std_msgs/String", bytes, Encoding::kCdr).status().message(),
              HasSubstr("'std_msgs/String' is not decoded"));
}

}  // namespace
}  // namespace roamlab::importers::internal
