#include "sim/ackermann.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "common/check.h"
#include "sim/mujoco_model.h"

namespace roamlab::sim {
namespace {

enum Tire { kFrontLeft = 0, kFrontRight, kRearLeft, kRearRight };
const char* const kTireGeoms[4] = {"tire_front_left", "tire_front_right", "tire_rear_left", "tire_rear_right"};

Status Missing(const std::string& what, const std::string& element) {
  return Status::Error(what + ": the Ackermann vehicle needs " + element + " (see models/atv.xml)");
}

// A hinge joint's id, or -1.
int HingeJoint(const mjModel* model, const std::string& name) {
  const int id = IdOf(model, mjOBJ_JOINT, name);
  return id >= 0 && model->jnt_type[id] == mjJNT_HINGE ? id : -1;
}

// An actuator driving `joint` directly, or -1.
int JointActuator(const mjModel* model, const std::string& name, int joint) {
  const int id = IdOf(model, mjOBJ_ACTUATOR, name);
  if (id < 0 || model->actuator_trntype[id] != mjTRN_JOINT || model->actuator_trnid[2 * id] != joint) return -1;
  return id;
}

}  // namespace

void AckermannWheelAngles(double delta_rad, double wheelbase_m, double front_track_m, double* left_rad,
                          double* right_rad) {
  const double t = std::tan(delta_rad);
  const double half = 0.5 * front_track_m;
  *left_rad = std::atan(wheelbase_m * t / (wheelbase_m - half * t));
  *right_rad = std::atan(wheelbase_m * t / (wheelbase_m + half * t));
}

double BicycleEquivalentAngle(double left_rad, double right_rad) {
  const double tl = std::tan(left_rad);
  const double tr = std::tan(right_rad);
  if (tl * tr <= 0.0) return 0.5 * (left_rad + right_rad);
  return std::atan(2.0 * tl * tr / (tl + tr));
}

double SpeedController::Update(double setpoint_mps, double measured_mps, double dt_s) {
  const double error = setpoint_mps - measured_mps;
  const double limit = options_.torque_limit_nm;
  const double candidate = options_.kp_nm_per_mps * error + options_.ki_nm_per_m * (integral_m_ + error * dt_s);
  // Integrate only while the output is not saturated (anti-windup).
  if (std::abs(candidate) <= limit) {
    integral_m_ += error * dt_s;
    return candidate;
  }
  return std::clamp(options_.kp_nm_per_mps * error + options_.ki_nm_per_m * integral_m_, -limit, limit);
}

Result<AckermannVehicle> AckermannVehicle::Bind(const mjModel* model, const std::string& what) {
  AckermannVehicle v;
  // The free joint and the odometric site on its body.
  const int root = IdOf(model, mjOBJ_JOINT, "root");
  if (root < 0 || model->jnt_type[root] != mjJNT_FREE) return Missing(what, "a free joint 'root'");
  v.root_qpos_ = model->jnt_qposadr[root];
  v.root_body_ = model->jnt_bodyid[root];
  v.mass_kg_ = model->body_subtreemass[v.root_body_];
  v.odom_site_ = IdOf(model, mjOBJ_SITE, "odom");
  if (v.odom_site_ < 0) return Missing(what, "a site 'odom' (the odometric frame O)");
  if (model->site_bodyid[v.odom_site_] != v.root_body_)
    return Status::Error(what + ": site 'odom' must be on the body of the free joint 'root'");
  for (int i = 0; i < 3; ++i) v.odom_in_root_pos_[i] = model->site_pos[3 * v.odom_site_ + i];
  for (int i = 0; i < 4; ++i) v.odom_in_root_quat_[i] = model->site_quat[4 * v.odom_site_ + i];

  // Steering and rear wheel joints and their actuators.
  const int steer_left = HingeJoint(model, "steer_left");
  const int steer_right = HingeJoint(model, "steer_right");
  const int wheel_left = HingeJoint(model, "wheel_rear_left");
  const int wheel_right = HingeJoint(model, "wheel_rear_right");
  if (steer_left < 0 || steer_right < 0) return Missing(what, "hinge joints 'steer_left' and 'steer_right'");
  if (wheel_left < 0 || wheel_right < 0) return Missing(what, "hinge joints 'wheel_rear_left' and 'wheel_rear_right'");
  v.steer_left_qpos_ = model->jnt_qposadr[steer_left];
  v.steer_right_qpos_ = model->jnt_qposadr[steer_right];
  v.wheel_left_dof_ = model->jnt_dofadr[wheel_left];
  v.wheel_right_dof_ = model->jnt_dofadr[wheel_right];
  v.steer_left_actuator_ = JointActuator(model, "steer_left", steer_left);
  v.steer_right_actuator_ = JointActuator(model, "steer_right", steer_right);
  v.drive_left_actuator_ = JointActuator(model, "drive_rear_left", wheel_left);
  v.drive_right_actuator_ = JointActuator(model, "drive_rear_right", wheel_right);
  if (v.steer_left_actuator_ < 0 || v.steer_right_actuator_ < 0)
    return Missing(what, "actuators 'steer_left' and 'steer_right' on the steering joints");
  if (v.drive_left_actuator_ < 0 || v.drive_right_actuator_ < 0)
    return Missing(what, "actuators 'drive_rear_left' and 'drive_rear_right' on the rear wheel joints");

  // Tires: ids and radius.
  int tires[4];
  for (int i = 0; i < 4; ++i) {
    tires[i] = IdOf(model, mjOBJ_GEOM, kTireGeoms[i]);
    if (tires[i] < 0 || (model->geom_type[tires[i]] != mjGEOM_SPHERE && model->geom_type[tires[i]] != mjGEOM_CYLINDER))
      return Missing(what, std::string("a sphere or cylinder geom '") + kTireGeoms[i] + "'");
    v.tire_geoms_[i] = tires[i];
  }
  v.wheel_radius_m_ = 0.5 * (model->geom_size[3 * tires[kRearLeft]] + model->geom_size[3 * tires[kRearRight]]);

  // Geometry at qpos0: tire centres in O.
  DataPtr scratch = MakeData(model);
  mj_kinematics(model, scratch.get());
  const Eigen::Vector3d p_odom(scratch->site_xpos + 3 * v.odom_site_);
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R_world_odom(scratch->site_xmat + 9 * v.odom_site_);
  Eigen::Vector3d centre[4];
  for (int i = 0; i < 4; ++i) {
    centre[i] = R_world_odom.transpose() * (Eigen::Vector3d(scratch->geom_xpos + 3 * tires[i]) - p_odom);
    for (int k = 0; k < 3; ++k) v.tire_in_odom_[i][k] = centre[i][k];
  }
  const Eigen::Vector3d rear_mid = 0.5 * (centre[kRearLeft] + centre[kRearRight]);
  const Eigen::Vector3d front_mid = 0.5 * (centre[kFrontLeft] + centre[kFrontRight]);
  v.wheelbase_m_ = front_mid.x() - rear_mid.x();
  v.front_track_m_ = centre[kFrontLeft].y() - centre[kFrontRight].y();
  v.rear_track_m_ = centre[kRearLeft].y() - centre[kRearRight].y();
  if (!(v.wheelbase_m_ > 0.0 && v.front_track_m_ > 0.0 && v.rear_track_m_ > 0.0))
    return Status::Error(what +
                         ": the front tires must be ahead of the rear ones (+x of 'odom') and the left tires "
                         "on +y");
  if (std::hypot(rear_mid.x(), rear_mid.y()) > 0.05)
    return Status::Error(what + ": site 'odom' must be at the midpoint of the rear axle (it is " +
                         std::to_string(std::hypot(rear_mid.x(), rear_mid.y())) + " m away)");

  // Handlebar limit: the inner front wheel reaches the smaller servo (or joint) limit.
  double limit = 1e9;
  for (int actuator : {v.steer_left_actuator_, v.steer_right_actuator_}) {
    const int joint = model->actuator_trnid[2 * actuator];
    if (model->actuator_ctrllimited[actuator]) {
      limit = std::min({limit, std::abs(model->actuator_ctrlrange[2 * actuator]),
                        std::abs(model->actuator_ctrlrange[2 * actuator + 1])});
    }
    if (model->jnt_limited[joint]) {
      limit = std::min({limit, std::abs(model->jnt_range[2 * joint]), std::abs(model->jnt_range[2 * joint + 1])});
    }
  }
  limit = std::min(limit, 1.2);
  const double t = std::tan(limit);
  v.max_handlebar_rad_ = std::atan(v.wheelbase_m_ * t / (v.wheelbase_m_ + 0.5 * v.front_track_m_ * t));
  return v;
}

void AckermannVehicle::Place(const mjModel* model, mjData* data, const Terrain& terrain, double x, double y,
                             double yaw_rad, double clearance_m) const {
  // Ground height under each tire at the requested heading.
  const Eigen::Matrix3d R_yaw = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  double ground[4];
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d offset = R_yaw * Eigen::Vector3d(tire_in_odom_[i][0], tire_in_odom_[i][1], 0.0);
    ground[i] = terrain.HeightAt(x + offset.x(), y + offset.y());
  }
  // Pitch and roll of the plane through them; nose up is a negative rotation about y.
  const double pitch = std::atan2(
      0.5 * (ground[kFrontLeft] + ground[kFrontRight]) - 0.5 * (ground[kRearLeft] + ground[kRearRight]), wheelbase_m_);
  const double roll =
      std::atan2(0.5 * (ground[kFrontLeft] + ground[kRearLeft]) - 0.5 * (ground[kFrontRight] + ground[kRearRight]),
                 0.5 * (front_track_m_ + rear_track_m_));
  const Eigen::Quaterniond q_world_odom = Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ())) *
                                          Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()) *
                                          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  // Height of O: every tire (on average) its radius plus the clearance above the ground.
  double z = 0.0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d tire =
        q_world_odom * Eigen::Vector3d(tire_in_odom_[i][0], tire_in_odom_[i][1], tire_in_odom_[i][2]);
    z += 0.25 * (ground[i] - tire.z());
  }
  z += wheel_radius_m_ + clearance_m;

  // The root body's pose from O's pose.
  mj_resetData(model, data);
  const Eigen::Quaterniond q_root_odom(odom_in_root_quat_[0], odom_in_root_quat_[1], odom_in_root_quat_[2],
                                       odom_in_root_quat_[3]);
  const Eigen::Quaterniond q_world_root = (q_world_odom * q_root_odom.conjugate()).normalized();
  const Eigen::Vector3d p_world_root =
      Eigen::Vector3d(x, y, z) -
      q_world_root * Eigen::Vector3d(odom_in_root_pos_[0], odom_in_root_pos_[1], odom_in_root_pos_[2]);
  mjtNum* qpos = data->qpos + root_qpos_;
  qpos[0] = p_world_root.x();
  qpos[1] = p_world_root.y();
  qpos[2] = p_world_root.z();
  qpos[3] = q_world_root.w();
  qpos[4] = q_world_root.x();
  qpos[5] = q_world_root.y();
  qpos[6] = q_world_root.z();
  mj_forward(model, data);
}

void AckermannVehicle::TurnRearAxle(mjModel* model, double yaw_rad) const {
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()));
  for (int dof : {wheel_left_dof_, wheel_right_dof_}) {
    mjtNum* q = model->body_quat + 4 * model->dof_bodyid[dof];
    const Eigen::Quaterniond turned = (turn * Eigen::Quaterniond(q[0], q[1], q[2], q[3])).normalized();
    q[0] = turned.w();
    q[1] = turned.x();
    q[2] = turned.y();
    q[3] = turned.z();
  }
}

Status AckermannVehicle::SoftenTires(mjModel* model, double scale, const std::string& what) const {
  for (int i = 0; i < 4; ++i) {
    mjtNum* solref = model->geom_solref + mjNREF * tire_geoms_[i];
    if (!(solref[0] > 0.0))
      return Status::Error(what + ": lateral_slip needs the tire '" + kTireGeoms[i] +
                           "' to give solref as a time constant (solref[0] > 0)");
    solref[0] *= scale;
  }
  return Status::Ok();
}

void AckermannVehicle::Apply(double handlebar_rad, double torque_per_wheel_nm, mjData* data) const {
  const double delta = std::clamp(handlebar_rad, -max_handlebar_rad_, max_handlebar_rad_);
  double left = 0.0, right = 0.0;
  AckermannWheelAngles(delta, wheelbase_m_, front_track_m_, &left, &right);
  data->ctrl[steer_left_actuator_] = left;
  data->ctrl[steer_right_actuator_] = right;
  data->ctrl[drive_left_actuator_] = torque_per_wheel_nm;
  data->ctrl[drive_right_actuator_] = torque_per_wheel_nm;
}

double AckermannVehicle::RearWheelRate(const mjData* data) const {
  return 0.5 * (data->qvel[wheel_left_dof_] + data->qvel[wheel_right_dof_]);
}

double AckermannVehicle::SteeringAngle(const mjData* data) const {
  return BicycleEquivalentAngle(data->qpos[steer_left_qpos_], data->qpos[steer_right_qpos_]);
}

}  // namespace roamlab::sim
