// Wheeled indoor robots driven by wheel-speed servos (seed 000, Section VI): the binding to a compiled MuJoCo model
// whose element names follow models/diffdrive.xml (see the comment at its top), the wheel geometry measured on the
// model, and the driver's inverse kinematics.
//
// Kinematics (recording/wheel_kinematics.h): wheel i at p_i in O with rolling direction d_i = a_i x e_z (a_i its
// hinge axis in O: turning positive about a_i, the contact point moves along -d_i, so the body moves along +d_i) and
// true radius r_i. The wheel is locked along a direction u_i of the floor plane and free across it: a standard tire
// and an omni wheel (rollers along the rim) have u_i = d_i, a mecanum wheel has u_i = the axis of the roller at the
// contact (45 deg off d_i). Without slip u_i . (v + omega_z e_z x p_i) = r_i omega_i (u_i . d_i), so
//     omega_i = u_i . (v + omega_z e_z x p_i) / (r_i u_i . d_i),
// which is d_i . (v + omega_z e_z x p_i) / r_i for u_i = d_i. The driver turns body-velocity set-points (v_x, v_y,
// omega_z) into wheel-speed commands with these rows; the motors are MuJoCo velocity servos with a torque limit, so a
// set-point step asks for more torque than the tires can pass and the wheels slip.
//
// Kinds and the names they need (see the comments at the top of the models):
//   differential_drive  models/diffdrive.xml: wheel_0 left, wheel_1 right, sphere tires
//   omni3               models/omni3.xml: wheels 0, 1, 2 at 60, 180, 300 deg from x, equal distance L, axles towards
//                       O; tire_<i> a sphere or cylinder; roller_<i>_0 the roller under wheel i at qpos0
//   mecanum             models/mecanum.xml: wheels 0-3 front left, front right, rear left, rear right at (+-lx, +-ly)
//                       rolling along +x; roller_<i>_0 under wheel i, its axis 45 deg off x and not along p_i
//   skid_steer          models/husky.xml: wheels 0-3 front left, front right, rear left, rear right, sphere tires
//                       rolling along +x; the driver's rows are a differential drive's of the two sides (a wheel at
//                       y_i turns at (v_x - omega_z y_i) / r), and the tires must scrub sideways to turn the body
// omni3 wheels may sit at any angles (models/optiodom_omni3.xml: -60, 60, 180 deg) and roll either way round: the
// rows are measured on the model; NominalLayout() says whether they are the 60, 180, 300 deg counter-clockwise
// layout that the nominal geometry keys (wheel_radius_m, wheel_distance_m) describe.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>
#include <Eigen/Core>

#include "common/status.h"

namespace roamlab::sim {

struct WheelGeometry {
  Eigen::Vector2d p_body_m = Eigen::Vector2d::Zero();  // contact point below the wheel centre, in O [m]
  Eigen::Vector2d drive_direction = Eigen::Vector2d::UnitX();
  Eigen::Vector2d locked_direction = Eigen::Vector2d::UnitX();  // u: unit, the direction the wheel cannot slide in
  double radius_m = 0.0;                                        // nominal rolling radius (the tire as modelled)
  // Travel per radian: a tire's radius_m unless deformed; a roller wheel's as SetRollingRadii measured it (below its
  // envelope: sim/rolling_radius.h), its envelope until then.
  double mean_rolling_radius_m = 0.0;
  double envelope_radius_m = 0.0;  // roller wheels: the rollers' envelope (radius_m unless scaled); tires: 0
};

// A change of one wheel's mounting, applied to the compiled model before binding (the wheel turns about its centre):
// yaw about the body's z axis (its axle out of alignment) and tilt (camber) about its rolling direction.
struct WheelMountingChange {
  int wheel = 0;
  double yaw_rad = 0.0;
  double tilt_rad = 0.0;
};

// A change of one wheel's tire (a sphere in the model), applied to the compiled model after binding, so that the
// platform geometry and the driver keep the nominal wheel: the tire's radius r becomes r * radius_scale (a worn or
// over-inflated tire), and ovality_m > 0 stretches it into an ellipsoid whose semi-axis along one direction of the
// wheel plane is r * radius_scale + ovality_m (a wheel deformed by thick tape, seed 001 Section IV-B5). Rolling on a
// floor, the axle height h(phi) then varies between r * radius_scale and that semi-axis twice per revolution; the
// centre advances h(phi) per radian of wheel rotation, so the travel per revolution is the ellipse's perimeter.
// keep_mean_radius: the short semi-axis is chosen instead so that the mean rolling radius (perimeter / 2 pi) stays
// r * radius_scale (an out-of-round tire: only the periodic part of the radius, the reality-gap effect).
struct WheelDeformation {
  int wheel = 0;
  double radius_scale = 1.0;
  double ovality_m = 0.0;
  bool keep_mean_radius = false;
};

// A wheel moved from its nominal position (an assembly error: its motor bracket fastened in the wrong holes, a bent
// bracket), applied to the compiled model after binding, so that the platform geometry and the driver keep the nominal
// wheel: the wheel body (wheel, rollers, tire) is translated by offset_m along O's x and y axes [m].
struct WheelOffset {
  int wheel = 0;
  Eigen::Vector2d offset_m = Eigen::Vector2d::Zero();
};

class WheeledRobot {
 public:
  // Finds the named elements and measures the wheels at qpos0. `kind` is the robot kind (differential_drive, omni3,
  // mecanum, skid_steer); errors name `what` (the model file) and the missing element.
  static Result<WheeledRobot> Bind(const mjModel* model, const std::string& kind, const std::string& what);
  // Turns wheel bodies of a compiled model (before Bind); errors name `what` and the wheel.
  static Status ChangeMounting(mjModel* model, const std::vector<WheelMountingChange>& changes,
                               const std::string& what);

  // Deforms tires of the bound model (see WheelDeformation); needs sphere tires. Updates each deformed wheel's
  // mean_rolling_radius_m (the true odometer radius) but neither the platform geometry nor the driver's kinematics.
  // Errors name `what` and the wheel.
  Status Deform(mjModel* model, const std::vector<WheelDeformation>& deformations, const std::string& what);
  // A roller wheel (omni3, mecanum) of another size: its rollers moved radially so that their envelope's radius is
  // radius_scale times the nominal (Deform's radius_scale on a roller wheel; ovality needs sphere tires).
  Status ScaleRollerWheel(mjModel* model, int wheel, double radius_scale, const std::string& what);
  // Whether the wheels are roller wheels (omni3, mecanum), whose true radius is measured (sim/rolling_radius.h).
  bool HasRollers() const;
  // Each wheel's travel per radian [m] (EncoderColumns order), measured on the physics: the true odometer radii.
  void SetRollingRadii(const std::vector<double>& radii_m);

  // Moves the wheels of the bound model apart by track_error_m (< 0: together), half on each side, along O's y axis
  // (a track wider or narrower than designed); differential_drive and mecanum, whose wheel bodies are children of the
  // root body. As Deform, it keeps the platform geometry and the driver's kinematics nominal; the true odometer
  // geometry (TrueOdometerCalibration) follows: baseline + track_error_m, lx_plus_ly + track_error_m / 2.
  Status ChangeTrack(mjModel* model, double track_error_m, const std::string& what);

  // skid_steer: scales the effective track B_eff = B + L^2 / B (four Coulomb contacts at (+-L/2, +-B/2)) by `ratio`
  // (> B / B_eff) by moving the front and rear wheels along O's x to +-L'/2, L'^2 = B (ratio B_eff - B), with
  // MoveWheels; returns L'. Errors name `what`.
  Result<double> ScaleEffectiveTrack(mjModel* model, double ratio, const std::string& what);

  // Moves wheel bodies of the bound model (see WheelOffset); their bodies must be children of the root body. As
  // Deform, it keeps the platform geometry and the driver's kinematics nominal; the true odometer geometry
  // (TrueOdometerCalibration) follows the moved wheels' yaw lever arms. Errors name `what` and the wheel.
  Status MoveWheels(mjModel* model, const std::vector<WheelOffset>& offsets, const std::string& what);

  const std::vector<WheelGeometry>& wheels() const { return wheels_; }
  int odom_site() const { return odom_site_; }
  int laser_site() const { return laser_site_; }  // -1 when the model has none
  // Wheel rows of the kinematics: n x 3, rates [rad/s] = J [v_x, v_y, omega_z].
  const Eigen::MatrixXd& J_rates_twist() const { return J_rates_twist_; }
  double mean_radius_m() const;
  // Distance between the left and right contact lines (differential_drive, skid_steer) [m].
  double SideToSideM() const;
  // The recording's platform geometry (recording/wheel_kinematics.h keys for the kind), measured on the model.
  std::map<std::string, double> PlatformGeometry() const;
  // The geometry under per-wheel keys (recording/wheel_kinematics.h, the OptiOdom importer's), `names` the encoder
  // column name of each wheel: wheel_radius_<name>_m; differential_drive and skid_steer track_m; omni3
  // wheel_distance_m, wheel_angle_<name>_rad, wheel_direction_<name>; mecanum the nominal keys.
  std::map<std::string, double> PerWheelGeometry(const std::vector<std::string>& names) const;
  // Whether the wheels follow the layout the kind's nominal geometry keys describe (always, except omni3 wheels off
  // 60, 180, 300 deg or turning clockwise).
  bool NominalLayout() const;
  // Encoder column names, one per wheel.
  std::vector<std::string> EncoderColumns() const { return EncoderColumns(kind_); }
  // Those of a kind (differential_drive: left, right; mecanum: front_left, front_right, rear_left, rear_right; omni3:
  // wheel_0, wheel_1, wheel_2).
  static std::vector<std::string> EncoderColumns(const std::string& kind);
  // The true odometer geometry under the names of the kind's estimator model (odometer.<slot>); roller wheels also
  // odometer.radius_envelope_<i>, the rollers' envelope, which no estimator parameter has.
  std::map<std::string, std::vector<double>> TrueOdometerCalibration() const;

  // Puts the robot at rest on the flat floor (z = 0) with O above (x, y), heading yaw_rad, the tires clearance_m
  // above the floor. Calls mj_forward.
  void Place(const mjModel* model, mjData* data, double x, double y, double yaw_rad, double clearance_m) const;
  // Wheel-speed servo targets [rad/s] for the body-velocity set-points.
  void Apply(double v_x_mps, double v_y_mps, double omega_z_radps, mjData* data) const;
  // Each wheel's velocity servo set to its own rate [rad/s] (one per wheel, EncoderColumns order): a replay of
  // measured wheel speeds.
  void ApplyWheelRates(const Eigen::VectorXd& rates_radps, mjData* data) const;
  // Cumulative angle [rad] and rate [rad/s] of wheel i relative to the chassis.
  double WheelAngle(const mjData* data, int i) const { return data->qpos[wheel_qpos_[i]]; }
  double WheelRate(const mjData* data, int i) const { return data->qvel[wheel_dof_[i]]; }
  // Root body id (its subtree is the robot).
  int root_body() const { return root_body_; }

 private:
  std::string kind_;
  int root_qpos_ = -1;
  int root_body_ = -1;
  int odom_site_ = -1;
  int laser_site_ = -1;
  std::vector<int> wheel_qpos_, wheel_dof_, actuators_, tires_;
  std::vector<WheelGeometry> wheels_;
  Eigen::MatrixXd J_rates_twist_;
  double track_error_m_ = 0.0;              // ChangeTrack's, for the true geometry
  std::vector<Eigen::Vector2d> offsets_m_;  // MoveWheels', per wheel in O, for the true geometry
  double odom_height_m_ = 0.0;              // height of O above the tires' lowest points at qpos0
  double odom_in_root_pos_[3] = {};
  double odom_in_root_quat_[4] = {1, 0, 0, 0};
};

}  // namespace roamlab::sim
