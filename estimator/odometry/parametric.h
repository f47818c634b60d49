// Parametric odometry models: the baselines of seed 001 (Section IV-C, Tables III-IV).
//
// A wheeled robot whose wheels roll without slip obeys rim_i = r_i dphi_i/dt = J_i . [v_x, v_y, omega] (body twist at
// the odometric frame O), one row J_i per wheel. Over an interval with constant twist the wheel rotations delta give
// the twist integral xi = J^+ diag(r) delta (least squares for more wheels than 3 components; for a differential drive
// the v_y column is zero and J^+ gives v_y = 0) and the robot displacement q = Exp(xi):
//   q = [(xi_x sin w - xi_y (1 - cos w)) / w,  (xi_x (1 - cos w) + xi_y sin w) / w,  w],  w = xi_theta
// The exteroceptive sensor at pose l in O moves by s = (-)l (+) q (+) l (Section II).
//
// Nominal rows from recording.yaml's platform (keys carry units; per-wheel keys use the encoder column names):
//   differential_drive  wheels `right`, `left`: right [1, 0, b/2], left [1, 0, -b/2]; b = geometry.track_m
//   omni3               wheel i at angle a_i (geometry.wheel_angle_<name>_rad, from the body x axis, counter-clockwise)
//                       and distance L (geometry.wheel_distance_m): d_i [-sin a_i, cos a_i, L], d_i = +1 when a
//                       positive wheel rotation drives the robot counter-clockwise, -1 when clockwise
//                       (geometry.wheel_direction_<name>, default +1)
//   mecanum             wheels front_left, front_right, rear_left, rear_right, rollers at 45 deg (Taheri et al., the
//                       seed's [16]): [1, -1, -k], [1, 1, k], [1, 1, -k], [1, -1, k], k = (wheelbase_m + track_m) / 2
//   omni4               wheels front_left, front_right, rear_left, rear_right (recording/wheel_kinematics.h omni4):
//                       (1, -1, -K) / sqrt 2, (-1, -1, -K) / sqrt 2, (1, 1, -K) / sqrt 2, (-1, 1, -K) / sqrt 2,
//                       K = (wheelbase_m + track_m) / 2
//   tricycle            columns <wheel>_cos_steering, <wheel>_sin_steering (training_data.h): [cos o, 0, L sin o],
//                       [-sin o, 0, L cos o], o = geometry.steering_offset_rad (default 0), L =
//                       geometry.wheel_to_axle_m, radius of <wheel> for both
// Radii: geometry.wheel_radius_<name>_m, else geometry.wheel_radius_m. The nominal sensor pose is O itself.
// A simulated recording's platform uses the keys of recording/wheel_kinematics.h instead (differential_drive
// baseline_m, omni3 wheel_distance_m without per-wheel angles, mecanum half_length_m and half_width_m; wheels in the
// simulator's column order): then the rows are that header's, J_i = r J_rates_twist_i.
//
// Censi et al. (the seed's [10], "CMLE" baseline) calibrate a differential drive from the same training pairs:
//   1. J21 = -r_L / b and J22 = r_R / b from the sensor rotations, s_theta = J21 delta_L + J22 delta_R (linear, here
//      Huber-robust);
//   2. with theta known, the robot translation is b c_jk (c from J21, J22 and the wheel rotations), and the sensor
//      relation l (+) s = q (+) l is linear in phi = [l_x, l_y, b, cos l_theta, sin l_theta]:
//        (I - R(q_theta)) l_xy - b c + R(l_theta) s_xy = 0,
//      solved by min |G phi|^2 subject to cos^2 + sin^2 = 1: eliminate [l_x, l_y, b] (Schur complement) and take the
//      eigenvector of the smallest eigenvalue of the remaining 2 x 2 matrix, signed so that b > 0;
//   3. r_L = -J21 b, r_R = J22 b.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/odometry/se2.h"
#include "estimator/odometry/training_data.h"
#include "recording/recording.h"

namespace roamlab::estimator::odometry {

struct WheelKinematics {
  std::string kind;                   // platform kind
  std::vector<std::string> wheels;    // encoder column names, in the order of the rows of J
  Eigen::MatrixXd J;                  // m x 3
  Eigen::VectorXd radius_m;           // m
  Pose2 sensor_pose = Pose2::Zero();  // l: sensor in O

  // Sensor displacement for wheel rotations delta [rad] (m entries).
  Pose2 Displacement(const Eigen::VectorXd& delta) const;
};

// Exp of a planar twist integral [x, y, theta] (constant twist over the interval).
Pose2 ExpTwist(const Eigen::Vector3d& xi);

// The nominal model from the platform entry. Errors name the missing key or wheel, or an unsupported kind.
Result<WheelKinematics> NominalKinematics(const recording::Platform& platform, const std::vector<std::string>& wheels);

// Differential drive from wheel radii and track.
WheelKinematics DifferentialDrive(const std::vector<std::string>& wheels, double radius_right_m, double radius_left_m,
                                  double track_m, const Pose2& sensor_pose);

struct CensiCalibration {
  double radius_left_m = 0.0;
  double radius_right_m = 0.0;
  double track_m = 0.0;
  Pose2 sensor_pose = Pose2::Zero();
  WheelKinematics kinematics;
};

// Censi et al.'s calibration (steps above). The set must have wheels `left` and `right`. Errors: missing wheels,
// degenerate data (no rotation, or no translation).
Result<CensiCalibration> CalibrateDifferentialDrive(const TrainingSet& data);

}  // namespace roamlab::estimator::odometry
