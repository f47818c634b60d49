// Linear velocity of a sensor in its own frame (Pitot tube, wheel speed sensor, Doppler radar), as a constraint
// between two consecutive poses. Seed 000, eqs. 5 and 7 (the odometer's velocity relation, inverted).
//
//   (v^(O), omega^(O)) = VelocitiesBetween(Gamma_O^W(t_k), Gamma_O^W(t_k+1), dt)                 (eq. 7 inverted)
//   v_hat^(S) = (q_S^O)^-1 (v^(O) + omega^(O) x S^(O))                              (eq. 5 solved for v^(S))
//   e = v_hat^(S) + eta - z                                             e [m/s] in R^3, eta [m/s] in R^3
//
// Frames: the two poses of the odometric frame O in the world W, dt = t(k+1) - t(k) [s] apart. v^(O) is the chord
// velocity of O seen from the orientation half-way through the interval, omega^(O) the body rate over the interval,
// so the prediction refers to the middle of [t_k, t_k+1]; it is exact for motion at constant body-frame v and omega
// composed as in eq. 7 (rotate half, translate, rotate half) and in error by O((omega dt)^2) relative on a circle.
// The reading z is the velocity of the sensor's origin relative to W, in the sensor frame S [m/s], all three axes. A
// sensor that measures fewer components (a Pitot tube or a wheel encoder: one) needs a variant that keeps only those
// rows; this model always returns three.
// Calibration: S^(O) = position of S in O [m]; q_S^O = misalignment q_body_sensor (unit quaternion).
// Noise: eta ~ N(0, sigma^2 I), sigma [m/s]; J_e_eta = I.
// Variables: pose at t_k (PoseBlock), pose at t_k+1 (PoseBlock), S^(O) (Vector3Block), q_body_sensor
// (QuaternionBlock).
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

class LinearVelocityError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, Vector3Block, QuaternionBlock>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // z_mps: the sensor's velocity [m/s] in its own frame; dt_s: t(k+1) - t(k) [s], > 0.
  LinearVelocityError(const Eigen::Vector3d& z_mps, double dt_s) : z_mps_(z_mps), dt_s_(dt_s) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Pose<T> pose_k = PoseFromArray(x[0]);
    const Pose<T> pose_k1 = PoseFromArray(x[1]);
    const Eigen::Map<const Vector3<T>> p_body_sensor(x[2]);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[3]);
    const Eigen::Map<const Vector3<T>> eta(noise);
    Eigen::Map<Vector3<T>> e(error);

    // Velocities of O over the interval (eq. 7 inverted).
    Vector3<T> v_body;
    Vector3<T> omega_body;
    VelocitiesBetween<T>(pose_k, pose_k1, T(dt_s_), &v_body, &omega_body);

    // Velocity of the sensor's origin, in S (eq. 5).
    const Vector3<T> v_sensor = q_body_sensor.conjugate() * (v_body + omega_body.cross(p_body_sensor));
    e = v_sensor + eta - z_mps_.cast<T>();
    return true;
  }

 private:
  Eigen::Vector3d z_mps_;
  double dt_s_;
};

}  // namespace roamlab::estimator
