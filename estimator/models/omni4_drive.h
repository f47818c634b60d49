// Four-wheel omnidirectional odometer in measurement space (the X-layout sibling of omni3_drive.h and
// mecanum_drive.h: a logical odometer on the forward kinematics, seed 000 eqs. 5-8, with the wheel radii and the
// lever as calibration parameters). The body velocities between two poses predict the four wheel rates.
//
//   v^(O), omega^(O) = VelocitiesBetween(pose_k, pose_k+1, dt)        (eq. 7 inverted; middle of the interval)
//   z_i_hat = (d_i . (v_x, v_y) - K omega_z) / r_i,    K = (l1 + l2) / (2 sqrt 2)                       (i = 0..3)
//   e = [z_i_hat - z_i (i = 0..3);  v_z;  omega_x;  omega_y] + eta                                   e in R^7
//
// Wheels 0-3 front left, front right, rear left, rear right at (+-l1/2, +-l2/2), omni rollers, each wheel turned
// 45 deg (the OptiOdom robot's X layout, recording/wheel_kinematics.h omni4): a positive rotation of wheel i pushes
// the body along d_0 = (1, -1)/sqrt 2, d_1 = (-1, -1)/sqrt 2, d_2 = (1, 1)/sqrt 2, d_3 = (-1, 1)/sqrt 2 and turns it
// clockwise, with the lever p_i x d_i = -K for every wheel. The wheelbase l1 and the track l2 enter only through their
// sum: wheelbase_plus_track l1 + l2 is the parameter (the wheel rates cannot tell them apart). The graph builder's
// initial guess for a new pose uses the least-squares inverse (BodyVelocity).
//
// Frames: O at the centre of the four contact points (x forward, z up). Measurements: z_i mean wheel rates over
// [t_k, t_k+1] [rad/s]. Calibration: radius_0 .. radius_3 r_i [m], wheelbase_plus_track l1 + l2 [m].
// Noise eta = [sigma_wheel (rad/s) x 4, vertical (m/s), tilt (rad/s) x 2], as omni3_drive.h.
// Variables: pose at t_k, pose at t_k+1 (PoseBlock), r_0 .. r_3, l1 + l2 (ScalarBlock each). Jacobians by the jets
// (factor.h); tests/estimator/models/omni4_drive_test.cc checks them against central differences.
#pragma once

#include <cmath>
#include <tuple>

#include <Eigen/Core>
#include <Eigen/QR>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"
#include "recording/wheel_kinematics.h"

namespace roamlab::estimator {

class Omni4DriveError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, ScalarBlock, ScalarBlock, ScalarBlock, ScalarBlock, ScalarBlock>;
  static constexpr int kResidualDim = 7;
  static constexpr int kNoiseDim = 7;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // z_radps: mean wheel rates over the interval (front left, front right, rear left, rear right); dt_s > 0.
  Omni4DriveError(const Eigen::Vector4d& z_radps, double dt_s) : z_radps_(z_radps), dt_s_(dt_s) {
    ROAMLAB_CHECK(dt_s > 0.0, "omni4 drive dt " << dt_s);
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    Vector3<T> v_body, omega_body;
    VelocitiesBetween<T>(PoseFromArray(x[0]), PoseFromArray(x[1]), T(dt_s_), &v_body, &omega_body);
    const double c = 1.0 / std::sqrt(2.0);
    const T turn = omega_body.z() * x[6][0] * T(0.5 * c);
    for (int i = 0; i < 4; ++i)
      error[i] = (T(c * kSignX[i]) * v_body.x() + T(c * kSignY[i]) * v_body.y() - turn) / x[2 + i][0] - T(z_radps_[i]) +
                 noise[i];
    error[4] = v_body.z() + noise[4];
    error[5] = omega_body.x() + noise[5];
    error[6] = omega_body.y() + noise[6];
    return true;
  }

  // Forward kinematics: the least-squares body velocities of O from the four wheel rates; l1 + l2 split evenly (only
  // the sum matters).
  static void BodyVelocity(const Eigen::Vector4d& z_radps, const Eigen::Vector4d& radii_m,
                           double wheelbase_plus_track_m, Eigen::Vector3d* v_body, Eigen::Vector3d* omega_body) {
    const Eigen::Vector3d twist =
        recording::Omni4RatesFromTwist(radii_m, 0.5 * wheelbase_plus_track_m, 0.5 * wheelbase_plus_track_m)
            .colPivHouseholderQr()
            .solve(z_radps);
    *v_body = Eigen::Vector3d(twist[0], twist[1], 0.0);
    *omega_body = Eigen::Vector3d(0.0, 0.0, twist[2]);
  }

  // Signs of d_i's components (front left, front right, rear left, rear right).
  static constexpr double kSignX[4] = {1.0, -1.0, 1.0, -1.0};
  static constexpr double kSignY[4] = {-1.0, -1.0, 1.0, 1.0};

 private:
  Eigen::Vector4d z_radps_;
  double dt_s_;
};

}  // namespace roamlab::estimator
