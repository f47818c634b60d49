// Four-wheel mecanum odometer in measurement space (the holonomic sibling of omni3_drive.h and differential_drive.h:
// a logical odometer on the forward kinematics, seed 000 eqs. 5-8, with the wheel radii and the half-track sum as
// calibration parameters). The body velocities between two poses predict the four wheel rates.
//
//   v^(O), omega^(O) = VelocitiesBetween(pose_k, pose_k+1, dt)        (eq. 7 inverted; middle of the interval)
//   z_i_hat = (v_x + s_i v_y + w_i K omega_z) / r_i,    s = (-1, +1, +1, -1),  w = (-1, +1, -1, +1)
//   e = [z_i_hat - z_i (i = 0..3);  v_z;  omega_x;  omega_y] + eta                                   e in R^7
//
// Wheels 0-3 front left, front right, rear left, rear right at (+-lx, +-ly), rolling along +x, 45 deg rollers in the
// X layout (models/mecanum.xml, recording/wheel_kinematics.h): the roller under wheel i is locked along
// u_i = (1, s_i) / sqrt(2), so u_i . (v + omega_z e_z x p_i) = r_i z_i / sqrt(2) gives the rows above with
// K = lx + ly. lx and ly enter only through their sum: K is the parameter (they cannot be told apart from the wheel
// rates). The graph builder's initial guess for a new pose uses the least-squares inverse (BodyVelocity).
//
// Frames: O at the centre of the four contact points (x forward, z up). Measurements: z_i mean wheel rates over
// [t_k, t_k+1] [rad/s]. Calibration: radius_0 .. radius_3 r_i [m], lx_plus_ly K [m].
// Noise eta = [sigma_wheel (rad/s) x 4, vertical (m/s), tilt (rad/s) x 2], as omni3_drive.h.
// Variables: pose at t_k, pose at t_k+1 (PoseBlock), r_0 .. r_3, K (ScalarBlock each).
#pragma once

#include <tuple>

#include <Eigen/Core>
#include <Eigen/QR>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"
#include "recording/wheel_kinematics.h"

namespace roamlab::estimator {

class MecanumDriveError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, ScalarBlock, ScalarBlock, ScalarBlock, ScalarBlock, ScalarBlock>;
  static constexpr int kResidualDim = 7;
  static constexpr int kNoiseDim = 7;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // z_radps: mean wheel rates over the interval (front left, front right, rear left, rear right); dt_s > 0.
  MecanumDriveError(const Eigen::Vector4d& z_radps, double dt_s) : z_radps_(z_radps), dt_s_(dt_s) {
    ROAMLAB_CHECK(dt_s > 0.0, "mecanum drive dt " << dt_s);
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    Vector3<T> v_body, omega_body;
    VelocitiesBetween<T>(PoseFromArray(x[0]), PoseFromArray(x[1]), T(dt_s_), &v_body, &omega_body);
    const T turn = omega_body.z() * x[6][0];
    for (int i = 0; i < 4; ++i)
      error[i] = (v_body.x() + T(kSideSign[i]) * v_body.y() + T(kTurnSign[i]) * turn) / x[2 + i][0] - T(z_radps_[i]) +
                 noise[i];
    error[4] = v_body.z() + noise[4];
    error[5] = omega_body.x() + noise[5];
    error[6] = omega_body.y() + noise[6];
    return true;
  }

  // Forward kinematics: the least-squares body velocities of O from the four wheel rates.
  static void BodyVelocity(const Eigen::Vector4d& z_radps, const Eigen::Vector4d& radii_m, double lx_plus_ly_m,
                           Eigen::Vector3d* v_body, Eigen::Vector3d* omega_body) {
    const Eigen::Vector3d twist =
        recording::MecanumRatesFromTwist(radii_m, lx_plus_ly_m).colPivHouseholderQr().solve(z_radps);
    *v_body = Eigen::Vector3d(twist[0], twist[1], 0.0);
    *omega_body = Eigen::Vector3d(0.0, 0.0, twist[2]);
  }

  static constexpr double kSideSign[4] = {-1.0, 1.0, 1.0, -1.0};
  static constexpr double kTurnSign[4] = {-1.0, 1.0, -1.0, 1.0};

 private:
  Eigen::Vector4d z_radps_;
  double dt_s_;
};

}  // namespace roamlab::estimator
