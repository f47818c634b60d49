// Small synthetic recordings with exact known truth, for the estimator's end-to-end tests (until the simulator
// exists): an ATV-like vehicle (seed 000, Section V) driven by a kinematic bicycle model over an analytic terrain,
// read by an IMU, a magnetometer, a GPS, a rear-wheel speed sensor and a handlebar angle sensor whose calibration is
// that of the seed's Table I (or any other given in the options).
//
// Vehicle (truth):
//   - Planar state (x, y, yaw) [m, m, rad], integrated with RK4 on a 1 kHz grid from (0, 0, 0) at t = 0 (the origin,
//     heading east):  d(x, y)/dt = u (cos yaw, sin yaw),  d yaw/dt = v tan(delta) / L,
//     where v(t) [m/s] is the speed along the surface, u = v / sqrt(1 + s^2) its horizontal part and s the slope of
//     the terrain along the heading. Position of O (rear-axle midpoint): p_world_body = (x, y, h(x, y)), h(0, 0) = 0.
//   - v(t) = 4.5 + 1.0 sin(2 pi t / 13) + 0.4 sin(2 pi t / 4.7 + 0.6)            in [3.1, 5.9] m/s
//     delta(t) = 0.18 sin(2 pi t / 11 + 0.3) + 0.1 sin(2 pi t / 3.7 + 1.1)      |delta| <= 0.28 rad, both ways
//     Both are fixed: the seed changes the noise only, so runs with different seeds share one trajectory.
//   - Terrain (hilly): a sum of four plane sinusoids with 30-60 m wavelengths; along the default 30 s path the height
//     spans about 2.3 m and pitch and roll reach about 10 and 12 deg; (flat): h = 0. The path wanders up to about
//     100 m from the origin.
//   - Body frame O: x = unit velocity (the path's tangent on the surface), z = terrain normal (orthogonal to x), y =
//     z cross x. Hence v_body = [v, 0, 0] exactly: no side slip and no vertical motion in O.
//   - omega_body(t) = Log(q(t - 1 ms)^-1 q(t + 1 ms)) / 2 ms and a_world(t) = second central difference of p_world_body
//     with 1 ms steps; both are within about 1e-6 of the exact derivatives, far below the sensor noise.
//
// Sensors (conventions of estimator/geometry.h: Hamilton, q_a_b maps b into a, W = ENU, specific force +9.80665 up):
//   imu           gyro  = q_body_imu^-1 omega_body + b_g + eta_g                             (seed eq. 11, unit scale)
//                 b_g = gyro_bias_radps, a constant bias in the IMU frame (zero by default).
//                 accel = q_body_imu^-1 q_world_body^-1 (a_world + [0, 0, g]) + eta_a         (eq. 14 with S^(O) = 0)
//                 The IMU sits at the origin of O: there is no lever arm in this generator, so the omega x (omega x
//                 S) and alpha x S terms of eq. 14 vanish.
//   magnetometer  A (q_world_body q_body_imu)^-1 field_world + b + eta_m                     (eq. 10)
//                 It shares the IMU's frame: q_body_imu is the seed's q_S^O for both.
//   gps           p_world_body + q_world_body gps_lever_arm + eta_p, eta_p ~ N(0, sigma^2 I) in ENU [m], then
//                 converted to latitude, longitude [deg], altitude [m] with GeographicLib::LocalCartesian at the
//                 origin (45.4642, 9.19, 120.0)                                                (eq. 9)
//                 With gps_bias_sigma_m > 0 the fixes carry a slow error on top of eta_p: per ENU axis a first-order
//                 Gauss-Markov process b(t_k+1) = a b(t_k) + s sqrt(1 - a^2) n, a = exp(-period / gps_bias_tau_s),
//                 b(t_0) ~ N(0, s^2), s = gps_bias_sigma_m (the receiver's wandering error; models/gps.h's bias).
//   rear_wheel    z_v = v / k_v + eta_v, k_v = kv_over_L * wheelbase_m [m/s]                  (eq. 15: v = k_v z_v)
//   steering      z_theta = (delta_eff - k_gamma) / k_theta + eta_theta [rad], with delta_eff = atan(L omega_z / v)
//                 the steering angle for which eq. 15 gives the body yaw rate exactly (on a slope the body yaw rate
//                 differs from the planar one, so delta_eff differs slightly from delta(t)).
// Each noise source (gyro, accel, magnetometer, gps, speed, steering, gps bias) has its own std::mt19937_64 seeded from
// (seed, source index). Sample times are t_k = k * period, period = round(1e9 / rate) ns, from 0 to duration_s
// inclusive. Same options -> identical SyntheticRecording.
//
// The recording declares nominal mountings (identity rotation, zero lever arm) and the options' sigmas as nominal
// noise; the true calibration is only in `truth`.
#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "recording/recording.h"
#include "recording/truth.h"

namespace roamlab::testing {

struct SyntheticOptions {
  double duration_s = 30.0;         // > 0
  std::uint32_t seed = 1;           // noise realization
  bool hilly = true;                // false: flat plane z = 0 (the GPS lever arm's z is then unobservable)
  bool noise = true;                // false: all sensor noise off (calibration effects still applied)
  double imu_rate_hz = 100.0;       // also the rate of the magnetometer and of ground_truth; each in (0, 1000]
  double odometer_rate_hz = 100.0;  // rear_wheel and steering
  double gps_rate_hz = 5.0;

  // True calibration (defaults: seed Table I). Names in truth.calibration in brackets.
  Eigen::Vector3d gps_lever_arm_m{0.57, -0.46, 0.32};                // [gps.lever_arm] GPS antenna in O [m]
  Eigen::Quaterniond q_body_imu{0.938, 0.104, 0.313, 0.104};         // [imu.misalignment] w, x, y, z; normalized on use
  Eigen::Matrix3d mag_A = (Eigen::Matrix3d() << 0.87, -0.02, -0.02,  //
                           0.00, 0.88, 0.00,                         //
                           -0.02, -0.04, 0.85)
                              .finished();                    // [magnetometer.A]
  Eigen::Vector3d mag_b{-0.008, -0.007, -0.040};              // [magnetometer.b] normalized units
  double kv_over_L = 0.8;                                     // [odometer.kv_over_L] 1/m, > 0
  double k_theta = 1.0;                                       // [odometer.k_theta] -, nonzero
  double k_gamma = 0.0;                                       // [odometer.k_gamma] rad
  double wheelbase_m = 1.25;                                  // L, known (platform geometry), > 0
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();  // [imu.gyro_bias] in the IMU frame [rad/s]
  // [imu.time_offset_s] the IMU's clock offset [s], |offset| <= 1: the imu and magnetometer rows stamped t hold the
  // readings taken at t - offset (ground_truth stays at the stamps).
  double imu_time_offset_s = 0.0;

  // Noise standard deviations per sample (seed Section V), each >= 0.
  double sigma_gps_m = 0.33;
  double sigma_mag = 0.067;  // normalized units (fraction of |field_world|)
  double sigma_acc_mps2 = 0.067;
  double sigma_gyro_radps = 0.033;
  double sigma_speed_mps = 0.033;     // on z_v
  double sigma_steering_rad = 0.014;  // on z_theta
  // The fixes' slow Gauss-Markov error (header comment): stationary std [m] (>= 0; 0: none) and correlation time [s]
  // (> 0).
  double gps_bias_sigma_m = 0.0;
  double gps_bias_tau_s = 10.0;

  Eigen::Vector3d field_world{0.0, 0.5, -0.8660254037844386};  // Earth field in ENU, unit magnitude (dip 60 deg)

  // Empty when the options are usable, otherwise what is wrong.
  std::string Validate() const;
};

struct SyntheticRecording {
  // Streams "imu", "magnetometer", "gps", "rear_wheel", "steering" (in this order); ground_truth = pose of O at every
  // IMU sample time; platform ackermann with geometry.wheelbase_m; origin set; provenance "simulated" with the seed.
  recording::Recording recording;
  // calibration: gps.lever_arm [3], imu.misalignment [w, x, y, z] (normalized), magnetometer.A [9, row-major],
  // magnetometer.b [3], odometer.kv_over_L, odometer.k_theta, odometer.k_gamma [1 each], and imu.gyro_bias [3] and
  // imu.time_offset_s [1] when not zero (as the simulator records optional effects such as imu.lever_arm); no effects.
  recording::Truth truth;
};

// Generates the recording. Aborts (ROAMLAB_CHECK) when options.Validate() is not empty.
SyntheticRecording MakeAtvRecording(const SyntheticOptions& options);

}  // namespace roamlab::testing
