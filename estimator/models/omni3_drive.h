// Three-wheel omnidirectional odometer in measurement space (seed 000, Section VI: the Triskar2 robot's logical
// odometer built on its forward kinematics, eqs. 5-8, with the wheel radii and the wheels' distance from O as
// calibration parameters). The body velocities between two poses predict the three wheel rates, and the error is the
// difference to the encoder rates.
//
//   v^(O), omega^(O) = VelocitiesBetween(pose_k, pose_k+1, dt)        (eq. 7 inverted; middle of the interval)
//   z_i_hat = (-sin alpha_i v_x + cos alpha_i v_y + L omega_z) / r_i,   alpha_i = 60, 180, 300 deg    (i = 0, 1, 2)
//   e = [z_0_hat - z_0;  z_1_hat - z_1;  z_2_hat - z_2;  v_z;  omega_x;  omega_y] + eta              e in R^6
//
// Wheel i touches the floor at L (cos alpha_i, sin alpha_i) and pushes the body along the counter-clockwise tangent
// d_i = (-sin alpha_i, cos alpha_i); its rollers absorb the radial component, so the three rows see v_x, v_y and
// omega_z (recording/wheel_kinematics.h, the same rows). The forward kinematics that the graph builder uses for a new
// pose's initial guess (eq. 7) is the inverse of the 3 x 3 matrix of the first three rows (BodyVelocity).
// Measurement space for the reason given in differential_drive.h: the reading noise stays additive, so calibrating
// r_i and L is not biased by errors in variables. O is the robot's centre, so no displacement or misalignment.
//
// Frames: O at the centre of the wheels' contact circle (x forward between wheels 0 and 2, z up). Measurements: z_i
// mean wheel rates over [t_k, t_k+1] [rad/s] (differences of cumulative encoder angles over dt).
// Calibration: radius_0, radius_1, radius_2 r_i [m], distance L [m].
// Noise eta = [sigma_wheel (rad/s) x 3, vertical (m/s), tilt (rad/s) x 2]: encoder quantization and slip on the wheel
// rows; no motion off the floor and no roll or pitch rate on a flat floor on the others (the rollers make the body
// rock: the tilt noise must cover it). Slip is not Gaussian: give the stream a robust loss (seed Section VI).
// Variables: pose at t_k, pose at t_k+1 (PoseBlock), r_0, r_1, r_2, L (ScalarBlock each).
#pragma once

#include <cmath>
#include <tuple>

#include <Eigen/Core>
#include <Eigen/LU>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"
#include "recording/wheel_kinematics.h"

namespace roamlab::estimator {

class Omni3DriveError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, ScalarBlock, ScalarBlock, ScalarBlock, ScalarBlock>;
  static constexpr int kResidualDim = 6;
  static constexpr int kNoiseDim = 6;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // z_radps: mean wheel rates over the interval (wheels 0, 1, 2); dt_s = t_k+1 - t_k > 0.
  Omni3DriveError(const Eigen::Vector3d& z_radps, double dt_s) : z_radps_(z_radps), dt_s_(dt_s) {
    ROAMLAB_CHECK(dt_s > 0.0, "omni3 drive dt " << dt_s);
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    Vector3<T> v_body, omega_body;
    VelocitiesBetween<T>(PoseFromArray(x[0]), PoseFromArray(x[1]), T(dt_s_), &v_body, &omega_body);
    const T tangential = omega_body.z() * x[5][0];
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d d = RollingDirection(i);
      error[i] = (T(d.x()) * v_body.x() + T(d.y()) * v_body.y() + tangential) / x[2 + i][0] - T(z_radps_[i]) + noise[i];
    }
    error[3] = v_body.z() + noise[3];
    error[4] = omega_body.x() + noise[4];
    error[5] = omega_body.y() + noise[5];
    return true;
  }

  // d_i = (-sin alpha_i, cos alpha_i), alpha_i = 60 + 120 i deg.
  static Eigen::Vector2d RollingDirection(int i) {
    constexpr double kPi = 3.14159265358979323846;
    const double alpha = (60.0 + 120.0 * i) * kPi / 180.0;
    return Eigen::Vector2d(-std::sin(alpha), std::cos(alpha));
  }

  // Forward kinematics: the body velocities of O from the three wheel rates (the wheel rows inverted).
  static void BodyVelocity(const Eigen::Vector3d& z_radps, const Eigen::Vector3d& radii_m, double distance_m,
                           Eigen::Vector3d* v_body, Eigen::Vector3d* omega_body) {
    const Eigen::Vector3d twist = recording::Omni3RatesFromTwist(radii_m, distance_m).inverse() * z_radps;
    *v_body = Eigen::Vector3d(twist[0], twist[1], 0.0);
    *omega_body = Eigen::Vector3d(0.0, 0.0, twist[2]);
  }

 private:
  Eigen::Vector3d z_radps_;
  double dt_s_;
};

}  // namespace roamlab::estimator
