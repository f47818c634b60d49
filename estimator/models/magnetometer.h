// Three-axis magnetometer with hard/soft iron distortion, misalignment and motor interference. Seed 000, eq. 10,
// with one added term, the motor interference:
//
//   z_hat = A (q_O^W q_S^O)^-1 h^(W) + b + k tau_hat + eta,      e = z_hat - z           e, eta in R^3 [units of z]
//   tau_hat = c e_x^T q_S^O f^(S)                                                         [N m]
//
// The added term: the drive motors' current magnetizes the sensor's surroundings, a bias in S along k (the slot
// b_per_drive_nm) [units of z per N m] proportional to the drive torque per wheel. The recording carries no torque
// or current, so tau_hat is a proxy: the vehicle's forward specific force e_x^T q_S^O f^(S) [m/s^2] (f^(S): the
// accelerometer's reading at the sample's time, in S, i.e. the accelerometer shares the magnetometer's frame, one IMU
// package), which is the traction force over the mass (the slope's pull included: f_x = a_x + g sin(pitch)), times
// c = m r / n [N m per m/s^2] (mass m, wheel radius r, n driven wheels). Without the input (f^(S) = 0) or with k = 0
// (the default) this is eq. 10 as written.
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
// (QuaternionBlock), A (Matrix3Block), b (Vector3Block), k (Vector3Block).
// Jacobians (Linearize), with R = R(q_O^W), R_S = R(q_S^O) and h^(S) = (R R_S)^T h^(W); a right perturbation of
// either rotation turns the field in S by [h^(S)]x d ((R Exp(d))^T v = R^T v + [R^T v]x d):
//   J_e_theta = A [h^(S)]x R_S^T   (pose: dtheta in O, moved into S by R_S^T; J_e_p = 0),   J_e_qS = A [h^(S)]x,
//   J_e_A = [h^(S)T 0 0; 0 h^(S)T 0; 0 0 h^(S)T]   (A row-major),   J_e_b = I,   J_e_k = tau_hat I,
// and the proxy adds to J_e_qS only: d tau_hat / d(right perturbation of q_S^O) = -c e_x^T R_S [f^(S)]x, so
// J_e_qS += -c k e_x^T R_S [f^(S)]x.
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

class MagnetometerError {
 public:
  using Blocks = std::tuple<PoseBlock, QuaternionBlock, Matrix3Block, Vector3Block, Vector3Block>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // z: the reading in the sensor frame; h_world: the Earth's field in W, in the same units as z; f_sensor_mps2: the
  // accelerometer's specific force in S at the reading's time [m/s^2]; drive_nm_per_mps2: c, the drive torque per
  // wheel per m/s^2 of forward specific force [N m s^2 / m] (zero: no interference term).
  MagnetometerError(const Eigen::Vector3d& z, const Eigen::Vector3d& h_world,
                    const Eigen::Vector3d& f_sensor_mps2 = Eigen::Vector3d::Zero(), double drive_nm_per_mps2 = 0.0)
      : z_(z), h_world_(h_world), f_sensor_mps2_(f_sensor_mps2), drive_nm_per_mps2_(drive_nm_per_mps2) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Pose<T> pose = PoseFromArray(x[0]);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[1]);
    const Eigen::Map<const Eigen::Matrix<T, 3, 3, Eigen::RowMajor>> A(x[2]);
    const Eigen::Map<const Vector3<T>> b(x[3]);
    const Eigen::Map<const Vector3<T>> k(x[4]);
    const Eigen::Map<const Vector3<T>> eta(noise);
    Eigen::Map<Vector3<T>> e(error);

    // The field in S, then through the distortion model; the drive torque's proxy from the forward specific force.
    const Quaternion<T> q_world_sensor = pose.q_world_body * q_body_sensor;
    const Vector3<T> h_sensor = q_world_sensor.conjugate() * h_world_.cast<T>();
    const T tau_hat = T(drive_nm_per_mps2_) * (q_body_sensor * f_sensor_mps2_.cast<T>())[0];
    e = A * h_sensor + b + k * tau_hat + eta - z_.cast<T>();
    return true;
  }

  // Analytic Jacobians (header comment), with Factor::Evaluate's layout and zero noise; fills only the requested
  // blocks. J_e_eta = I is left to AutoDiffFactor.
  bool Linearize(const double* const* x, double* error, double* const* jacobians, double* /*noise_jacobian*/) const {
    const Quaternion<double> q_world_body = QuaternionFromArray(x[0] + 3);
    const Quaternion<double> q_body_sensor = QuaternionFromArray(x[1]);
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> A(x[2]);
    const Eigen::Map<const Eigen::Vector3d> b(x[3]);
    const Eigen::Map<const Eigen::Vector3d> k(x[4]);
    Eigen::Map<Eigen::Vector3d> e(error);

    // As operator().
    const Quaternion<double> q_world_sensor = q_world_body * q_body_sensor;
    const Eigen::Vector3d h_sensor = q_world_sensor.conjugate() * h_world_;
    const Eigen::Matrix3d R_S = q_body_sensor.toRotationMatrix();
    const double tau_hat = drive_nm_per_mps2_ * (q_body_sensor * f_sensor_mps2_)[0];  // as operator(), to the bit
    e = A * h_sensor + b + k * tau_hat - z_;
    if (jacobians == nullptr) return true;

    // d e / d(right perturbation of q_world_sensor) = A [h^(S)]x; the pose's dtheta enters as R_S^T dtheta. The
    // misalignment also turns the proxy's forward axis.
    const Eigen::Matrix3d J_e_field = A * Skew<double>(h_sensor);
    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 6>> J_e_pose(jacobians[0]);
      J_e_pose.leftCols<3>().setZero();
      J_e_pose.rightCols<3>() = J_e_field * R_S.transpose();
    }
    if (jacobians[1] != nullptr) {
      const Eigen::RowVector3d J_tau_qS = -drive_nm_per_mps2_ * R_S.row(0) * Skew<double>(f_sensor_mps2_);
      Eigen::Map<Eigen::Matrix3d>{jacobians[1]} = J_e_field + k * J_tau_qS;
    }
    if (jacobians[2] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 3, 9>> J_e_A(jacobians[2]);
      J_e_A.setZero();
      for (int i = 0; i < 3; ++i) J_e_A.block<1, 3>(i, 3 * i) = h_sensor.transpose();
    }
    if (jacobians[3] != nullptr) Eigen::Map<Eigen::Matrix3d>{jacobians[3]}.setIdentity();
    if (jacobians[4] != nullptr) Eigen::Map<Eigen::Matrix3d>{jacobians[4]} = tau_hat * Eigen::Matrix3d::Identity();
    return true;
  }

 private:
  Eigen::Vector3d z_;
  Eigen::Vector3d h_world_;
  Eigen::Vector3d f_sensor_mps2_;
  double drive_nm_per_mps2_;
};

}  // namespace roamlab::estimator
