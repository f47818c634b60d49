#include "sim/scenario.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "sim/internal/yaml_reader.h"

namespace roamlab::sim {
namespace {

namespace fs = std::filesystem;
using internal::YamlReader;

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d ToVector3(const std::vector<double>& v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

// One profile term: a mapping with exactly one of the term types (plus an optional window_s).
void ReadTerm(YamlReader& r, const YAML::Node& node, const std::string& key, ProfileTerm* term) {
  r.CheckKeys(node, key, {"constant", "sine", "square", "ramp", "piecewise", "window_s"});
  if (!r.ok()) return;
  int types = 0;
  for (const char* type : {"constant", "sine", "square", "ramp", "piecewise"}) types += node[type] ? 1 : 0;
  if (types != 1) {
    r.Fail(node, key, "a term needs exactly one of constant, sine, square, ramp, piecewise");
    return;
  }
  if (node["window_s"]) {
    std::vector<double> window;
    r.Numbers(node, key, "window_s", 2, &window);
    if (r.ok()) {
      term->windowed = true;
      term->window_begin_s = window[0];
      term->window_end_s = window[1];
    }
  }
  if (node["constant"]) {
    term->type = ProfileTerm::Type::kConstant;
    r.NodeNumber(node["constant"], key + ".constant", &term->value);
  } else if (node["sine"] || node["square"]) {
    const bool sine = static_cast<bool>(node["sine"]);
    term->type = sine ? ProfileTerm::Type::kSine : ProfileTerm::Type::kSquare;
    const std::string k = key + (sine ? ".sine" : ".square");
    const YAML::Node spec = node[sine ? "sine" : "square"];
    r.CheckKeys(spec, k, {"amplitude", "period_s", "phase_rad"});
    if (r.Require(spec, k, "amplitude") && r.Require(spec, k, "period_s")) {
      r.Number(spec, k, "amplitude", &term->amplitude);
      r.Number(spec, k, "period_s", &term->period_s);
      r.Number(spec, k, "phase_rad", &term->phase_rad);
    }
  } else if (node["ramp"]) {
    term->type = ProfileTerm::Type::kRamp;
    const std::string k = key + ".ramp";
    const YAML::Node spec = node["ramp"];
    r.CheckKeys(spec, k, {"start_s", "end_s", "from", "to"});
    for (const char* required : {"start_s", "end_s", "from", "to"})
      if (!r.Require(spec, k, required)) return;
    r.Number(spec, k, "start_s", &term->start_s);
    r.Number(spec, k, "end_s", &term->end_s);
    r.Number(spec, k, "from", &term->from);
    r.Number(spec, k, "to", &term->to);
  } else {
    term->type = ProfileTerm::Type::kPiecewise;
    const std::string k = key + ".piecewise";
    const YAML::Node spec = node["piecewise"];
    r.CheckKeys(spec, k, {"times_s", "values", "interpolation"});
    if (r.Require(spec, k, "times_s") && r.Require(spec, k, "values")) {
      r.Numbers(spec, k, "times_s", -1, &term->times_s);
      r.Numbers(spec, k, "values", -1, &term->values);
      std::string interpolation = "linear";
      r.String(spec, k, "interpolation", &interpolation);
      if (interpolation == "step") {
        term->interpolation = ProfileTerm::Interpolation::kStep;
      } else if (interpolation != "linear") {
        r.Fail(spec["interpolation"], k + ".interpolation", "expected linear or step, got '" + interpolation + "'");
      }
    }
  }
}

// A profile: a number (constant) or a sequence of terms.
void ReadProfile(YamlReader& r, const YAML::Node& map, const std::string& parent, const std::string& name,
                 Profile* profile) {
  if (!r.ok() || !map[name]) return;
  const YAML::Node node = map[name];
  const std::string key = YamlReader::Join(parent, name);
  r.Remember(key, node);
  if (node.IsScalar()) {
    double value = 0.0;
    r.NodeNumber(node, key, &value);
    *profile = Profile::Constant(value);
    return;
  }
  if (!node.IsSequence()) {
    r.Fail(node, key, "expected a number or a list of profile terms (constant, sine, square, ramp, piecewise)");
    return;
  }
  profile->terms.assign(node.size(), ProfileTerm{});
  for (std::size_t i = 0; i < node.size(); ++i) {
    ReadTerm(r, node[i], key + "[" + std::to_string(i) + "]", &profile->terms[i]);
  }
}

// robot.encoder_columns, geometry_keys and geometry: how the recording names the wheels and the geometry.
void ReadRobotNaming(YamlReader& r, const YAML::Node& node, Scenario* s) {
  if (node["encoder_columns"]) {
    const YAML::Node list = node["encoder_columns"];
    const std::string k = "robot.encoder_columns";
    r.Remember(k, list);
    if (!list.IsSequence()) return r.Fail(list, k, "expected a list of {wheel, name}");
    for (std::size_t i = 0; i < list.size() && r.ok(); ++i) {
      const std::string ki = k + "[" + std::to_string(i) + "]";
      r.CheckKeys(list[i], ki, {"wheel", "name"});
      if (!r.Require(list[i], ki, "wheel") || !r.Require(list[i], ki, "name")) return;
      std::int64_t wheel = 0;
      EncoderColumn c;
      r.Integer(list[i], ki, "wheel", &wheel);
      r.String(list[i], ki, "name", &c.name);
      c.wheel = static_cast<int>(std::clamp<std::int64_t>(wheel, -1, 64));
      s->robot.encoder_columns.push_back(c);
    }
  }
  if (node["geometry_keys"]) {
    std::string keys;
    r.String(node, "robot", "geometry_keys", &keys);
    if (r.ok() && keys != "nominal" && keys != "per_wheel")
      return r.Fail(node["geometry_keys"], "robot.geometry_keys", "expected nominal or per_wheel, got '" + keys + "'");
    s->robot.per_wheel_geometry = keys == "per_wheel";
  }
  if (node["geometry"]) {
    const YAML::Node map = node["geometry"];
    r.Remember("robot.geometry", map);
    if (!map.IsMap()) return r.Fail(map, "robot.geometry", "expected a map of key: number");
    for (const auto& item : map) {
      const std::string key = item.first.as<std::string>("");
      double value = 0.0;
      r.Number(map, "robot.geometry", key, &value);
      if (!r.ok()) return;
      s->robot.stated_geometry[key] = value;
    }
  }
}

void ReadRobot(YamlReader& r, const YAML::Node& node, const std::string& scenario_dir, Scenario* s) {
  const std::string key = "robot";
  r.CheckKeys(node, key,
              {"kind", "model", "start", "speed_controller", "wheel_mounting", "wheel_deformation", "wheel_offset",
               "encoder_columns", "geometry_keys", "geometry"});
  if (!r.Require(node, key, "kind") || !r.Require(node, key, "model")) return;
  r.OneOf(node, key, "kind", {"ackermann", "differential_drive", "skid_steer", "omni3", "mecanum"}, &s->robot.kind);
  std::string model;
  r.String(node, key, "model", &model);
  if (!r.ok()) return;
  const fs::path resolved = fs::path(model).is_absolute() ? fs::path(model) : fs::path(scenario_dir) / model;
  std::error_code error;
  if (!fs::is_regular_file(resolved, error)) {
    r.Fail(node["model"], "robot.model", "no such file '" + model + "' (looked for " + resolved.string() + ")");
    return;
  }
  s->robot.model_file = resolved.lexically_normal().string();
  if (node["start"]) {
    const YAML::Node start = node["start"];
    r.CheckKeys(start, "robot.start", {"position_m", "heading_deg"});
    std::vector<double> position;
    r.Numbers(start, "robot.start", "position_m", 2, &position);
    if (r.ok() && !position.empty()) s->robot.start_position_m = Eigen::Vector2d(position[0], position[1]);
    double heading_deg = s->robot.start_heading_rad * 180.0 / kPi;
    r.Number(start, "robot.start", "heading_deg", &heading_deg);
    s->robot.start_heading_rad = heading_deg * kPi / 180.0;
  }
  if (node["speed_controller"]) {
    const YAML::Node c = node["speed_controller"];
    const std::string k = "robot.speed_controller";
    r.CheckKeys(c, k, {"kp_nm_per_mps", "ki_nm_per_m", "torque_limit_nm"});
    r.Number(c, k, "kp_nm_per_mps", &s->robot.speed_controller.kp_nm_per_mps);
    r.Number(c, k, "ki_nm_per_m", &s->robot.speed_controller.ki_nm_per_m);
    r.Number(c, k, "torque_limit_nm", &s->robot.speed_controller.torque_limit_nm);
  }
  if (node["wheel_mounting"]) {
    const YAML::Node list = node["wheel_mounting"];
    const std::string k = "robot.wheel_mounting";
    r.Remember(k, list);
    if (!list.IsSequence()) {
      r.Fail(list, k, "expected a list of {wheel, yaw_deg, tilt_deg}");
      return;
    }
    for (std::size_t i = 0; i < list.size() && r.ok(); ++i) {
      const YAML::Node item = list[i];
      const std::string ki = k + "[" + std::to_string(i) + "]";
      r.CheckKeys(item, ki, {"wheel", "yaw_deg", "tilt_deg"});
      if (!r.Require(item, ki, "wheel")) return;
      std::int64_t wheel = 0;
      double yaw_deg = 0.0, tilt_deg = 0.0;
      r.Integer(item, ki, "wheel", &wheel);
      r.Number(item, ki, "yaw_deg", &yaw_deg);
      r.Number(item, ki, "tilt_deg", &tilt_deg);
      s->robot.wheel_mounting.push_back(
          {static_cast<int>(std::clamp<std::int64_t>(wheel, -1, 64)), yaw_deg * kPi / 180.0, tilt_deg * kPi / 180.0});
    }
  }
  if (node["wheel_deformation"]) {
    const YAML::Node list = node["wheel_deformation"];
    const std::string k = "robot.wheel_deformation";
    r.Remember(k, list);
    if (!list.IsSequence()) {
      r.Fail(list, k, "expected a list of {wheel, radius_scale, ovality_m}");
      return;
    }
    for (std::size_t i = 0; i < list.size() && r.ok(); ++i) {
      const YAML::Node item = list[i];
      const std::string ki = k + "[" + std::to_string(i) + "]";
      r.CheckKeys(item, ki, {"wheel", "radius_scale", "ovality_m"});
      if (!r.Require(item, ki, "wheel")) return;
      std::int64_t wheel = 0;
      WheelDeformation d;
      r.Integer(item, ki, "wheel", &wheel);
      r.Number(item, ki, "radius_scale", &d.radius_scale);
      r.Number(item, ki, "ovality_m", &d.ovality_m);
      d.wheel = static_cast<int>(std::clamp<std::int64_t>(wheel, -1, 64));
      s->robot.wheel_deformation.push_back(d);
    }
  }
  if (node["wheel_offset"]) {
    const YAML::Node list = node["wheel_offset"];
    const std::string k = "robot.wheel_offset";
    r.Remember(k, list);
    if (!list.IsSequence()) {
      r.Fail(list, k, "expected a list of {wheel, offset_m: [x, y]}");
      return;
    }
    for (std::size_t i = 0; i < list.size() && r.ok(); ++i) {
      const YAML::Node item = list[i];
      const std::string ki = k + "[" + std::to_string(i) + "]";
      r.CheckKeys(item, ki, {"wheel", "offset_m"});
      if (!r.Require(item, ki, "wheel") || !r.Require(item, ki, "offset_m")) return;
      std::int64_t wheel = 0;
      std::vector<double> offset;
      r.Integer(item, ki, "wheel", &wheel);
      r.Numbers(item, ki, "offset_m", 2, &offset);
      if (!r.ok()) return;
      s->robot.wheel_offset.push_back(
          {static_cast<int>(std::clamp<std::int64_t>(wheel, -1, 64)), Eigen::Vector2d(offset[0], offset[1])});
    }
  }
  ReadRobotNaming(r, node, s);
}

void ReadWorld(YamlReader& r, const YAML::Node& node, const std::string& scenario_dir, Scenario* s) {
  r.CheckKeys(node, "world", {"terrain", "model"});
  if (!r.Require(node, "world", "terrain")) return;
  if (node["model"]) {
    std::string model;
    r.String(node, "world", "model", &model);
    if (!r.ok()) return;
    const fs::path resolved = fs::path(model).is_absolute() ? fs::path(model) : fs::path(scenario_dir) / model;
    std::error_code error;
    if (!fs::is_regular_file(resolved, error)) {
      r.Fail(node["model"], "world.model", "no such file '" + model + "' (looked for " + resolved.string() + ")");
      return;
    }
    s->world_model_file = resolved.lexically_normal().string();
  }
  const YAML::Node t = node["terrain"];
  const std::string k = "world.terrain";
  r.CheckKeys(t, k, {"type", "seed", "size_m", "resolution_m", "relief_m", "wavelength_m", "waves", "friction"});
  if (!r.Require(t, k, "type")) return;
  std::string type;
  r.String(t, k, "type", &type);
  if (!r.ok()) return;
  TerrainOptions& terrain = s->terrain;
  if (type == "flat") {
    terrain.type = TerrainOptions::Type::kFlat;
    for (const char* hills_only : {"seed", "size_m", "resolution_m", "relief_m", "wavelength_m", "waves"}) {
      if (t[hills_only]) r.Fail(t[hills_only], k + "." + hills_only, "only for type hills");
    }
  } else if (type == "hills") {
    terrain.type = TerrainOptions::Type::kHills;
  } else {
    r.Fail(t["type"], k + ".type", "expected hills or flat, got '" + type + "'");
    return;
  }
  r.Unsigned(t, k, "seed", &terrain.seed);
  std::vector<double> size;
  r.Numbers(t, k, "size_m", 2, &size);
  if (r.ok() && !size.empty()) terrain.size_m = Eigen::Vector2d(size[0], size[1]);
  r.Number(t, k, "resolution_m", &terrain.resolution_m);
  r.Number(t, k, "relief_m", &terrain.relief_m);
  std::vector<double> wavelength;
  r.Numbers(t, k, "wavelength_m", 2, &wavelength);
  if (r.ok() && !wavelength.empty()) {
    terrain.min_wavelength_m = wavelength[0];
    terrain.max_wavelength_m = wavelength[1];
  }
  std::int64_t waves = terrain.waves;
  r.Integer(t, k, "waves", &waves);
  terrain.waves = static_cast<int>(std::max<std::int64_t>(std::min<std::int64_t>(waves, 1 << 20), -1));
  r.Number(t, k, "friction", &terrain.friction);
}

void ReadDriver(YamlReader& r, const YAML::Node& node, Scenario* s) {
  const std::string k = "driver";
  if (!r.Require(node, k, "type")) return;
  // The type decides the schema of the other keys: an unknown one is refused before they are read.
  r.OneOf(node, k, "type", {"ackermann", "body_velocity"}, &s->driver.type);
  if (!r.ok()) return;
  if (s->driver.type == "body_velocity") {
    r.CheckKeys(node, k, {"type", "lead_in_s", "linear_mps", "angular_radps", "lateral_mps"});
    r.Number(node, k, "lead_in_s", &s->driver.lead_in_s);
    if (!r.Require(node, k, "linear_mps") || !r.Require(node, k, "angular_radps")) return;
    ReadProfile(r, node, k, "linear_mps", &s->driver.linear_mps);
    ReadProfile(r, node, k, "angular_radps", &s->driver.angular_radps);
    ReadProfile(r, node, k, "lateral_mps", &s->driver.lateral_mps);
    return;
  }
  r.CheckKeys(node, k, {"type", "lead_in_s", "speed_mps", "handlebar_rad"});
  r.Number(node, k, "lead_in_s", &s->driver.lead_in_s);
  if (!r.Require(node, k, "speed_mps") || !r.Require(node, k, "handlebar_rad")) return;
  ReadProfile(r, node, k, "speed_mps", &s->driver.speed_mps);
  ReadProfile(r, node, k, "handlebar_rad", &s->driver.handlebar_rad);
}

void ReadSensors(YamlReader& r, const YAML::Node& node, Scenario* s) {
  r.CheckKeys(node, "sensors",
              {"imu", "magnetometer", "gps", "odometer", "wheel_encoders", "laser", "camera", "mocap"});
  if (!r.ok()) return;
  // A present key with an empty value ("imu:" or "imu: {}") is a sensor with all defaults.
  const auto section = [&r](const YAML::Node& n, const std::string& k, std::initializer_list<std::string_view> keys) {
    if (n.IsNull()) return false;
    r.CheckKeys(n, k, keys);
    return r.ok();
  };
  if (node["imu"]) {
    ImuOptions& imu = s->sensors.imu.emplace();
    const YAML::Node n = node["imu"];
    const std::string k = "sensors.imu";
    if (section(n, k,
                {"rate_hz", "gyro_sigma_radps", "accel_sigma_mps2", "misalignment", "lever_arm_m",
                 "noise_correlation_s"})) {
      r.Number(n, k, "rate_hz", &imu.rate_hz);
      r.Number(n, k, "gyro_sigma_radps", &imu.gyro_sigma_radps);
      r.Number(n, k, "accel_sigma_mps2", &imu.accel_sigma_mps2);
      r.Number(n, k, "noise_correlation_s", &imu.noise_correlation_s);
      std::vector<double> q, lever;
      r.Numbers(n, k, "misalignment", 4, &q);
      if (r.ok() && !q.empty()) imu.misalignment = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
      r.Numbers(n, k, "lever_arm_m", 3, &lever);
      if (r.ok() && !lever.empty()) imu.lever_arm_m = ToVector3(lever);
    }
  }
  if (node["magnetometer"]) {
    MagnetometerOptions& mag = s->sensors.magnetometer.emplace();
    const YAML::Node n = node["magnetometer"];
    const std::string k = "sensors.magnetometer";
    if (section(n, k, {"rate_hz", "sigma", "A", "b", "field_world", "noise_correlation_s"})) {
      r.Number(n, k, "rate_hz", &mag.rate_hz);
      r.Number(n, k, "sigma", &mag.sigma);
      r.Number(n, k, "noise_correlation_s", &mag.noise_correlation_s);
      std::vector<double> A, b, field;
      r.Numbers(n, k, "A", 9, &A);
      if (r.ok() && !A.empty()) mag.A = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(A.data());
      r.Numbers(n, k, "b", 3, &b);
      if (r.ok() && !b.empty()) mag.b = ToVector3(b);
      r.Numbers(n, k, "field_world", 3, &field);
      if (r.ok() && !field.empty()) mag.field_world = ToVector3(field);
    }
  }
  if (node["gps"]) {
    GpsOptions& gps = s->sensors.gps.emplace();
    const YAML::Node n = node["gps"];
    const std::string k = "sensors.gps";
    if (section(n, k, {"rate_hz", "sigma_m", "lever_arm_m", "noise_correlation_s"})) {
      r.Number(n, k, "rate_hz", &gps.rate_hz);
      r.Number(n, k, "sigma_m", &gps.sigma_m);
      r.Number(n, k, "noise_correlation_s", &gps.noise_correlation_s);
      std::vector<double> lever;
      r.Numbers(n, k, "lever_arm_m", 3, &lever);
      if (r.ok() && !lever.empty()) gps.lever_arm_m = ToVector3(lever);
    }
  }
  if (node["mocap"]) {
    MocapOptions& mocap = s->sensors.mocap.emplace();
    const YAML::Node n = node["mocap"];
    const std::string k = "sensors.mocap";
    if (section(n, k, {"rate_hz", "position_sigma_m", "orientation_sigma_rad", "noise_correlation_s"})) {
      r.Number(n, k, "rate_hz", &mocap.rate_hz);
      r.Number(n, k, "position_sigma_m", &mocap.position_sigma_m);
      r.Number(n, k, "orientation_sigma_rad", &mocap.orientation_sigma_rad);
      r.Number(n, k, "noise_correlation_s", &mocap.noise_correlation_s);
    }
  }
  if (node["odometer"]) {
    OdometerOptions& odo = s->sensors.odometer.emplace();
    const YAML::Node n = node["odometer"];
    const std::string k = "sensors.odometer";
    if (section(n, k,
                {"rate_hz", "speed_sigma_mps", "steering_sigma_rad", "kv_over_L", "k_theta", "k_gamma",
                 "noise_correlation_s"})) {
      r.Number(n, k, "rate_hz", &odo.rate_hz);
      r.Number(n, k, "speed_sigma_mps", &odo.speed_sigma_mps);
      r.Number(n, k, "steering_sigma_rad", &odo.steering_sigma_rad);
      r.Number(n, k, "kv_over_L", &odo.kv_over_L);
      r.Number(n, k, "k_theta", &odo.k_theta);
      r.Number(n, k, "k_gamma", &odo.k_gamma);
      r.Number(n, k, "noise_correlation_s", &odo.noise_correlation_s);
    }
  }
}

void ReadIndoorSensors(YamlReader& r, const YAML::Node& node, Scenario* s) {
  if (node["wheel_encoders"] && !node["wheel_encoders"].IsNull()) {
    WheelEncoderOptions& enc = s->sensors.wheel_encoders.emplace();
    const YAML::Node n = node["wheel_encoders"];
    const std::string k = "sensors.wheel_encoders";
    r.CheckKeys(n, k, {"name", "rate_hz", "ticks_per_revolution"});
    r.String(n, k, "name", &enc.name);
    r.Number(n, k, "rate_hz", &enc.rate_hz);
    r.Number(n, k, "ticks_per_revolution", &enc.ticks_per_revolution);
  } else if (node["wheel_encoders"]) {
    s->sensors.wheel_encoders.emplace();
  }
  if (node["laser"] && !node["laser"].IsNull()) {
    LaserOptions& laser = s->sensors.laser.emplace();
    const YAML::Node n = node["laser"];
    const std::string k = "sensors.laser";
    r.CheckKeys(n, k, {"rate_hz", "beams", "fov_deg", "min_range_m", "max_range_m", "sigma_m", "store_scans"});
    r.Number(n, k, "rate_hz", &laser.rate_hz);
    std::int64_t beams = laser.beams;
    r.Integer(n, k, "beams", &beams);
    laser.beams = static_cast<int>(std::clamp<std::int64_t>(beams, -1, 1 << 20));
    r.Number(n, k, "fov_deg", &laser.fov_deg);
    r.Number(n, k, "min_range_m", &laser.min_range_m);
    r.Number(n, k, "max_range_m", &laser.max_range_m);
    r.Number(n, k, "sigma_m", &laser.sigma_m);
    r.Bool(n, k, "store_scans", &laser.store_scans);
  } else if (node["laser"]) {
    s->sensors.laser.emplace();
  }
  if (node["camera"] && !node["camera"].IsNull()) {
    CameraOptions& camera = s->sensors.camera.emplace();
    const YAML::Node n = node["camera"];
    const std::string k = "sensors.camera";
    r.Remember(k, n);
    r.CheckKeys(n, k, {"rate_hz", "width_px", "height_px", "store_images"});
    r.Number(n, k, "rate_hz", &camera.rate_hz);
    std::int64_t width = camera.width_px, height = camera.height_px;
    r.Integer(n, k, "width_px", &width);
    r.Integer(n, k, "height_px", &height);
    camera.width_px = static_cast<int>(std::clamp<std::int64_t>(width, -1, 1 << 20));
    camera.height_px = static_cast<int>(std::clamp<std::int64_t>(height, -1, 1 << 20));
    r.Bool(n, k, "store_images", &camera.store_images);
  } else if (node["camera"]) {
    r.Remember("sensors.camera", node["camera"]);
    s->sensors.camera.emplace();
  }
}

void ReadEffects(YamlReader& r, const YAML::Node& node, Scenario* s) {
  r.Remember("effects", node);
  if (node.IsNull()) return;
  if (!node.IsSequence()) {
    r.Fail(node, "effects", "expected a list of effects");
    return;
  }
  for (std::size_t i = 0; i < node.size() && r.ok(); ++i) {
    const std::string k = "effects[" + std::to_string(i) + "]";
    EffectOptions effect;
    r.CheckKeys(node[i], k, {"name", "parameters"});
    if (!r.Require(node[i], k, "name")) return;
    r.String(node[i], k, "name", &effect.name);
    if (node[i]["parameters"]) {
      const YAML::Node p = node[i]["parameters"];
      if (!p.IsMap()) {
        r.Fail(p, k + ".parameters", "expected a mapping of numbers");
        return;
      }
      for (const auto& item : p) {
        const std::string name = item.first.Scalar();
        r.NodeNumber(item.second, k + ".parameters." + name, &effect.parameters[name]);
      }
    }
    s->effects.push_back(effect);
  }
}

void ReadFaults(YamlReader& r, const YAML::Node& node, Scenario* s) {
  r.Remember("faults", node);
  if (node.IsNull()) return;
  if (!node.IsSequence()) {
    r.Fail(node, "faults", "expected a list of faults");
    return;
  }
  for (std::size_t i = 0; i < node.size() && r.ok(); ++i) {
    const std::string k = "faults[" + std::to_string(i) + "]";
    FaultOptions fault;
    if (!r.Require(node[i], k, "type") || !r.Require(node[i], k, "stream")) return;
    r.String(node[i], k, "type", &fault.type);
    r.String(node[i], k, "stream", &fault.stream);
    const std::vector<std::string>& keys = FaultKeys(fault.type);
    if (keys.empty()) {
      r.Fail(node[i]["type"], k + ".type",
             "unknown fault '" + fault.type + "' (outliers, outage, clock_jump, duplicates, freeze)");
      return;
    }
    for (const auto& item : node[i]) {
      const std::string key = item.first.Scalar();
      if (key != "type" && key != "stream" && std::find(keys.begin(), keys.end(), key) == keys.end()) {
        std::string allowed = "type, stream";
        for (const std::string& name : keys) allowed += ", " + name;
        r.Fail(item.first, k + "." + key, "unknown key for fault type " + fault.type + " (allowed: " + allowed + ")");
        return;
      }
    }
    std::map<std::string, double*> fields = {{"fraction", &fault.fraction}, {"size", &fault.size},
                                             {"start_s", &fault.start_s},   {"duration_s", &fault.duration_s},
                                             {"at_s", &fault.at_s},         {"jump_s", &fault.jump_s}};
    for (const std::string& key : keys) {
      if (r.Require(node[i], k, key)) r.Number(node[i], k, key, fields.at(key));
    }
    s->faults.push_back(fault);
  }
}

}  // namespace

std::vector<std::string> Scenario::StreamNames() const {
  std::vector<std::string> names;
  if (sensors.imu) names.push_back("imu");
  if (sensors.magnetometer) names.push_back("magnetometer");
  if (sensors.gps) names.push_back("gps");
  if (sensors.mocap) names.push_back("mocap");
  if (sensors.odometer) {
    names.push_back("rear_wheel");
    names.push_back("steering");
  }
  if (sensors.wheel_encoders) names.push_back(sensors.wheel_encoders->name);
  if (sensors.laser) {
    names.push_back("scan_matching");
    if (sensors.laser->store_scans) names.push_back("laser_scan");
  }
  if (sensors.camera) names.push_back("visual_odometry");
  return names;
}

void Scenario::DropUnreadCostlySensors(const std::set<std::string>& read) {
  std::set<std::string> faulted;
  for (const FaultOptions& fault : faults) faulted.insert(fault.stream);
  const auto unread = [&](const std::vector<std::string>& streams) {
    return std::none_of(streams.begin(), streams.end(),
                        [&](const std::string& s) { return read.count(s) > 0 || faulted.count(s) > 0; });
  };
  if (sensors.laser && unread({"scan_matching", "laser_scan"})) sensors.laser.reset();
  if (sensors.camera && unread({"visual_odometry", "visual_odometry_images"})) sensors.camera.reset();
}

const std::map<std::string, std::map<std::string, double>>& KnownEffects() {
  static const std::map<std::string, std::map<std::string, double>> known = {
      {"gps_latency", {{"latency_s", 0.0}}},
      {"imu_time_offset", {{"offset_s", 0.0}}},
      {"pose_time_offset", {{"offset_s", 0.0}}},
      {"drive_time_offset", {{"offset_s", 0.0}, {"drift_ppm", 0.0}}},
      {"steering_offset", {{"offset_rad", 0.0}}},
      {"gyro_scale_error", {{"scale_x", 1.0}, {"scale_y", 1.0}, {"scale_z", 1.0}}},
      {"gyro_bias_drift", {{"initial_x", 0.0}, {"initial_y", 0.0}, {"initial_z", 0.0}, {"random_walk", 0.0}}},
      {"magnetometer_motor_interference", {{"b_per_nm_x", 0.0}, {"b_per_nm_y", 0.0}, {"b_per_nm_z", 0.0}}},
      {"accelerometer_scale_error", {{"scale_x", 1.0}, {"scale_y", 1.0}, {"scale_z", 1.0}}},
      {"gps_multipath", {{"sigma_m", 0.0}, {"correlation_s", 5.0}}},
      {"tire_growth", {{"growth_per_mps2", 0.0}}},
      {"longitudinal_slip", {{"slip_per_mps2", 0.0}}},
      {"slope_slip", {{"slip_per_mps2", 0.0}}},
      {"lateral_slip", {{"contact_time_scale", 1.0}}},
      {"wheel_radius_asymmetry", {{"ratio_right_left", 1.0}}},
      {"wheel_radius_scale", {{"scale", 1.0}}},
      {"track_width_error", {{"track_error_m", 0.0}}},
      {"skid_steer_track", {{"track_ratio", 1.0}}},
      {"wheel_deformation", {{"wheel", 0.0}, {"ovality_m", 0.0}}},
      {"axle_misalignment", {{"wheel", 0.0}, {"yaw_deg", 0.0}}},
      {"odometry_scale_error", {{"scale", 1.0}}},
  };
  return known;
}

double EffectParameter(const std::vector<EffectOptions>& effects, const std::string& name, const std::string& parameter,
                       double fallback) {
  for (const EffectOptions& e : effects) {
    if (e.name != name) continue;
    if (const auto it = e.parameters.find(parameter); it != e.parameters.end()) return it->second;
    const auto known = KnownEffects().find(name);
    if (known != KnownEffects().end() && known->second.count(parameter)) return known->second.at(parameter);
    return fallback;
  }
  return fallback;
}

Result<Scenario> LoadScenario(const std::string& path) {
  YamlReader r(path);
  if (!r.ok()) return r.status();
  Scenario s;
  s.source_file = path;
  const YAML::Node root = r.root();
  r.CheckKeys(root, "",
              {"name", "duration_s", "seed", "origin", "ground_truth_rate_hz", "robot", "world", "driver", "sensors",
               "effects", "faults"});
  for (const char* required : {"duration_s", "robot", "world", "driver", "sensors"}) r.Require(root, "", required);
  r.String(root, "", "name", &s.name);
  r.Number(root, "", "duration_s", &s.duration_s);
  r.Unsigned(root, "", "seed", &s.seed);
  r.Number(root, "", "ground_truth_rate_hz", &s.ground_truth_rate_hz);
  if (r.ok() && root["origin"]) {
    const YAML::Node o = root["origin"];
    r.CheckKeys(o, "origin", {"latitude_deg", "longitude_deg", "altitude_m"});
    for (const char* required : {"latitude_deg", "longitude_deg", "altitude_m"}) r.Require(o, "origin", required);
    r.Number(o, "origin", "latitude_deg", &s.origin.latitude_deg);
    r.Number(o, "origin", "longitude_deg", &s.origin.longitude_deg);
    r.Number(o, "origin", "altitude_m", &s.origin.altitude_m);
  }
  const std::string dir = fs::path(path).parent_path().string();
  if (r.ok()) ReadRobot(r, root["robot"], dir, &s);
  if (r.ok()) ReadWorld(r, root["world"], dir, &s);
  if (r.ok()) ReadDriver(r, root["driver"], &s);
  if (r.ok()) ReadSensors(r, root["sensors"], &s);
  if (r.ok()) ReadIndoorSensors(r, root["sensors"], &s);
  if (r.ok() && root["effects"]) ReadEffects(r, root["effects"], &s);
  if (r.ok() && root["faults"]) ReadFaults(r, root["faults"], &s);
  if (!r.ok()) return r.status();

  if (const auto problem = s.Validate()) {
    return Status::Error(r.LineOf(problem->key) + ": " + problem->key + ": " + problem->message);
  }
  if (s.sensors.imu) s.sensors.imu->misalignment.normalize();
  return s;
}

}  // namespace roamlab::sim
