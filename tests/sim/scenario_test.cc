// Scenario files (sim/scenario.h): the shipped scenario loads with the seed's Section V values, and every kind of bad
// input gives one line naming the file, the line and the key.
#include "sim/scenario.h"

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

TEST(ScenarioTest, AtvHillsIsTheSectionVSetup) {
  auto loaded = LoadScenario(testing::SourcePath("scenarios/atv_hills.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  const Scenario& s = loaded.value();
  EXPECT_EQ(s.duration_s, 30.0);
  EXPECT_EQ(s.seed, 1u);
  EXPECT_EQ(s.robot.kind, "ackermann");
  EXPECT_NE(s.robot.model_file.find("models/atv.xml"), std::string::npos);
  EXPECT_EQ(s.terrain.type, TerrainOptions::Type::kHills);
  EXPECT_EQ(s.terrain.seed, 7u);
  ASSERT_TRUE(s.sensors.imu && s.sensors.magnetometer && s.sensors.gps && s.sensors.odometer);
  EXPECT_EQ(s.sensors.imu->rate_hz, 100.0);
  EXPECT_EQ(s.sensors.gps->rate_hz, 5.0);
  EXPECT_EQ(s.sensors.gps->sigma_m, 0.33);
  EXPECT_EQ(s.sensors.magnetometer->sigma, 0.067);
  EXPECT_EQ(s.sensors.imu->accel_sigma_mps2, 0.067);
  EXPECT_EQ(s.sensors.imu->gyro_sigma_radps, 0.033);
  EXPECT_EQ(s.sensors.odometer->speed_sigma_mps, 0.033);
  EXPECT_EQ(s.sensors.odometer->steering_sigma_rad, 0.014);
  EXPECT_NEAR(s.sensors.imu->misalignment.norm(), 1.0, 1e-15);
  EXPECT_EQ(s.sensors.gps->lever_arm_m, Eigen::Vector3d(0.57, -0.46, 0.32));
  EXPECT_EQ(s.sensors.magnetometer->A(2, 1), -0.04);
  EXPECT_EQ(s.sensors.odometer->kv_over_L, 0.8);
  EXPECT_TRUE(s.effects.empty());
  // The drive turns both ways.
  double left = 0.0, right = 0.0;
  for (double t = 0.0; t <= 30.0; t += 0.01) {
    left = std::max(left, s.driver.handlebar_rad.Evaluate(t));
    right = std::min(right, s.driver.handlebar_rad.Evaluate(t));
  }
  EXPECT_GT(left, 0.15);
  EXPECT_LT(right, -0.15);
}

// Writes atv_hills.yaml with one substitution into a temporary directory, with the model path made absolute.
class ScenarioErrorTest : public ::testing::Test {
 protected:
  // Replaces `from` (which must occur) by `to` and loads; returns the error message ("" if it loaded).
  std::string LoadWith(const std::string& from, const std::string& to) {
    std::string text = testing::ReadText(testing::SourcePath("scenarios/atv_hills.yaml"));
    const std::string model = "model: ../models/atv.xml";
    text.replace(text.find(model), model.size(), "model: " + testing::SourcePath("models/atv.xml"));
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at == std::string::npos) return "";
    text.replace(at, from.size(), to);
    text_ = text;
    path_ = dir_.File("scenario.yaml");
    roamlab::testing::WriteFile(path_, text);
    auto loaded = LoadScenario(path_);
    return loaded.ok() ? "" : loaded.status().message();
  }
  // The same with scenarios/indoor_diffdrive_slip.yaml.
  std::string LoadIndoorWith(const std::string& from, const std::string& to) {
    std::string text = testing::ReadText(testing::SourcePath("scenarios/indoor_diffdrive_slip.yaml"));
    for (const std::string file : {"diffdrive.xml", "indoor_room.xml"}) {
      const std::string relative = "../models/" + file;
      text.replace(text.find(relative), relative.size(), testing::SourcePath("models/" + file));
    }
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at == std::string::npos) return "";
    text.replace(at, from.size(), to);
    text_ = text;
    path_ = dir_.File("indoor.yaml");
    roamlab::testing::WriteFile(path_, text);
    auto loaded = LoadScenario(path_);
    return loaded.ok() ? "" : loaded.status().message();
  }
  // 1-based line of the first occurrence of `marker` in the last written file.
  int LineOf(const std::string& marker) const {
    const std::size_t at = text_.find(marker);
    EXPECT_NE(at, std::string::npos) << marker;
    return 1 + static_cast<int>(std::count(text_.begin(), text_.begin() + static_cast<long>(at), '\n'));
  }
  // Checks "<file>:<line of marker>: <key>: ..." on a single line.
  void ExpectError(const std::string& message, const std::string& marker, const std::string& key,
                   const std::string& problem) {
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    const std::string prefix = path_ + ":" + std::to_string(LineOf(marker)) + ": " + key + ": ";
    EXPECT_EQ(message.rfind(prefix, 0), 0u) << message << "\nexpected prefix: " << prefix;
    EXPECT_NE(message.find(problem), std::string::npos) << message;
  }

  roamlab::testing::TempDir dir_;
  std::string path_;
  std::string text_;
};

// The laser and the camera are left out of a run whose estimator reads neither of their streams, unless a fault
// names one; every other sensor stays.
TEST(ScenarioTest, UnreadLaserAndCameraAreDropped) {
  auto loaded = LoadScenario(testing::SourcePath("scenarios/indoor_omni_slip.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  ASSERT_TRUE(loaded.value().sensors.laser && loaded.value().sensors.camera && loaded.value().sensors.imu);
  Scenario wheels_only = loaded.value();
  wheels_only.DropUnreadCostlySensors({"imu", "wheel_encoders"});
  EXPECT_FALSE(wheels_only.sensors.laser);
  EXPECT_FALSE(wheels_only.sensors.camera);
  EXPECT_TRUE(wheels_only.sensors.imu && wheels_only.sensors.wheel_encoders);
  Scenario laser_read = loaded.value();
  laser_read.DropUnreadCostlySensors({"imu", "scan_matching"});
  EXPECT_TRUE(laser_read.sensors.laser);
  EXPECT_FALSE(laser_read.sensors.camera);
  Scenario camera_faulted = loaded.value();
  camera_faulted.faults.push_back({"outliers", "visual_odometry", 0.1, 0.05});
  camera_faulted.DropUnreadCostlySensors({"imu"});
  EXPECT_TRUE(camera_faulted.sensors.camera);
  EXPECT_FALSE(camera_faulted.sensors.laser);
}

TEST_F(ScenarioErrorTest, FaultsAreReadAndChecked) {
  EXPECT_EQ(LoadWith("effects: []",
                     "effects: []\nfaults:\n  - {type: outage, stream: gps, start_s: 5, duration_s: 20}\n"
                     "  - {type: clock_jump, stream: imu, at_s: 15, jump_s: 1}"),
            "");
  auto loaded = LoadScenario(path_);
  ASSERT_TRUE(loaded.ok());
  ASSERT_EQ(loaded.value().faults.size(), 2u);
  EXPECT_EQ(loaded.value().faults[0].type, "outage");
  EXPECT_EQ(loaded.value().faults[0].duration_s, 20.0);
  EXPECT_EQ(loaded.value().faults[1].jump_s, 1.0);
  ExpectError(
      LoadWith("effects: []", "effects: []\nfaults:\n  - {type: outage, stream: lidar, start_s: 5, duration_s: 2}"),
      "type: outage", "faults[0].stream", "no stream 'lidar'");
  ExpectError(LoadWith("effects: []", "effects: []\nfaults:\n  - {type: outage, stream: gps, start_s: 5, size: 2}"),
              "start_s: 5, size", "faults[0].size", "unknown key for fault type outage");
  ExpectError(LoadWith("effects: []", "effects: []\nfaults:\n  - {type: outage, stream: gps, start_s: 5}"),
              "type: outage", "faults[0].duration_s", "missing");
  ExpectError(LoadWith("effects: []", "effects: []\nfaults:\n  - {type: clock_jump, stream: gps, at_s: 5, jump_s: -1}"),
              "type: clock_jump", "faults[0].jump_s", "backward jump");
}

TEST_F(ScenarioErrorTest, UnchangedCopyLoads) { EXPECT_EQ(LoadWith("name: atv_hills", "name: copy"), ""); }

TEST_F(ScenarioErrorTest, UnknownKeys) {
  ExpectError(LoadWith("duration_s: 30.0", "duration_s: 30.0\ncolour: red"), "colour", "colour", "unknown key");
  ExpectError(LoadWith("sigma_m: 0.33", "sigma_m: 0.33\n    sigma: 1.0"), "sigma: 1.0", "sensors.gps.sigma",
              "unknown key");
}

TEST_F(ScenarioErrorTest, BadValues) {
  ExpectError(LoadWith("rate_hz: 5\n", "rate_hz: fast\n"), "rate_hz: fast", "sensors.gps.rate_hz",
              "expected a finite number");
  ExpectError(LoadWith("rate_hz: 5\n", "rate_hz: -5\n"), "rate_hz: -5", "sensors.gps.rate_hz", "must be > 0");
  ExpectError(LoadWith("lever_arm_m: [0.57, -0.46, 0.32]", "lever_arm_m: [0.57, -0.46]"), "lever_arm_m: [0.57",
              "sensors.gps.lever_arm_m", "expected 3 numbers");
  ExpectError(LoadWith("type: hills", "type: mountains"), "type: mountains", "world.terrain.type", "hills or flat");
  ExpectError(LoadWith("relief_m: 4.0", "relief_m: 0"), "relief_m: 0", "world.terrain.relief_m", "must be > 0");
  ExpectError(LoadWith("kind: ackermann", "kind: hovercraft"), "kind: hovercraft", "robot.kind",
              "unknown value 'hovercraft' (allowed: ackermann, differential_drive, skid_steer, omni3, mecanum)");
  // A mistyped driver type is refused as such, not read with another driver's keys.
  ExpectError(LoadWith("  type: ackermann\n  lead_in_s", "  type: body_velocty\n  lead_in_s"), "type: body_velocty",
              "driver.type", "unknown value 'body_velocty' (allowed: ackermann, body_velocity)");
  ExpectError(LoadWith("{amplitude: 1.2, period_s: 5.5, phase_rad: 1.5708}", "{amplitude: 1.2, period_s: -5.5}"),
              "period_s: -5.5", "driver.speed_mps[1]", "period_s must be > 0");
  ExpectError(LoadWith("effects: []", "effects: [{name: flux_capacitor, parameters: {gigawatts: 1.21}}]"),
              "flux_capacitor", "effects[0].name", "unknown effect");
  ExpectError(LoadWith("effects: []", "effects: [{name: gps_latency, parameters: {latency_s: 2}}]"), "gps_latency",
              "effects[0].parameters.latency_s", "must be in [0, 1]");
  ExpectError(LoadWith("sigma_m: 0.33", "sigma_m: 0.33\n    noise_correlation_s: -1"), "noise_correlation_s: -1",
              "sensors.gps.noise_correlation_s", "must be in [0, 3600] s");
}

TEST_F(ScenarioErrorTest, MotionCaptureNoiseCorrelationIsParsedAndChecked) {
  const std::string sensors = "sensors:\n";
  EXPECT_EQ(LoadIndoorWith(sensors, sensors + "  mocap: {rate_hz: 20, noise_correlation_s: 0.2}\n"), "");
  auto loaded = LoadScenario(path_);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  ASSERT_TRUE(loaded.value().sensors.mocap.has_value());
  EXPECT_EQ(loaded.value().sensors.mocap->noise_correlation_s, 0.2);
  ExpectError(LoadIndoorWith(sensors, sensors + "  mocap: {rate_hz: 20, noise_correlation_s: -1}\n"),
              "noise_correlation_s: -1", "sensors.mocap.noise_correlation_s", "must be in [0, 3600] s");
}

TEST_F(ScenarioErrorTest, WheelOffsetIsParsedAndChecked) {
  const std::string kind = "kind: differential_drive\n";
  EXPECT_EQ(LoadIndoorWith(kind, kind + "  wheel_offset: [{wheel: 1, offset_m: [-0.03, 0.01]}]\n"), "");
  auto loaded = LoadScenario(path_);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  ASSERT_EQ(loaded.value().robot.wheel_offset.size(), 1u);
  EXPECT_EQ(loaded.value().robot.wheel_offset[0].wheel, 1);
  EXPECT_EQ(loaded.value().robot.wheel_offset[0].offset_m, Eigen::Vector2d(-0.03, 0.01));
  ExpectError(LoadIndoorWith(kind, kind + "  wheel_offset: [{wheel: 1, offset_m: [0.06, 0.0]}]\n"), "wheel_offset",
              "robot.wheel_offset[0].offset_m", "within +-0.05 m");
  ExpectError(LoadIndoorWith(kind, kind + "  wheel_offset: [{wheel: 0, offset_m: [0.0, .nan]}]\n"), "wheel_offset",
              "robot.wheel_offset[0].offset_m[1]", "expected a finite number");
  ExpectError(LoadIndoorWith(kind, kind + "  wheel_offset: [{wheel: -1, offset_m: [0.0, 0.0]}]\n"), "wheel_offset",
              "robot.wheel_offset[0].wheel", "must be >= 0");
  ExpectError(LoadIndoorWith(kind, kind + "  wheel_offset: [{wheel: 1, offset_m: [0.01, 0.0]}, "
                                          "{wheel: 1, offset_m: [0.0, 0.01]}]\n"),
              "wheel_offset", "robot.wheel_offset[1].wheel", "wheel listed twice");
  ExpectError(LoadIndoorWith(kind, kind + "  wheel_offset: [{wheel: 1, offset_m: [0.01]}]\n"), "wheel_offset",
              "robot.wheel_offset[0].offset_m", "expected 2 numbers");
  ExpectError(LoadIndoorWith(kind, kind + "  wheel_offset: [{wheel: 1}]\n"), "wheel_offset",
              "robot.wheel_offset[0].offset_m", "missing required key");
  ExpectError(LoadIndoorWith(kind, kind + "  wheel_offset: {wheel: 1}\n"), "wheel_offset", "robot.wheel_offset",
              "expected a list");
  Scenario atv = testing::AtvHills(1.0);
  atv.robot.wheel_offset = {{0, Eigen::Vector2d(0.01, 0.0)}};
  ASSERT_TRUE(atv.Validate().has_value());
  EXPECT_EQ(atv.Validate()->key, "robot.wheel_offset");
}

TEST_F(ScenarioErrorTest, EncoderColumnsAndGeometryKeysAreParsedAndChecked) {
  const std::string kind = "kind: differential_drive\n";
  const std::string columns = "  encoder_columns: [{wheel: 1, name: right}, {wheel: 0, name: left}]\n";
  EXPECT_EQ(LoadIndoorWith(kind, kind + columns + "  geometry_keys: per_wheel\n  geometry: {gear_ratio: 43.7}\n"), "");
  auto loaded = LoadScenario(path_);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  const RobotOptions& robot = loaded.value().robot;
  ASSERT_EQ(robot.encoder_columns.size(), 2u);
  EXPECT_EQ(robot.encoder_columns[0].wheel, 1);
  EXPECT_EQ(robot.encoder_columns[0].name, "right");
  EXPECT_TRUE(robot.per_wheel_geometry);
  EXPECT_EQ(robot.stated_geometry.at("gear_ratio"), 43.7);
  ExpectError(LoadIndoorWith(kind, kind + "  encoder_columns: [{wheel: 0, name: a}, {wheel: 0, name: b}]\n"),
              "encoder_columns", "robot.encoder_columns[1].wheel", "wheel listed twice");
  ExpectError(LoadIndoorWith(kind, kind + "  encoder_columns: [{wheel: 0, name: a}, {wheel: 1, name: a}]\n"),
              "encoder_columns", "robot.encoder_columns[1].name", "name listed twice");
  ExpectError(LoadIndoorWith(kind, kind + "  encoder_columns: [{wheel: 0, name: \"a b\"}]\n"), "encoder_columns",
              "robot.encoder_columns[0].name", "letters, digits and _");
  ExpectError(LoadIndoorWith(kind, kind + "  encoder_columns: [{wheel: 0}]\n"), "encoder_columns",
              "robot.encoder_columns[0].name", "missing required key");
  ExpectError(LoadIndoorWith(kind, kind + "  geometry_keys: all\n"), "geometry_keys", "robot.geometry_keys",
              "nominal or per_wheel");
  ExpectError(LoadIndoorWith(kind, kind + "  geometry_keys: per_wheel\n"), "geometry_keys", "robot.geometry_keys",
              "needs robot.encoder_columns");
  ExpectError(LoadIndoorWith(kind, kind + "  geometry: {gear_ratio: many}\n"), "gear_ratio",
              "robot.geometry.gear_ratio", "expected a finite number");
  ExpectError(LoadIndoorWith("ticks_per_revolution: 2048", "ticks_per_revolution: 2048\n    name: \"wheel/s\""),
              "wheel/s", "sensors.wheel_encoders.name", "letters, digits and _");
  // Ticks per revolution need not be whole (64 motor ticks through a 43.7:1 gearbox).
  EXPECT_EQ(LoadIndoorWith("ticks_per_revolution: 2048", "ticks_per_revolution: 2796.8"), "");
}

TEST_F(ScenarioErrorTest, MissingFilesAndKeys) {
  ExpectError(LoadWith("model: " + testing::SourcePath("models/atv.xml"), "model: no_such_robot.xml"),
              "no_such_robot.xml", "robot.model", "no such file 'no_such_robot.xml'");
  ExpectError(LoadWith("{amplitude: 1.2, period_s: 5.5, phase_rad: 1.5708}", "{amplitude: 1.2}"), "{amplitude: 1.2}",
              "driver.speed_mps[1].sine.period_s", "missing required key");
  const std::string message = LoadWith("duration_s: 30.0\n", "");
  EXPECT_NE(message.find("duration_s: missing required key"), std::string::npos) << message;
  EXPECT_EQ(LoadScenario(dir_.File("absent.yaml")).status().message(), dir_.File("absent.yaml") + ": cannot open file");
}

TEST_F(ScenarioErrorTest, LaserStoreScans) {
  EXPECT_EQ(LoadIndoorWith("    sigma_m: 0.01\n", "    sigma_m: 0.01\n    store_scans: true\n"), "");
  ExpectError(LoadIndoorWith("    sigma_m: 0.01\n", "    sigma_m: 0.01\n    store_scans: 1.5\n"), "store_scans",
              "sensors.laser.store_scans", "expected true or false");
}

TEST_F(ScenarioErrorTest, CameraSection) {
  EXPECT_EQ(LoadIndoorWith("    rate_hz: 15\n", "    rate_hz: 15\n    store_images: true\n"), "");
  ExpectError(LoadIndoorWith("    rate_hz: 15\n", "    rate_hz: 40\n"), "rate_hz: 40", "sensors.camera.rate_hz",
              "must be in [10, 30]");
  ExpectError(LoadIndoorWith("    width_px: 320\n", "    width_px: 640\n"), "height_px: 240",
              "sensors.camera.height_px", "320x240 or 640x480");
  ExpectError(LoadIndoorWith("    width_px: 320\n", "    width_px: 300\n"), "width_px: 300", "sensors.camera.width_px",
              "320x240 or 640x480");
  ExpectError(LoadIndoorWith("    rate_hz: 15\n", "    rate_hz: 15\n    store_images: maybe\n"), "store_images",
              "sensors.camera.store_images", "expected true or false");
  ExpectError(LoadIndoorWith("    rate_hz: 15\n", "    rate_hz: 15\n    fps: 15\n"), "fps", "sensors.camera.fps",
              "unknown key");
  ExpectError(LoadWith("lever_arm_m: [0.57, -0.46, 0.32]", "lever_arm_m: [0.57, -0.46, 0.32]\n  camera: {}"),
              "camera: {}", "sensors.camera", "only for wheeled indoor robots");
}

TEST_F(ScenarioErrorTest, YamlSyntaxErrorsGiveLineAndColumn) {
  const std::string message = LoadWith("seed: 1 ", "seed: [1\n");
  EXPECT_EQ(message.rfind(path_ + ":", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

}  // namespace
}  // namespace roamlab::sim

namespace roamlab::sim {
namespace {

TEST(ScenarioTest, IndoorOmniDrivesSidewaysAndWheelMountingIsParsedAndChecked) {
  auto loaded = LoadScenario(testing::SourcePath("scenarios/indoor_omni_slip.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  Scenario s = loaded.value();
  EXPECT_EQ(s.robot.kind, "omni3");
  double left = 0.0, right = 0.0;
  for (double t = 0.0; t <= 30.0; t += 0.01) {
    left = std::max(left, s.driver.lateral_mps.Evaluate(t));
    right = std::min(right, s.driver.lateral_mps.Evaluate(t));
  }
  EXPECT_EQ(left, 0.4);
  EXPECT_EQ(right, -0.4);

  // Wheel mounting from YAML (degrees), then the checks of Validate.
  std::string text = testing::ReadText(testing::SourcePath("scenarios/indoor_omni_slip.yaml"));
  for (const std::string model : {"../models/omni3.xml", "../models/indoor_room.xml"})
    text.replace(text.find(model), model.size(), testing::SourcePath(model.substr(3)));
  const std::string kind = "kind: omni3\n";
  text.replace(text.find(kind), kind.size(), kind + "  wheel_mounting: [{wheel: 2, yaw_deg: 2.0, tilt_deg: -3.0}]\n");
  roamlab::testing::TempDir dir;
  roamlab::testing::WriteFile(dir.File("omni.yaml"), text);
  auto mounted = LoadScenario(dir.File("omni.yaml"));
  ASSERT_TRUE(mounted.ok()) << mounted.status().message();
  ASSERT_EQ(mounted.value().robot.wheel_mounting.size(), 1u);
  EXPECT_EQ(mounted.value().robot.wheel_mounting[0].wheel, 2);
  EXPECT_NEAR(mounted.value().robot.wheel_mounting[0].yaw_rad, 2.0 * M_PI / 180.0, 1e-15);
  EXPECT_NEAR(mounted.value().robot.wheel_mounting[0].tilt_rad, -3.0 * M_PI / 180.0, 1e-15);

  // Wheel deformation from YAML, then the checks of Validate.
  const std::string deformed_text = std::string(text).replace(
      text.find(kind), kind.size(), kind + "  wheel_deformation: [{wheel: 1, radius_scale: 1.01, ovality_m: 0.003}]\n");
  roamlab::testing::WriteFile(dir.File("deformed.yaml"), deformed_text);
  auto deformed = LoadScenario(dir.File("deformed.yaml"));
  ASSERT_TRUE(deformed.ok()) << deformed.status().message();
  ASSERT_EQ(deformed.value().robot.wheel_deformation.size(), 1u);
  EXPECT_EQ(deformed.value().robot.wheel_deformation[0].wheel, 1);
  EXPECT_EQ(deformed.value().robot.wheel_deformation[0].radius_scale, 1.01);
  EXPECT_EQ(deformed.value().robot.wheel_deformation[0].ovality_m, 0.003);
  roamlab::testing::WriteFile(dir.File("typo.yaml"),
                              std::string(text).replace(text.find(kind), kind.size(),
                                                        kind + "  wheel_deformation: [{wheel: 1, ovality: 0.003}]\n"));
  auto typo = LoadScenario(dir.File("typo.yaml"));
  ASSERT_FALSE(typo.ok());
  EXPECT_NE(typo.status().message().find("robot.wheel_deformation[0]"), std::string::npos) << typo.status().message();
  EXPECT_NE(typo.status().message().find("ovality"), std::string::npos) << typo.status().message();
  EXPECT_EQ(typo.status().message().find('\n'), std::string::npos);
  for (const auto& [deformation, key] : std::vector<std::pair<WheelDeformation, std::string>>{
           {{-1, 1.0, 0.0}, "robot.wheel_deformation[0].wheel"},
           {{0, 1.5, 0.0}, "robot.wheel_deformation[0].radius_scale"},
           {{0, 1.0, -0.001}, "robot.wheel_deformation[0].ovality_m"},
           {{0, 1.0, 0.03}, "robot.wheel_deformation[0].ovality_m"}}) {
    Scenario wrong = s;
    wrong.robot.wheel_deformation = {deformation};
    ASSERT_TRUE(wrong.Validate().has_value()) << key;
    EXPECT_EQ(wrong.Validate()->key, key);
  }
  Scenario atv = testing::AtvHills(1.0);
  atv.robot.wheel_deformation = {{0, 1.0, 0.001}};
  ASSERT_TRUE(atv.Validate().has_value());
  EXPECT_EQ(atv.Validate()->key, "robot.wheel_deformation");

  Scenario bad = s;
  bad.robot.wheel_mounting = {{0, 0.5, 0.0}};
  ASSERT_TRUE(bad.Validate().has_value());
  EXPECT_EQ(bad.Validate()->key, "robot.wheel_mounting[0].yaw_deg");
  bad = s;
  bad.robot.kind = "differential_drive";
  ASSERT_TRUE(bad.Validate().has_value());
  EXPECT_EQ(bad.Validate()->key, "driver.lateral_mps");
  bad.driver.lateral_mps = Profile::Constant(0.0);
  EXPECT_FALSE(bad.Validate().has_value());
}

}  // namespace
}  // namespace roamlab::sim
