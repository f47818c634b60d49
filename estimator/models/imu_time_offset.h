// The IMU's readings with a time offset delta of the IMU's clock (the slot time_offset_s of the gyroscope,
// accelerometer and magnetometer models; issue 6, imu_time_offset): the reading stamped t is the sensor's quantity at
// t - delta (as the simulator's imu_time_offset effect, sim/scenario.h). The samples keep the poses they attach to
// (problem.h), and the predicted quantity is moved by delta to first order with its time derivative from the
// neighbouring poses,
//
//   y(t - delta) = y(t) - delta y'(t),
//
// so the pairing of the IMU's samples with the other streams' never changes and the chi-square is smooth in delta.
// The second-order remainder, delta^2 y'' / 2, bounds the offsets this handles to a few master periods at the
// motion's bandwidth (the diagnosis shifts the stamps by whole master periods first for larger ones, gap/diagnose.cc).
// Each model is the plain one (gyroscope.h, accelerometer.h, magnetometer.h) with the poses of the derivative and
// delta (ScalarBlock, [s]) last; at delta = 0 it is the plain model exactly. The gyroscope's and accelerometer's
// Jacobians are analytic (Linearize), the magnetometer's come from the jets; all, the derivative w.r.t. delta among
// them, are checked against the jets and central differences in tests/estimator/models/imu_time_offset_test.cc.
//
// Derivatives (y in O's or S's coordinates, a function of time, so that the frames' own rotation is part of it),
// central differences over m master intervals on each side (problem.cc: the poses' rates over single intervals carry
// the readings' own noise, which delta would multiply by delta / dt; over m intervals it averages down):
//   gyroscope: omega^(O) over [t(k), t(k+1)] = omega_hat^(O) + delta alpha^(O), with the angular acceleration at the
//     interval's middle from the mean rates over the m intervals before and after it,
//       alpha^(O) = (Log(q_k+1^-1 q_k+1+m) / dt+ - Log(q_k-m^-1 q_k) / dt-) / (dt + (dt- + dt+) / 2),
//     dt- = t(k) - t(k-m), dt = t(k+1) - t(k), dt+ = t(k+1+m) - t(k+1);
//   accelerometer: f^(O)(t(k) - delta) = f^(O)(t(k)) - delta (f_+ - f_-) / (t(k+m) - t(k-m)), f^(O)(t(k)) eq. 14 on
//     the poses at t(k-1), t(k), t(k+1) as in the plain model, f_- and f_+ eq. 14 on the poses at t(k-2m), t(k-m),
//     t(k) and t(k), t(k+m), t(k+2m) (seven poses in all);
//   magnetometer: h^(S)(t - delta) = h^(S)(t) + delta omega^(S) x h^(S)(t) (d h^(S) / dt = -omega^(S) x h^(S)), with
//     omega^(O) = Log(q_k-m^-1 q_k+m) / (t(k+m) - t(k-m)), omega^(S) = (q_S^O)^-1 omega^(O).
// The magnetometer's drive-torque proxy (its inputs.specific_force) is read at the stamp, not moved by delta.
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "estimator/geometry.h"
#include "estimator/internal/so3_jacobians.h"
#include "estimator/manifold.h"
#include "estimator/models/accelerometer.h"

namespace roamlab::estimator {

// Variables: poses at t(k-m), t(k), t(k+1), t(k+1+m) (m >= 1), q_body_sensor, bias, scale, delta; the reading held
// over [t(k), t(k+1)].
class GyroscopeTimeOffsetError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, PoseBlock, PoseBlock, QuaternionBlock, Vector3Block, Vector3Block,
                            ScalarBlock>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;

  // z_radps: the reading [rad/s]; dt_before_s = t(k) - t(k-m), dt_s = t(k+1) - t(k), dt_after_s = t(k+1+m) - t(k+1)
  // (dt-, dt, dt+ above) [s], > 0.
  GyroscopeTimeOffsetError(const Eigen::Vector3d& z_radps, double dt_before_s, double dt_s, double dt_after_s)
      : z_radps_(z_radps), dt_before_s_(dt_before_s), dt_s_(dt_s), dt_after_s_(dt_after_s) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Quaternion<T> q_before = QuaternionFromArray(x[0] + 3);
    const Quaternion<T> q_k = QuaternionFromArray(x[1] + 3);
    const Quaternion<T> q_k1 = QuaternionFromArray(x[2] + 3);
    const Quaternion<T> q_after = QuaternionFromArray(x[3] + 3);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[4]);
    const Eigen::Map<const Vector3<T>> bias(x[5]);
    const Eigen::Map<const Vector3<T>> scale(x[6]);
    const T delta = x[7][0];
    const Eigen::Map<const Vector3<T>> eta(noise);
    Eigen::Map<Vector3<T>> e(error);

    const Vector3<T> omega_sensor = (z_radps_.cast<T>() - bias - eta).cwiseQuotient(scale);
    const Vector3<T> rate_before = QuaternionLog<T>(q_before.conjugate() * q_k) / T(dt_before_s_);
    const Vector3<T> rate_after = QuaternionLog<T>(q_k1.conjugate() * q_after) / T(dt_after_s_);
    const Vector3<T> alpha_body =
        (rate_after - rate_before) / T(dt_s_ + 0.5 * (dt_before_s_ + dt_after_s_));
    const Vector3<T> omega_body = q_body_sensor * omega_sensor + delta * alpha_body;
    const Quaternion<T> q_hat = Phi<T>(q_k, omega_body, T(dt_s_));
    e = QuaternionLog<T>(q_hat * q_k1.conjugate());
    return true;
  }

  // Analytic Jacobians, with Factor::Evaluate's layout and zero noise (the jets are the oracle in the tests). As
  // GyroscopeError's, with M = d e / d omega^(O) = dt Jl^-1(e) R_hat Jr(phi), plus the angular acceleration's poses
  // (phi_b = Log(q_k-m^-1 q_k), phi_a = Log(q_k+1^-1 q_k+1+m), H its denominator; d Log(qa^-1 qb) / d theta_a =
  // -Jl^-1, / d theta_b = Jr^-1):
  //   J_theta_k-m = M delta / H Jl^-1(phi_b) / dt-,     J_theta_k += -M delta / H Jr^-1(phi_b) / dt-,
  //   J_theta_k+1 += -M delta / H Jl^-1(phi_a) / dt+,   J_theta_k+1+m = M delta / H Jr^-1(phi_a) / dt+,
  //   J_delta = M alpha^(O).
  bool Linearize(const double* const* x, double* error, double* const* jacobians, double* noise_jacobian) const {
    const Quaternion<double> q_before = QuaternionFromArray(x[0] + 3);
    const Quaternion<double> q_k = QuaternionFromArray(x[1] + 3);
    const Quaternion<double> q_k1 = QuaternionFromArray(x[2] + 3);
    const Quaternion<double> q_after = QuaternionFromArray(x[3] + 3);
    const Quaternion<double> q_body_sensor = QuaternionFromArray(x[4]);
    const Eigen::Map<const Eigen::Vector3d> bias(x[5]);
    const Eigen::Map<const Eigen::Vector3d> scale(x[6]);
    const double delta = x[7][0];
    Eigen::Map<Eigen::Vector3d> e(error);

    const double span = dt_s_ + 0.5 * (dt_before_s_ + dt_after_s_);
    const Eigen::Vector3d omega_sensor = (z_radps_ - bias).cwiseQuotient(scale);
    const Eigen::Vector3d phi_b = QuaternionLog<double>(q_before.conjugate() * q_k);
    const Eigen::Vector3d phi_a = QuaternionLog<double>(q_k1.conjugate() * q_after);
    const Eigen::Vector3d alpha_body = (phi_a / dt_after_s_ - phi_b / dt_before_s_) / span;
    const Eigen::Vector3d phi = (q_body_sensor * omega_sensor + delta * alpha_body) * dt_s_;
    const Quaternion<double> q_hat = q_k * QuaternionExp<double>(phi);
    e = QuaternionLog<double>(q_hat * q_k1.conjugate());
    if (jacobians == nullptr && noise_jacobian == nullptr) return true;
    const auto wanted = [&](int i) { return jacobians != nullptr && jacobians[i] != nullptr; };

    const Eigen::Matrix3d jl_inv_e = internal::InverseRightJacobianSO3(e).transpose();
    const Eigen::Matrix3d R_hat = q_hat.toRotationMatrix();
    const Eigen::Matrix3d M = dt_s_ * jl_inv_e * R_hat * internal::RightJacobianSO3(phi);
    const Eigen::Matrix3d M_b = M * (delta / (span * dt_before_s_));
    const Eigen::Matrix3d M_a = M * (delta / (span * dt_after_s_));
    const auto rotation = [&](int i) -> Eigen::Map<Eigen::Matrix<double, 3, 6>> {
      Eigen::Map<Eigen::Matrix<double, 3, 6>> J(jacobians[i]);
      J.leftCols<3>().setZero();
      return J;
    };
    if (wanted(0) || wanted(1)) {
      const Eigen::Matrix3d jr_inv_b = internal::InverseRightJacobianSO3(phi_b);
      if (wanted(0)) rotation(0).rightCols<3>() = M_b * jr_inv_b.transpose();
      if (wanted(1)) rotation(1).rightCols<3>() = jl_inv_e * q_k.toRotationMatrix() - M_b * jr_inv_b;
    }
    if (wanted(2) || wanted(3)) {
      const Eigen::Matrix3d jr_inv_a = internal::InverseRightJacobianSO3(phi_a);
      if (wanted(2)) rotation(2).rightCols<3>() = -jl_inv_e * R_hat - M_a * jr_inv_a.transpose();
      if (wanted(3)) rotation(3).rightCols<3>() = M_a * jr_inv_a;
    }
    const Eigen::Matrix3d J_e_omega_sensor = M * q_body_sensor.toRotationMatrix();
    if (wanted(4)) Eigen::Map<Eigen::Matrix3d>{jacobians[4]} = -J_e_omega_sensor * Skew<double>(omega_sensor);
    const Eigen::Matrix3d J_e_bias = -J_e_omega_sensor * scale.cwiseInverse().asDiagonal();
    if (wanted(5)) Eigen::Map<Eigen::Matrix3d>{jacobians[5]} = J_e_bias;
    if (wanted(6))
      Eigen::Map<Eigen::Matrix3d>{jacobians[6]} = -J_e_omega_sensor * omega_sensor.cwiseQuotient(scale).asDiagonal();
    if (wanted(7)) Eigen::Map<Eigen::Vector3d>{jacobians[7]} = M * alpha_body;
    if (noise_jacobian != nullptr) Eigen::Map<Eigen::Matrix3d>{noise_jacobian} = J_e_bias;
    return true;
  }

 private:
  Eigen::Vector3d z_radps_;
  double dt_before_s_, dt_s_, dt_after_s_;
};

// Variables: poses at t(k-2m), t(k-m), t(k-1), t(k), t(k+1), t(k+m), t(k+2m) (m >= 2), q_body_sensor, S^(O), bias,
// scale, delta (the reading nearest t(k)).
class AccelerometerTimeOffsetError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, PoseBlock, PoseBlock, PoseBlock, PoseBlock, PoseBlock,
                            QuaternionBlock, Vector3Block, Vector3Block, Vector3Block, ScalarBlock>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;
  static constexpr bool kAdditiveNoise = true;

  // z_mps2: the reading [m/s^2]; dt0_s = t(k) - t(k-1), dt1_s = t(k+1) - t(k) (AccelerometerError's); span_dt_s: the
  // steps t(k-m) - t(k-2m), t(k) - t(k-m), t(k+m) - t(k), t(k+2m) - t(k+m) [s], all > 0.
  AccelerometerTimeOffsetError(const Eigen::Vector3d& z_mps2, double dt0_s, double dt1_s,
                               const Eigen::Vector4d& span_dt_s)
      : z_mps2_(z_mps2), dt0_s_(dt0_s), dt1_s_(dt1_s), span_dt_s_(span_dt_s) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    Pose<T> poses[7];
    for (int i = 0; i < 7; ++i) poses[i] = PoseFromArray(x[i]);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[7]);
    const Vector3<T> p_body_sensor = Eigen::Map<const Vector3<T>>(x[8]);
    const Eigen::Map<const Vector3<T>> bias(x[9]);
    const Eigen::Map<const Vector3<T>> scale(x[10]);
    const T delta = x[11][0];
    const Eigen::Map<const Vector3<T>> eta(noise);
    Eigen::Map<Vector3<T>> e(error);

    const Vector3<T> f_now = AccelerometerError::SpecificForceBody<T>(poses[2], poses[3], poses[4], T(dt0_s_),
                                                                      T(dt1_s_), p_body_sensor);
    const Vector3<T> f_before = AccelerometerError::SpecificForceBody<T>(
        poses[0], poses[1], poses[3], T(span_dt_s_[0]), T(span_dt_s_[1]), p_body_sensor);
    const Vector3<T> f_after = AccelerometerError::SpecificForceBody<T>(
        poses[3], poses[5], poses[6], T(span_dt_s_[2]), T(span_dt_s_[3]), p_body_sensor);
    const Vector3<T> f_rate = (f_after - f_before) / T(span_dt_s_[1] + span_dt_s_[2]);
    e = scale.cwiseProduct(q_body_sensor.conjugate() * (f_now - delta * f_rate)) + bias + eta - z_mps2_.cast<T>();
    return true;
  }

  // Analytic Jacobians, with Factor::Evaluate's layout and zero noise (the jets are the oracle in the tests): with
  // f = f_now - delta f_rate, D = diag(k_s) R_S^T and AccelerometerError::LinearizeSpecificForce for each of the three
  // specific forces, J_e_x = D (d f_now / dx - delta / (t(k+m) - t(k-m)) (d f_+ / dx - d f_- / dx)) for the poses and
  // S^(O), J_e_delta = -D f_rate; the misalignment, bias and scale as AccelerometerError's. J_e_eta = I is left to
  // AutoDiffFactor.
  bool Linearize(const double* const* x, double* error, double* const* jacobians, double* /*noise_jacobian*/) const {
    Pose<double> poses[7];
    for (int i = 0; i < 7; ++i) poses[i] = PoseFromArray(x[i]);
    const Quaternion<double> q_body_sensor = QuaternionFromArray(x[7]);
    const Eigen::Map<const Eigen::Vector3d> p_body_sensor(x[8]);
    const Eigen::Map<const Eigen::Vector3d> bias(x[9]);
    const Eigen::Map<const Eigen::Vector3d> scale(x[10]);
    const double delta = x[11][0];
    Eigen::Map<Eigen::Vector3d> e(error);

    const auto wanted = [&](int i) { return jacobians != nullptr && jacobians[i] != nullptr; };
    using Linearization = AccelerometerError::SpecificForceLinearization;
    const Linearization now = AccelerometerError::LinearizeSpecificForce(
        poses[2], poses[3], poses[4], dt0_s_, dt1_s_, p_body_sensor, {wanted(2), wanted(3), wanted(4), wanted(8)});
    const Linearization before = AccelerometerError::LinearizeSpecificForce(
        poses[0], poses[1], poses[3], span_dt_s_[0], span_dt_s_[1], p_body_sensor,
        {wanted(0), wanted(1), wanted(3), wanted(8)});
    const Linearization after = AccelerometerError::LinearizeSpecificForce(
        poses[3], poses[5], poses[6], span_dt_s_[2], span_dt_s_[3], p_body_sensor,
        {wanted(3), wanted(5), wanted(6), wanted(8)});
    const double rate_span = span_dt_s_[1] + span_dt_s_[2];
    const Eigen::Vector3d f_rate = (after.f_body - before.f_body) / rate_span;   // as operator(), to the bit
    const Eigen::Vector3d f_sensor = q_body_sensor.conjugate() * (now.f_body - delta * f_rate);
    e = scale.cwiseProduct(f_sensor) + bias - z_mps2_;
    if (jacobians == nullptr) return true;

    const Eigen::Matrix3d D = scale.asDiagonal() * q_body_sensor.toRotationMatrix().transpose();
    const double c = delta / rate_span;
    const auto pose = [&](int i) { return Eigen::Map<Eigen::Matrix<double, 3, 6>>(jacobians[i]); };
    if (wanted(0)) pose(0) = D * (c * before.J_pose[0]);
    if (wanted(1)) pose(1) = D * (c * before.J_pose[1]);
    if (wanted(2)) pose(2) = D * now.J_pose[0];
    if (wanted(3)) pose(3) = D * (now.J_pose[1] - c * (after.J_pose[0] - before.J_pose[2]));
    if (wanted(4)) pose(4) = D * now.J_pose[2];
    if (wanted(5)) pose(5) = D * (-c * after.J_pose[1]);
    if (wanted(6)) pose(6) = D * (-c * after.J_pose[2]);
    if (wanted(7)) Eigen::Map<Eigen::Matrix3d>{jacobians[7]} = scale.asDiagonal() * Skew<double>(f_sensor);
    if (wanted(8))
      Eigen::Map<Eigen::Matrix3d>{jacobians[8]} = D * (now.J_lever - c * (after.J_lever - before.J_lever));
    if (wanted(9)) Eigen::Map<Eigen::Matrix3d>{jacobians[9]}.setIdentity();
    if (wanted(10)) Eigen::Map<Eigen::Matrix3d>{jacobians[10]} = f_sensor.asDiagonal();
    if (wanted(11)) Eigen::Map<Eigen::Vector3d>{jacobians[11]} = -D * f_rate;
    return true;
  }

 private:
  Eigen::Vector3d z_mps2_;
  double dt0_s_, dt1_s_;
  Eigen::Vector4d span_dt_s_;
};

// Variables: poses at t(k-m), t(k), t(k+m) (m >= 1), q_body_sensor, A, b, k (b_per_drive_nm), delta (the reading
// nearest t(k)). Constructor as MagnetometerError's, plus t(k) - t(k-m) and t(k+m) - t(k) [s], > 0.
class MagnetometerTimeOffsetError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, PoseBlock, QuaternionBlock, Matrix3Block, Vector3Block,
                            Vector3Block, ScalarBlock>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;
  static constexpr bool kAdditiveNoise = true;

  MagnetometerTimeOffsetError(const Eigen::Vector3d& z, const Eigen::Vector3d& h_world,
                              const Eigen::Vector3d& f_sensor_mps2, double drive_nm_per_mps2, double dt_before_s,
                              double dt_after_s)
      : z_(z), h_world_(h_world), f_sensor_mps2_(f_sensor_mps2), drive_nm_per_mps2_(drive_nm_per_mps2),
        span_s_(dt_before_s + dt_after_s) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Quaternion<T> q_before = QuaternionFromArray(x[0] + 3);
    const Quaternion<T> q_k = QuaternionFromArray(x[1] + 3);
    const Quaternion<T> q_after = QuaternionFromArray(x[2] + 3);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[3]);
    const Eigen::Map<const Eigen::Matrix<T, 3, 3, Eigen::RowMajor>> A(x[4]);
    const Eigen::Map<const Vector3<T>> b(x[5]);
    const Eigen::Map<const Vector3<T>> k(x[6]);
    const T delta = x[7][0];
    const Eigen::Map<const Vector3<T>> eta(noise);
    Eigen::Map<Vector3<T>> e(error);

    const Vector3<T> h_sensor = (q_k * q_body_sensor).conjugate() * h_world_.cast<T>();
    const Vector3<T> omega_sensor =
        q_body_sensor.conjugate() * (QuaternionLog<T>(q_before.conjugate() * q_after) / T(span_s_));
    const Vector3<T> h_then = h_sensor + delta * omega_sensor.cross(h_sensor);
    const T tau_hat = T(drive_nm_per_mps2_) * (q_body_sensor * f_sensor_mps2_.cast<T>())[0];
    e = A * h_then + b + k * tau_hat + eta - z_.cast<T>();
    return true;
  }

 private:
  Eigen::Vector3d z_;
  Eigen::Vector3d h_world_;
  Eigen::Vector3d f_sensor_mps2_;
  double drive_nm_per_mps2_;
  double span_s_;
};

}  // namespace roamlab::estimator
