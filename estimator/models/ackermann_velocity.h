// Ackermann-steering odometer in measurement space (seed 000, eq. 15 inverted): the body velocities between two
// poses predict the rear-wheel speed and the handlebar angle, and the error is the difference to the readings.
//
//   v^(O), omega^(O) = VelocitiesBetween(pose_k, pose_k+1, dt)          (eq. 7 inverted; middle of the interval)
//   z_v_hat     = v_x / k_v                                              k_v = kv_over_L * L
//   z_theta_hat = (atan(L omega_z / v_x) - k_gamma) / k_theta           (eq. 15: omega_z = (k_v / L) v tan(delta))
//   e = [z_v_hat - z_v;  z_theta_hat - z_theta;  v_y;  v_z] + eta                                      e in R^4
//
// Why not the seed's form (ackermann_odometer.h, eqs. 7-8 with the readings as inputs): there the reading noise
// passes through the nonlinear model, so the error covariance of eq. 1 depends on the parameters, and the
// Gauss-Newton fixed point (which holds the covariance constant within an iteration) regresses the precise motion on
// noisy readings: an errors-in-variables bias. With sensor noise on, the seed form estimates kv_over_L 0.5-0.7% low
// (2-3 reported standard deviations on 12 s drives); here the noise is additive on the readings, the covariance is
// constant, and the least-squares problem is the likelihood of the readings themselves.
//
// Frames: O is the middle of the rear axle (x forward, z up). Measurements: z_v rear-wheel speed with the nominal
// wheel radius [m/s], z_theta handlebar angle [rad], both over [t_k, t_k+1]. Calibration: kv_over_L [1/m], k_theta
// [-], k_gamma [rad]; the wheelbase L [m] is known. Noise eta = [sigma_v (m/s), sigma_theta (rad), lateral (m/s),
// vertical (m/s)], the last two the uncertainty of eq. 15's non-holonomic assumptions (no sideways slip, no motion
// off the ground). Eq. 15 says nothing about roll and pitch rates, and on hills they are not zero (the terrain tilts
// the vehicle): pretending they are pulls the estimated attitude flat and biases the IMU misalignment, so this form
// leaves them to the other sensors. Below kMinSteeringSpeed the steering angle does not affect the motion, so its
// error is zero (eta only).
// Variables: pose at t_k, pose at t_k+1 (PoseBlock), kv_over_L, k_theta, k_gamma (ScalarBlock each).
#pragma once

#include <cmath>
#include <tuple>

#include <Eigen/Core>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

class AckermannVelocityError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, ScalarBlock, ScalarBlock, ScalarBlock>;
  static constexpr int kResidualDim = 4;
  static constexpr int kNoiseDim = 4;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta
  static constexpr double kMinSteeringSpeed = 0.2;  // [m/s]

  AckermannVelocityError(double z_v_mps, double z_theta_rad, double wheelbase_m, double dt_s)
      : z_v_mps_(z_v_mps), z_theta_rad_(z_theta_rad), wheelbase_m_(wheelbase_m), dt_s_(dt_s) {
    ROAMLAB_CHECK(wheelbase_m > 0.0 && dt_s > 0.0, "Ackermann wheelbase " << wheelbase_m << " dt " << dt_s);
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    using std::abs;
    using std::atan;
    Vector3<T> v_body, omega_body;
    VelocitiesBetween<T>(PoseFromArray(x[0]), PoseFromArray(x[1]), T(dt_s_), &v_body, &omega_body);
    const T& kv_over_l = x[2][0];
    const T& k_theta = x[3][0];
    const T& k_gamma = x[4][0];
    error[0] = v_body.x() / (kv_over_l * T(wheelbase_m_)) - T(z_v_mps_) + noise[0];
    if (std::abs(ValueOf(v_body.x())) >= kMinSteeringSpeed) {
      const T delta = atan(T(wheelbase_m_) * omega_body.z() / v_body.x());
      error[1] = (delta - k_gamma) / k_theta - T(z_theta_rad_) + noise[1];
    } else {
      error[1] = noise[1];
    }
    error[2] = v_body.y() + noise[2];
    error[3] = v_body.z() + noise[3];
    return true;
  }

 private:
  double z_v_mps_;
  double z_theta_rad_;
  double wheelbase_m_;
  double dt_s_;
};

}  // namespace roamlab::estimator
