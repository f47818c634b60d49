// Three-axis accelerometer, as a constraint on three consecutive poses. Seed 000, eqs. 13-14.
//
//   z = k_s o a^(S) + b + eta                                          (sensor model: per-axis scale, bias, noise)
//   a_hat^(S) = (q_S^O)^-1 ( (q_O^W(t1))^-1 f_rest^(W) + alpha^(O) x S^(O) + a^(O) + omega^(O) x (omega^(O) x S^(O)) )
//                                                                                                        (eq. 14)
//   e = k_s o a_hat^(S) + b + eta - z                          e [m/s^2] in R^3, eta [m/s^2] in R^3
//
// with the motion of O at the middle time stamp t1 estimated from the poses at t0 < t1 < t2 (dt0 = t1 - t0,
// dt1 = t2 - t1, both > 0):
//   V0 = (O(t1) - O(t0)) / dt0,  V1 = (O(t2) - O(t1)) / dt1        chord velocities of O in W
//   a^(O)     = (q_O^W(t1))^-1 (V1 - V0) / ((dt0 + dt1) / 2)        linear acceleration of O, in O(t1)
//   omega^(O) = Log(q0^-1 q2) / (dt0 + dt1)                         angular rate at t1
//   alpha^(O) = (Log(q1^-1 q2) / dt1 - Log(q0^-1 q1) / dt0) / ((dt0 + dt1) / 2)   angular acceleration at t1
// where qi = q_O^W(ti).
//
// Relation to eq. 13: the seed inverts eq. 7 on the pose pairs (t0, t1) and (t1, t2) to get body-frame velocities,
// rotates the older one into the newer body frame with q_{O_{t-1}}^{O_t} and differences them. Rotating both body
// velocities back to W first, as done here, is the same estimator to first order in dt, with two gains: the second
// difference of positions is exact for any motion whose position is quadratic in time (also with dt0 != dt1), and no
// bookkeeping is needed for which orientation (interval start, middle or end) each velocity is expressed in. The
// result is rotated into the body frame at t1, so the estimate belongs to the middle pose, which is where this model
// attaches the measurement (the seed labels it with the newest pose, a lag of one sample). For the angular terms no
// rotation is needed at all: the rotation vector Log(qa^-1 qb) has the same coordinates in O(ta) and in O(tb) (a
// rotation leaves its own axis fixed), so both interval rates are already in O(t1) and alpha is their plain
// difference. omega is the rotation vector of q0^-1 q2, whose coordinates are those of O(t0) and O(t2); they equal
// those of O(t1) exactly when the axis of rotation is fixed, and to first order in dt otherwise.
//
// Gravity convention (geometry.h): W is East-North-Up, gravity is -9.80665 m/s^2 along z_W, and an accelerometer
// measures specific force (acceleration minus gravity). f_rest^(W) = kSpecificForceAtRest_world = [0, 0, +9.80665] is
// the reading of a level accelerometer at rest (the seed's g_hat^(W)); a free-falling one reads zero.
//
// Calibration: q_S^O = misalignment q_body_sensor (unit quaternion), S^(O) = position of the sensor in O [m],
// b = bias [m/s^2], k_s = per-axis scale (gain, dimensionless, nominally 1).
// Noise: eta ~ N(0, sigma^2 I), sigma [m/s^2]; J_e_eta = I. The finite differences add an O(dt^2) model error that
// is not part of eta.
// Variables: poses at t0, t1, t2 (PoseBlock x3), q_body_sensor (QuaternionBlock), S^(O) (Vector3Block), bias
// (Vector3Block), scale (Vector3Block).
//
// Jacobians (Linearize; so3_jacobians.h for Jr^-1, Jl^-1 = (Jr^-1)^T). With f^(O) the specific force in O,
// D = diag(k_s) R_S^T (so that de = D df^(O)), R1 = R(q1), h = (dt0 + dt1) / 2 and phi_ab = Log(qa^-1 qb):
//   positions:  df/dp0 = R1^T / (dt0 h),  df/dp1 = -R1^T (1/dt0 + 1/dt1) / h,  df/dp2 = R1^T / (dt1 h)
//   rotation vectors: dphi_ab/dtheta_a = -Jl^-1(phi_ab)  (Log(Exp(-d) Q)),  dphi_ab/dtheta_b = Jr^-1(phi_ab)
//   (Log(Q Exp(d))), so with K_alpha = -[S]x / h (alpha x S = -[S]x alpha) and
//   K_omega = -([omega x S]x + [omega]x [S]x) / (dt0 + dt1) (the differential of omega x (omega x S)):
//   df/dtheta0 = K_alpha Jl^-1(phi01) / dt0 - K_omega Jl^-1(phi02)
//   df/dtheta1 = [R1^T (f_rest^(W) + (V1 - V0) / h)]x - K_alpha (Jl^-1(phi12) / dt1 + Jr^-1(phi01) / dt0)
//                (the first term: (R1 Exp(d))^T v = R1^T v + [R1^T v]x d, for gravity and a^(O))
//   df/dtheta2 = K_alpha Jr^-1(phi12) / dt1 + K_omega Jr^-1(phi02)
//   J_e_qS = diag(k_s) [f^(S)]x,  J_e_S = D ([alpha]x + [omega]x^2),  J_e_b = I,  J_e_ks = diag(f^(S)).
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "estimator/geometry.h"
#include "estimator/manifold.h"
#include "estimator/so3_jacobians.h"

namespace roamlab::estimator {

class AccelerometerError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, PoseBlock, QuaternionBlock, Vector3Block, Vector3Block, Vector3Block>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // z_mps2: the reading [m/s^2] in the sensor frame, taken at t1; dt0_s = t1 - t0 and dt1_s = t2 - t1 [s], > 0.
  AccelerometerError(const Eigen::Vector3d& z_mps2, double dt0_s, double dt1_s)
      : z_mps2_(z_mps2), dt0_s_(dt0_s), dt1_s_(dt1_s) {}

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    const Pose<T> pose0 = PoseFromArray(x[0]);
    const Pose<T> pose1 = PoseFromArray(x[1]);
    const Pose<T> pose2 = PoseFromArray(x[2]);
    const Quaternion<T> q_body_sensor = QuaternionFromArray(x[3]);
    const Eigen::Map<const Vector3<T>> p_body_sensor(x[4]);
    const Eigen::Map<const Vector3<T>> bias(x[5]);
    const Eigen::Map<const Vector3<T>> scale(x[6]);
    const Eigen::Map<const Vector3<T>> eta(noise);
    Eigen::Map<Vector3<T>> e(error);

    const T dt0(dt0_s_);
    const T dt1(dt1_s_);
    const T half_span = (dt0 + dt1) * T(0.5);
    const Quaternion<T>& q0 = pose0.q_world_body;
    const Quaternion<T>& q1 = pose1.q_world_body;
    const Quaternion<T>& q2 = pose2.q_world_body;

    // Linear acceleration of O at t1: second difference of the positions in W, rotated into O(t1).
    const Vector3<T> v01_world = (pose1.p_world_body - pose0.p_world_body) / dt0;
    const Vector3<T> v12_world = (pose2.p_world_body - pose1.p_world_body) / dt1;
    const Vector3<T> a_body = q1.conjugate() * ((v12_world - v01_world) / half_span);

    // Angular rate at t1 over the whole span, and angular acceleration from the two interval rates (all in O(t1)).
    const Vector3<T> omega_body = QuaternionLog<T>(q0.conjugate() * q2) / (dt0 + dt1);
    const Vector3<T> omega01_body = QuaternionLog<T>(q0.conjugate() * q1) / dt0;
    const Vector3<T> omega12_body = QuaternionLog<T>(q1.conjugate() * q2) / dt1;
    const Vector3<T> alpha_body = (omega12_body - omega01_body) / half_span;

    // Specific force at the sensor, in O (eq. 14), then in S.
    const Vector3<T> f_body = q1.conjugate() * kSpecificForceAtRest_world.cast<T>() + alpha_body.cross(p_body_sensor) +
                              a_body + omega_body.cross(omega_body.cross(p_body_sensor));
    const Vector3<T> f_sensor = q_body_sensor.conjugate() * f_body;

    // Through the sensor model.
    e = scale.cwiseProduct(f_sensor) + bias + eta - z_mps2_.cast<T>();
    return true;
  }

  // Analytic Jacobians (header comment), with Factor::Evaluate's layout and zero noise; fills only the requested
  // blocks. J_e_eta = I is left to AutoDiffFactor.
  bool Linearize(const double* const* x, double* error, double* const* jacobians, double* /*noise_jacobian*/) const {
    const Pose<double> pose0 = PoseFromArray(x[0]);
    const Pose<double> pose1 = PoseFromArray(x[1]);
    const Pose<double> pose2 = PoseFromArray(x[2]);
    const Quaternion<double> q_body_sensor = QuaternionFromArray(x[3]);
    const Eigen::Map<const Eigen::Vector3d> p_body_sensor(x[4]);
    const Eigen::Map<const Eigen::Vector3d> bias(x[5]);
    const Eigen::Map<const Eigen::Vector3d> scale(x[6]);
    Eigen::Map<Eigen::Vector3d> e(error);

    // As operator(), keeping the rotation vectors.
    const double dt0 = dt0_s_;
    const double dt1 = dt1_s_;
    const double half_span = (dt0 + dt1) * 0.5;
    const Quaternion<double>& q0 = pose0.q_world_body;
    const Quaternion<double>& q1 = pose1.q_world_body;
    const Quaternion<double>& q2 = pose2.q_world_body;
    const Eigen::Vector3d v01_world = (pose1.p_world_body - pose0.p_world_body) / dt0;
    const Eigen::Vector3d v12_world = (pose2.p_world_body - pose1.p_world_body) / dt1;
    const Eigen::Vector3d a_body = q1.conjugate() * ((v12_world - v01_world) / half_span);
    const Eigen::Vector3d phi02 = QuaternionLog<double>(q0.conjugate() * q2);
    const Eigen::Vector3d phi01 = QuaternionLog<double>(q0.conjugate() * q1);
    const Eigen::Vector3d phi12 = QuaternionLog<double>(q1.conjugate() * q2);
    const Eigen::Vector3d omega_body = phi02 / (dt0 + dt1);
    const Eigen::Vector3d alpha_body = (phi12 / dt1 - phi01 / dt0) / half_span;
    const Eigen::Vector3d g_body = q1.conjugate() * kSpecificForceAtRest_world;
    const Eigen::Vector3d f_body =
        g_body + alpha_body.cross(p_body_sensor) + a_body + omega_body.cross(omega_body.cross(p_body_sensor));
    const Eigen::Vector3d f_sensor = q_body_sensor.conjugate() * f_body;
    e = scale.cwiseProduct(f_sensor) + bias - z_mps2_;
    if (jacobians == nullptr) return true;

    const auto wanted = [&](int i) { return jacobians[i] != nullptr; };
    const Eigen::Matrix3d R_body_sensor = q_body_sensor.toRotationMatrix();
    const Eigen::Matrix3d D = scale.asDiagonal() * R_body_sensor.transpose();  // de = D df^(O)

    // Poses: de/dp_i = D R1^T c_i, de/dtheta_i = D df/dtheta_i.
    if (wanted(0) || wanted(1) || wanted(2)) {
      const Eigen::Matrix3d D_R1T = D * q1.toRotationMatrix().transpose();
      const Eigen::Matrix3d S_x = Skew<double>(p_body_sensor);
      const Eigen::Matrix3d omega_x = Skew<double>(omega_body);
      const Eigen::Matrix3d D_K_alpha = D * S_x * (-1.0 / half_span);
      const Eigen::Matrix3d D_K_omega =
          D * (Skew<double>(omega_body.cross(p_body_sensor)) + omega_x * S_x) * (-1.0 / (dt0 + dt1));
      const auto J_e_pose = [&](int i) { return Eigen::Map<Eigen::Matrix<double, 3, 6>>(jacobians[i]); };
      // Jr^-1 of the rotation vectors a pose touches (Jl^-1 is its transpose).
      const bool need01 = wanted(0) || wanted(1), need02 = wanted(0) || wanted(2), need12 = wanted(1) || wanted(2);
      const Eigen::Matrix3d jr_inv01 = need01 ? InverseRightJacobianSO3(phi01) : Eigen::Matrix3d();
      const Eigen::Matrix3d jr_inv02 = need02 ? InverseRightJacobianSO3(phi02) : Eigen::Matrix3d();
      const Eigen::Matrix3d jr_inv12 = need12 ? InverseRightJacobianSO3(phi12) : Eigen::Matrix3d();
      if (wanted(0)) {
        J_e_pose(0).leftCols<3>() = D_R1T / (dt0 * half_span);
        J_e_pose(0).rightCols<3>() = D_K_alpha * jr_inv01.transpose() / dt0 - D_K_omega * jr_inv02.transpose();
      }
      if (wanted(1)) {
        J_e_pose(1).leftCols<3>() = D_R1T * (-(1.0 / dt0 + 1.0 / dt1) / half_span);
        J_e_pose(1).rightCols<3>() =
            D * Skew<double>(g_body + a_body) - D_K_alpha * (jr_inv12.transpose() / dt1 + jr_inv01 / dt0);
      }
      if (wanted(2)) {
        J_e_pose(2).leftCols<3>() = D_R1T / (dt1 * half_span);
        J_e_pose(2).rightCols<3>() = D_K_alpha * jr_inv12 / dt1 + D_K_omega * jr_inv02;
      }
    }

    // Calibration.
    if (wanted(3)) Eigen::Map<Eigen::Matrix3d>{jacobians[3]} = scale.asDiagonal() * Skew<double>(f_sensor);
    if (wanted(4)) {
      Eigen::Map<Eigen::Matrix3d>{jacobians[4]} =
          D * (Skew<double>(alpha_body) + Skew<double>(omega_body) * Skew<double>(omega_body));
    }
    if (wanted(5)) Eigen::Map<Eigen::Matrix3d>{jacobians[5]}.setIdentity();
    if (wanted(6)) Eigen::Map<Eigen::Matrix3d>{jacobians[6]} = f_sensor.asDiagonal();
    return true;
  }

 private:
  Eigen::Vector3d z_mps2_;
  double dt0_s_;
  double dt1_s_;
};

}  // namespace roamlab::estimator
