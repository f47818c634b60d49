// A small simulated problem for the range_beacon model (range_beacon.h): a robot slaloms on the plane z = 0 at
// constant speed, its yaw rate a cosine (a circle would leave the lever arm's direction unobservable: the antenna's
// path would be the same circle for every lever arm at the same distance from its centre), starting at the origin
// facing x. Its odometer reads the body velocity and a ranging antenna at a lever arm measures its distance to three
// beacons, all with Gaussian noise. The twist is held over each sample period and moves the robot as the estimator's
// odometer predicts it (estimator/geometry.h PredictPose).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "recording/recording.h"

namespace beacon {

struct BeaconDriveOptions {
  double duration_s = 60.0;
  double rate_hz = 10.0;
  double speed_mps = 1.0;
  double yaw_rate_amplitude_radps = 0.4;
  double yaw_rate_period_s = 20.0;
  Eigen::Vector3d p_body_antenna = Eigen::Vector3d(0.3, -0.2, 0.5);  // the true lever arm [m]
  std::vector<Eigen::Vector3d> beacons_world = {{0.0, 10.0, 2.0}, {20.0, -10.0, 3.0}, {40.0, 10.0, 1.0}};
  double odometer_sigma_mps = 0.02;
  double odometer_sigma_radps = 0.005;
  double range_sigma_m = 0.05;
  std::uint64_t seed = 7;
};

// The recording: an odometry stream "odometer" and one inputs stream "uwb_<i>" (column range_m) per beacon, all at
// rate_hz on the same stamps, with the true trajectory as ground truth.
roamlab::recording::Recording SimulateBeaconDrive(const BeaconDriveOptions& options);

// The estimator configuration for it: the odometer as master, one range_beacon stream per beacon sharing the
// parameter antenna.lever_arm, free in x and y (its height is held by a prior at the truth: on a level drive it
// cannot be told from the poses' height).
std::string BeaconDriveConfig(const BeaconDriveOptions& options);

}  // namespace beacon
