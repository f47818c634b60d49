#include "sim/wheeled_robot.h"

#include <cmath>

#include <Eigen/Geometry>

#include "sim/mujoco_model.h"

namespace roamlab::sim {
namespace {

std::string ModelOf(const std::string& kind) {
  if (kind == "omni3") return "models/omni3.xml";
  if (kind == "mecanum") return "models/mecanum.xml";
  if (kind == "skid_steer") return "models/husky.xml";
  return "models/diffdrive.xml";
}

Status Missing(const std::string& what, const std::string& kind, const std::string& element) {
  return Status::Error(what + ": the " + kind + " robot needs " + element + " (see " + ModelOf(kind) + ")");
}

int ExpectedWheels(const std::string& kind) {
  if (kind == "differential_drive") return 2;
  if (kind == "omni3") return 3;
  if (kind == "mecanum" || kind == "skid_steer") return 4;
  return 0;
}

bool KindHasRollers(const std::string& kind) { return kind == "omni3" || kind == "mecanum"; }

// The layout each kind's nominal kinematics assumes (recording/wheel_kinematics.h); empty when the wheels follow it.
// Tolerances leave room for small mounting changes (WheelMountingChange).
std::string LayoutProblem(const std::string& kind, const std::vector<WheelGeometry>& w) {
  if (kind == "differential_drive") {
    if (!(w[0].p_body_m.y() > 0.0 && w[1].p_body_m.y() < 0.0 && std::abs(w[0].p_body_m.x()) < 0.01 &&
          std::abs(w[1].p_body_m.x()) < 0.01 && w[0].drive_direction.x() > 0.99 && w[1].drive_direction.x() > 0.99))
      return "differential drive: wheel_0 must be on the left (+y), wheel_1 on the right, both on the y axis of "
             "'odom' and rolling forward about +y";
  } else if (kind == "omni3") {
    const double distance = w[0].p_body_m.norm();
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d radial = w[i].p_body_m.normalized();
      if (std::abs(w[i].p_body_m.norm() - distance) > 0.02 ||
          std::abs(w[i].drive_direction.dot(Eigen::Vector2d(-radial.y(), radial.x()))) < 0.98 ||
          w[i].locked_direction.dot(w[i].drive_direction) < 0.98)
        return "omni3: wheel_" + std::to_string(i) +
               " must be at the same distance from 'odom' as wheel_0, its axle along the line to 'odom', its bottom "
               "roller along the rolling direction";
    }
  } else if (kind == "skid_steer") {
    const double sx[4] = {1, 1, -1, -1}, sy[4] = {1, -1, 1, -1};
    for (int i = 0; i < 4; ++i) {
      if (!(w[i].p_body_m.x() * sx[i] > 0.0 && w[i].p_body_m.y() * sy[i] > 0.0 && w[i].drive_direction.x() > 0.99))
        return "skid steer: wheel_" + std::to_string(i) + " must be " + (i < 2 ? "front " : "rear ") +
               (i % 2 == 0 ? "left" : "right") + " and roll forward about +y";
    }
  } else if (kind == "mecanum") {
    const double sx[4] = {1, 1, -1, -1}, sy[4] = {1, -1, 1, -1};
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector2d& p = w[i].p_body_m;
      // The locked direction must be about 45 deg off the rolling direction and across the diagonal through p (the
      // "X" layout); along the diagonal the wheel could not turn the body.
      const Eigen::Vector2d across(-sy[i], sx[i]);
      if (!(p.x() * sx[i] > 0.0 && p.y() * sy[i] > 0.0 && w[i].drive_direction.x() > 0.98 &&
            std::abs(std::abs(w[i].locked_direction.dot(w[i].drive_direction)) - std::sqrt(0.5)) < 0.1 &&
            std::abs(w[i].locked_direction.dot(across.normalized())) > 0.9))
        return "mecanum: wheel_" + std::to_string(i) + " must be " + (i < 2 ? "front " : "rear ") +
               (i % 2 == 0 ? "left" : "right") +
               ", rolling forward, its bottom roller's axis 45 deg off x and "
               "across the diagonal through the wheel (X layout)";
    }
  }
  return "";
}

}  // namespace

Result<WheeledRobot> WheeledRobot::Bind(const mjModel* model, const std::string& kind, const std::string& what) {
  WheeledRobot r;
  const int n = ExpectedWheels(kind);
  if (n == 0) return Status::Error(what + ": unsupported wheeled robot kind '" + kind + "'");
  r.kind_ = kind;
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
    if (tire < 0 || !(model->geom_type[tire] == mjGEOM_SPHERE ||
                      (KindHasRollers(kind) && model->geom_type[tire] == mjGEOM_CYLINDER)))
      return Missing(
          what, kind,
          std::string("a ") + (KindHasRollers(kind) ? "sphere or cylinder" : "sphere") + " geom 'tire_" + index + "'");
    r.wheel_qpos_.push_back(model->jnt_qposadr[joint]);
    r.wheel_dof_.push_back(model->jnt_dofadr[joint]);
    r.actuators_.push_back(actuator);
    r.tires_.push_back(tire);

    // Geometry in O: centre, axis, rolling direction d = a x e_z.
    const Eigen::Vector3d centre = R_world_odom.transpose() * (Eigen::Vector3d(scratch->geom_xpos + 3 * tire) - p_odom);
    const Eigen::Vector3d axis = R_world_odom.transpose() * Eigen::Vector3d(scratch->xaxis + 3 * joint);
    const Eigen::Vector3d direction = axis.cross(Eigen::Vector3d::UnitZ());
    if (direction.head<2>().norm() < 0.5)
      return Status::Error(what + ": wheel_" + index + " must turn about a horizontal axis");
    WheelGeometry w;
    w.p_body_m = centre.head<2>();
    w.drive_direction = direction.head<2>().normalized();
    w.locked_direction = w.drive_direction;
    w.radius_m = model->geom_size[3 * tire];
    w.mean_rolling_radius_m = w.radius_m;
    if (KindHasRollers(kind)) {
      w.envelope_radius_m = w.radius_m;
      // The roller under the wheel: its hinge axis, seen from above, is the locked direction u.
      const int roller = IdOf(model, mjOBJ_JOINT, "roller_" + index + "_0");
      if (roller < 0 || model->jnt_type[roller] != mjJNT_HINGE)
        return Missing(what, kind, "a hinge joint 'roller_" + index + "_0' (the roller under wheel_" + index + ")");
      const Eigen::Vector3d roller_axis = R_world_odom.transpose() * Eigen::Vector3d(scratch->xaxis + 3 * roller);
      if (roller_axis.head<2>().norm() < 0.9)
        return Status::Error(what + ": roller_" + index + "_0 must turn about a horizontal axis");
      w.locked_direction = roller_axis.head<2>().normalized();
      if (w.locked_direction.dot(w.drive_direction) < 0.0) w.locked_direction = -w.locked_direction;
    }
    height_sum += w.radius_m - centre.z();
    // omega_i = u . (v + omega_z (-y_i, x_i)) / (r u . d).
    const Eigen::Vector2d& u = w.locked_direction;
    const double scale = w.radius_m * u.dot(w.drive_direction);
    r.J_rates_twist_.row(i) << u.x() / scale, u.y() / scale, (-u.x() * w.p_body_m.y() + u.y() * w.p_body_m.x()) / scale;
    r.wheels_.push_back(w);
  }
  r.odom_height_m_ = height_sum / n;
  r.offsets_m_.assign(static_cast<std::size_t>(n), Eigen::Vector2d::Zero());
  if (const std::string problem = LayoutProblem(kind, r.wheels_); !problem.empty())
    return Status::Error(what + ": " + problem);
  return r;
}

Status WheeledRobot::ChangeMounting(mjModel* model, const std::vector<WheelMountingChange>& changes,
                                    const std::string& what) {
  for (const WheelMountingChange& c : changes) {
    const std::string name = "wheel_" + std::to_string(c.wheel);
    const int joint = IdOf(model, mjOBJ_JOINT, name);
    if (joint < 0) return Status::Error(what + ": robot.wheel_mounting: no wheel joint '" + name + "'");
    // The body turns about its origin (the wheel centre): yaw about z of the parent frame, then tilt about the
    // rolling direction d = a x e_z (a: the hinge axis in the parent's frame at qpos0).
    const int body = model->jnt_bodyid[joint];
    Eigen::Quaterniond q(model->body_quat[4 * body], model->body_quat[4 * body + 1], model->body_quat[4 * body + 2],
                         model->body_quat[4 * body + 3]);
    const Eigen::Vector3d axle = q * Eigen::Vector3d(model->jnt_axis + 3 * joint);
    const Eigen::Vector3d d = axle.cross(Eigen::Vector3d::UnitZ()).normalized();
    q = Eigen::AngleAxisd(c.yaw_rad, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(c.tilt_rad, d) * q;
    q.normalize();
    model->body_quat[4 * body] = q.w();
    model->body_quat[4 * body + 1] = q.x();
    model->body_quat[4 * body + 2] = q.y();
    model->body_quat[4 * body + 3] = q.z();
  }
  return Status::Ok();
}

Status WheeledRobot::Deform(mjModel* model, const std::vector<WheelDeformation>& deformations,
                            const std::string& what) {
  for (const WheelDeformation& d : deformations) {
    const std::string name = "robot.wheel_deformation: wheel " + std::to_string(d.wheel);
    if (d.wheel < 0 || d.wheel >= static_cast<int>(wheels_.size()))
      return Status::Error(what + ": " + name + ": the " + kind_ + " robot has " + std::to_string(wheels_.size()) +
                           " wheels");
    const int tire = tires_[static_cast<std::size_t>(d.wheel)];
    if (KindHasRollers(kind_) && d.ovality_m == 0.0 && !d.keep_mean_radius) {
      if (Status s = ScaleRollerWheel(model, d.wheel, d.radius_scale, what + ": " + name); !s.ok()) return s;
      continue;
    }
    if (model->geom_type[tire] != mjGEOM_SPHERE)
      return Status::Error(what + ": " + name + ": only sphere tires can be deformed");
    // Mean rolling radius of an ellipse of semi-axes a >= b: its perimeter / 2 pi (Ramanujan's second
    // approximation, exact to ~(h^5)).
    const auto mean_radius = [](double a, double b) {
      const double h = (a - b) * (a - b) / ((a + b) * (a + b));
      return (a + b) / 2.0 * (1.0 + 3.0 * h / (10.0 + std::sqrt(4.0 - 3.0 * h)));
    };
    const double r0 = model->geom_size[3 * tire];
    double r = r0 * d.radius_scale;
    if (!(r > 0.0) || !(d.ovality_m >= 0.0) || d.ovality_m > 0.5 * r)
      return Status::Error(what + ": " + name + ": needs radius_scale > 0 and 0 <= ovality_m <= half the radius");
    if (d.keep_mean_radius) {
      // The mean grows with r at a rate of about 1: a few fixed-point steps reach the target to rounding.
      const double target = r;
      for (int i = 0; i < 30; ++i) r -= mean_radius(r + d.ovality_m, r) - target;
    }
    const double a = r + d.ovality_m;
    // A tire of another size (radius_scale) is mounted with its hub moved along the parent's z by the radius change,
    // so that it keeps its contact with the floor beside the rigid casters (the chassis stays level, as a sprung
    // caster would keep it); otherwise a smaller tire hangs on the casters and loses its grip. The oval (ovality_m)
    // is the deformation itself and lifts its side, as tape around a wheel does.
    const int wheel_body = model->geom_bodyid[tire];
    model->body_pos[3 * wheel_body + 2] += r - r0;
    // Ellipsoid semi-axes (a, r, r) in a geom frame whose y axis is the wheel's hinge axis (in the body frame), so
    // that x is a direction of the wheel plane.
    const int joint = IdOf(model, mjOBJ_JOINT, "wheel_" + std::to_string(d.wheel));
    const Eigen::Vector3d axis = Eigen::Vector3d(model->jnt_axis + 3 * joint).normalized();
    const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitY(), axis);
    model->geom_type[tire] = d.ovality_m > 0.0 ? mjGEOM_ELLIPSOID : mjGEOM_SPHERE;
    model->geom_size[3 * tire] = a;
    model->geom_size[3 * tire + 1] = r;
    model->geom_size[3 * tire + 2] = r;
    model->geom_rbound[tire] = a;
    model->geom_quat[4 * tire] = q.w();
    model->geom_quat[4 * tire + 1] = q.x();
    model->geom_quat[4 * tire + 2] = q.y();
    model->geom_quat[4 * tire + 3] = q.z();
    wheels_[static_cast<std::size_t>(d.wheel)].mean_rolling_radius_m = mean_radius(a, r);
  }
  return Status::Ok();
}

Status WheeledRobot::ScaleRollerWheel(mjModel* model, int wheel, double radius_scale, const std::string& what) {
  const int tire = tires_[static_cast<std::size_t>(wheel)];
  const double r0 = model->geom_size[3 * tire], r = r0 * radius_scale;
  const std::string prefix = "roller_" + std::to_string(wheel) + "_";
  int rollers = 0;
  for (int body = IdOf(model, mjOBJ_BODY, prefix + "0"); body >= 0;
       body = IdOf(model, mjOBJ_BODY, prefix + std::to_string(++rollers))) {
    // The roller's centre sits at r0 - its radius from the hub; moved radially so that its rim reaches r.
    const int geom = model->body_geomadr[body];
    if (model->body_geomnum[body] < 1 || model->geom_type[geom] != mjGEOM_SPHERE)
      return Status::Error(what + ": " + prefix + std::to_string(rollers) + ": needs a sphere roller geom");
    const double roller_m = model->geom_size[3 * geom];
    if (!(r > roller_m) || !(r0 > roller_m))
      return Status::Error(what + ": the wheel's radius must stay above its rollers' radius");
    for (int k = 0; k < 3; ++k) model->body_pos[3 * body + k] *= (r - roller_m) / (r0 - roller_m);
  }
  if (rollers == 0) return Status::Error(what + ": no roller bodies '" + prefix + "<k>'");
  // As a sphere tire's: the hub moved along z by the radius change, so that the chassis keeps its height.
  model->body_pos[3 * model->geom_bodyid[tire] + 2] += r - r0;
  model->geom_size[3 * tire] = r;
  wheels_[static_cast<std::size_t>(wheel)].mean_rolling_radius_m = r;
  wheels_[static_cast<std::size_t>(wheel)].envelope_radius_m = r;
  return Status::Ok();
}

bool WheeledRobot::HasRollers() const { return KindHasRollers(kind_); }

void WheeledRobot::SetRollingRadii(const std::vector<double>& radii_m) {
  for (std::size_t i = 0; i < wheels_.size() && i < radii_m.size(); ++i) wheels_[i].mean_rolling_radius_m = radii_m[i];
}

Status WheeledRobot::ChangeTrack(mjModel* model, double track_error_m, const std::string& what) {
  if (kind_ != "differential_drive" && kind_ != "mecanum")
    return Status::Error(what + ": a track width error needs a differential_drive or mecanum robot");
  const Eigen::Quaterniond q_root_odom(odom_in_root_quat_[0], odom_in_root_quat_[1], odom_in_root_quat_[2],
                                       odom_in_root_quat_[3]);
  for (std::size_t i = 0; i < wheels_.size(); ++i) {
    const int body = model->jnt_bodyid[IdOf(model, mjOBJ_JOINT, "wheel_" + std::to_string(i))];
    if (model->body_parentid[body] != root_body_)
      return Status::Error(what + ": wheel_" + std::to_string(i) + "'s body must be a child of the root body");
    // Outwards: the side of O's x axis the wheel is on.
    const double side = wheels_[i].p_body_m.y() > 0.0 ? 1.0 : -1.0;
    const Eigen::Vector3d shift_root = q_root_odom * Eigen::Vector3d(0.0, 0.5 * side * track_error_m, 0.0);
    for (int k = 0; k < 3; ++k) model->body_pos[3 * body + k] += shift_root[k];
  }
  track_error_m_ += track_error_m;
  return Status::Ok();
}

Result<double> WheeledRobot::ScaleEffectiveTrack(mjModel* model, double ratio, const std::string& what) {
  if (kind_ != "skid_steer") return Status::Error(what + ": an effective track scale needs a skid_steer robot");
  const double track_m = SideToSideM();
  const double wheelbase_m =
      0.5 * (wheels_[0].p_body_m.x() + wheels_[1].p_body_m.x() - wheels_[2].p_body_m.x() - wheels_[3].p_body_m.x());
  const double effective_m = track_m + wheelbase_m * wheelbase_m / track_m;
  const double squared_m2 = track_m * (ratio * effective_m - track_m);
  if (!(track_m > 0.0 && wheelbase_m > 0.0 && squared_m2 > 0.0))
    return Status::Error(what + ": an effective track of " + std::to_string(ratio * effective_m) +
                         " m is not reachable with a track of " + std::to_string(track_m) + " m");
  const double shift_m = 0.5 * (std::sqrt(squared_m2) - wheelbase_m);
  std::vector<WheelOffset> offsets;
  for (int i = 0; i < 4; ++i)
    offsets.push_back(
        {i, Eigen::Vector2d(wheels_[static_cast<std::size_t>(i)].p_body_m.x() > 0.0 ? shift_m : -shift_m, 0.0)});
  if (Status st = MoveWheels(model, offsets, what); !st.ok()) return st;
  return std::sqrt(squared_m2);
}

Status WheeledRobot::MoveWheels(mjModel* model, const std::vector<WheelOffset>& offsets, const std::string& what) {
  const Eigen::Quaterniond q_root_odom(odom_in_root_quat_[0], odom_in_root_quat_[1], odom_in_root_quat_[2],
                                       odom_in_root_quat_[3]);
  for (const WheelOffset& o : offsets) {
    const std::string name = "robot.wheel_offset: wheel " + std::to_string(o.wheel);
    if (o.wheel < 0 || o.wheel >= static_cast<int>(wheels_.size()))
      return Status::Error(what + ": " + name + ": the " + kind_ + " robot has " + std::to_string(wheels_.size()) +
                           " wheels");
    const int body = model->jnt_bodyid[IdOf(model, mjOBJ_JOINT, "wheel_" + std::to_string(o.wheel))];
    if (model->body_parentid[body] != root_body_)
      return Status::Error(what + ": " + name + ": its body must be a child of the root body");
    const Eigen::Vector3d shift_root = q_root_odom * Eigen::Vector3d(o.offset_m.x(), o.offset_m.y(), 0.0);
    for (int k = 0; k < 3; ++k) model->body_pos[3 * body + k] += shift_root[k];
    offsets_m_[static_cast<std::size_t>(o.wheel)] += o.offset_m;
  }
  return Status::Ok();
}

double WheeledRobot::SideToSideM() const {
  if (kind_ == "differential_drive") return (wheels_.front().p_body_m - wheels_.back().p_body_m).norm();
  // skid_steer: the mean lateral positions of the left (0, 2) and right (1, 3) wheels.
  return 0.5 * (wheels_[0].p_body_m.y() + wheels_[2].p_body_m.y() - wheels_[1].p_body_m.y() - wheels_[3].p_body_m.y());
}

bool WheeledRobot::NominalLayout() const {
  if (kind_ != "omni3") return true;
  constexpr double kPi = 3.14159265358979323846;
  for (int i = 0; i < 3; ++i) {
    const WheelGeometry& w = wheels_[static_cast<std::size_t>(i)];
    const double alpha = (60.0 + 120.0 * i) * kPi / 180.0;
    const Eigen::Vector2d radial(std::cos(alpha), std::sin(alpha));
    if ((w.p_body_m - w.p_body_m.norm() * radial).norm() > 0.02 ||
        w.drive_direction.dot(Eigen::Vector2d(-radial.y(), radial.x())) < 0.98)
      return false;
  }
  return true;
}

std::map<std::string, double> WheeledRobot::PerWheelGeometry(const std::vector<std::string>& names) const {
  std::map<std::string, double> g;
  for (std::size_t i = 0; i < wheels_.size() && i < names.size(); ++i)
    g["wheel_radius_" + names[i] + "_m"] = wheels_[i].radius_m;
  if (kind_ == "differential_drive" || kind_ == "skid_steer") {
    g["track_m"] = SideToSideM();
  } else if (kind_ == "omni3") {
    g["wheel_distance_m"] = PlatformGeometry().at("wheel_distance_m");
    for (std::size_t i = 0; i < wheels_.size() && i < names.size(); ++i) {
      const Eigen::Vector2d& p = wheels_[i].p_body_m;
      g["wheel_angle_" + names[i] + "_rad"] = std::atan2(p.y(), p.x());
      // +1 when a positive rotation pushes the body along the counter-clockwise tangent.
      g["wheel_direction_" + names[i]] = wheels_[i].drive_direction.dot(Eigen::Vector2d(-p.y(), p.x())) > 0.0 ? 1 : -1;
    }
  } else {
    for (const auto& [key, value] : PlatformGeometry())
      if (key != "wheel_radius_m") g[key] = value;
  }
  return g;
}

std::map<std::string, double> WheeledRobot::PlatformGeometry() const {
  std::map<std::string, double> g{{"wheel_radius_m", mean_radius_m()}};
  if (kind_ == "differential_drive" || kind_ == "skid_steer") {
    g["baseline_m"] = SideToSideM();
  } else if (kind_ == "omni3") {
    double sum = 0.0;
    for (const WheelGeometry& w : wheels_) sum += w.p_body_m.norm();
    g["wheel_distance_m"] = sum / 3.0;
  } else {
    double lx = 0.0, ly = 0.0;
    for (const WheelGeometry& w : wheels_) {
      lx += 0.25 * std::abs(w.p_body_m.x());
      ly += 0.25 * std::abs(w.p_body_m.y());
    }
    g["half_length_m"] = lx;
    g["half_width_m"] = ly;
  }
  return g;
}

std::vector<std::string> WheeledRobot::EncoderColumns(const std::string& kind) {
  if (kind == "differential_drive") return {"left", "right"};
  if (kind == "mecanum" || kind == "skid_steer") return {"front_left", "front_right", "rear_left", "rear_right"};
  return {"wheel_0", "wheel_1", "wheel_2"};
}

std::map<std::string, std::vector<double>> WheeledRobot::TrueOdometerCalibration() const {
  const std::map<std::string, double> g = PlatformGeometry();
  // A moved wheel (MoveWheels) changes its yaw lever arm lambda_i = u_i . (e_z x p_i) / (u_i . d_i), the wheel row's
  // omega_z coefficient times r (sim/wheeled_robot.h), by u_i . (e_z x offset_i) / (u_i . d_i): the differential
  // drive's baseline is lambda_1 - lambda_0, omni3's distance and mecanum's lx + ly the mean |lambda_i| (the value
  // with which the nominal kinematics gives the true yaw rate; a single moved wheel makes the wheels' lever arms
  // differ, which no single value describes).
  std::vector<double> lever_change(wheels_.size());
  double change_of_mean_abs_lever_m = 0.0;
  for (std::size_t i = 0; i < wheels_.size(); ++i) {
    const WheelGeometry& w = wheels_[i];
    const Eigen::Vector2d& o = offsets_m_[i];
    const auto lever = [&w](const Eigen::Vector2d& p) {
      return w.locked_direction.dot(Eigen::Vector2d(-p.y(), p.x())) / w.locked_direction.dot(w.drive_direction);
    };
    lever_change[i] = lever(o);
    change_of_mean_abs_lever_m +=
        (lever(w.p_body_m) < 0.0 ? -1.0 : 1.0) * lever_change[i] / static_cast<double>(wheels_.size());
  }
  if (kind_ == "differential_drive")
    return {{"odometer.radius_left", {wheels_[0].mean_rolling_radius_m}},
            {"odometer.radius_right", {wheels_[1].mean_rolling_radius_m}},
            {"odometer.baseline", {g.at("baseline_m") + track_error_m_ + (lever_change[1] - lever_change[0])}}};
  // A skid steer's sides as the differential_drive model reads them: the geometric track (the effective one, wider
  // when the tires scrub, is the physics' and not known here).
  if (kind_ == "skid_steer")
    return {{"odometer.radius_left", {0.5 * (wheels_[0].mean_rolling_radius_m + wheels_[2].mean_rolling_radius_m)}},
            {"odometer.radius_right", {0.5 * (wheels_[1].mean_rolling_radius_m + wheels_[3].mean_rolling_radius_m)}},
            {"odometer.baseline",
             {g.at("baseline_m") + 0.5 * (lever_change[1] + lever_change[3] - lever_change[0] - lever_change[2])}}};
  std::map<std::string, std::vector<double>> cal;
  for (std::size_t i = 0; i < wheels_.size(); ++i) {
    cal["odometer.radius_" + std::to_string(i)] = {wheels_[i].mean_rolling_radius_m};
    cal["odometer.radius_envelope_" + std::to_string(i)] = {wheels_[i].envelope_radius_m};
  }
  if (kind_ == "omni3") {
    cal["odometer.distance"] = {g.at("wheel_distance_m") + change_of_mean_abs_lever_m};
  } else {
    cal["odometer.lx_plus_ly"] = {g.at("half_length_m") + g.at("half_width_m") + 0.5 * track_error_m_ +
                                  change_of_mean_abs_lever_m};
  }
  return cal;
}

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

void WheeledRobot::ApplyWheelRates(const Eigen::VectorXd& rates_radps, mjData* data) const {
  for (std::size_t i = 0; i < actuators_.size() && static_cast<Eigen::Index>(i) < rates_radps.size(); ++i)
    data->ctrl[actuators_[i]] = rates_radps[static_cast<Eigen::Index>(i)];
}

}  // namespace roamlab::sim
