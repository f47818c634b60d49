// Tricycle odometer in measurement space (the steered sibling of differential_drive.h: a logical odometer on the
// forward kinematics, seed 000 eqs. 5-8, with the wheel radius, the wheel-to-axle distance and the steering offset as
// calibration parameters). One front wheel is both steered and driven; the rear wheels are unpowered on a fixed axle.
// The body velocities between two poses predict the front wheel's rate and steering angle.
//
//   v^(O), omega^(O) = VelocitiesBetween(pose_k, pose_k+1, dt)        (eq. 7 inverted; middle of the interval)
//   delta = z_delta + offset                     the true steering angle (z_delta as measured; positive: turning left)
//   u = (v_x, v_y + omega_z L)                   the velocity of the front wheel's contact point, L ahead of O
//   z_w_hat = (u_x cos delta + u_y sin delta) / r                     its rate: u along the wheel's rolling direction
//   e_delta = (-u_x sin delta + u_y cos delta) / (r max(|z_w|, w_min))   u across the wheel, per measured rim speed
//   e = [z_w_hat - z_w;  e_delta;  v_y;  v_z;  omega_x;  omega_y] + eta                               e in R^6
//
// e_delta is the steering row: |u| sin(delta_hat - delta) / (r |z_w|) with delta_hat = atan2(u_y, u_x), i.e. the
// predicted minus the measured steering angle [rad] to first order (sign-flipped when reversing; the noise is
// symmetric), without atan2's singularity at standstill: below w_min = kMinWheelRate the divisor stays r w_min and
// the row tends to the front wheel's side-slip velocity, zero when the robot stands still. The forward kinematics
// (recording/wheel_kinematics.h TricycleTwist) that the graph builder uses for a new pose's initial guess:
//   v_x = r z_w cos delta,  omega_z = r z_w sin delta / L,  v_y = v_z = 0.
// Measurement space for the reason given in differential_drive.h: the reading noise stays additive, so calibrating
// r, L and the offset is not biased by errors in variables. O is the middle of the rear axle (the only point without
// side slip), so no displacement or misalignment.
//
// Frames: O at the middle of the rear axle (x forward, towards the front wheel; z up). Measurements: z_w the front
// wheel's mean rate over [t_k, t_k+1] [rad/s] (difference of cumulative encoder angles over dt), z_delta its steering
// angle over the interval [rad] (the mean of the interval's ends).
// Calibration: radius r [m], wheel_to_axle L [m], steering_offset [rad] (true = measured + offset).
// Noise eta = [sigma_wheel (rad/s), sigma_steering (rad), lateral (m/s), vertical (m/s), tilt (rad/s) x 2]: encoder
// quantization and slip, the steering encoder's resolution and play, and the planar, non-holonomic slack (no side
// slip of the rear axle, no motion off the floor, no roll or pitch rate). Give the stream a robust loss (slip).
// Variables: pose at t_k, pose at t_k+1 (PoseBlock), r, L, offset (ScalarBlock each). Jacobians by the jets
// (factor.h); tests/estimator/models/tricycle_drive_test.cc checks them against central differences.
#pragma once

#include <algorithm>
#include <cmath>
#include <tuple>

#include <Eigen/Core>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"
#include "recording/wheel_kinematics.h"

namespace roamlab::estimator {

class TricycleDriveError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, ScalarBlock, ScalarBlock, ScalarBlock>;
  static constexpr int kResidualDim = 6;
  static constexpr int kNoiseDim = 6;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta
  static constexpr double kMinWheelRate = 0.5;  // w_min [rad/s]

  // z_wheel_radps: the front wheel's mean rate over the interval; z_steering_rad: the measured steering angle;
  // dt_s = t_k+1 - t_k > 0.
  TricycleDriveError(double z_wheel_radps, double z_steering_rad, double dt_s)
      : z_wheel_radps_(z_wheel_radps), z_steering_rad_(z_steering_rad), dt_s_(dt_s) {
    ROAMLAB_CHECK(dt_s > 0.0, "tricycle drive dt " << dt_s);
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    using std::cos;
    using std::sin;
    Vector3<T> v_body, omega_body;
    VelocitiesBetween<T>(PoseFromArray(x[0]), PoseFromArray(x[1]), T(dt_s_), &v_body, &omega_body);
    const T& radius = x[2][0];
    const T delta = T(z_steering_rad_) + x[4][0];
    const T u_x = v_body.x();
    const T u_y = v_body.y() + omega_body.z() * x[3][0];
    const T c = cos(delta), s = sin(delta);
    error[0] = (u_x * c + u_y * s) / radius - T(z_wheel_radps_) + noise[0];
    error[1] = (u_y * c - u_x * s) / (radius * T(std::max(std::abs(z_wheel_radps_), kMinWheelRate))) + noise[1];
    error[2] = v_body.y() + noise[2];
    error[3] = v_body.z() + noise[3];
    error[4] = omega_body.x() + noise[4];
    error[5] = omega_body.y() + noise[5];
    return true;
  }

  // Forward kinematics: the body velocities of O from the wheel rate and the measured steering angle.
  static void BodyVelocity(double z_wheel_radps, double z_steering_rad, double radius_m, double wheel_to_axle_m,
                           double steering_offset_rad, Eigen::Vector3d* v_body, Eigen::Vector3d* omega_body) {
    const Eigen::Vector3d twist =
        recording::TricycleTwist(z_wheel_radps, z_steering_rad + steering_offset_rad, radius_m, wheel_to_axle_m);
    *v_body = Eigen::Vector3d(twist[0], twist[1], 0.0);
    *omega_body = Eigen::Vector3d(0.0, 0.0, twist[2]);
  }

 private:
  double z_wheel_radps_;
  double z_steering_rad_;
  double dt_s_;
};

}  // namespace roamlab::estimator
