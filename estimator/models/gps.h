// GPS (or any absolute position logical sensor) with lever arm. Seed 000, eq. 9.
//
//   z_hat = O^(W) + q_O^W S^(O) + b^(W) + eta,      e = z_hat - z                    e, b, eta in R^3 [m]
//
// Frames: O^(W), q_O^W: pose of the odometric frame in the world W (East-North-Up at the recording's origin).
// Measurement z: the antenna position in W [m] (latitude/longitude/altitude converted to ENU with
// GeographicLib::LocalCartesian, see enu.h). Calibration: S^(O) = lever arm of the antenna in O [m] ("lever_arm");
// b^(W) = the fixes' slow error in W [m] ("bias": 0 and fixed by default; free under a Gauss-Markov process, the
// receiver's error that wanders over seconds to minutes, which eta, white, does not hold).
// Noise: eta ~ N(0, sigma^2 I), sigma [m].
// Variables: pose at the nearest time stamp (PoseBlock), lever arm (Vector3Block), bias (Vector3Block).
// Jacobians (Linearize; R = R(q_O^W), pose tangent [dp (W), dtheta (O)]):
//   J_e_p = I,   J_e_theta = -R [S^(O)]x   (R Exp(dtheta) S = R S - R [S]x dtheta),   J_e_S = R,   J_e_b = I.
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

class GpsError {
 public:
  using Blocks = std::tuple<PoseBlock, Vector3Block, Vector3Block>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  explicit GpsError(const Eigen::Vector3d& z_world) : z_world_(z_world) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Pose<T> pose = PoseFromArray(x[0]);
    const Eigen::Map<const Vector3<T>> p_body_antenna(x[1]);
    const Eigen::Map<const Vector3<T>> bias_world(x[2]);
    const Eigen::Map<const Vector3<T>> eta(noise);
    Eigen::Map<Vector3<T>> e(error);
    e = pose.p_world_body + pose.q_world_body * p_body_antenna + bias_world + eta - z_world_.cast<T>();
    return true;
  }

  // Analytic Jacobians (header comment), with Factor::Evaluate's layout and zero noise; fills only the requested
  // blocks. J_e_eta = I is left to AutoDiffFactor.
  bool Linearize(const double* const* x, double* error, double* const* jacobians, double* /*noise_jacobian*/) const {
    const Pose<double> pose = PoseFromArray(x[0]);
    const Eigen::Map<const Eigen::Vector3d> p_body_antenna(x[1]);
    const Eigen::Map<const Eigen::Vector3d> bias_world(x[2]);
    Eigen::Map<Eigen::Vector3d> e(error);
    e = pose.p_world_body + pose.q_world_body * p_body_antenna + bias_world - z_world_;
    if (jacobians == nullptr) return true;

    const Eigen::Matrix3d R = pose.q_world_body.toRotationMatrix();
    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 6>> J_e_pose(jacobians[0]);
      J_e_pose.leftCols<3>().setIdentity();
      J_e_pose.rightCols<3>() = -R * Skew<double>(p_body_antenna);
    }
    if (jacobians[1] != nullptr) Eigen::Map<Eigen::Matrix3d>{jacobians[1]} = R;
    if (jacobians[2] != nullptr) Eigen::Map<Eigen::Matrix3d>{jacobians[2]}.setIdentity();
    return true;
  }

 private:
  Eigen::Vector3d z_world_;
};

}  // namespace roamlab::estimator
