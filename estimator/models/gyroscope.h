// Three-axis gyroscope, as an orientation constraint between two consecutive poses. Seed 000, eqs. 11-12.
//
//   z = k_s o omega^(S) + b + eta                                  (sensor model: per-axis scale, bias, noise)
//   omega_hat^(S) = (z - b - eta) ./ k_s,     omega_hat^(O) = q_S^O omega_hat^(S)
//   q_hat_O^W(t+1) = Phi(q_O^W(t), omega_hat^(O), dt) = q_O^W(t) Exp(omega_hat^(O) dt)           (eq. 11)
//   e = Log(q_hat_O^W(t+1) (q_O^W(t+1))^-1)                                                    (eq. 12)
//                                                         e [rad] in R^3, eta [rad/s] in R^3
//
// Frames: q_O^W(t), q_O^W(t+1): orientation of the odometric frame O in the world W at the two time stamps (only the
// orientations are used). The reading z is the angular rate of the sensor frame S in S [rad/s], held constant over
// dt = t(k+1) - t(k) [s]. Calibration: q_S^O = misalignment q_body_sensor (unit quaternion), b = bias [rad/s],
// k_s = per-axis scale (gain, dimensionless, nominally 1; must stay away from 0).
// Noise: eta ~ N(0, sigma^2 I), sigma [rad/s]. It enters where the bias does, before the scale is undone, so at e = 0
// J_e_eta = -dt R(q_O^W(t+1)) R(q_S^O) diag(1/k_s) up to O(|omega dt|) terms: not a constant.
// The error is the full-angle rotation vector of the error quaternion (geometry.h), expressed in W because the error
// quaternion multiplies from the left; the seed keeps the vector part, which is half of it near the identity.
// Variables: pose at t(k) (PoseBlock), pose at t(k+1) (PoseBlock), q_body_sensor (QuaternionBlock), bias
// (Vector3Block), scale (Vector3Block).
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

class GyroscopeError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, QuaternionBlock, Vector3Block, Vector3Block>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;

  // z_radps: the reading [rad/s] in the sensor frame; dt_s: t(k+1) - t(k) [s], > 0.
  GyroscopeError(const Eigen::Vector3d& z_radps, double dt_s) : z_radps_(z_radps), dt_s_(dt_s) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Pose<T> pose_k = PoseFromArray(x[0]);
    const Pose<T> pose_k1 = PoseFromArray(x[1]);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[2]);
    const Eigen::Map<const Vector3<T>> bias(x[3]);
    const Eigen::Map<const Vector3<T>> scale(x[4]);
    const Eigen::Map<const Vector3<T>> eta(noise);
    Eigen::Map<Vector3<T>> e(error);

    // Undo bias, noise and scale, then rotate the rate into O.
    const Vector3<T> omega_sensor = (z_radps_.cast<T>() - bias - eta).cwiseQuotient(scale);
    const Vector3<T> omega_body = q_body_sensor * omega_sensor;

    // Integrate over dt (eq. 11) and compare with the orientation at t(k+1) (eq. 12).
    const Quaternion<T> q_hat = Phi<T>(pose_k.q_world_body, omega_body, T(dt_s_));
    e = QuaternionLog<T>(q_hat * pose_k1.q_world_body.conjugate());
    return true;
  }

 private:
  Eigen::Vector3d z_radps_;
  double dt_s_;
};

}  // namespace roamlab::estimator
