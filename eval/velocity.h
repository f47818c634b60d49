// Velocity accuracy of wheeled indoor robots (seed 000, Section VI and Fig. 6): estimated against true linear and
// angular velocity over time, for the encoders' forward kinematics alone and for the fused estimate, with the
// rotational relative pose error of each.
//
// Velocities between two poses are the interval estimators of eq. 7 inverted (as the estimator's velocity models use
// them): omega = Log(q_0^-1 q_1) / dt, v = R_mid^T (p_1 - p_0) / dt with R_mid the orientation rotated half-way, so
// that they refer to the middle of the interval and are independent of the world frame (no alignment needed).
//   fused           between consecutive poses of the estimate (trajectory.tum)
//   encoders_only   forward kinematics of the wheel-encoder stream with the nominal platform geometry
//                   (recording/wheel_kinematics.h), per encoder interval; dead-reckoned with eq. 7 for the RPE
//   truth           between the ground-truth poses stamped at the same interval ends (within the tolerance)
// Errors per interval: linear |(v_x, v_y)_est - (v_x, v_y)_true| [m/s] (the planar body velocity), angular
// |omega_z,est - omega_z,true| [rad/s]; each summarized by its RMSE.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "common/status.h"
#include "eval/metrics.h"
#include "recording/recording.h"
#include "recording/trajectory.h"

namespace roamlab::eval {

struct StampedTwist {
  Time t_begin, t_end;
  Eigen::Vector3d v_body = Eigen::Vector3d::Zero();      // [m/s], in O
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();  // [rad/s], in O
};

// Velocities between consecutive poses.
std::vector<StampedTwist> TrajectoryVelocities(const Trajectory& trajectory);

struct EncoderOdometry {
  std::vector<StampedTwist> twists;
  Trajectory dead_reckoning;  // from the identity at the first encoder stamp
};
// Forward kinematics of the recording's wheel-encoder stream (cumulative angles, rad), with the platform's nominal
// kinematics for that stream's columns (recording/wheel_kinematics.h). Errors: no wheeled platform, no such stream,
// or a geometry key missing.
Result<EncoderOdometry> EncoderOnlyOdometry(const recording::Recording& recording);

struct VelocityErrors {
  std::vector<double> t_s;             // interval middles, seconds since the truth's first stamp
  std::vector<StampedTwist> estimate;  // the compared intervals
  std::vector<StampedTwist> truth;
  ErrorStatistics linear_mps;
  ErrorStatistics angular_radps;
};
// Intervals of `estimate` whose two ends have ground-truth poses within tolerance_s.
VelocityErrors CompareVelocities(const std::vector<StampedTwist>& estimate, const Trajectory& truth,
                                 double tolerance_s);

// {"linear_rmse", "angular_rmse", "rpe_rot_deg", "intervals"}.
nlohmann::json VelocityJson(const VelocityErrors& errors, double rpe_rot_deg);

}  // namespace roamlab::eval
