// Sensor synthesis: noise-free readings from the simulated motion of the odometric frame O and the true calibration.
// The simulator adds each source's noise (noise.h). The formulas are those of the kinematic generator in
// tests/support/synthetic.h and of the estimator's error models, so that an estimator configuration written for one
// works on the other. Conventions (estimator/geometry.h): Hamilton quaternions, q_a_b maps b coordinates into a,
// W = East-North-Up, an accelerometer at rest reads +9.80665 m/s^2 along its up axis.
//
//   gyroscope      omega_S = q_body_imu^-1 omega_O                                              (seed eq. 11)
//   accelerometer  f_S = q_body_imu^-1 (f_O + alpha_O x S + omega_O x (omega_O x S))            (seed eq. 14)
//                  f_O = q_world_body^-1 (a_world + [0, 0, g]) is the specific force at O in O, S = p_body_imu the
//                  IMU's displacement (the seed's S^(O)); the synthetic generator has S = 0.
//   magnetometer   m = A (q_world_body q_body_imu)^-1 h_world + b                               (seed eq. 10)
//                  it shares the IMU's frame; h_world is the Earth field in ENU (unit magnitude by default)
//   gps            p_antenna = p_world_body + q_world_body S_GPS (then ENU -> latitude, longitude, altitude)  (eq. 9)
//   rear wheel     z_v = omega_rear r / k_v,  k_v = kv_over_L L                                 (seed eq. 15)
//                  omega_rear = mean spin rate of the two rear wheels relative to the chassis [rad/s], r the tires'
//                  geometric radius [m]; the ground passes at omega_rear times their travel per radian, below r by
//                  the contact's sink (rolling_radius.h), which truth.yaml's kv_over_L takes in
//   handlebar      z_theta = (delta - k_gamma) / k_theta                                         (seed eq. 15)
//                  delta = the bicycle-equivalent steering angle of the two front wheels (ackermann.h)
//
// The state comes from MuJoCo (ReadSiteKinematics): MuJoCo's cacc carries the gravity offset, so the linear part of
// mj_objectAcceleration is the specific force, the same quantity as MuJoCo's own accelerometer sensor.
#pragma once

#include <mujoco/mujoco.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace roamlab::sim {

// Motion of a frame B fixed on the robot (here O), all rates and accelerations expressed in B.
struct FrameKinematics {
  Eigen::Vector3d p_world_body = Eigen::Vector3d::Zero();            // [m]
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();  // B -> W
  Eigen::Vector3d v_body = Eigen::Vector3d::Zero();                  // linear velocity of B's origin [m/s]
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();              // angular velocity [rad/s]
  Eigen::Vector3d alpha_body = Eigen::Vector3d::Zero();              // angular acceleration [rad/s^2]
  Eigen::Vector3d specific_force_body = Eigen::Vector3d::Zero();     // a - g at B's origin [m/s^2]
};

// Reads the kinematics of `site` from `data`. Precondition: mj_forward (or mj_step's forward part) and
// mj_rnePostConstraint have run on this state, so that cvel and cacc are current.
FrameKinematics ReadSiteKinematics(const mjModel* model, const mjData* data, int site);

struct ImuCalibration {
  Eigen::Quaterniond q_body_imu = Eigen::Quaterniond::Identity();  // unit; the seed's q_S^O
  Eigen::Vector3d p_body_imu = Eigen::Vector3d::Zero();            // [m], the seed's S^(O)
};

struct MagnetometerCalibration {
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();             // soft iron, scale, non-orthogonality
  Eigen::Vector3d b = Eigen::Vector3d::Zero();                 // hard iron [field units]
  Eigen::Vector3d field_world{0.0, 0.5, -0.8660254037844386};  // ENU, unit magnitude (dip 60 deg)
};

Eigen::Vector3d GyroReading(const FrameKinematics& body, const ImuCalibration& imu);   // [rad/s]
Eigen::Vector3d AccelReading(const FrameKinematics& body, const ImuCalibration& imu);  // [m/s^2]
Eigen::Vector3d MagnetometerReading(const FrameKinematics& body, const Eigen::Quaterniond& q_body_imu,
                                    const MagnetometerCalibration& magnetometer);
Eigen::Vector3d GpsAntennaWorld(const FrameKinematics& body, const Eigen::Vector3d& lever_arm_m);  // ENU [m]

// Eq. 15 readings. rear_wheel_rate_radps: mean rear-wheel spin rate; wheel_radius_m: the tires' geometric radius.
double SpeedReading(double rear_wheel_rate_radps, double wheel_radius_m, double kv_over_L, double wheelbase_m);
double SteeringReading(double delta_rad, double k_theta, double k_gamma);

}  // namespace roamlab::sim
