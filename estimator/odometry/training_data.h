// Training data for model-free odometry (seed 001, Sections III and IV-B4): key times T seconds apart, the wheel
// rotations delta_jk between consecutive key times (m wheels) and the exteroceptive sensor's planar displacement
// s_jk = (-)s_j (+) s_k with its covariance.
//
// Inputs come from a recording (recording/recording.h):
//   - a wheel_encoders stream, one column per wheel, in rad (cumulative wheel angle: the reader turns ticks into rad
//     with ticks_per_revolution) or rad/s (integrated here by the trapezoidal rule). delta_jk is the difference of the
//     cumulative angles, linearly interpolated at the key times. Any linear unit gives the same learned model up to
//     the scale of C and W; rad keeps encoders of different resolution comparable.
//     A tricycle (platform.kind tricycle: one wheel column and a steering stream [rad]) is not linear in its wheel
//     angle: its two columns are <wheel>_cos_steering and <wheel>_sin_steering, the running sums of the wheel
//     increments times cos and sin of the measured steering angle (mean of each encoder interval's ends). Its motion
//     is linear in those (v_x ~ cos(delta + offset), omega ~ sin(delta + offset) for any steering offset).
//   - either a pose stream (absolute pose of the exteroceptive sensor: motion capture, or a SLAM trajectory): its
//     planar part (x, y, yaw) is interpolated at the key times (position linearly, heading along the shorter arc),
//     s_jk = (-)s_j (+) s_k. Noise from the stream's noise entry: position_m and orientation_rad (the absolute_pose
//     model's keys; defaults kDefaultPositionSigma_m, kDefaultOrientationSigma_rad); the displacement then has the
//     covariance diag(2 sp^2, 2 sp^2, 2 so^2) (independent pose errors, first order, cross terms dropped).
//   - or an interval stream (scan_matching: the sensor's velocity between consecutive scans, a row stamped t covering
//     [t - dt/2, t + dt/2] with dt = 1 / rate_hz, the rotate-half/translate/rotate-half form of sim/simulator.cc): each
//     row's displacement d = (R(theta / 2) v dt, theta = omega_z dt) and s_jk = d_1 (+) d_2 (+) ... over the rows that
//     exactly tile [t_j, t_k]; the key times then lie on the rows' grid (T a whole number of row periods), and a key
//     interval with a missing row (a failed scan match) gives no pair. Each row has the covariance
//     diag((sv dt)^2, (sv dt)^2, (sw dt)^2) from the noise entry (sigma_mps, sigma_radps), propagated to first order
//     through (+) (Jacobians of Table I's operator).
//   Either displacement is carried from the sensor frame S to O with the stream's mounting l (the hand-measured
//   extrinsic of the recording metadata; identity when absent): q_jk = l (+) s_jk (+) (-)l, covariance J Sigma J^T.
// The learner never reads ground_truth.tum or truth.yaml; evaluation reads the reference separately.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "common/time.h"
#include "estimator/odometry/se2.h"
#include "recording/recording.h"

namespace roamlab::estimator::odometry {

inline constexpr double kDefaultPositionSigma_m = 0.001;
inline constexpr double kDefaultOrientationSigma_rad = 0.002;

struct KeyTimeOptions {
  double interval_s = 0.5;       // T, the spacing of the key times
  std::string encoder_stream;    // "" = the only wheel_encoders stream
  std::string sensor_stream;     // "" = the only pose stream, else the only scan_matching stream; unused (and not
                                 // required) by CutAtKeyTimes(..., false)
  std::string Validate() const;  // "" when valid
};

// One recording cut at key times t_0 < t_1 < ... (T apart, from the first time both streams cover).
struct KeySequence {
  std::vector<std::string> wheels;  // encoder column names
  std::vector<Time> t;              // key times
  Eigen::MatrixXd wheel_angle_rad;  // rows = key times, columns = wheels: cumulative angle
  // With a sensor, for k = 1..size()-1 (index k-1): the displacement q_(k-1)k in O, its standard deviations
  // (diagonal of the covariance; [m, m, rad]) and whether the sensor covered the interval.
  std::vector<Pose2> sensor_step;
  Eigen::MatrixXd sensor_step_sigma;
  std::vector<bool> step_valid;

  int size() const { return static_cast<int>(t.size()); }
  // delta_(k-1)k for k = 1..size()-1: (size()-1) x m.
  Eigen::MatrixXd WheelIncrements() const;
};

// Cuts `recording` at key times. With with_sensor, also the sensor poses (the key times then lie inside both streams).
// Errors name the recording and the problem: no or several candidate streams, a named stream missing or of the wrong
// type, unsupported encoder units, fewer than two key times.
Result<KeySequence> CutAtKeyTimes(const recording::Recording& recording, const std::string& recording_name,
                                  const KeyTimeOptions& options, bool with_sensor);

// Training pairs D = (delta_jk, s_jk) stacked over one or more sequences (n rows).
struct TrainingSet {
  std::vector<std::string> wheels;
  Eigen::MatrixXd delta;    // n x m wheel rotations [rad]
  Eigen::MatrixXd s;        // n x 3 sensor displacements [m, m, rad]
  Eigen::MatrixXd s_sigma;  // n x 3 standard deviations of s (diagonal of Sigma_jk)

  int size() const { return static_cast<int>(delta.rows()); }
};

// Consecutive key pairs (k-1, k) of every sequence that the sensor covered; all sequences must have the same wheel
// names and sensor steps.
Result<TrainingSet> MakeTrainingSet(const std::vector<KeySequence>& sequences);

}  // namespace roamlab::estimator::odometry
