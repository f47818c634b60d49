// The step of `roamlab init`: a nominal estimator configuration (EST.yaml, estimator/config.h) written from what a
// recording states about itself, for `calibrate`, `track` and `diagnose` on a robot without a hand-written one.
//
// Each stream type maps to its model:
//   wheel_encoders   by platform kind: differential_drive and skid_steer -> differential_drive, omni3 ->
//                    omni3_drive, mecanum -> mecanum_drive, ackermann -> ackermann (speed in m/s, with the recording's
//                    steering stream); the master. One radius for all wheels, free (the odometry's scale), from
//                    platform.geometry wheel_radius_m (else the mean of wheel_radius_<column>_m); the yaw lever arm
//                    fixed (baseline_m or track_m; wheel_distance_m; half_length_m + half_width_m); ackermann:
//                    wheelbase_m, kv_over_L and k_theta free, k_gamma fixed at 0.
//   odometry         odometer when it is the master (no wheel model), else linear_velocity; left out when a wheel
//                    stream was derived from it (attribute derived_from_odometry: the same information twice).
//   visual_odometry, scan_matching
//                    relative_motion; odometer as the master when the recording has nothing better.
//   imu              gyroscope and accelerometer sharing one misalignment (free, from the stream's mounting), the
//                    gyroscope bias free; gyroscope, accelerometer streams alike with a misalignment of their own.
//   gps, position    gps, the lever arm from the stream's mounting: free on an ackermann vehicle (as
//                    configs/atv_calibration.yaml), fixed on the other kinds, which move in a plane (its height is
//                    unobservable there and its horizontal offset trades with the IMU's yaw).
//   pose             absolute_pose, its mounting fixed (the reference the rest is calibrated against); left out when
//                    it is an odometry's pose (<odometry>_pose beside an odometry stream <odometry>, as the ROS bag
//                    importer writes a nav_msgs/Odometry): dead-reckoned, not an absolute reference.
//   magnetometer, steering (outside ackermann), camera, laser_scan, inputs
//                    left out, each with its reason (the magnetometer model needs the field in W, which a recording
//                    does not state; camera and laser_scan need a front end, `roamlab frontend`).
// Noise: the stream's stated `noise` entries, else a documented default per type (wheel encoders: the quantization of
// ticks_per_revolution over one sample period when stated). Free parameters are staged as
// configs/atv_calibration.yaml: lever arms and misalignments, then the odometric gains and biases, then all jointly
// (one stage when either group is empty). No outlier gate and no robust loss: the diagnosis compares Gaussian costs.
// Every key of the written YAML has a comment line above it saying where its value came from; the configuration is
// parsed back (estimator::ParseEstimatorConfig) and bound to the recording (estimator::ProblemBuilder::Create) before
// it is returned, so a file the estimator would refuse is never written.
#pragma once

#include <string>
#include <vector>

#include "common/status.h"
#include "estimator/config.h"
#include "experiment/steps.h"
#include "recording/recording.h"

namespace roamlab::experiment {

struct InitConfig {
  std::string yaml;                   // the commented EST.yaml text
  estimator::EstimatorConfig config;  // the text parsed back
  std::string platform_kind;          // the kind the wheel model was chosen by
  std::vector<std::string> left_out;  // "<stream> (<type>): <reason>", one per stream not used
};

// The nominal configuration of `recording` (read from `recording_path`, named in messages and comments);
// `platform_kind` overrides the recording's platform.kind when not empty. Errors (bad input): an unknown platform
// kind given, no stream that can make poses, a geometry key the wheel model needs missing.
Result<InitConfig> NominalConfigFromRecording(const recording::Recording& recording, const std::string& recording_path,
                                              const std::string& platform_kind = "");

// The platform kinds NominalConfigFromRecording knows a wheel model for.
const std::vector<std::string>& InitPlatformKinds();

struct InitRequest {
  std::string recording;      // REC
  std::string out;            // EST.yaml
  std::string platform_kind;  // "" = the recording's
};
// Reads REC (without ground truth), builds its nominal configuration and writes it to request.out (creating the
// parent directory). A recording that does not load or cannot make a configuration is bad input; a file that cannot
// be written is a failure. `result` (optional) receives the configuration.
Outcome InitToFile(const InitRequest& request, InitConfig* result = nullptr);

}  // namespace roamlab::experiment
