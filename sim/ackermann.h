// The Ackermann vehicle (the seed's ATV): steering geometry, the rear-wheel speed controller, and the binding to a
// compiled MuJoCo model whose element names follow models/atv.xml (see the comment at its top).
//
// Steering. The driver commands one handlebar angle delta [rad], the steering angle of the equivalent bicycle (one
// front wheel on the centre line; positive turns left). With wheelbase L and front track w, the two front wheels are
// set to the Ackermann angles that share the bicycle's turning centre on the rear-axle line:
//     tan(delta_left)  = L tan(delta) / (L - (w/2) tan(delta)),   tan(delta_right) = L tan(delta) / (L + (w/2)
//     tan(delta))
// and, back from the two joint angles (whatever they are, e.g. lagging the servos), the bicycle-equivalent angle is
//     cot(delta) = (cot(delta_left) + cot(delta_right)) / 2,   i.e. tan(delta) = 2 t_l t_r / (t_l + t_r),
// which inverts the first pair exactly and does not depend on L or w. If the two wheels point to opposite sides (only
// possible near zero), it falls back to the mean angle.
//
// Drive. A PI controller on the rear-wheel speed (mean rear spin rate times the tire radius, what the vehicle's
// own speed sensor sees) outputs one torque that goes to both rear wheels: an open differential, so the rear wheels
// may turn at different rates in curves. The integral is frozen while the torque saturates (anti-windup). The same
// torque brakes when negative. The steering servos are MuJoCo position actuators on the steering hinges.
#pragma once

#include <string>

#include <mujoco/mujoco.h>

#include "common/status.h"
#include "sim/terrain.h"

namespace roamlab::sim {

// Front-wheel angles [rad] for the bicycle-equivalent angle delta [rad], |delta| < atan(2 L / w).
void AckermannWheelAngles(double delta_rad, double wheelbase_m, double front_track_m, double* left_rad,
                          double* right_rad);
// The bicycle-equivalent angle [rad] of two front-wheel angles [rad].
double BicycleEquivalentAngle(double left_rad, double right_rad);

struct SpeedControllerOptions {
  double kp_nm_per_mps = 300.0;    // torque per rear wheel per m/s of speed error
  double ki_nm_per_m = 150.0;      // torque per rear wheel per m of integrated speed error
  double torque_limit_nm = 400.0;  // per rear wheel, both ways

  // Empty when usable; otherwise "<field>: <problem>".
  std::string Validate() const;
};

class SpeedController {
 public:
  explicit SpeedController(const SpeedControllerOptions& options) : options_(options) {}
  // Torque per rear wheel [N m] after one control period dt_s [s].
  double Update(double setpoint_mps, double measured_mps, double dt_s);

 private:
  SpeedControllerOptions options_;
  double integral_m_ = 0.0;
};

// Indices of an Ackermann vehicle's elements in a compiled model, and its geometry measured on the model.
class AckermannVehicle {
 public:
  // Finds the named elements (models/atv.xml) and measures the geometry at qpos0. Errors name `what` (the model file)
  // and the missing or malformed element.
  static Result<AckermannVehicle> Bind(const mjModel* model, const std::string& what);

  double wheelbase_m() const { return wheelbase_m_; }  // rear to front wheel centres along x of O
  double front_track_m() const { return front_track_m_; }
  double rear_track_m() const { return rear_track_m_; }
  double wheel_radius_m() const { return wheel_radius_m_; }        // the rear tires' geometric radius
  double mass_kg() const { return mass_kg_; }                      // the whole vehicle (the root body's subtree)
  double max_handlebar_rad() const { return max_handlebar_rad_; }  // the inner wheel reaches the servo limit
  int odom_site() const { return odom_site_; }

  // Puts the vehicle at rest with O above (x, y) and heading yaw_rad (from east, counter-clockwise), pitched and
  // rolled to the plane of the ground under its four wheels, the tires `clearance_m` above the ground. Calls
  // mj_forward.
  void Place(const mjModel* model, mjData* data, const Terrain& terrain, double x, double y, double yaw_rad,
             double clearance_m) const;
  // A misaligned rear axle (the scenario's axle_misalignment effect): both rear wheel bodies turned about their
  // parent's z through their centre by yaw_rad (positive counter-clockwise), so that their hinges, hence their rolling
  // directions, point yaw_rad off O's x (a thrust angle). Changes the compiled model only: the geometry measured by
  // Bind (tire centres) is unchanged, and the driver's steering stays nominal.
  void TurnRearAxle(mjModel* model, double yaw_rad) const;
  // Softer tires (the scenario's lateral_slip effect): the four tires' contact time constant (MuJoCo's solref[0], the
  // ground geom takes the robot's softness) times `scale`. MuJoCo's soft contact lets a tangential force through by a
  // slip velocity proportional to it and to the time constant, so the cornering compliance grows with `scale` (on the
  // ATV about linearly); the vertical contact softens too (a lower tire pressure). Changes the compiled model
  // only. Fails, naming `what`, when a tire's solref is not in the time-constant form (solref[0] <= 0).
  Status SoftenTires(mjModel* model, double scale, const std::string& what) const;
  // Steering servo targets for the handlebar angle (clamped to +-max_handlebar_rad) and the drive torque per rear
  // wheel.
  void Apply(double handlebar_rad, double torque_per_wheel_nm, mjData* data) const;
  // Mean rear-wheel spin rate relative to the chassis [rad/s], positive forward.
  double RearWheelRate(const mjData* data) const;
  // Bicycle-equivalent angle of the two steering joints [rad].
  double SteeringAngle(const mjData* data) const;

 private:
  int root_qpos_ = -1;  // free joint: x y z qw qx qy qz
  int root_body_ = -1;
  double mass_kg_ = 0.0;
  int odom_site_ = -1;
  int steer_left_qpos_ = -1, steer_right_qpos_ = -1;
  int wheel_left_dof_ = -1, wheel_right_dof_ = -1;
  int steer_left_actuator_ = -1, steer_right_actuator_ = -1;
  int drive_left_actuator_ = -1, drive_right_actuator_ = -1;
  double wheelbase_m_ = 0.0, front_track_m_ = 0.0, rear_track_m_ = 0.0, wheel_radius_m_ = 0.0;
  double max_handlebar_rad_ = 0.0;
  // Tire centres in O at qpos0 (front left, front right, rear left, rear right) and O in the root body's frame.
  double tire_in_odom_[4][3] = {};
  int tire_geoms_[4] = {-1, -1, -1, -1};  // front left, front right, rear left, rear right
  double odom_in_root_pos_[3] = {};
  double odom_in_root_quat_[4] = {1, 0, 0, 0};
};

}  // namespace roamlab::sim
