// Importer for ROS1 bags (format version 2.0, http://wiki.ros.org/Bags/Format/2.0), read by our own parser: no ROS
// libraries. Records are `header_len (u32) header data_len (u32) data`, a header being `field_len (u32) name=value`
// fields; the op codes read are 0x03 bag header, 0x05 chunk (compression "none" or "bz2"; "lz4" is refused with an
// error), 0x07 connection (topic, type, md5sum) and 0x02 message data; index (0x04) and chunk-info (0x06) records are
// skipped (every message is found by walking the chunks). Messages are decoded from their ROS1 serialization by type:
//   sensor_msgs/Imu         -> stream `imu` (type imu): angular_velocity [rad/s], linear_acceleration [m/s^2]; the
//                              orientation estimate and the covariances are not imported (the noise entry keeps the
//                              median of the covariance diagonals' square roots, when they are positive)
//   nav_msgs/Odometry       -> stream `odometry` (type odometry): twist.linear and twist.angular, which ROS gives in
//                              the child frame (the body), followed by the 21 covariance columns of twist.covariance
//   sensor_msgs/NavSatFix   -> stream `gps` (type gps): latitude, longitude, altitude, followed by the 6 covariance
//                              columns of position_covariance (ENU, m^2; recording.h); fixes with status -1 (no fix)
//                              or a NaN coordinate are skipped and counted. origin: the first kept fix.
// Several topics of one type give one stream per topic, named after the topic ("/imu/data" -> "imu_data").
// Other message types are counted and ignored.
//
// Time: each sample keeps its message's header stamp (the sensor's own clock), not the bag's receive time; the bag time
// is later by the transport delay (26 ms for the Husky IMU). A stream's samples are sorted by header stamp; a sample
// whose stamp repeats the previous one is skipped and counted (ImportReport). All stamps are kept absolute (Unix
// time), so the streams of one bag share one clock.
//
// Wheels (RosbagImportOptions::wheels_from_odometry, one odometry topic, platform geometry wheel_radius_m and
// baseline_m): a differential-drive / skid-steer controller (ROS diff_drive_controller, the Husky's) computes its twist
// from the wheel speeds with its nominal geometry, v = r (w_R + w_L) / 2, omega = r (w_R - w_L) / B, so the wheel
// speeds are recovered exactly by the inverse w_L = (v - omega B / 2) / r, w_R = (v + omega B / 2) / r with the same
// r and B. The importer then also writes stream `wheels` (type wheel_encoders, columns left, right, units rad): the
// cumulative wheel angles, integrated by the trapezoid rule over the odometry stamps, with attribute
// derived_from_odometry = 1. It is a re-expression of the odometry, not a new measurement; its use is that the
// estimator's differential_drive model (with its calibration of radii and effective track) can read it. If the
// controller's geometry differs from the one given, the recovered speeds are scaled, which the radius and track
// calibration absorbs: ratios against the given geometry are what is meaningful.
//
// Mounting: the importer does not know the sensors' mounting (a bag without /tf does not say it), so the mounting is
// given by the caller (RosbagImportOptions), and written into recording.yaml where the estimator's configuration
// can read and check it.
#pragma once

#include <map>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "common/status.h"
#include "recording/recording.h"

namespace roamlab::importers {

struct RosbagImportOptions {
  std::optional<Eigen::Quaterniond> q_body_imu;  // IMU mounting (rotates IMU coordinates into the body frame)
  recording::Platform platform;                  // written as is (kind, nominal geometry)
  bool wheels_from_odometry = false;             // also write `wheels` (header comment)
};

struct RosbagImportReport {
  std::map<std::string, int> messages;       // topic -> messages read
  std::map<std::string, int> skipped;        // "topic: reason" -> samples skipped
  std::map<std::string, std::string> types;  // topic -> message type
  int chunks = 0;
};

// Reads the bag. Errors are one line naming the file and the problem (bad magic or version, a truncated record, a
// compressed chunk in an unsupported format, a message shorter than its type, no supported topic).
Result<recording::Recording> ImportRosbag(const std::string& bag_path, const RosbagImportOptions& options,
                                          RosbagImportReport* report = nullptr);

}  // namespace roamlab::importers
