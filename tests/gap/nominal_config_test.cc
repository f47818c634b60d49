// The nominal estimator configuration that `roamlab diagnose` builds from a scenario (gap::NominalConfig).
#include <optional>

#include <gtest/gtest.h>

#include "gap/nominal_config.h"
#include "sim/scenario.h"
#include "tests/support/paths.h"

namespace roamlab::gap {
namespace {

std::string Source(const std::string& relative) { return roamlab::testing::SourceDir() + "/" + relative; }

// The nominal configuration of the scenario at `relative`; none (with a test failure) when either fails.
std::optional<estimator::EstimatorConfig> NominalOf(const std::string& relative) {
  auto scenario = sim::LoadScenario(Source(relative));
  EXPECT_TRUE(scenario.ok()) << scenario.status().message();
  if (!scenario.ok()) return std::nullopt;
  auto config = NominalConfig(scenario.value());
  EXPECT_TRUE(config.ok()) << config.status().message();
  if (!config.ok()) return std::nullopt;
  return config.value();
}

TEST(NominalConfigTest, TheAtvScenarioGivesTheCalibrationWithKGammaFixedAtTheBelievedValue) {
  auto scenario = sim::LoadScenario(Source("scenarios/atv_hills.yaml"));
  ASSERT_TRUE(scenario.ok()) << scenario.status().message();
  scenario.value().sensors.odometer->k_gamma = 0.01;
  auto config = NominalConfig(scenario.value());
  ASSERT_TRUE(config.ok()) << config.status().message();
  const estimator::EstimatorConfig& c = config.value();
  EXPECT_EQ(c.master, "odometer");
  for (const char* stream : {"odometer", "gyroscope", "accelerometer", "magnetometer", "gps"})
    EXPECT_TRUE(c.streams.count(stream)) << stream;
  EXPECT_EQ(c.streams.at("odometer").model, "ackermann");
  EXPECT_EQ(c.streams.at("gps").noise.at("sigma_m"), 0.33);
  EXPECT_FALSE(c.gate_probability.has_value());
  // The Table I calibration is free from the scenario's values; the effects' slots are not.
  for (const char* free : {"gps.lever_arm", "imu.misalignment", "magnetometer.A", "magnetometer.b",
                           "odometer.kv_over_L", "odometer.k_theta"})
    EXPECT_TRUE(c.parameters.at(free).free) << free;
  EXPECT_FALSE(c.parameters.at("odometer.k_gamma").free);
  EXPECT_EQ((*c.parameters.at("odometer.k_gamma").value)[0], 0.01);
  EXPECT_EQ((*c.parameters.at("gps.lever_arm").value)[0], 0.57);
  EXPECT_FALSE(c.parameters.count("gyroscope.scale"));
  EXPECT_FALSE(c.parameters.count("odometer.cornering_rear"));
  EXPECT_FALSE(c.parameters.count("magnetometer.b_per_drive_nm"));
  // The motor interference's proxy: the IMU's specific force, c = m r / 2 of models/atv.xml (354 kg, 0.28 m).
  EXPECT_EQ(c.streams.at("magnetometer").inputs.at("specific_force"), "imu");
  EXPECT_NEAR(c.streams.at("magnetometer").options.at("drive_nm_per_mps2").at(0), 354.0 * 0.28 / 2.0, 1e-6);
  // The longitudinal slip's proxy: the IMU's specific force along O's x, R(q_body_imu)^T e_x in the IMU's frame.
  EXPECT_EQ(c.streams.at("odometer").inputs.at("specific_force"), "imu");
  const Eigen::Vector3d forward = scenario.value().sensors.imu->misalignment.conjugate() * Eigen::Vector3d::UnitX();
  const std::vector<double>& f = c.streams.at("odometer").options.at("forward_in_sensor");
  ASSERT_EQ(f.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(f[static_cast<std::size_t>(i)], forward[i], 1e-12) << i;
  EXPECT_GT(std::abs(forward.y()) + std::abs(forward.z()), 0.3);  // Table I's mounting is far from O's axes
  EXPECT_FALSE(c.parameters.count("odometer.slip_per_mps2"));
  EXPECT_FALSE(c.parameters.count("odometer.slope_slip_per_mps2"));
  ASSERT_EQ(c.stages.size(), 3u);
  EXPECT_EQ(c.stages.back().size(), 6u);
}

// The differential drive's nominal model: its geometry measured on models/diffdrive.xml (wheel radius 0.075 m at
// +-0.2 m), one radius free for both wheels, the baseline fixed, the gyroscope as the yaw reference.
TEST(NominalConfigTest, DifferentialDriveGeometryFromTheModel) {
  const std::optional<estimator::EstimatorConfig> config = NominalOf("scenarios/indoor_diffdrive_gap.yaml");
  ASSERT_TRUE(config);
  const estimator::EstimatorConfig& c = *config;
  EXPECT_EQ(c.master, "odometer");
  EXPECT_EQ(c.streams.at("odometer").model, "differential_drive");
  EXPECT_EQ(c.streams.at("odometer").parameters.at("radius_left"), "odometer.radius");
  EXPECT_EQ(c.streams.at("odometer").parameters.at("radius_right"), "odometer.radius");
  EXPECT_TRUE(c.parameters.at("odometer.radius").free);
  EXPECT_FALSE(c.parameters.at("odometer.baseline").free);
  EXPECT_NEAR((*c.parameters.at("odometer.baseline").value)[0], 0.4, 1e-6);
  EXPECT_TRUE(c.streams.count("gyroscope"));
}

// The omni3 robot's nominal model: models/omni3.xml's wheels (radius 0.05 m at L = 0.2 m), one radius free for the
// three wheels, the distance fixed, the gyroscope as the yaw reference.
TEST(NominalConfigTest, Omni3GeometryFromTheModel) {
  const std::optional<estimator::EstimatorConfig> config = NominalOf("scenarios/indoor_omni_slip.yaml");
  ASSERT_TRUE(config);
  const estimator::EstimatorConfig& c = *config;
  EXPECT_EQ(c.master, "odometer");
  ASSERT_EQ(c.streams.size(), 2u);
  const estimator::StreamConfig& odo = c.streams.at("odometer");
  EXPECT_EQ(odo.model, "omni3_drive");
  EXPECT_EQ(odo.sources.at(""), "wheel_encoders");
  EXPECT_EQ(odo.noise.at("wheel_radps"), 0.3);
  EXPECT_EQ(odo.loss.type, estimator::Loss::Type::kTrivial);
  ASSERT_EQ(odo.parameters.size(), 3u);
  for (const char* slot : {"radius_0", "radius_1", "radius_2"}) EXPECT_EQ(odo.parameters.at(slot), "odometer.radius");
  EXPECT_TRUE(c.parameters.at("odometer.radius").free);
  EXPECT_NEAR((*c.parameters.at("odometer.radius").value)[0], 0.05, 1e-3);
  EXPECT_FALSE(c.parameters.at("odometer.distance").free);
  EXPECT_NEAR((*c.parameters.at("odometer.distance").value)[0], 0.2, 1e-3);
  EXPECT_FALSE(c.parameters.count("odometer.lx_plus_ly"));
  EXPECT_EQ(c.streams.at("gyroscope").model, "gyroscope");
  EXPECT_EQ(c.streams.at("gyroscope").noise.at("sigma_radps"), 0.01);
  EXPECT_TRUE(c.parameters.at("imu.misalignment").free);
  ASSERT_EQ(c.stages.size(), 1u);
}

// The mecanum robot's nominal model: models/mecanum.xml's wheels (radius 0.05 m at lx = 0.2 m, ly = 0.18 m), one
// radius free for the four wheels, lx + ly fixed, and the scenario's position fixes.
TEST(NominalConfigTest, MecanumGeometryFromTheModel) {
  const std::optional<estimator::EstimatorConfig> config = NominalOf("scenarios/indoor_mecanum_gap.yaml");
  ASSERT_TRUE(config);
  const estimator::EstimatorConfig& c = *config;
  ASSERT_EQ(c.streams.size(), 3u);
  const estimator::StreamConfig& odo = c.streams.at("odometer");
  EXPECT_EQ(odo.model, "mecanum_drive");
  EXPECT_EQ(odo.loss.type, estimator::Loss::Type::kTrivial);
  ASSERT_EQ(odo.parameters.size(), 4u);
  for (const char* slot : {"radius_0", "radius_1", "radius_2", "radius_3"})
    EXPECT_EQ(odo.parameters.at(slot), "odometer.radius");
  EXPECT_TRUE(c.parameters.at("odometer.radius").free);
  EXPECT_NEAR((*c.parameters.at("odometer.radius").value)[0], 0.05, 1e-3);
  EXPECT_FALSE(c.parameters.at("odometer.lx_plus_ly").free);
  EXPECT_NEAR((*c.parameters.at("odometer.lx_plus_ly").value)[0], 0.38, 1e-3);
  EXPECT_FALSE(c.parameters.count("odometer.distance"));
  EXPECT_TRUE(c.streams.count("gyroscope"));
  EXPECT_TRUE(c.parameters.at("imu.misalignment").free);
  // The scenario's indoor position fixes (the translation's reference) with the believed antenna mounting.
  EXPECT_EQ(c.streams.at("gps").model, "gps");
  EXPECT_EQ(c.streams.at("gps").noise.at("sigma_m"), 0.01);
  EXPECT_FALSE(c.parameters.at("gps.lever_arm").free);
  EXPECT_EQ((*c.parameters.at("gps.lever_arm").value)[2], 0.1);
}

TEST(NominalConfigTest, OtherRobotKindsAndMissingYawReferenceAreRefused) {
  auto scenario = sim::LoadScenario(Source("scenarios/indoor_mecanum_gap.yaml"));
  ASSERT_TRUE(scenario.ok()) << scenario.status().message();
  sim::Scenario no_imu = scenario.value();
  no_imu.sensors.imu.reset();
  auto config = NominalConfig(no_imu);
  ASSERT_FALSE(config.ok());
  EXPECT_NE(config.status().message().find("needs sensors.imu"), std::string::npos) << config.status().message();
  sim::Scenario other = scenario.value();
  other.robot.kind = "tracked";
  config = NominalConfig(other);
  ASSERT_FALSE(config.ok());
  EXPECT_NE(config.status().message().find("mecanum robots only, not 'tracked'"), std::string::npos);
}

}  // namespace
}  // namespace roamlab::gap
