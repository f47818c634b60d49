// Importer for ROS bags: a ROS 1 bag (v2.0; chunks none, bz2 or lz4), a rosbag2 directory (SQLite) or an MCAP file,
// read by the project's own readers (internal/bag.h: no ROS libraries) and decoded from their ROS 1 or CDR
// serialization (internal/ros_messages.h). Message types and the streams they become (ROS 2 types without "/msg"):
//   sensor_msgs/Imu          -> imu: angular_velocity [rad/s], linear_acceleration [m/s^2]; the orientation estimate
//                               is not imported; noise gyro_sigma_radps / accel_sigma_mps2 = median square root of
//                               the covariances' first diagonal entry, when positive
//   sensor_msgs/NavSatFix    -> gps: latitude, longitude, altitude and the 6 ENU covariance columns; a fix with status
//                               -1 (no fix), or a latitude beyond +-90 deg or longitude beyond +-180 deg, is skipped and
//                               counted; origin = the first kept fix of the first gps stream
//   sensor_msgs/MagneticField-> magnetometer, units uT (the message's tesla times 1e6)
//   sensor_msgs/JointState   -> wheel_encoders: one column per joint (RosbagImportOptions::joints, else the joints of
//                               the topic's first message), positions [rad] or velocities [rad/s]
//                               (joint_velocities); a message without a selected joint is skipped and counted
//   sensor_msgs/LaserScan    -> laser_scan (LaserScanColumns(beams), beams of the first message): angle_min,
//                               angle_increment, range_min, range_max, ranges; a non-finite range (no return) is
//                               written as -1, outside [range_min, range_max]; a scan with another beam count or an
//                               invalid geometry is skipped and counted
//   sensor_msgs/Image        -> camera: each frame written as <stream>/<index>.pgm (mono8) or .ppm (rgb8, bgr8);
//                               other encodings, and images with fewer bytes than height x step, skipped and counted
//   sensor_msgs/CompressedImage -> camera: each frame's bytes as given, <stream>/<index>.jpg or .png (by the bytes'
//                               signature, else the format string); other formats skipped and counted
//   nav_msgs/Odometry        -> odometry <name>: the twist in the body (child) frame and its 21 covariance columns;
//                               PLUS pose <name>_pose: the pose (x y z qx qy qz qw) in the parent frame
//   geometry_msgs/TwistStamped -> odometry: the twist as given, in header.frame_id
//   geometry_msgs/PoseStamped, geometry_msgs/PoseWithCovarianceStamped -> pose (the latter's noise sigma_m = median
//                               square root of the mean position variance, when positive)
// Frame rule (nav_msgs/Odometry): the twist is in child_frame_id. A message with an empty child_frame_id gives its
// twist in the parent frame header.frame_id; it is rotated into the body frame by the message's own pose orientation
// (v_body = R^T v_parent, and the covariance likewise). A message whose frames cannot be resolved (both frame ids
// empty, or a parent-frame twist with an orientation that is not a unit quaternion) is refused with one line. A pose
// sample whose orientation is not a unit quaternion is skipped and counted.
//
// Streams: `topics` selects topics and names their streams; without it every topic of a supported type is imported,
// named after the topic ("/imu/data" -> "imu_data"). Other topics are listed in the report and ignored.
//
// Time: each sample keeps its message's header stamp (the sensor's clock), kept absolute (Unix time) so the streams of
// one bag share one clock. Checks, each a warning line (RosbagImportReport::warnings) and a field of the topic's
// report:
//   - values all zero, or all constant (the type's value columns, covariances aside)
//   - header stamps that jump back from the previous message: counted, and the stream sorted by stamp
//   - gaps of more than 10 s between consecutive stamps: counted, the largest given
//   - header stamps far from the bag's receive times: a median offset of more than 50 ms is reported as a clock offset
//     with its value and sign ("header stamps are 75 ms earlier than the bag's receive times"); the offset of every
//     imported topic is in its report (the command line prints it)
//   - a repeated header stamp: the sample is skipped and counted
// Samples with a non-finite value are skipped and counted. A topic with fewer than two samples left is not imported
// (a warning; an error when the topic was selected).
//
// Wheels (wheels_from_odometry; platform geometry wheel_radius_m and baseline_m; odometry_topic chooses the topic
// when the bag has several odometry streams): a differential-drive / skid-steer controller (ROS
// diff_drive_controller) computes its twist from the wheel speeds with its nominal geometry, v = r (w_R + w_L) / 2,
// omega = r (w_R - w_L) / B, so the wheel speeds are recovered exactly by w_L = (v - omega B / 2) / r,
// w_R = (v + omega B / 2) / r, B the controller's wheel separation: odometry_wheel_separation_m when given, else
// baseline_m. A skid steer's controller divides by an effective separation wider than the geometric one (ROS
// diff_drive_controller: the wheel_separation, from the robot's URDF or its parameter, times
// wheel_separation_multiplier; the Clearpath Husky's is 0.5708 m x 1.875 = 1.07 m), so the wheel speeds it measured
// need that value: with the geometric track the recovered wheel-rate difference is smaller than the real one by the
// multiplier. The importer then also writes stream `wheels` (wheel_encoders, columns left, right, units rad): the
// cumulative wheel angles, integrated by the trapezoid rule over the odometry stamps, with attributes
// derived_from_odometry = 1 and wheel_separation_m = B. It re-expresses the odometry (no new measurement) so that the
// estimator's differential_drive model, with its calibration of radii and effective track, can read it.
//
// Mounting: a bag without /tf does not say how the sensors are mounted, so the IMU's is given by the caller and written
// into recording.yaml, where the estimator's configuration can read and check it.
//
// Errors are one line naming the file and the problem: the container's (internal/bag.h), a message that does not
// hold its declared fields ("<bag>: /topic message K (counting from 0): <problem>"), a frame that cannot be resolved,
// an unknown or unsupported selected topic, no supported topic.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "common/status.h"
#include "common/time.h"
#include "recording/recording.h"

namespace roamlab::importers {

struct RosbagImportOptions {
  std::optional<Eigen::Quaterniond> q_body_imu;             // IMU mounting (rotates IMU coordinates into the body)
  recording::Platform platform;                             // written as is (kind, nominal geometry)
  std::vector<std::pair<std::string, std::string>> topics;  // (topic, stream name); empty = every supported topic
  std::vector<std::string> joints;                          // JointState joints; empty = the first message's
  bool joint_velocities = false;                            // JointState: velocities [rad/s], not positions [rad]
  bool wheels_from_odometry = false;                        // also write `wheels` (header comment)
  std::string odometry_topic;                               // the wheels' odometry topic when there are several
  std::optional<double> odometry_wheel_separation_m;        // the controller's B for the wheels (header comment)
  // Optional: the fraction of the selected topics' messages decoded, in (0, 1], every kProgressMessages messages and
  // at the end (1). Reading the bag's container comes before the first call.
  std::function<void(double fraction)> progress;

  static constexpr std::size_t kProgressMessages = 1024;
};

// What happened to one topic of the bag.
struct RosbagTopicReport {
  std::string topic;
  std::string type;
  bool decoded = false;                // selected, of a supported type, and decoded
  std::vector<std::string> streams;    // the streams written from it (none: ignored or not imported)
  int messages = 0;                    // in the bag
  std::map<std::string, int> skipped;  // reason -> samples skipped
  int stamps_back = 0;                 // header stamps before the previous message's (the stream is sorted)
  int gaps = 0;                        // gaps of more than 10 s between consecutive stamps
  double largest_gap_s = 0.0;
  double clock_offset_s = 0.0;  // median of header stamp - receive time (negative: stamps earlier)
  bool all_zero = false;
  bool constant = false;  // all values equal (and not all zero)
};

// A camera frame to write beside the recording: `file` relative to the recording directory.
struct CameraFrame {
  std::string file;
  std::string bytes;
};

struct RosbagImportReport {
  std::string format;                     // "ROS 1 bag v2.0", "rosbag2 SQLite", "MCAP"
  int chunks = 0;                         // ROS 1 and MCAP chunks read
  std::vector<RosbagTopicReport> topics;  // every topic of the bag, in the bag's order
  std::vector<std::string> warnings;      // one line each: "<topic>: <check>"
  std::vector<CameraFrame> frames;        // the camera streams' frames (WriteCameraFrames)

  const RosbagTopicReport* Find(const std::string& topic) const;
};

// Reads the bag at `bag_path` (a ROS 1 .bag, a rosbag2 directory or an .mcap) into a recording.
Result<recording::Recording> ImportRosbag(const std::string& bag_path, const RosbagImportOptions& options,
                                          RosbagImportReport* report = nullptr);

// Writes the report's camera frames into the recording directory (creating their folders).
Status WriteCameraFrames(const std::vector<CameraFrame>& frames, const std::string& directory);

// One row of ListRosbag: a topic, its type, message count, rate and the span of its receive times.
struct RosbagTopicListing {
  std::string topic;
  std::string type;
  bool supported = false;  // a type this importer decodes
  int messages = 0;
  double rate_hz = 0.0;  // (messages - 1) / span; 0 with fewer than two messages
  Time first, last;      // receive times
};

// Every topic of the bag, in the bag's order, without decoding a message.
Result<std::vector<RosbagTopicListing>> ListRosbag(const std::string& bag_path);

// "header stamps are 26 ms earlier than the bag's receive times" for an offset (header - receive) of -0.026 s.
std::string DescribeClockOffset(double offset_s);

// The stream name a topic gets by default: its letters and digits, runs of other characters as one '_'.
std::string StreamNameOfTopic(const std::string& topic);

}  // namespace roamlab::importers
