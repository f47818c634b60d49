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
//
// Jacobians (Linearize; so3_jacobians.h for Jr, Jl^-1), with phi = omega_hat^(O) dt, R_k, R_k+1, R_hat the
// rotation matrices of q_O^W(t), q_O^W(t+1), q_hat and E = q_hat (q_O^W(t+1))^-1 = Exp(e):
//   pose k:    E' = q_k Exp(d) Exp(phi) q_k+1^-1 = Exp(R_k d) E            => J_e_theta_k = Jl^-1(e) R_k
//   pose k+1:  E' = E q_k+1 Exp(-d) q_k+1^-1 = Exp(-R_hat d) E             => J_e_theta_k+1 = -Jl^-1(e) R_hat
//   rate:      q_k Exp(phi + d) = q_hat Exp(Jr(phi) d)                     => M = d e / d omega^(O)
//                                                                             = dt Jl^-1(e) R_hat Jr(phi)
//   then, with omega^(O) = R_S (z - b - eta) ./ k_s:
//   J_e_qS = -M R_S [omega^(S)]x,   J_e_b = J_e_eta = -M R_S diag(1 ./ k_s),   J_e_ks = -M R_S diag(omega^(S) ./ k_s),
// and J_e_p = 0 for both positions.
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "estimator/geometry.h"
#include "estimator/manifold.h"
#include "estimator/so3_jacobians.h"

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

  // Analytic Jacobians (header comment), with Factor::Evaluate's layout and zero noise; fills only the requested
  // blocks and, when noise_jacobian is not null, J_e_eta.
  bool Linearize(const double* const* x, double* error, double* const* jacobians, double* noise_jacobian) const {
    const Quaternion<double> q_k = QuaternionFromArray(x[0] + 3);
    const Quaternion<double> q_k1 = QuaternionFromArray(x[1] + 3);
    const Quaternion<double> q_body_sensor = QuaternionFromArray(x[2]);
    const Eigen::Map<const Eigen::Vector3d> bias(x[3]);
    const Eigen::Map<const Eigen::Vector3d> scale(x[4]);
    Eigen::Map<Eigen::Vector3d> e(error);

    // As operator().
    const Eigen::Vector3d omega_sensor = (z_radps_ - bias).cwiseQuotient(scale);
    const Eigen::Vector3d omega_body = q_body_sensor * omega_sensor;
    const Eigen::Vector3d phi = omega_body * dt_s_;
    const Quaternion<double> q_hat = q_k * QuaternionExp<double>(phi);
    e = QuaternionLog<double>(q_hat * q_k1.conjugate());

    const auto wanted = [&](int i) { return jacobians != nullptr && jacobians[i] != nullptr; };
    const bool calibration_wanted = wanted(2) || wanted(3) || wanted(4) || noise_jacobian != nullptr;
    if (!wanted(0) && !wanted(1) && !calibration_wanted) return true;

    // Orientation blocks.
    const Eigen::Matrix3d jl_inv_e = InverseRightJacobianSO3(e).transpose();
    const Eigen::Matrix3d R_hat = q_hat.toRotationMatrix();
    if (wanted(0)) {
      Eigen::Map<Eigen::Matrix<double, 3, 6>> J_e_pose_k(jacobians[0]);
      J_e_pose_k.leftCols<3>().setZero();
      J_e_pose_k.rightCols<3>() = jl_inv_e * q_k.toRotationMatrix();
    }
    if (wanted(1)) {
      Eigen::Map<Eigen::Matrix<double, 3, 6>> J_e_pose_k1(jacobians[1]);
      J_e_pose_k1.leftCols<3>().setZero();
      J_e_pose_k1.rightCols<3>() = -jl_inv_e * R_hat;
    }
    if (!calibration_wanted) return true;

    // Through the rate: J_e_omega_sensor = M R_S; bias and noise enter as -diag(1 ./ k_s), the scale as
    // -diag(omega^(S) ./ k_s), the misalignment as -[omega^(S)]x.
    const Eigen::Matrix3d J_e_omega_sensor =
        (dt_s_ * jl_inv_e * R_hat * RightJacobianSO3(phi)) * q_body_sensor.toRotationMatrix();
    if (wanted(2)) Eigen::Map<Eigen::Matrix3d>{jacobians[2]} = -J_e_omega_sensor * Skew<double>(omega_sensor);
    const Eigen::Matrix3d J_e_bias = -J_e_omega_sensor * scale.cwiseInverse().asDiagonal();
    if (wanted(3)) Eigen::Map<Eigen::Matrix3d>{jacobians[3]} = J_e_bias;
    if (wanted(4))
      Eigen::Map<Eigen::Matrix3d>{jacobians[4]} = -J_e_omega_sensor * omega_sensor.cwiseQuotient(scale).asDiagonal();
    if (noise_jacobian != nullptr) Eigen::Map<Eigen::Matrix3d>{noise_jacobian} = J_e_bias;
    return true;
  }

 private:
  Eigen::Vector3d z_radps_;
  double dt_s_;
};

}  // namespace roamlab::estimator
