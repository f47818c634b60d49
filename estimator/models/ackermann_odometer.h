// Ackermann-steering odometer in the seed's form (model `ackermann_seed`; the ATV of Section V): rear-wheel speed and
// handlebar angle feed a first-order kinematic model whose sensor-frame velocities enter the odometer error of
// eqs. 7-8. Seed 000, eq. 15. This form biases the speed gain (errors in variables); the default model `ackermann`
// is the measurement-space form in ackermann_velocity.h, which explains why.
//
//   v_hat^(S)     = [k_v (z_v + eta_v);  eta_vy;  eta_vz]                           k_v = kv_over_L * L
//   omega_hat^(S) = [eta_wx;  eta_wy;  kv_over_L (z_v + eta_v) tan(k_theta (z_theta + eta_theta) + k_gamma)]
//   v_hat^(O) = v_hat^(S),  omega_hat^(O) = omega_hat^(S)                            (eq. 5 with S = O)
//   e = [O_hat^(W)(t_k+1) - O^(W)(t_k+1);  Log(q_hat_O^W(t_k+1) (q_O^W(t_k+1))^-1)]    (eqs. 7-8)      e in R^6
//
// Frames: the sensor frame is O itself (the middle of the rear axle, x forward, z up), so there is no displacement or
// misalignment. Position error in W [m], orientation error a full-angle rotation vector in W [rad] (see odometer.h).
// Measurements: z_v = rear-wheel speed computed with the nominal wheel radius [m/s]; z_theta = handlebar angle [rad];
// both held constant over [t_k, t_k+1], dt = t_k+1 - t_k [s].
// Calibration (eq. 15 written with one name each): kv_over_L = k_v / L [1/m] (speed gain over wheelbase),
// k_theta [-] (steering gain), k_gamma [rad] (steering offset). The wheelbase L [m] is a known constant, so the speed
// gain k_v = kv_over_L * L is not a separate variable.
//
// Noise, eta = [eta_v (m/s), eta_theta (rad), eta_vy (m/s), eta_vz (m/s), eta_wx (rad/s), eta_wy (rad/s)]:
// eta_v and eta_theta are the reading noises of eq. 15 (the seed's sigma_v, sigma_theta). Eq. 15 alone has two noisy
// inputs for a six-dimensional error, so J_e_eta Sigma_eta J_e_eta^T (eq. 1) would have rank 2 and no inverse. The
// other four are the uncertainty of eq. 15's non-holonomic assumptions: on hilly terrain the vehicle also slips
// sideways, moves vertically along the ground and rolls and pitches, which eq. 15 sets to zero. Their sigmas come from
// the configuration. With them the error covariance has full rank 6 whenever z_v, kv_over_L and k_theta are nonzero.
// At standstill (z_v = 0) the yaw rate no longer depends on eta_theta and the covariance drops to rank 5: eq. 15 says
// the vehicle cannot turn in place, and the graph has to treat such intervals (skip them or floor the covariance).
// Variables: pose at t_k (PoseBlock), pose at t_k+1 (PoseBlock), kv_over_L, k_theta, k_gamma (ScalarBlock each).
#pragma once

#include <tuple>

#include <Eigen/Core>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"
#include "estimator/models/odometer.h"

namespace roamlab::estimator {

class AckermannOdometerError {
 public:
  using Blocks = std::tuple<PoseBlock, PoseBlock, ScalarBlock, ScalarBlock, ScalarBlock>;
  static constexpr int kResidualDim = 6;
  static constexpr int kNoiseDim = 6;

  // Noise components, in order.
  enum NoiseIndex { kSpeed = 0, kSteering, kLateralSpeed, kVerticalSpeed, kRollRate, kPitchRate };

  // z_v_mps: rear-wheel speed [m/s]; z_theta_rad: handlebar angle [rad]; wheelbase_m: L [m]; dt_s = t_k+1 - t_k > 0.
  AckermannOdometerError(double z_v_mps, double z_theta_rad, double wheelbase_m, double dt_s)
      : z_v_mps_(z_v_mps), z_theta_rad_(z_theta_rad), wheelbase_m_(wheelbase_m), dt_s_(dt_s) {
    ROAMLAB_CHECK(wheelbase_m > 0.0 && dt_s > 0.0, "Ackermann odometer wheelbase " << wheelbase_m << " dt " << dt_s);
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    using std::tan;
    const Pose<T> pose_k = PoseFromArray(x[0]);
    const Pose<T> pose_k1 = PoseFromArray(x[1]);
    const T& kv_over_l = x[2][0];
    const T& k_theta = x[3][0];
    const T& k_gamma = x[4][0];

    // Eq. 15 with noisy readings, plus the noise on the velocities eq. 15 assumes to be zero.
    const T speed_reading = T(z_v_mps_) + noise[kSpeed];
    const T steering = k_theta * (T(z_theta_rad_) + noise[kSteering]) + k_gamma;
    const Vector3<T> v_body(kv_over_l * T(wheelbase_m_) * speed_reading, noise[kLateralSpeed], noise[kVerticalSpeed]);
    const Vector3<T> omega_body(noise[kRollRate], noise[kPitchRate], kv_over_l * speed_reading * tan(steering));

    // Eqs. 7-8.
    OdometryPoseError<T>(pose_k, pose_k1, v_body, omega_body, T(dt_s_), error);
    return true;
  }

  double z_v_mps() const { return z_v_mps_; }
  double z_theta_rad() const { return z_theta_rad_; }
  double wheelbase_m() const { return wheelbase_m_; }
  double dt_s() const { return dt_s_; }

 private:
  double z_v_mps_;
  double z_theta_rad_;
  double wheelbase_m_;
  double dt_s_;
};

}  // namespace roamlab::estimator
