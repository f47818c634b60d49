#include "sim/wheeled_robot.h"

#include <cmath>

#include <Eigen/Geometry>

#include "sim/mujoco_model.h"

namespace roamlab::sim {
namespace {

Status Missing(const std::string& what, const std::string& kind, const std::string& element) {
  return Status::Error(what + ": the " + kind + " robot needs " + element + " (see models/diffdrive.xml)");
}

int ExpectedWheels(const std::string& kind) { return kind == "differential_drive" ? 2 : 0; }

}  // namespace

Result<WheeledRobot> WheeledRobot::Bind(const mjModel* model, const std::string& kind, const std::string& what) {
  WheeledRobot r;
  const int n = ExpectedWheels(kind);
  if (n == 0) return Status::Error(what + ": unsupported wheeled robot kind '" + kind + "'");
  const int root = IdOf(model, mjOBJ_JOINT, "root");
  if (root < 0 || model->jnt_type[root] != mjJNT_FREE) return Missing(what, kind, "a free joint 'root'");
  r.root_qpos_ = model->jnt_qposadr[root];
  r.root_body_ = model->jnt_bodyid[root];
  r.odom_site_ = IdOf(model, mjOBJ_SITE, "odom");
  if (r.odom_site_ < 0 || model->site_bodyid[r.odom_site_] != r.root_body_)
    return Missing(what, kind, "a site 'odom' (the odometric frame O) on the body of the free joint 'root'");
  for (int i = 0; i < 3; ++i) r.odom_in_root_pos_[i] = model->site_pos[3 * r.odom_site_ + i];
  for (int i = 0; i < 4; ++i) r.odom_in_root_quat_[i] = model->site_quat[4 * r.odom_site_ + i];
  r.laser_site_ = IdOf(model, mjOBJ_SITE, "laser");

  // Wheel joints, actuators and tires.
  DataPtr scratch = MakeData(model);
  mj_kinematics(model, scratch.get());
  const Eigen::Vector3d p_odom(scratch->site_xpos + 3 * r.odom_site_);
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R_world_odom(scratch->site_xmat + 9 * r.odom_site_);
  r.J_rates_twist_.resize(n, 3);
  double height_sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const std::string index = std::to_string(i);
    const int joint = IdOf(model, mjOBJ_JOINT, "wheel_" + index);
    if (joint < 0 || model->jnt_type[joint] != mjJNT_HINGE)
      return Missing(what, kind, "a hinge joint 'wheel_" + index + "'");
    const int actuator = IdOf(model, mjOBJ_ACTUATOR, "drive_" + index);
    if (actuator < 0 || model->actuator_trntype[actuator] != mjTRN_JOINT ||
        model->actuator_trnid[2 * actuator] != joint)
      return Missing(what, kind, "a velocity actuator 'drive_" + index + "' on joint 'wheel_" + index + "'");
    const int tire = IdOf(model, mjOBJ_GEOM, "tire_" + index);
    if (tire < 0 || model->geom_type[tire] != mjGEOM_SPHERE)
      return Missing(what, kind, "a sphere geom 'tire_" + index + "'");
    r.wheel_qpos_.push_back(model->jnt_qposadr[joint]);
    r.wheel_dof_.push_back(model->jnt_dofadr[joint]);
    r.actuators_.push_back(actuator);

    // Geometry in O: centre, axis, rolling direction d = a x e_z.
    const Eigen::Vector3d centre =
        R_world_odom.transpose() * (Eigen::Vector3d(scratch->geom_xpos + 3 * tire) - p_odom);
    const Eigen::Vector3d axis = R_world_odom.transpose() * Eigen::Vector3d(scratch->xaxis + 3 * joint);
    const Eigen::Vector3d direction = axis.cross(Eigen::Vector3d::UnitZ());
    if (direction.head<2>().norm() < 0.5)
      return Status::Error(what + ": wheel_" + index + " must turn about a horizontal axis");
    WheelGeometry w;
    w.p_body_m = centre.head<2>();
    w.drive_direction = direction.head<2>().normalized();
    w.radius_m = model->geom_size[3 * tire];
    height_sum += w.radius_m - centre.z();
    // omega_i = d . (v + omega_z (-y_i, x_i)) / r.
    const Eigen::Vector2d& d = w.drive_direction;
    r.J_rates_twist_.row(i) << d.x() / w.radius_m, d.y() / w.radius_m,
        (-d.x() * w.p_body_m.y() + d.y() * w.p_body_m.x()) / w.radius_m;
    r.wheels_.push_back(w);
  }
  r.odom_height_m_ = height_sum / n;
  if (kind == "differential_drive" &&
      !(r.wheels_[0].p_body_m.y() > 0.0 && r.wheels_[1].p_body_m.y() < 0.0 &&
        std::abs(r.wheels_[0].p_body_m.x()) < 0.01 && std::abs(r.wheels_[1].p_body_m.x()) < 0.01 &&
        r.wheels_[0].drive_direction.x() > 0.99 && r.wheels_[1].drive_direction.x() > 0.99))
    return Status::Error(what + ": differential drive: wheel_0 must be on the left (+y), wheel_1 on the right, both "
                                "on the y axis of 'odom' and rolling forward about +y");
  return r;
}

double WheeledRobot::baseline_m() const { return (wheels_.front().p_body_m - wheels_.back().p_body_m).norm(); }

double WheeledRobot::mean_radius_m() const {
  double sum = 0.0;
  for (const WheelGeometry& w : wheels_) sum += w.radius_m;
  return sum / static_cast<double>(wheels_.size());
}

void WheeledRobot::Place(const mjModel* model, mjData* data, double x, double y, double yaw_rad,
                         double clearance_m) const {
  mj_resetData(model, data);
  const Eigen::Quaterniond q_world_odom(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond q_root_odom(odom_in_root_quat_[0], odom_in_root_quat_[1], odom_in_root_quat_[2],
                                       odom_in_root_quat_[3]);
  const Eigen::Quaterniond q_world_root = (q_world_odom * q_root_odom.conjugate()).normalized();
  const Eigen::Vector3d p_world_root =
      Eigen::Vector3d(x, y, odom_height_m_ + clearance_m) -
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

void WheeledRobot::Apply(double v_x_mps, double v_y_mps, double omega_z_radps, mjData* data) const {
  const Eigen::VectorXd rates = J_rates_twist_ * Eigen::Vector3d(v_x_mps, v_y_mps, omega_z_radps);
  for (std::size_t i = 0; i < actuators_.size(); ++i) data->ctrl[actuators_[i]] = rates[static_cast<int>(i)];
}

}  // namespace roamlab::sim
