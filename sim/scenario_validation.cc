// Scenario::Validate (scenario.h): every check of a loaded or built scenario, in named parts.
#include "sim/scenario.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

namespace roamlab::sim {
namespace {

using P = Scenario::Problem;

bool Finite(double x) { return std::isfinite(x); }
bool Positive(double x) { return std::isfinite(x) && x > 0.0; }
bool NonNegative(double x) { return std::isfinite(x) && x >= 0.0; }

std::optional<Scenario::Problem> ProfileProblem(const Profile& profile, const std::string& key) {
  for (std::size_t i = 0; i < profile.terms.size(); ++i) {
    const std::string problem = profile.terms[i].Validate();
    if (!problem.empty()) return Scenario::Problem{key + "[" + std::to_string(i) + "]", problem};
  }
  return std::nullopt;
}

// The wheeled robots' effects (scenario.h): the kinds they apply to and their parameters' ranges.
std::optional<Scenario::Problem> WheelEffectProblem(const std::vector<EffectOptions>& effects, const std::string& name,
                                                    const std::string& kind, const std::string& k) {
  using P = Scenario::Problem;
  const bool wheel_effect = name == "wheel_radius_asymmetry" || name == "wheel_radius_scale" ||
                            name == "track_width_error" || name == "wheel_deformation" || name == "axle_misalignment" ||
                            name == "skid_steer_track";
  if (!wheel_effect) return std::nullopt;
  if (kind == "ackermann" && name == "axle_misalignment") {
    // The Ackermann vehicle's rear axle (both rear wheels: a thrust angle); the front wheels are steered, and their
    // zero is steering_offset.
    for (const EffectOptions& e : effects)
      if (e.name == name && e.parameters.count("wheel"))
        return P{k + ".parameters.wheel",
                 "ackermann: axle_misalignment turns the rear axle (both rear wheels); "
                 "no wheel index"};
    if (!(std::abs(EffectParameter(effects, name, "yaw_deg", 0.0)) <= 5.0))
      return P{k + ".parameters.yaw_deg", "must be within +-5 on the ackermann rear axle"};
    return std::nullopt;
  }
  const int wheels = kind == "differential_drive"                ? 2
                     : kind == "omni3"                           ? 3
                     : kind == "mecanum" || kind == "skid_steer" ? 4
                                                                 : 0;
  if (wheels == 0) return P{k + ".name", name + " is for wheeled indoor robots, not '" + kind + "'"};
  if (name == "wheel_radius_asymmetry") {
    if (kind != "differential_drive") return P{k + ".name", name + " is for differential_drive robots only"};
    const double ratio = EffectParameter(effects, name, "ratio_right_left", 1.0);
    if (!(ratio >= 0.8 && ratio <= 1.2)) return P{k + ".parameters.ratio_right_left", "must be in [0.8, 1.2]"};
  }
  if (name == "wheel_radius_scale") {
    if (kind != "differential_drive" && kind != "skid_steer" && kind != "omni3" && kind != "mecanum")
      return P{k + ".name", name + " is for differential_drive, skid_steer, omni3 and mecanum robots"};
    const double scale = EffectParameter(effects, name, "scale", 1.0);
    if (!(scale >= 0.8 && scale <= 1.2)) return P{k + ".parameters.scale", "must be in [0.8, 1.2]"};
  }
  if (name == "track_width_error") {
    if (kind != "differential_drive" && kind != "mecanum")
      return P{k + ".name", name + " is for differential_drive and mecanum robots only"};
    if (!(std::abs(EffectParameter(effects, name, "track_error_m", 0.0)) <= 0.1))
      return P{k + ".parameters.track_error_m", "must be in [-0.1, 0.1] m"};
  }
  if (name == "skid_steer_track") {
    if (kind != "skid_steer") return P{k + ".name", name + " is for skid_steer robots only"};
    const double ratio = EffectParameter(effects, name, "track_ratio", 1.0);
    if (!(ratio >= 0.7 && ratio <= 1.5)) return P{k + ".parameters.track_ratio", "must be in [0.7, 1.5]"};
  }
  if (name == "wheel_deformation" || name == "axle_misalignment") {
    const double wheel = EffectParameter(effects, name, "wheel", 0.0);
    if (!(wheel >= 0.0 && wheel < wheels && wheel == std::floor(wheel)))
      return P{k + ".parameters.wheel",
               "no such wheel: the " + kind + " robot has wheels 0 to " + std::to_string(wheels - 1)};
  }
  if (name == "wheel_deformation") {
    if (kind != "differential_drive") return P{k + ".name", name + " needs sphere tires (differential_drive)"};
    const double ovality = EffectParameter(effects, name, "ovality_m", 0.0);
    if (!(ovality >= 0.0 && ovality <= 0.02)) return P{k + ".parameters.ovality_m", "must be in [0, 0.02] m"};
  }
  if (name == "axle_misalignment" && !(std::abs(EffectParameter(effects, name, "yaw_deg", 0.0)) <= 20.0))
    return P{k + ".parameters.yaw_deg", "must be within +-20"};
  return std::nullopt;
}

// Validate's parts, in the order of its checks: the first problem found is the one reported.

// Duration, origin and the ground truth's rate.
std::optional<P> TopLevelProblem(const Scenario& s) {
  if (!Positive(s.duration_s) || s.duration_s > 1.0e6) return P{"duration_s", "must be > 0 (and at most 1e6)"};
  if (!(Finite(s.origin.latitude_deg) && std::abs(s.origin.latitude_deg) <= 90.0))
    return P{"origin.latitude_deg", "must be in [-90, 90]"};
  if (!(Finite(s.origin.longitude_deg) && std::abs(s.origin.longitude_deg) <= 180.0))
    return P{"origin.longitude_deg", "must be in [-180, 180]"};
  if (!Finite(s.origin.altitude_m)) return P{"origin.altitude_m", "must be finite"};
  if (!Positive(s.ground_truth_rate_hz)) return P{"ground_truth_rate_hz", "must be > 0"};
  return std::nullopt;
}

// Robot and driver: the Ackermann vehicle, or a wheeled indoor robot driven by body-velocity set-points.
std::optional<P> RobotAndDriverProblem(const Scenario& s) {
  const bool ackermann = s.robot.kind == "ackermann";
  const bool holonomic = s.robot.kind == "omni3" || s.robot.kind == "mecanum";
  if (!ackermann && !holonomic && s.robot.kind != "differential_drive" && s.robot.kind != "skid_steer")
    return P{"robot.kind", "unsupported kind '" + s.robot.kind +
                               "' (supported: ackermann, differential_drive, skid_steer, omni3, mecanum)"};
  if (s.robot.model_file.empty() && s.robot.model_xml.empty()) return P{"robot.model", "missing"};
  if (!s.robot.start_position_m.allFinite()) return P{"robot.start.position_m", "must be finite"};
  if (!Finite(s.robot.start_heading_rad)) return P{"robot.start.heading_deg", "must be finite"};
  if (const std::string p = s.robot.speed_controller.Validate(); !p.empty())
    return P{"robot.speed_controller." + p.substr(0, p.find(':')), p.substr(p.find(':') + 2)};
  if (const std::string p = s.terrain.Validate(); !p.empty())
    return P{"world.terrain." + p.substr(0, p.find(':')), p.substr(p.find(':') + 2)};
  if (s.terrain.type == TerrainOptions::Type::kHills &&
      !(std::abs(s.robot.start_position_m.x()) < 0.5 * s.terrain.size_m.x() - 5.0 &&
        std::abs(s.robot.start_position_m.y()) < 0.5 * s.terrain.size_m.y() - 5.0))
    return P{"robot.start.position_m", "must be on the terrain, at least 5 m from its edge"};
  const std::string driver_type = ackermann ? "ackermann" : "body_velocity";
  if (s.driver.type != driver_type)
    return P{"driver.type",
             "'" + s.driver.type + "' does not drive a robot of kind '" + s.robot.kind + "' (use " + driver_type + ")"};
  if (!ackermann && s.terrain.type != TerrainOptions::Type::kFlat)
    return P{"world.terrain.type", "a " + s.robot.kind + " robot needs a flat floor (type: flat)"};
  if (!NonNegative(s.driver.lead_in_s) || s.driver.lead_in_s > 60.0) return P{"driver.lead_in_s", "must be in [0, 60]"};
  if (auto p = ProfileProblem(s.driver.speed_mps, "driver.speed_mps")) return p;
  if (auto p = ProfileProblem(s.driver.handlebar_rad, "driver.handlebar_rad")) return p;
  if (auto p = ProfileProblem(s.driver.linear_mps, "driver.linear_mps")) return p;
  if (auto p = ProfileProblem(s.driver.angular_radps, "driver.angular_radps")) return p;
  if (auto p = ProfileProblem(s.driver.lateral_mps, "driver.lateral_mps")) return p;
  for (const ProfileTerm& term : s.driver.lateral_mps.terms) {
    if (!holonomic && !(term.type == ProfileTerm::Type::kConstant && term.value == 0.0))
      return P{"driver.lateral_mps", "only for holonomic robots (omni3, mecanum); a " + s.robot.kind + " cannot"};
  }
  return std::nullopt;
}

bool Identifier(const std::string& name) {
  if (name.empty()) return false;
  for (const char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

// robot.encoder_columns, geometry_keys and geometry (the wheel indices are checked against the model when bound).
std::optional<P> RobotNamingProblem(const Scenario& s) {
  const RobotOptions& r = s.robot;
  const bool ackermann = r.kind == "ackermann";
  if (ackermann && !r.encoder_columns.empty()) return P{"robot.encoder_columns", "only for wheeled indoor robots"};
  for (std::size_t i = 0; i < r.encoder_columns.size(); ++i) {
    const EncoderColumn& c = r.encoder_columns[i];
    const std::string k = "robot.encoder_columns[" + std::to_string(i) + "]";
    if (c.wheel < 0) return P{k + ".wheel", "must be >= 0"};
    if (!Identifier(c.name)) return P{k + ".name", "must be letters, digits and _"};
    for (std::size_t j = 0; j < i; ++j) {
      if (r.encoder_columns[j].wheel == c.wheel) return P{k + ".wheel", "wheel listed twice"};
      if (r.encoder_columns[j].name == c.name) return P{k + ".name", "name listed twice"};
    }
  }
  if (r.per_wheel_geometry && r.encoder_columns.empty())
    return P{"robot.geometry_keys", "per_wheel needs robot.encoder_columns (the names of the per-wheel keys)"};
  for (const auto& [key, value] : r.stated_geometry)
    if (!Identifier(key) || !Finite(value)) return P{"robot.geometry." + key, "must be a finite number"};
  return std::nullopt;
}

// The changes to a wheeled robot's wheels: mounting, deformation, offset.
std::optional<P> WheelChangesProblem(const Scenario& s) {
  const bool ackermann = s.robot.kind == "ackermann";
  if (ackermann && !s.robot.wheel_mounting.empty()) return P{"robot.wheel_mounting", "only for wheeled indoor robots"};
  for (std::size_t i = 0; i < s.robot.wheel_mounting.size(); ++i) {
    const WheelMountingChange& c = s.robot.wheel_mounting[i];
    const std::string k = "robot.wheel_mounting[" + std::to_string(i) + "]";
    if (c.wheel < 0) return P{k + ".wheel", "must be >= 0"};
    if (!(Finite(c.yaw_rad) && std::abs(c.yaw_rad) <= 0.35)) return P{k + ".yaw_deg", "must be within +-20"};
    if (!(Finite(c.tilt_rad) && std::abs(c.tilt_rad) <= 0.35)) return P{k + ".tilt_deg", "must be within +-20"};
  }
  if (ackermann && !s.robot.wheel_deformation.empty())
    return P{"robot.wheel_deformation", "only for wheeled indoor robots"};
  for (std::size_t i = 0; i < s.robot.wheel_deformation.size(); ++i) {
    const WheelDeformation& d = s.robot.wheel_deformation[i];
    const std::string k = "robot.wheel_deformation[" + std::to_string(i) + "]";
    if (d.wheel < 0) return P{k + ".wheel", "must be >= 0"};
    if (!(Finite(d.radius_scale) && d.radius_scale >= 0.8 && d.radius_scale <= 1.2))
      return P{k + ".radius_scale", "must be in [0.8, 1.2]"};
    if (!(Finite(d.ovality_m) && d.ovality_m >= 0.0 && d.ovality_m <= 0.02))
      return P{k + ".ovality_m", "must be in [0, 0.02]"};
  }

  if (auto p = RobotNamingProblem(s)) return p;
  if (ackermann && !s.robot.wheel_offset.empty()) return P{"robot.wheel_offset", "only for wheeled indoor robots"};
  for (std::size_t i = 0; i < s.robot.wheel_offset.size(); ++i) {
    const WheelOffset& o = s.robot.wheel_offset[i];
    const std::string k = "robot.wheel_offset[" + std::to_string(i) + "]";
    if (o.wheel < 0) return P{k + ".wheel", "must be >= 0"};
    for (std::size_t j = 0; j < i; ++j)
      if (s.robot.wheel_offset[j].wheel == o.wheel) return P{k + ".wheel", "wheel listed twice"};
    // An assembly error of a few cm; beyond that a wheel could change sides of O or run into the chassis.
    if (!(Finite(o.offset_m.x()) && Finite(o.offset_m.y()) && o.offset_m.cwiseAbs().maxCoeff() <= 0.05))
      return P{k + ".offset_m", "each component must be within +-0.05 m"};
  }
  return std::nullopt;
}

// A sensor noise's Gauss-Markov correlation time [s]: 0 (white) or up to an hour.
bool CorrelationTime(double seconds) { return seconds >= 0.0 && seconds <= 3600.0; }
// drive_time_offset's drift: 1 % (a clock that far off is not a drift but a wrong rate setting).
constexpr double kMaxDriveDriftPpm = 1e4;
constexpr const char* kCorrelationRange = "must be in [0, 3600] s (0: white noise)";

// The IMU, magnetometer and GPS.
std::optional<P> InertialAndGpsProblem(const Scenario& s) {
  if (const auto& imu = s.sensors.imu) {
    if (!Positive(imu->rate_hz)) return P{"sensors.imu.rate_hz", "must be > 0"};
    if (!NonNegative(imu->gyro_sigma_radps)) return P{"sensors.imu.gyro_sigma_radps", "must be >= 0"};
    if (!NonNegative(imu->accel_sigma_mps2)) return P{"sensors.imu.accel_sigma_mps2", "must be >= 0"};
    const double norm = imu->misalignment.norm();
    if (!(imu->misalignment.coeffs().allFinite() && norm > 0.5 && norm < 2.0))
      return P{"sensors.imu.misalignment", "must be a quaternion [w, x, y, z] near unit norm"};
    if (!imu->lever_arm_m.allFinite()) return P{"sensors.imu.lever_arm_m", "must be finite"};
    if (!CorrelationTime(imu->noise_correlation_s)) return P{"sensors.imu.noise_correlation_s", kCorrelationRange};
  }
  if (const auto& mag = s.sensors.magnetometer) {
    if (!s.sensors.imu) return P{"sensors.magnetometer", "needs sensors.imu (it shares the IMU's frame)"};
    if (!Positive(mag->rate_hz)) return P{"sensors.magnetometer.rate_hz", "must be > 0"};
    if (!NonNegative(mag->sigma)) return P{"sensors.magnetometer.sigma", "must be >= 0"};
    if (!mag->A.allFinite()) return P{"sensors.magnetometer.A", "must be finite"};
    if (!mag->b.allFinite()) return P{"sensors.magnetometer.b", "must be finite"};
    if (!(mag->field_world.allFinite() && mag->field_world.norm() > 0.0))
      return P{"sensors.magnetometer.field_world", "must be finite and nonzero"};
    if (!CorrelationTime(mag->noise_correlation_s))
      return P{"sensors.magnetometer.noise_correlation_s", kCorrelationRange};
  }
  if (const auto& mocap = s.sensors.mocap) {
    if (!Positive(mocap->rate_hz)) return P{"sensors.mocap.rate_hz", "must be > 0"};
    if (!NonNegative(mocap->position_sigma_m)) return P{"sensors.mocap.position_sigma_m", "must be >= 0"};
    if (!NonNegative(mocap->orientation_sigma_rad)) return P{"sensors.mocap.orientation_sigma_rad", "must be >= 0"};
    if (!CorrelationTime(mocap->noise_correlation_s))
      return P{"sensors.mocap.noise_correlation_s", kCorrelationRange};
  }
  if (const auto& gps = s.sensors.gps) {
    if (!Positive(gps->rate_hz)) return P{"sensors.gps.rate_hz", "must be > 0"};
    if (!NonNegative(gps->sigma_m)) return P{"sensors.gps.sigma_m", "must be >= 0"};
    if (!gps->lever_arm_m.allFinite()) return P{"sensors.gps.lever_arm_m", "must be finite"};
    if (!CorrelationTime(gps->noise_correlation_s)) return P{"sensors.gps.noise_correlation_s", kCorrelationRange};
  }
  return std::nullopt;
}

// The odometer of the Ackermann vehicle; wheel encoders, laser and camera of the wheeled indoor robots.
std::optional<P> OdometrySensorsProblem(const Scenario& s) {
  const bool ackermann = s.robot.kind == "ackermann";
  if (s.sensors.odometer && !ackermann)
    return P{"sensors.odometer", "is the Ackermann odometer; a " + s.robot.kind + " robot has wheel_encoders"};
  if ((s.sensors.wheel_encoders || s.sensors.laser) && ackermann)
    return P{s.sensors.laser ? "sensors.laser" : "sensors.wheel_encoders", "only for wheeled indoor robots"};
  if (s.sensors.camera && ackermann) return P{"sensors.camera", "only for wheeled indoor robots"};
  if (const auto& camera = s.sensors.camera) {
    if (!(Finite(camera->rate_hz) && camera->rate_hz >= 10.0 && camera->rate_hz <= 30.0))
      return P{"sensors.camera.rate_hz", "must be in [10, 30]"};
    const bool small = camera->width_px == 320 && camera->height_px == 240;
    const bool large = camera->width_px == 640 && camera->height_px == 480;
    if (!small && !large)
      return P{
          camera->width_px != 320 && camera->width_px != 640 ? "sensors.camera.width_px" : "sensors.camera.height_px",
          "the image must be 320x240 or 640x480"};
  }
  if (const auto& enc = s.sensors.wheel_encoders) {
    if (!Positive(enc->rate_hz)) return P{"sensors.wheel_encoders.rate_hz", "must be > 0"};
    if (!Positive(enc->ticks_per_revolution)) return P{"sensors.wheel_encoders.ticks_per_revolution", "must be > 0"};
    if (!Identifier(enc->name)) return P{"sensors.wheel_encoders.name", "must be letters, digits and _"};
  }
  if (const auto& laser = s.sensors.laser) {
    if (!Positive(laser->rate_hz)) return P{"sensors.laser.rate_hz", "must be > 0"};
    if (laser->beams < 10 || laser->beams > 10000) return P{"sensors.laser.beams", "must be in [10, 10000]"};
    if (!(Positive(laser->fov_deg) && laser->fov_deg <= 360.0))
      return P{"sensors.laser.fov_deg", "must be in (0, 360]"};
    if (!NonNegative(laser->min_range_m)) return P{"sensors.laser.min_range_m", "must be >= 0"};
    if (!(Positive(laser->max_range_m) && laser->max_range_m > laser->min_range_m))
      return P{"sensors.laser.max_range_m", "must be > min_range_m"};
    if (!NonNegative(laser->sigma_m)) return P{"sensors.laser.sigma_m", "must be >= 0"};
  }
  if (const auto& odo = s.sensors.odometer) {
    if (!Positive(odo->rate_hz)) return P{"sensors.odometer.rate_hz", "must be > 0"};
    if (!NonNegative(odo->speed_sigma_mps)) return P{"sensors.odometer.speed_sigma_mps", "must be >= 0"};
    if (!NonNegative(odo->steering_sigma_rad)) return P{"sensors.odometer.steering_sigma_rad", "must be >= 0"};
    if (!Positive(odo->kv_over_L)) return P{"sensors.odometer.kv_over_L", "must be > 0"};
    if (!(Finite(odo->k_theta) && odo->k_theta != 0.0)) return P{"sensors.odometer.k_theta", "must be nonzero"};
    if (!Finite(odo->k_gamma)) return P{"sensors.odometer.k_gamma", "must be finite"};
    if (!CorrelationTime(odo->noise_correlation_s)) return P{"sensors.odometer.noise_correlation_s", kCorrelationRange};
  }

  return std::nullopt;
}

// Effects: known names and parameters, each at most once, with values in range.
std::optional<P> EffectsProblem(const Scenario& s) {
  const bool ackermann = s.robot.kind == "ackermann";
  std::set<std::string> seen;
  for (std::size_t i = 0; i < s.effects.size(); ++i) {
    const std::string k = "effects[" + std::to_string(i) + "]";
    const EffectOptions& e = s.effects[i];
    const auto known = KnownEffects().find(e.name);
    if (known == KnownEffects().end()) {
      std::string names;
      for (const auto& [name, unused] : KnownEffects()) names += (names.empty() ? "" : ", ") + name;
      return P{k + ".name", "unknown effect '" + e.name + "' (known: " + names + ")"};
    }
    if (!seen.insert(e.name).second) return P{k + ".name", "effect '" + e.name + "' appears twice"};
    for (const auto& [parameter, value] : e.parameters) {
      if (!known->second.count(parameter)) return P{k + ".parameters." + parameter, "unknown parameter of " + e.name};
      if (!Finite(value)) return P{k + ".parameters." + parameter, "must be finite"};
    }
    const double latency = EffectParameter(s.effects, "gps_latency", "latency_s", 0.0);
    if (e.name == "gps_latency" && !(latency >= 0.0 && latency <= 1.0))
      return P{k + ".parameters.latency_s", "must be in [0, 1]"};
    if (e.name == "imu_time_offset" && !(std::abs(EffectParameter(s.effects, e.name, "offset_s", 0.0)) <= 0.5))
      return P{k + ".parameters.offset_s", "must be in [-0.5, 0.5]"};
    if ((e.name == "pose_time_offset" || e.name == "drive_time_offset") &&
        !(std::abs(EffectParameter(s.effects, e.name, "offset_s", 0.0)) <= 0.5))
      return P{k + ".parameters.offset_s", "must be in [-0.5, 0.5]"};
    if (e.name == "drive_time_offset" &&
        !(std::abs(EffectParameter(s.effects, e.name, "drift_ppm", 0.0)) <= kMaxDriveDriftPpm))
      return P{k + ".parameters.drift_ppm", "must be in [-10000, 10000]"};
    if (e.name == "gps_latency" && !s.sensors.gps) return P{k + ".name", "gps_latency needs sensors.gps"};
    if (e.name == "pose_time_offset" && !s.sensors.mocap) return P{k + ".name", "pose_time_offset needs sensors.mocap"};
    if (e.name == "gyro_bias_drift") {
      if (!(EffectParameter(s.effects, e.name, "random_walk", 0.0) >= 0.0))
        return P{k + ".parameters.random_walk", "must be >= 0"};
      for (const char* axis : {"initial_x", "initial_y", "initial_z"})
        if (!(std::abs(EffectParameter(s.effects, e.name, axis, 0.0)) <= 0.5))
          return P{k + ".parameters." + axis, "must be in [-0.5, 0.5] rad/s"};
    }
    if ((e.name == "imu_time_offset" || e.name == "gyro_scale_error" || e.name == "gyro_bias_drift" ||
         e.name == "accelerometer_scale_error") &&
        !s.sensors.imu)
      return P{k + ".name", e.name + " needs sensors.imu"};
    if (e.name == "accelerometer_scale_error") {
      for (const char* axis : {"scale_x", "scale_y", "scale_z"}) {
        const double scale = EffectParameter(s.effects, e.name, axis, 1.0);
        if (!(scale >= 0.5 && scale <= 1.5)) return P{k + ".parameters." + axis, "must be in [0.5, 1.5]"};
      }
    }
    if (e.name == "gps_multipath") {
      if (!s.sensors.gps) return P{k + ".name", "gps_multipath needs sensors.gps"};
      const double sigma = EffectParameter(s.effects, e.name, "sigma_m", 0.0);
      if (!(sigma >= 0.0 && sigma <= 10.0)) return P{k + ".parameters.sigma_m", "must be in [0, 10] m"};
      const double tau = EffectParameter(s.effects, e.name, "correlation_s", 5.0);
      if (!(tau >= 0.1 && tau <= 600.0)) return P{k + ".parameters.correlation_s", "must be in [0.1, 600] s"};
    }
    if (e.name == "tire_growth") {
      if (!ackermann) return P{k + ".name", "tire_growth is implemented for ackermann robots only"};
      if (!s.sensors.odometer) return P{k + ".name", "tire_growth needs sensors.odometer"};
      const double c = EffectParameter(s.effects, e.name, "growth_per_mps2", 0.0);
      if (!(c >= 0.0 && c <= 0.01)) return P{k + ".parameters.growth_per_mps2", "must be in [0, 0.01] s^2/m^2"};
    }
    if (e.name == "longitudinal_slip" || e.name == "slope_slip") {
      if (!ackermann) return P{k + ".name", e.name + " is implemented for ackermann robots only"};
      if (!s.sensors.odometer) return P{k + ".name", e.name + " needs sensors.odometer"};
      const double slip = EffectParameter(s.effects, e.name, "slip_per_mps2", 0.0);
      if (!(slip >= 0.0 && slip <= 0.2)) return P{k + ".parameters.slip_per_mps2", "must be in [0, 0.2] s^2/m"};
    }
    if (e.name == "lateral_slip") {
      if (!ackermann) return P{k + ".name", "lateral_slip is implemented for ackermann robots only"};
      const double scale = EffectParameter(s.effects, e.name, "contact_time_scale", 1.0);
      if (!(scale >= 1.0 && scale <= 4.0)) return P{k + ".parameters.contact_time_scale", "must be in [1, 4]"};
    }
    if (e.name == "odometry_scale_error") {
      if (!s.sensors.wheel_encoders && !s.sensors.odometer)
        return P{k + ".name", "odometry_scale_error needs sensors.wheel_encoders or sensors.odometer"};
      const double scale = EffectParameter(s.effects, e.name, "scale", 1.0);
      if (!(scale >= 0.5 && scale <= 1.5)) return P{k + ".parameters.scale", "must be in [0.5, 1.5]"};
    }
    if (e.name == "steering_offset" && !s.sensors.odometer)
      return P{k + ".name", "steering_offset needs sensors.odometer"};
    if (e.name == "magnetometer_motor_interference" && !s.sensors.magnetometer)
      return P{k + ".name", e.name + " needs sensors.magnetometer"};
    if ((e.name == "steering_offset" || e.name == "magnetometer_motor_interference") && !ackermann)
      return P{k + ".name", e.name + " is implemented for ackermann robots only"};
    if (auto p = WheelEffectProblem(s.effects, e.name, s.robot.kind, k)) return p;
  }
  return std::nullopt;
}

// Faults: each on a stream the sensors write, with values in range (sim/faults.h).
std::optional<P> FaultsProblem(const Scenario& s) {
  const std::vector<std::string> streams = s.StreamNames();
  for (std::size_t i = 0; i < s.faults.size(); ++i) {
    if (const auto problem = CheckFault(s.faults[i], s.duration_s, streams))
      return P{"faults[" + std::to_string(i) + "]." + problem->key, problem->message};
  }
  return std::nullopt;
}

}  // namespace

std::optional<Scenario::Problem> Scenario::Validate() const {
  for (const auto part : {TopLevelProblem, RobotAndDriverProblem, WheelChangesProblem, InertialAndGpsProblem,
                          OdometrySensorsProblem, EffectsProblem, FaultsProblem}) {
    if (auto problem = part(*this)) return problem;
  }
  return std::nullopt;
}

}  // namespace roamlab::sim
