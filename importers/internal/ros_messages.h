// Decoders of the ROS message types the bag importer reads (importers/rosbag.h), for both serializations of the common
// bag form (internal/bag.h): ROS 1 (packed little-endian) and CDR (ROS 2). Each type is decoded by one function over
// MessageReader, which hides the difference: CDR's 4-byte encapsulation header (byte 1: 0x00 big-endian, 0x01
// little-endian; other kinds refused), its alignment of every primitive to its own size counted from the byte after
// that header, and the two std_msgs/Header layouts (ROS 1: u32 seq, u32 sec, u32 nsec, string frame_id; ROS 2: int32
// sec, uint32 nanosec, string frame_id). Strings are a u32 length then the bytes (CDR counts and drops a trailing NUL),
// sequences a u32 count then the elements; fixed-size arrays have no count.
//
// A message must hold every field its type and its own counts declare: a string or sequence that runs past the
// message, or a message that ends before its last field, is refused (DecodeRosMessage's error). Bytes after the last
// field are ignored (CDR pads).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "common/status.h"
#include "common/time.h"
#include "importers/internal/bag.h"

namespace roamlab::importers::internal {

struct RosHeader {
  Time stamp;
  std::string frame_id;
};

// geometry_msgs/Pose: position [m], orientation (x, y, z, w).
struct RosPose {
  std::array<double, 3> position{};
  std::array<double, 4> orientation_xyzw{};
};

struct RosImu {  // sensor_msgs/Imu
  std::array<double, 4> orientation_xyzw{};
  std::array<double, 9> orientation_covariance{};
  std::array<double, 3> angular_velocity{};  // [rad/s]
  std::array<double, 9> angular_velocity_covariance{};
  std::array<double, 3> linear_acceleration{};  // [m/s^2]
  std::array<double, 9> linear_acceleration_covariance{};
};
struct RosNavSatFix {  // sensor_msgs/NavSatFix
  std::int8_t status = 0;
  std::uint16_t service = 0;
  double latitude_deg = 0.0, longitude_deg = 0.0, altitude_m = 0.0;
  std::array<double, 9> position_covariance{};  // ENU [m^2]
  std::uint8_t position_covariance_type = 0;
};
struct RosMagneticField {           // sensor_msgs/MagneticField
  std::array<double, 3> field_t{};  // [T]
  std::array<double, 9> covariance{};
};
struct RosJointState {  // sensor_msgs/JointState
  std::vector<std::string> name;
  std::vector<double> position, velocity, effort;
};
struct RosLaserScan {  // sensor_msgs/LaserScan
  float angle_min = 0, angle_max = 0, angle_increment = 0, time_increment = 0, scan_time = 0, range_min = 0,
        range_max = 0;
  std::vector<float> ranges, intensities;
};
struct RosImage {  // sensor_msgs/Image
  std::uint32_t height = 0, width = 0;
  std::string encoding;
  std::uint8_t is_bigendian = 0;
  std::uint32_t step = 0;
  std::string_view data;  // points into the message
};
struct RosCompressedImage {  // sensor_msgs/CompressedImage
  std::string format;
  std::string_view data;  // points into the message
};
struct RosOdometry {  // nav_msgs/Odometry
  std::string child_frame_id;
  RosPose pose;
  std::array<double, 36> pose_covariance{};
  std::array<double, 6> twist{};  // linear [m/s], angular [rad/s]
  std::array<double, 36> twist_covariance{};
};
struct RosTwistStamped {  // geometry_msgs/TwistStamped
  std::array<double, 6> twist{};
};
struct RosPoseStamped {  // geometry_msgs/PoseStamped
  RosPose pose;
};
struct RosPoseWithCovarianceStamped {  // geometry_msgs/PoseWithCovarianceStamped
  RosPose pose;
  std::array<double, 36> covariance{};
};

using RosBody =
    std::variant<RosImu, RosNavSatFix, RosMagneticField, RosJointState, RosLaserScan, RosImage, RosCompressedImage,
                 RosOdometry, RosTwistStamped, RosPoseStamped, RosPoseWithCovarianceStamped>;

struct RosMessage {
  RosHeader header;
  RosBody body;
};

// The supported type names ("sensor_msgs/Imu", ...; ROS 2 names without "/msg"), in RosBody's order.
const std::vector<std::string>& SupportedRosTypes();
bool IsSupportedRosType(const std::string& type);

// Decodes one message of `type`; the error is the problem alone (the caller names the topic and message index).
Result<RosMessage> DecodeRosMessage(const std::string& type, std::string_view data, Encoding encoding);

}  // namespace roamlab::importers::internal
