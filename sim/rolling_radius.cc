#include "sim/rolling_radius.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/mujoco_model.h"
#include "sim/terrain.h"

namespace roamlab::sim {
namespace {

constexpr double kTwoPi = 6.28318530717958647692;
constexpr double kPlacementClearanceM = 0.01;
// The drive's time limit for a measurement window, in multiples of the time the window takes at the set speed.
constexpr double kWindowTimeLimit = 5.0;

// A copy of `model` whose world geoms other than the ground do not collide with the robot.
ModelPtr FloorOnlyCopy(const mjModel* model) {
  ModelPtr copy(mj_copyModel(nullptr, model));
  const int ground = IdOf(copy.get(), mjOBJ_GEOM, "terrain");
  for (int g = 0; g < copy->ngeom; ++g) {
    if (copy->geom_bodyid[g] != 0 || g == ground) continue;
    copy->geom_contype[g] = 0;
    copy->geom_conaffinity[g] = 0;
  }
  return copy;
}

// FloorOnlyCopy with its ground level at z = 0: a heightfield's samples and geom height set to 0 (a plane stays).
ModelPtr LevelGroundCopy(const mjModel* model) {
  ModelPtr copy = FloorOnlyCopy(model);
  const int hfield = IdOf(copy.get(), mjOBJ_HFIELD, "terrain");
  if (hfield >= 0) {
    float* samples = copy->hfield_data + copy->hfield_adr[hfield];
    std::fill(samples, samples + copy->hfield_nrow[hfield] * copy->hfield_ncol[hfield], 0.0f);
    copy->geom_pos[3 * IdOf(copy.get(), mjOBJ_GEOM, "terrain") + 2] = 0.0;
  }
  return copy;
}

// The angle [rad] over which wheel i is measured: `pitches` roller pitches, or one revolution without rollers.
double WindowRad(const mjModel* model, int wheel, int pitches) {
  const std::string prefix = "roller_" + std::to_string(wheel) + "_";
  int rollers = 0;
  while (IdOf(model, mjOBJ_BODY, prefix + std::to_string(rollers)) >= 0) ++rollers;
  return rollers == 0 ? kTwoPi : pitches * kTwoPi / rollers;
}

// Groups of wheels that share a rolling direction (in O).
std::vector<std::vector<int>> DirectionGroups(const WheeledRobot& robot) {
  std::vector<std::vector<int>> groups;
  const std::vector<WheelGeometry>& wheels = robot.wheels();
  for (int i = 0; i < static_cast<int>(wheels.size()); ++i) {
    const auto same = [&](const std::vector<int>& g) {
      return wheels[static_cast<std::size_t>(g.front())].drive_direction.dot(
                 wheels[static_cast<std::size_t>(i)].drive_direction) > 0.999;
    };
    const auto found = std::find_if(groups.begin(), groups.end(), same);
    if (found == groups.end()) {
      groups.push_back({i});
    } else {
      found->push_back(i);
    }
  }
  return groups;
}

// One wheel's measurement: its hub's travel along its rolling direction and its rotation since the window opened.
struct WheelTravel {
  int joint = -1;
  double window_rad = 0.0;
  double start_angle_rad = 0.0;
  Eigen::Vector3d last_hub_world = Eigen::Vector3d::Zero();
  double travel_m = 0.0;
  double radius_m = 0.0;    // set when the window closes
  double duration_s = 0.0;  // set when the window closes
};

// The rolling direction in the world, d = a x e_z (a: the hinge axis), of the wheel on `joint`.
Eigen::Vector3d RollingDirectionWorld(const mjData* data, int joint) {
  const Eigen::Vector3d axis(data->xaxis + 3 * joint);
  return axis.cross(Eigen::Vector3d::UnitZ()).normalized();
}

Eigen::Vector3d HubWorld(const mjModel* model, const mjData* data, int joint) {
  return Eigen::Vector3d(data->xpos + 3 * model->jnt_bodyid[joint]);
}

// Sets the robot's actuators for a body velocity set-point v (in O) before a physics step.
using ApplySetPoint = std::function<void(const Eigen::Vector2d& v, mjData* data)>;
// Sees the state after each physics step of a measurement while a window is open.
using ObserveStep = std::function<void(const mjData* data)>;

class Drive {
 public:
  Drive(const mjModel* model, mjData* data, ApplySetPoint apply, const std::string& what, ObserveStep observe = {})
      : model_(model), data_(data), apply_(std::move(apply)), what_(what), observe_(std::move(observe)) {}

  // Steps for duration_s with the body velocity set-point ramping from `from` to `to` (in O).
  Status Run(double duration_s, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
    const long steps = std::lround(duration_s / model_->opt.timestep);
    for (long k = 0; k < steps; ++k) {
      const Eigen::Vector2d v = from + (to - from) * (static_cast<double>(k + 1) / static_cast<double>(steps));
      if (Status s = Step(v); !s.ok()) return s;
    }
    return Status::Ok();
  }

  // Steps at the set-point v until every wheel in `travels` has turned its window.
  Status Measure(const Eigen::Vector2d& v, double limit_s, std::vector<WheelTravel>* travels) {
    for (WheelTravel& w : *travels) {
      w.start_angle_rad = data_->qpos[model_->jnt_qposadr[w.joint]];
      w.last_hub_world = HubWorld(model_, data_, w.joint);
    }
    const long limit_steps = std::lround(limit_s / model_->opt.timestep);
    for (long k = 0; k < limit_steps; ++k) {
      std::vector<double> turned_before;
      for (const WheelTravel& w : *travels) turned_before.push_back(Turned(w));
      if (Status s = Step(v); !s.ok()) return s;
      if (observe_) observe_(data_);
      bool open = false;
      for (std::size_t i = 0; i < travels->size(); ++i) {
        WheelTravel& w = (*travels)[i];
        if (w.radius_m > 0.0) continue;
        const Eigen::Vector3d hub = HubWorld(model_, data_, w.joint);
        const double step_m = (hub - w.last_hub_world).dot(RollingDirectionWorld(data_, w.joint));
        w.last_hub_world = hub;
        const double turned = Turned(w);
        if (turned < w.window_rad) {
          w.travel_m += step_m;
          open = true;
          continue;
        }
        // The window closes within this step: its share of the step's travel, linear in the rotation.
        const double share = (w.window_rad - turned_before[i]) / (turned - turned_before[i]);
        w.radius_m = (w.travel_m + share * step_m) / w.window_rad;
        w.duration_s = (static_cast<double>(k) + share) * model_->opt.timestep;
      }
      if (!open) return Status::Ok();
    }
    return Status::Error(what_ + ": measuring the rolling radius: a wheel did not turn its window within " +
                         std::to_string(limit_s) + " s");
  }

 private:
  double Turned(const WheelTravel& w) const { return data_->qpos[model_->jnt_qposadr[w.joint]] - w.start_angle_rad; }

  // One physics step at the set-point v (in O), then the positions for the new state.
  Status Step(const Eigen::Vector2d& v) {
    apply_(v, data_);
    mj_step(model_, data_);
    if (data_->warning[mjWARN_BADQACC].number > 0)
      return Status::Error(what_ +
                           ": measuring the rolling radius: the simulation diverged (MuJoCo: bad acceleration)");
    mj_kinematics(model_, data_);
    return Status::Ok();
  }

  const mjModel* model_;
  mjData* data_;
  ApplySetPoint apply_;
  const std::string& what_;
  ObserveStep observe_;
};

// A copy of LevelGroundCopy(model) whose gravity is turned by atan(grade) about y: the force balance of a drive along
// +x up a slope of that grade (unchanged at grade 0).
ModelPtr GradedGroundCopy(const mjModel* model, double grade) {
  ModelPtr copy = LevelGroundCopy(model);
  if (grade == 0.0) return copy;
  const double g_mps2 = Eigen::Vector3d(copy->opt.gravity).norm();
  const double slope_rad = std::atan(grade);
  copy->opt.gravity[0] = -g_mps2 * std::sin(slope_rad);
  copy->opt.gravity[1] = 0.0;
  copy->opt.gravity[2] = -g_mps2 * std::cos(slope_rad);
  return copy;
}

// The ground's force [N] on the geoms `tires` along the world direction `along`, summed over their contacts.
double ContactForceAlong(const mjModel* model, const mjData* data, const std::vector<int>& tires,
                         const Eigen::Vector3d& along) {
  double force_n = 0.0;
  for (int i = 0; i < data->ncon; ++i) {
    const mjContact& c = data->contact[i];
    const bool on_first = std::find(tires.begin(), tires.end(), c.geom1) != tires.end();
    const bool on_second = std::find(tires.begin(), tires.end(), c.geom2) != tires.end();
    if (on_first == on_second) continue;
    mjtNum f_contact[6];
    mj_contactForce(model, data, i, f_contact);
    // The contact frame's rows are the normal (from geom1 to geom2) and the two tangents; the force acts on geom2.
    Eigen::Vector3d f_world = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) f_world += f_contact[k] * Eigen::Vector3d(c.frame + 3 * k);
    force_n += (on_second ? 1.0 : -1.0) * f_world.dot(along);
  }
  return force_n;
}

}  // namespace

Result<std::vector<double>> MeasureRollingRadii(const mjModel* model, const WheeledRobot& robot, double x, double y,
                                                double yaw_rad, const std::string& what,
                                                const RollingRadiusDrive& drive) {
  const ModelPtr floor_only = FloorOnlyCopy(model);
  const mjModel* m = floor_only.get();
  DataPtr data = MakeData(m);
  robot.Place(m, data.get(), x, y, yaw_rad, kPlacementClearanceM);
  Drive driver(
      m, data.get(), [&robot](const Eigen::Vector2d& v, mjData* d) { robot.Apply(v.x(), v.y(), 0.0, d); }, what);
  const Eigen::Vector2d rest = Eigen::Vector2d::Zero();
  if (Status s = driver.Run(drive.settle_s, rest, rest); !s.ok()) return s;

  std::vector<double> radii(robot.wheels().size(), 0.0);
  for (const std::vector<int>& group : DirectionGroups(robot)) {
    const Eigen::Vector2d v = drive.speed_mps * robot.wheels()[static_cast<std::size_t>(group.front())].drive_direction;
    std::vector<WheelTravel> travels;
    double longest_window_rad = 0.0;
    for (int i : group) {
      WheelTravel w;
      w.joint = IdOf(m, mjOBJ_JOINT, "wheel_" + std::to_string(i));
      w.window_rad = WindowRad(m, i, drive.pitches);
      longest_window_rad = std::max(longest_window_rad, w.window_rad);
      travels.push_back(w);
    }
    const double window_s =
        longest_window_rad * robot.wheels()[static_cast<std::size_t>(group.front())].radius_m / drive.speed_mps;
    if (Status s = driver.Run(drive.ramp_s, rest, v); !s.ok()) return s;
    if (Status s = driver.Run(drive.hold_s, v, v); !s.ok()) return s;
    if (Status s = driver.Measure(v, kWindowTimeLimit * window_s, &travels); !s.ok()) return s;
    if (Status s = driver.Run(drive.ramp_s, v, rest); !s.ok()) return s;
    for (std::size_t k = 0; k < group.size(); ++k) radii[static_cast<std::size_t>(group[k])] = travels[k].radius_m;
  }
  return radii;
}

std::string RearRollingDrive::Validate() const {
  if (!(speed_mps > 0.0)) return "speed_mps: must be positive";
  if (!(settle_s >= 0.0) || !(ramp_s >= 0.0) || !(hold_s >= 0.0)) return "settle_s, ramp_s, hold_s: must be >= 0";
  if (revolutions < 1) return "revolutions: must be at least 1";
  if (!(std::abs(grade) < 1.0)) return "grade: must be within (-1, 1)";
  return "";
}

Result<double> MeasureRearRollingRadius(const mjModel* model, const AckermannVehicle& vehicle,
                                        const SpeedControllerOptions& controller, const std::string& what,
                                        const RearRollingDrive& drive) {
  auto roll = MeasureRearRoll(model, vehicle, controller, what, drive);
  if (!roll.ok()) return roll.status();
  return roll.value().travel_per_rad_m;
}

double RearTractionN(const mjModel* model, const mjData* data) {
  const std::vector<int> rear_tires{IdOf(model, mjOBJ_GEOM, "tire_rear_left"),
                                    IdOf(model, mjOBJ_GEOM, "tire_rear_right")};
  const Eigen::Vector3d along = (RollingDirectionWorld(data, IdOf(model, mjOBJ_JOINT, "wheel_rear_left")) +
                                 RollingDirectionWorld(data, IdOf(model, mjOBJ_JOINT, "wheel_rear_right")))
                                    .normalized();
  return ContactForceAlong(model, data, rear_tires, along);
}

Result<RearRoll> MeasureRearRoll(const mjModel* model, const AckermannVehicle& vehicle,
                                 const SpeedControllerOptions& controller, const std::string& what,
                                 const RearRollingDrive& drive) {
  if (const std::string problem = drive.Validate(); !problem.empty())
    return Status::Error(what + ": measuring the rear rolling: " + problem);
  const ModelPtr graded = GradedGroundCopy(model, drive.grade);
  const mjModel* m = graded.get();
  DataPtr data = MakeData(m);
  TerrainOptions flat;
  flat.type = TerrainOptions::Type::kFlat;
  vehicle.Place(m, data.get(), Terrain::Make(flat, Eigen::Vector2d::Zero()), 0.0, 0.0, 0.0, kPlacementClearanceM);
  SpeedController speed(controller);
  const double dt_s = m->opt.timestep;
  const ApplySetPoint apply = [&](const Eigen::Vector2d& v, mjData* d) {
    vehicle.Apply(0.0, speed.Update(v.x(), vehicle.RearWheelRate(d) * vehicle.wheel_radius_m(), dt_s), d);
  };
  // The traction on the rear tires, summed over the measurement's steps.
  double traction_sum_n = 0.0;
  long traction_steps = 0;
  const ObserveStep observe = [&](const mjData* d) {
    traction_sum_n += RearTractionN(m, d);
    ++traction_steps;
  };
  Drive driver(m, data.get(), apply, what, observe);
  const Eigen::Vector2d rest = Eigen::Vector2d::Zero();
  const Eigen::Vector2d v(drive.speed_mps, 0.0);
  if (Status s = driver.Run(drive.settle_s, rest, rest); !s.ok()) return s;
  if (Status s = driver.Run(drive.ramp_s, rest, v); !s.ok()) return s;
  if (Status s = driver.Run(drive.hold_s, v, v); !s.ok()) return s;
  std::vector<WheelTravel> travels(2);
  travels[0].joint = IdOf(m, mjOBJ_JOINT, "wheel_rear_left");
  travels[1].joint = IdOf(m, mjOBJ_JOINT, "wheel_rear_right");
  for (WheelTravel& w : travels) w.window_rad = drive.revolutions * kTwoPi;
  const double window_s = drive.revolutions * kTwoPi * vehicle.wheel_radius_m() / drive.speed_mps;
  if (Status s = driver.Measure(v, kWindowTimeLimit * window_s, &travels); !s.ok()) return s;
  RearRoll roll;
  roll.travel_per_rad_m = 0.5 * (travels[0].radius_m + travels[1].radius_m);
  roll.wheel_rate_radps =
      0.5 * (travels[0].window_rad / travels[0].duration_s + travels[1].window_rad / travels[1].duration_s);
  roll.traction_n = traction_sum_n / static_cast<double>(traction_steps);
  return roll;
}

}  // namespace roamlab::sim
