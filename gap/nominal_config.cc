#include "gap/nominal_config.h"

#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "sim/simulator.h"

namespace roamlab::gap {
namespace {

using estimator::EstimatorConfig;

Eigen::VectorXd Vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double d : v) x[i++] = d;
  return x;
}

void SetParameter(const std::string& name, const Eigen::VectorXd& value, bool free, EstimatorConfig* c) {
  c->parameters[name].value = value;
  c->parameters[name].free = free;
}

// The configuration every nominal model starts from: the odometer as master, the solver's limits.
EstimatorConfig NominalBase(const sim::Scenario& scenario) {
  EstimatorConfig c;
  c.source_file = scenario.source_file.empty() ? "nominal configuration" : scenario.source_file + " (nominal)";
  c.master = "odometer";
  c.solver.max_iterations = 100;
  c.solver.function_tolerance = 1e-10;
  return c;
}

// A stream of the recording's `imu` with its noise and the IMU's shared misalignment and clock offset.
estimator::StreamConfig ImuStream(const std::string& model, const std::string& noise_key, double sigma) {
  estimator::StreamConfig stream;
  stream.model = model;
  stream.sources = {{"", "imu"}};
  stream.noise = {{noise_key, sigma}};
  stream.parameters = {{"misalignment", "imu.misalignment"}, {"time_offset_s", "imu.time_offset_s"}};
  return stream;
}

// The GPS stream with the scenario's noise and its lever arm at the scenario's value.
void AddGps(const sim::GpsOptions& gps_options, bool lever_arm_free, EstimatorConfig* c) {
  estimator::StreamConfig gps;
  gps.model = "gps";
  gps.sources = {{"", "gps"}};
  gps.noise = {{"sigma_m", gps_options.sigma_m}};
  c->streams["gps"] = gps;
  const Eigen::Vector3d& l = gps_options.lever_arm_m;
  SetParameter("gps.lever_arm", Vec({l.x(), l.y(), l.z()}), lever_arm_free, c);
}

// The gyroscope (the yaw reference of a wheeled platform) with the scenario's noise and the IMU misalignment free.
void AddYawGyroscope(const sim::ImuOptions& imu, EstimatorConfig* c) {
  const Eigen::Quaterniond& q = imu.misalignment;
  SetParameter("imu.misalignment", Vec({q.w(), q.x(), q.y(), q.z()}), true, c);
  c->streams["gyroscope"] = ImuStream("gyroscope", "sigma_radps", imu.gyro_sigma_radps);
}

// The nominal model of a differential-drive scenario: the wheel encoders (master, differential_drive) with the
// robot's geometry measured on its model (sim::NominalPlatformGeometry): one radius for both wheels, free (the
// odometry's scale), the baseline fixed (a track_width_error is a departure from it), the right/left ratio at its
// default 1; the gyroscope (the yaw reference) with the scenario's noise and misalignment free. Encoder noise as
// configs/indoor_diffdrive_tracking.yaml (2048-tick quantization over 10 ms, the casters' slack).
Result<EstimatorConfig> NominalDiffDriveConfig(const sim::Scenario& scenario) {
  const sim::SensorOptions& s = scenario.sensors;
  if (!s.wheel_encoders) return Status::Error("the scenario has no wheel_encoders (the master stream)");
  if (!s.imu) return Status::Error("the differential-drive nominal model needs sensors.imu (the yaw reference)");
  auto geometry = sim::NominalPlatformGeometry(scenario);
  if (!geometry.ok()) return geometry.status();
  EstimatorConfig c = NominalBase(scenario);
  estimator::StreamConfig odo;
  odo.model = "differential_drive";
  odo.sources = {{"", "wheel_encoders"}};
  odo.noise = {{"wheel_radps", 0.15}, {"lateral_mps", 0.02}, {"vertical_mps", 0.02}, {"tilt_radps", 0.1}};
  odo.parameters = {{"radius_left", "odometer.radius"}, {"radius_right", "odometer.radius"}};
  c.streams["odometer"] = odo;
  SetParameter("odometer.radius", Vec({geometry.value().at("wheel_radius_m")}), true, &c);
  SetParameter("odometer.baseline", Vec({geometry.value().at("baseline_m")}), false, &c);
  AddYawGyroscope(*s.imu, &c);
  c.stages.push_back({"imu.misalignment", "odometer.radius"});
  return c;
}

// The nominal model of an omni3 or mecanum scenario, as NominalDiffDriveConfig: the wheel encoders (master, the
// omni3_drive or mecanum_drive model) with the platform geometry measured on the robot's model
// (sim::NominalPlatformGeometry): one radius for all wheels, free (the odometry's scale), the yaw lever arm fixed
// (omni3 `distance` = wheel_distance_m; mecanum `lx_plus_ly` = half_length_m + half_width_m: a track_width_error is a
// departure from it); the gyroscope (the yaw reference) with the scenario's noise and misalignment free. Encoder noise
// as configs/indoor_omni_tracking.yaml (quantization plus the rollers' bumps; the rollers rock the chassis).
Result<EstimatorConfig> NominalHolonomicConfig(const sim::Scenario& scenario) {
  const sim::SensorOptions& s = scenario.sensors;
  const bool omni3 = scenario.robot.kind == "omni3";
  if (!s.wheel_encoders) return Status::Error("the scenario has no wheel_encoders (the master stream)");
  if (!s.imu)
    return Status::Error("the " + scenario.robot.kind + " nominal model needs sensors.imu (the yaw reference)");
  auto geometry = sim::NominalPlatformGeometry(scenario);
  if (!geometry.ok()) return geometry.status();
  const std::map<std::string, double>& g = geometry.value();
  EstimatorConfig c = NominalBase(scenario);
  estimator::StreamConfig odo;
  odo.model = omni3 ? "omni3_drive" : "mecanum_drive";
  odo.sources = {{"", "wheel_encoders"}};
  odo.noise = {{"wheel_radps", 0.3}, {"vertical_mps", 0.02}, {"tilt_radps", 0.1}};
  for (int i = 0; i < (omni3 ? 3 : 4); ++i) odo.parameters["radius_" + std::to_string(i)] = "odometer.radius";
  c.streams["odometer"] = odo;
  SetParameter("odometer.radius", Vec({g.at("wheel_radius_m")}), true, &c);
  if (omni3) {
    SetParameter("odometer.distance", Vec({g.at("wheel_distance_m")}), false, &c);
  } else {
    SetParameter("odometer.lx_plus_ly", Vec({g.at("half_length_m") + g.at("half_width_m")}), false, &c);
  }
  AddYawGyroscope(*s.imu, &c);
  c.stages.push_back({"imu.misalignment", "odometer.radius"});
  // An absolute position reference (an indoor positioning system, as sensors.gps) when the scenario has one: with
  // the encoders and the gyroscope alone the translation has no reference, and the wheel rows give only v / r and
  // K omega_z / r, so the gyroscope fixes K / r and nothing fixes r and K apart; the fixes fix v, hence r. Its lever
  // arm is fixed at the scenario's value (the antenna's mounting is believed).
  if (s.gps) AddGps(*s.gps, false, &c);
  return c;
}

// The gyroscope and accelerometer of an Ackermann vehicle, their misalignment free (stage 1), and the IMU's specific
// force as the odometer's input: the longitudinal slip's (models/ackermann_velocity.h; its slot fixed at zero
// nominally), along O's forward axis, which the believed mounting puts at R(q)^T e_x in the IMU's frame.
void AddAckermannImu(const sim::ImuOptions& imu, EstimatorConfig* c, std::vector<std::string>* stage1) {
  const Eigen::Quaterniond& q = imu.misalignment;
  SetParameter("imu.misalignment", Vec({q.w(), q.x(), q.y(), q.z()}), true, c);
  stage1->push_back("imu.misalignment");
  c->streams["gyroscope"] = ImuStream("gyroscope", "sigma_radps", imu.gyro_sigma_radps);
  c->streams["accelerometer"] = ImuStream("accelerometer", "sigma_mps2", imu.accel_sigma_mps2);
  const Eigen::Vector3d forward_in_imu = q.conjugate() * Eigen::Vector3d::UnitX();
  c->streams["odometer"].inputs = {{"specific_force", "imu"}};
  c->streams["odometer"].options["forward_in_sensor"] = {forward_in_imu.x(), forward_in_imu.y(), forward_in_imu.z()};
  if (!imu.lever_arm_m.isZero(0.0)) {
    const Eigen::Vector3d& l = imu.lever_arm_m;
    SetParameter("accelerometer.lever_arm", Vec({l.x(), l.y(), l.z()}), false, c);
  }
}

// The magnetometer with its calibration A, b free (stage 2) and the drive torque's proxy of the motor-interference
// slot (models/magnetometer.h), fixed at zero nominally: the IMU's specific force, with c = m r / 2 (the rear wheels'
// common torque tau gives the traction 2 tau / r) from the nominal vehicle's mass and rear tire radius.
Status AddMagnetometer(const sim::Scenario& scenario, EstimatorConfig* c, std::vector<std::string>* stage2) {
  const sim::MagnetometerOptions& m = *scenario.sensors.magnetometer;
  estimator::StreamConfig mag;
  mag.model = "magnetometer";
  mag.sources = {{"", "magnetometer"}};
  mag.noise = {{"sigma", m.sigma}};
  mag.parameters = {{"misalignment", "imu.misalignment"}};
  const Eigen::Vector3d& h = m.field_world;
  mag.options = {{"field_world", {h.x(), h.y(), h.z()}}};
  auto mass = sim::NominalVehicleMassKg(scenario);
  if (!mass.ok()) return mass.status();
  auto geometry = sim::NominalPlatformGeometry(scenario);
  if (!geometry.ok()) return geometry.status();
  mag.inputs = {{"specific_force", "imu"}};
  mag.options["drive_nm_per_mps2"] = {mass.value() * geometry.value().at("wheel_radius_m") / 2.0};
  c->streams["magnetometer"] = mag;
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> A = m.A;
  SetParameter("magnetometer.A", Eigen::Map<const Eigen::VectorXd>(A.data(), 9), true, c);
  const Eigen::Vector3d& b = m.b;
  SetParameter("magnetometer.b", Vec({b.x(), b.y(), b.z()}), true, c);
  stage2->insert(stage2->end(), {"magnetometer.A", "magnetometer.b"});
  return Status::Ok();
}

// The nominal model of an Ackermann scenario (NominalConfig).
Result<EstimatorConfig> NominalAckermannConfig(const sim::Scenario& scenario) {
  const sim::SensorOptions& s = scenario.sensors;
  if (!s.odometer) return Status::Error("the scenario has no odometer (the master stream)");
  EstimatorConfig c = NominalBase(scenario);
  std::vector<std::string> stage1, stage2;
  estimator::StreamConfig odo;
  odo.model = "ackermann";
  odo.sources = {{"speed", "rear_wheel"}, {"steering", "steering"}};
  // lateral / vertical: eq. 15's non-holonomic assumptions on a suspended vehicle (configs/atv_calibration.yaml).
  odo.noise = {{"speed_mps", s.odometer->speed_sigma_mps},
               {"steering_rad", s.odometer->steering_sigma_rad},
               {"lateral_mps", 0.02},
               {"vertical_mps", 0.1}};
  c.streams["odometer"] = odo;
  SetParameter("odometer.kv_over_L", Vec({s.odometer->kv_over_L}), true, &c);
  SetParameter("odometer.k_theta", Vec({s.odometer->k_theta}), true, &c);
  SetParameter("odometer.k_gamma", Vec({s.odometer->k_gamma}), false, &c);
  stage2.insert(stage2.end(), {"odometer.kv_over_L", "odometer.k_theta"});
  if (s.imu) AddAckermannImu(*s.imu, &c, &stage1);
  if (s.magnetometer && s.imu)
    if (Status st = AddMagnetometer(scenario, &c, &stage2); !st.ok()) return st;
  if (s.gps) {
    AddGps(*s.gps, true, &c);
    stage1.insert(stage1.begin(), "gps.lever_arm");
  }
  // Stages as configs/atv_calibration.yaml: attitude and lever arm, then the rest, then all jointly.
  std::vector<std::string> all = stage1;
  all.insert(all.end(), stage2.begin(), stage2.end());
  if (!stage1.empty()) c.stages.push_back(stage1);
  if (!stage2.empty()) c.stages.push_back(stage2);
  c.stages.push_back(all);
  return c;
}

}  // namespace

Result<EstimatorConfig> NominalConfig(const sim::Scenario& scenario) {
  // The wheeled models below read the simulator's nominal geometry keys and its default encoder stream.
  if (scenario.robot.kind != "ackermann" &&
      (scenario.robot.per_wheel_geometry || !scenario.robot.encoder_columns.empty() ||
       (scenario.sensors.wheel_encoders && scenario.sensors.wheel_encoders->name != "wheel_encoders")))
    return Status::Error(
        "the nominal configuration needs the simulator's own encoder stream and geometry keys (no "
        "robot.encoder_columns, robot.geometry_keys: per_wheel or sensors.wheel_encoders.name)");
  if (scenario.robot.kind == "differential_drive") return NominalDiffDriveConfig(scenario);
  if (scenario.robot.kind == "omni3" || scenario.robot.kind == "mecanum") return NominalHolonomicConfig(scenario);
  if (scenario.robot.kind != "ackermann")
    return Status::Error(
        "the nominal configuration is implemented for ackermann, differential_drive, omni3 and "
        "mecanum robots only, not '" +
        scenario.robot.kind + "'");
  return NominalAckermannConfig(scenario);
}

}  // namespace roamlab::gap
