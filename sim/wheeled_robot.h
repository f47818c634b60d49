// Wheeled indoor robots driven by wheel-speed servos (seed 000, Section VI): the binding to a compiled MuJoCo model
// whose element names follow models/diffdrive.xml (see the comment at its top), the wheel geometry measured on the
// model, and the driver's inverse kinematics.
//
// Kinematics (recording/wheel_kinematics.h): wheel i at p_i in O with rolling direction d_i = a_i x e_z (a_i its
// hinge axis in O: turning positive about a_i, the contact point moves along -d_i, so the body moves along +d_i) and
// true radius r_i turns at omega_i = d_i . (v + omega_z e_z x p_i) / r_i without slip. The driver turns body-velocity
// set-points (v_x, v_y, omega_z) into wheel-speed commands with these rows; the motors are MuJoCo velocity servos with
// a torque limit, so a set-point step asks for more torque than the tires can pass and the wheels slip.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <mujoco/mujoco.h>

#include "common/status.h"

namespace roamlab::sim {

struct WheelGeometry {
  Eigen::Vector2d p_body_m = Eigen::Vector2d::Zero();     // contact point below the wheel centre, in O [m]
  Eigen::Vector2d drive_direction = Eigen::Vector2d::UnitX();
  double radius_m = 0.0;                                 // true rolling radius
};

class WheeledRobot {
 public:
  // Finds the named elements and measures the wheels at qpos0. `kind` is the robot kind (differential_drive); errors
  // name `what` (the model file) and the missing element.
  static Result<WheeledRobot> Bind(const mjModel* model, const std::string& kind, const std::string& what);

  const std::vector<WheelGeometry>& wheels() const { return wheels_; }
  int odom_site() const { return odom_site_; }
  int laser_site() const { return laser_site_; }  // -1 when the model has none
  // Wheel rows of the kinematics: n x 3, rates [rad/s] = J [v_x, v_y, omega_z].
  const Eigen::MatrixXd& J_rates_twist() const { return J_rates_twist_; }
  // Distance between the two wheels' contact points [m] (differential drive).
  double baseline_m() const;
  double mean_radius_m() const;

  // Puts the robot at rest on the flat floor (z = 0) with O above (x, y), heading yaw_rad, the tires clearance_m
  // above the floor. Calls mj_forward.
  void Place(const mjModel* model, mjData* data, double x, double y, double yaw_rad, double clearance_m) const;
  // Wheel-speed servo targets [rad/s] for the body-velocity set-points.
  void Apply(double v_x_mps, double v_y_mps, double omega_z_radps, mjData* data) const;
  // Cumulative angle [rad] and rate [rad/s] of wheel i relative to the chassis.
  double WheelAngle(const mjData* data, int i) const { return data->qpos[wheel_qpos_[i]]; }
  double WheelRate(const mjData* data, int i) const { return data->qvel[wheel_dof_[i]]; }
  // Root body id (its subtree is the robot).
  int root_body() const { return root_body_; }

 private:
  int root_qpos_ = -1;
  int root_body_ = -1;
  int odom_site_ = -1;
  int laser_site_ = -1;
  std::vector<int> wheel_qpos_, wheel_dof_, actuators_;
  std::vector<WheelGeometry> wheels_;
  Eigen::MatrixXd J_rates_twist_;
  double odom_height_m_ = 0.0;      // height of O above the tires' lowest points at qpos0
  double odom_in_root_pos_[3] = {};
  double odom_in_root_quat_[4] = {1, 0, 0, 0};
};

}  // namespace roamlab::sim
