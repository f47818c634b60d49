// The Clearpath Husky of robot_localization's test bag (test1.bag) as the real-data tests import it: a skid steer of
// nominal wheel radius 0.1651 m and baseline 0.555 m, its IMU mounted with its y axis vertical
// (q_body_imu = R_x(+90 deg)), the wheel angles re-expressed from the controller's odometry, and the streams named
// imu, odometry and gps as configs/real/husky_*.yaml read them.
#pragma once

#include <cmath>

#include <Eigen/Geometry>

#include "importers/rosbag.h"

namespace roamlab::testing {

inline importers::RosbagImportOptions HuskyImportOptions() {
  importers::RosbagImportOptions options;
  options.platform = {"skid_steer", {{"wheel_radius_m", 0.1651}, {"baseline_m", 0.555}}};
  options.q_body_imu = Eigen::Quaterniond(std::sqrt(0.5), std::sqrt(0.5), 0.0, 0.0);
  options.wheels_from_odometry = true;
  options.topics = {{"/imu/data", "imu"}, {"/husky_velocity_controller/odom", "odometry"}, {"/fix", "gps"}};
  return options;
}

}  // namespace roamlab::testing
