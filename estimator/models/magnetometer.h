// Three-axis magnetometer with hard/soft iron distortion and misalignment. Seed 000, eq. 10.
//
//   z_hat = A (q_O^W q_S^O)^-1 h^(W) + b + eta,      e = z_hat - z                 e, eta in R^3 [units of z]
//
// Frames: q_O^W: orientation of the odometric frame O in the world W (East-North-Up); h^(W): the Earth's magnetic
// field in W, a constant of the measurement. The reading z is the field in the sensor frame S, in the same units as
// h^(W). The simulator uses a field of unit magnitude, so z is normalized and the seed's sigma_MAG = 0.067 is relative
// to the field strength (dimensionless); with a field in Tesla, sigma must be scaled by |h| accordingly.
// Calibration: q_S^O = misalignment q_body_sensor (unit quaternion); A = unconstrained 3x3 matrix (soft iron,
// non-orthogonality of the axes, per-axis scale; identity nominally), stored row-major; b = hard iron and bias
// [units of z]. As the seed notes (Sec. III-D), A and q_S^O are not jointly observable (A R^T and A' R'^T can
// coincide): estimate one with the other fixed.
// Noise: eta ~ N(0, sigma^2 I); J_e_eta = I.
// Variables: pose at the nearest time stamp (PoseBlock; only the orientation is used), q_body_sensor
// (QuaternionBlock), A (Matrix3Block), b (Vector3Block).
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

class MagnetometerError {
 public:
  using Blocks = std::tuple<PoseBlock, QuaternionBlock, Matrix3Block, Vector3Block>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // z: the reading in the sensor frame; h_world: the Earth's field in W, in the same units as z.
  MagnetometerError(const Eigen::Vector3d& z, const Eigen::Vector3d& h_world) : z_(z), h_world_(h_world) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Pose<T> pose = PoseFromArray(x[0]);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[1]);
    const Eigen::Map<const Eigen::Matrix<T, 3, 3, Eigen::RowMajor>> A(x[2]);
    const Eigen::Map<const Vector3<T>> b(x[3]);
    const Eigen::Map<const Vector3<T>> eta(noise);
    Eigen::Map<Vector3<T>> e(error);

    // The field in S, then through the distortion model.
    const Quaternion<T> q_world_sensor = pose.q_world_body * q_body_sensor;
    const Vector3<T> h_sensor = q_world_sensor.conjugate() * h_world_.cast<T>();
    e = A * h_sensor + b + eta - z_.cast<T>();
    return true;
  }

 private:
  Eigen::Vector3d z_;
  Eigen::Vector3d h_world_;
};

}  // namespace roamlab::estimator
