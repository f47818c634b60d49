// Absolute pose logical sensor: a SLAM system or motion capture reporting the pose of its frame S in the world.
// Seed 000, eq. 9 (the seed's absolute positioning model) extended with the orientation.
//
//   p_hat = O^(W) + q_O^W S^(O),      q_hat = q_O^W q_S^O
//   e = [ p_hat + eta_p - z_p ;  Log(z_q^-1 q_hat Exp(eta_theta)) ]       e, eta in R^6: [m, m, m, rad, rad, rad]
//
// Frames: O^(W), q_O^W: pose of the odometric frame O in the world W. The measurement is the pose of the sensor frame
// S in W: its origin z_p [m] and orientation z_q = q_world_sensor. The orientation error is a full-angle rotation
// vector in S (a right, sensor-frame error: z_q [+] e = q_hat at zero noise), and eta_theta perturbs q_hat on the
// right, so J_e_eta is I in the position rows and the inverse right Jacobian of Log (I at e = 0) in the orientation
// rows. W must be the sensor's own world frame (align it once, e.g. from the first pose, if it is not).
// Calibration: S^(O) = position of S in O [m] (lever arm); q_S^O = misalignment q_body_sensor (unit quaternion).
// Noise: eta_p ~ N(0, sigma_p^2 I) [m], eta_theta ~ N(0, sigma_theta^2 I) [rad].
// Variables: pose at the nearest time stamp (PoseBlock), S^(O) (Vector3Block), q_body_sensor (QuaternionBlock).
#pragma once

#include <tuple>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

class AbsolutePoseError {
 public:
  using Blocks = std::tuple<PoseBlock, Vector3Block, QuaternionBlock>;
  static constexpr int kResidualDim = 6;
  static constexpr int kNoiseDim = 6;

  // z_p_world: origin of S in W [m]; z_q_world_sensor: orientation of S in W (unit quaternion).
  AbsolutePoseError(const Eigen::Vector3d& z_p_world, const Eigen::Quaterniond& z_q_world_sensor)
      : z_p_world_(z_p_world), z_q_world_sensor_(z_q_world_sensor.normalized()) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Pose<T> pose = PoseFromArray(x[0]);
    const Eigen::Map<const Vector3<T>> p_body_sensor(x[1]);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[2]);
    const Eigen::Map<const Vector3<T>> eta_p(noise);
    const Eigen::Map<const Vector3<T>> eta_theta(noise + 3);
    Eigen::Map<Vector3<T>> e_p(error);
    Eigen::Map<Vector3<T>> e_theta(error + 3);

    // Position of S in W (eq. 9).
    e_p = pose.p_world_body + pose.q_world_body * p_body_sensor + eta_p - z_p_world_.cast<T>();

    // Orientation of S in W, compared in S.
    const Quaternion<T> q_world_sensor = pose.q_world_body * q_body_sensor * QuaternionExp<T>(eta_theta);
    e_theta = QuaternionLog<T>(z_q_world_sensor_.cast<T>().conjugate() * q_world_sensor);
    return true;
  }

 private:
  Eigen::Vector3d z_p_world_;
  Eigen::Quaterniond z_q_world_sensor_;
};

}  // namespace roamlab::estimator
