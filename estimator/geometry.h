// Rotations and poses for the estimator, templated on the scalar so that error models can be differentiated with jets.
//
// Conventions (fixed once for the whole project):
//  - Hamilton unit quaternions. In arrays, YAML and JSON they are stored w first: [w, x, y, z].
//  - q_a_b rotates coordinates from frame b into frame a: v_a = q_a_b * v_b (the seed's q_b^a). The estimated pose is
//    q_world_body = q_O^W and p_world_body = O^(W).
//  - Box-plus is a right perturbation with a full-angle rotation vector in the body frame:
//        q [+] d = q * Exp(d),   Exp(d) = [cos(|d|/2), sin(|d|/2) d/|d|].
//    The seed's eq. 4, q * [1 - |d|, d], is not unit-norm; this is the exponential map it approximates.
//  - Poses are stored as 7 numbers [x, y, z, qw, qx, qy, qz] (position of O in W [m], then q_world_body). Their tangent
//    is [dp (world frame, m), dtheta (body frame, rad)]: (p, q) [+] (dp, dtheta) = (p + dp, q * Exp(dtheta)).
//  - Box-minus: x [-] y = d with y [+] d = x, i.e. (p_x - p_y, Log(q_y^-1 * q_x)).
//  - Orientation errors are Log(q_hat * q^-1) (a full-angle rotation vector). The seed keeps the vector part of the
//  error
//    quaternion, which is half this angle to first order; Log stays exact away from identity.
//  - The world frame W is East-North-Up; gravity is -9.81 m/s^2 along z. An accelerometer measures specific force:
//    at rest it reads +9.81 along its up axis. kSpecificForceAtRest_world is that reading in W.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/jet.h"

namespace roamlab::estimator {

template <typename T>
using Vector3 = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Matrix3 = Eigen::Matrix<T, 3, 3>;
template <typename T>
using Quaternion = Eigen::Quaternion<T>;

inline constexpr double kStandardGravity = 9.80665;  // [m/s^2]
inline const Eigen::Vector3d kSpecificForceAtRest_world(0.0, 0.0, kStandardGravity);

// Quaternion from a [w, x, y, z] array.
template <typename T>
Quaternion<T> QuaternionFromArray(const T* wxyz) {
  return Quaternion<T>(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}
template <typename T>
void QuaternionToArray(const Quaternion<T>& q, T* wxyz) {
  wxyz[0] = q.w();
  wxyz[1] = q.x();
  wxyz[2] = q.y();
  wxyz[3] = q.z();
}

// Exp: rotation vector [rad] -> unit quaternion. Below 1e-8 rad uses the second-order series so that jets get exact
// derivatives at zero.
template <typename T>
Quaternion<T> QuaternionExp(const Vector3<T>& rotation_vector) {
  const T theta_sq = rotation_vector.squaredNorm();
  if (ValueOf(theta_sq) < 1e-16) {
    const Vector3<T> half = rotation_vector * T(0.5);
    return Quaternion<T>(T(1.0) - theta_sq * T(0.125), half.x(), half.y(), half.z());
  }
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta = sqrt(theta_sq);
  const T k = sin(theta * T(0.5)) / theta;
  return Quaternion<T>(cos(theta * T(0.5)), k * rotation_vector.x(), k * rotation_vector.y(), k * rotation_vector.z());
}

// Log: unit quaternion -> rotation vector [rad] with angle in [0, pi] (q and -q give the same result).
template <typename T>
Vector3<T> QuaternionLog(const Quaternion<T>& q_in) {
  Quaternion<T> q = q_in;
  if (ValueOf(q.w()) < 0.0) q.coeffs() = -q.coeffs();
  const Vector3<T> v = q.vec();
  const T v_sq = v.squaredNorm();
  if (ValueOf(v_sq) < 1e-16) {
    // atan2(|v|, w) / |v| ~ 1/w - |v|^2 / (3 w^3).
    return v * (T(2.0) / q.w() - T(2.0 / 3.0) * v_sq / (q.w() * q.w() * q.w()));
  }
  using std::atan2;
  using std::sqrt;
  const T v_norm = sqrt(v_sq);
  return v * (T(2.0) * atan2(v_norm, q.w()) / v_norm);
}

// The seed's Phi(q, omega, dt) (eq. 6): orientation q after turning at body rate omega [rad/s] for dt [s]. Computed
// as q * Exp(omega dt); eq. 6 followed by normalization is its first-order form.
template <typename T>
Quaternion<T> Phi(const Quaternion<T>& q, const Vector3<T>& omega_body, const T& dt) {
  return q * QuaternionExp<T>(omega_body * dt);
}

template <typename T>
Matrix3<T> Skew(const Vector3<T>& v) {
  Matrix3<T> m;
  m << T(0.0), -v.z(), v.y(), v.z(), T(0.0), -v.x(), -v.y(), v.x(), T(0.0);
  return m;
}

// Pose of the odometric frame O in W, as stored in a pose variable.
template <typename T>
struct Pose {
  Vector3<T> p_world_body;
  Quaternion<T> q_world_body;
};

template <typename T>
Pose<T> PoseFromArray(const T* x) {
  return {Vector3<T>(x[0], x[1], x[2]), QuaternionFromArray(x + 3)};
}
template <typename T>
void PoseToArray(const Pose<T>& pose, T* x) {
  x[0] = pose.p_world_body.x();
  x[1] = pose.p_world_body.y();
  x[2] = pose.p_world_body.z();
  QuaternionToArray(pose.q_world_body, x + 3);
}

// Velocities of O between two poses dt apart, inverting the seed's eq. 7: the rotation Log(q0^-1 q1) / dt is the body
// rate, and the displacement, seen from the orientation half-way, is the body-frame linear velocity. These are the
// estimators of eq. 13; they refer to the middle of the interval.
template <typename T>
void VelocitiesBetween(const Pose<T>& pose0, const Pose<T>& pose1, const T& dt, Vector3<T>* v_body,
                       Vector3<T>* omega_body) {
  const Vector3<T> rotation = QuaternionLog<T>(pose0.q_world_body.conjugate() * pose1.q_world_body);
  *omega_body = rotation / dt;
  const Quaternion<T> q_mid = pose0.q_world_body * QuaternionExp<T>(rotation * T(0.5));
  *v_body = q_mid.conjugate() * ((pose1.p_world_body - pose0.p_world_body) / dt);
}

// The seed's eq. 7: pose at t + dt from the pose at t and the body velocities of O: rotate half-way, translate, rotate
// the rest.
template <typename T>
Pose<T> PredictPose(const Pose<T>& pose, const Vector3<T>& v_body, const Vector3<T>& omega_body, const T& dt) {
  const Quaternion<T> q_mid = Phi<T>(pose.q_world_body, omega_body, dt * T(0.5));
  return {pose.p_world_body + q_mid * (v_body * dt), Phi<T>(pose.q_world_body, omega_body, dt)};
}

// The seed's eq. 5: velocities of O from those of a sensor frame S mounted at p_body_sensor with q_body_sensor.
template <typename T>
void SensorToBodyVelocity(const Vector3<T>& v_sensor, const Vector3<T>& omega_sensor,
                          const Quaternion<T>& q_body_sensor, const Vector3<T>& p_body_sensor, Vector3<T>* v_body,
                          Vector3<T>* omega_body) {
  *v_body = q_body_sensor * (v_sensor - omega_sensor.cross(q_body_sensor.conjugate() * p_body_sensor));
  *omega_body = q_body_sensor * omega_sensor;
}

}  // namespace roamlab::estimator
