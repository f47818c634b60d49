// Generic odometer: any logical sensor that outputs its own linear and angular velocity (wheel odometry, visual
// odometry, scan matching, a kinematic model with control inputs). Seed 000, eqs. 5-8.
//
//   v_hat^(S) = z_v + eta_v,   omega_hat^(S) = z_omega + eta_omega                      z, eta in R^6
//   v_hat^(O) = q_S^O [v_hat^(S) - omega_hat^(S) x ((q_S^O)^-1 S^(O))],   omega_hat^(O) = q_S^O omega_hat^(S)   (eq. 5)
//   q_mid = q_O^W(t_k) Exp(omega_hat^(O) dt / 2)                                        (eqs. 6-7)
//   O_hat^(W)(t_k+1) = O^(W)(t_k) + q_mid v_hat^(O) dt
//   q_hat_O^W(t_k+1) = q_O^W(t_k) Exp(omega_hat^(O) dt)
//   e = [O_hat^(W)(t_k+1) - O^(W)(t_k+1);  Log(q_hat_O^W(t_k+1) (q_O^W(t_k+1))^-1)]    (eq. 8)      e in R^6
//
// Frames: O^(W), q_O^W: poses of the odometric frame in the world W at t_k and t_k+1. S: the sensor frame, whose
// velocities the sensor reports, expressed in S itself. The position error is in W [m]; the orientation error is a
// full-angle rotation vector in W [rad] (geometry.h; the seed keeps the vector part of the error quaternion instead).
// Measurement z = [v^(S) (m/s); omega^(S) (rad/s)], held constant over [t_k, t_k+1], dt = t_k+1 - t_k [s].
// Calibration: S^(O) = p_body_sensor, displacement of S in O [m] ("displacement"); q_S^O = q_body_sensor, misalignment
// of S in O ([w, x, y, z], "misalignment").
// Noise: eta = [eta_v (m/s); eta_omega (rad/s)] added to z, eta ~ N(0, diag(sigma_v^2 I3, sigma_omega^2 I3)).
// Variables: pose at t_k (PoseBlock), pose at t_k+1 (PoseBlock), displacement (Vector3Block), misalignment
// (QuaternionBlock).
//
// The prediction of eqs. 7-8 is shared by every velocity-domain model (OdometryPoseError below, used also by
// AckermannOdometerError).
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

// Eqs. 7-8: predicts the pose at t_k+1 from the pose at t_k and the velocities of O held for dt [s], and writes the
// 6-dim error [p_hat - p_k+1 (W, m); Log(q_hat q_k+1^-1) (W, rad)] to `error`.
template <typename T>
void OdometryPoseError(const Pose<T>& pose_k, const Pose<T>& pose_k1, const Vector3<T>& v_body,
                       const Vector3<T>& omega_body, const T& dt, T* error) {
  const Pose<T> predicted = PredictPose<T>(pose_k, v_body, omega_body, dt);
  Eigen::Map<Vector3<T>> e_position(error);
  Eigen::Map<Vector3<T>> e_orientation(error + 3);
  e_position = predicted.p_world_body - pose_k1.p_world_body;
  e_orientation = QuaternionLog<T>(predicted.q_world_body * pose_k1.q_world_body.conjugate());
}

class OdometerError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, Vector3Block, QuaternionBlock>;
  static constexpr int kResidualDim = 6;
  static constexpr int kNoiseDim = 6;

  // z_sensor = [v^(S) (m/s); omega^(S) (rad/s)]; dt_s = t_k+1 - t_k > 0.
  OdometerError(const Eigen::Matrix<double, 6, 1>& z_sensor, double dt_s) : z_sensor_(z_sensor), dt_s_(dt_s) {
    ROAMLAB_CHECK(dt_s > 0.0, "odometer dt " << dt_s);
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Pose<T> pose_k = PoseFromArray(x[0]);
    const Pose<T> pose_k1 = PoseFromArray(x[1]);
    const Eigen::Map<const Vector3<T>> p_body_sensor(x[2]);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[3]);

    // Noisy sensor-frame velocities, then eq. 5.
    const Vector3<T> v_sensor = z_sensor_.head<3>().cast<T>() + Eigen::Map<const Vector3<T>>(noise);
    const Vector3<T> omega_sensor = z_sensor_.tail<3>().cast<T>() + Eigen::Map<const Vector3<T>>(noise + 3);
    Vector3<T> v_body;
    Vector3<T> omega_body;
    SensorToBodyVelocity<T>(v_sensor, omega_sensor, q_body_sensor, Vector3<T>(p_body_sensor), &v_body, &omega_body);

    // Eqs. 7-8.
    OdometryPoseError<T>(pose_k, pose_k1, v_body, omega_body, T(dt_s_), error);
    return true;
  }

  const Eigen::Matrix<double, 6, 1>& z_sensor() const { return z_sensor_; }
  double dt_s() const { return dt_s_; }

 private:
  Eigen::Matrix<double, 6, 1> z_sensor_;
  double dt_s_;
};

}  // namespace roamlab::estimator
