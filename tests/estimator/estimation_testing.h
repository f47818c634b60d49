// Shared pieces of the end-to-end estimator tests: an estimator configuration for the synthetic ATV recording
// (tests/support/synthetic.h) with selectable free parameters, and a short differential-drive arc seen by motion
// capture.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/config.h"
#include "recording/recording.h"

namespace roamlab::estimator::testing {

// The ATV configuration: Ackermann master, IMU (gyroscope, accelerometer, magnetometer) and GPS, with the seed's
// Section V noise. `free` lists the parameters to estimate; their initial values are the nominal ones (lever arm 0,
// identity misalignment and A, zero bias, kv_over_L 0.8, k_theta 1, k_gamma 0); all others are fixed at the truth.
std::string AtvConfigYaml(const std::vector<std::string>& free, int window = 40);

EstimatorConfig AtvConfig(const std::vector<std::string>& free, int window = 40);

// A differential drive (wheel radius kArcRadius_m, track kArcTrack_m) driving 0.1 m/s forward while turning at
// 0.5 rad/s from yaw0_rad at start_m, sampled every kArcDt_s: its cumulative wheel angles (stream "wheels", rad) and
// motion-capture poses (stream "mocap"), `samples` of each at the same stamps.
constexpr double kArcRadius_m = 0.04, kArcTrack_m = 0.2, kArcDt_s = 0.05;
recording::Recording DiffDriveArcWithMotionCapture(int samples, double yaw0_rad, const Eigen::Vector2d& start_m);

// The noise of ArcConfigYaml's streams: the wheel rate (rad/s) and the motion capture's position (m) and orientation
// (rad).
struct ArcNoise {
  double wheel_radps = 0.5;
  double position_m = 0.0001;
  double orientation_rad = 0.001;
};

// An estimator configuration for DiffDriveArcWithMotionCapture's streams: the wheels as the differential-drive master
// (one free radius for both wheels and a free baseline, starting at the arc's true values) and the motion capture as
// absolute poses. `sections` is further top-level YAML (tracking, gating), each line ending in a newline.
std::string ArcConfigYaml(const ArcNoise& noise, const std::string& sections = "");

}  // namespace roamlab::estimator::testing
