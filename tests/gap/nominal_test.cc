// The nominal estimator configuration that `roamlab diagnose` builds from a scenario (gap::NominalConfig).
#include <gtest/gtest.h>

#include "gap/diagnose.h"
#include "sim/scenario.h"

namespace roamlab::gap {
namespace {

std::string Source(const std::string& relative) { return std::string(ROAMLAB_SOURCE_DIR) + "/" + relative; }

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
  ASSERT_EQ(c.stages.size(), 3u);
  EXPECT_EQ(c.stages.back().size(), 6u);
}

// The differential drive's nominal model: its geometry measured on models/diffdrive.xml (wheel radius 0.075 m at
// +-0.2 m), one radius free for both wheels, the baseline fixed, the gyroscope as the yaw reference.
TEST(NominalConfigTest, DifferentialDriveGeometryFromTheModel) {
  auto scenario = sim::LoadScenario(Source("scenarios/indoor_diffdrive_gap.yaml"));
  ASSERT_TRUE(scenario.ok()) << scenario.status().message();
  auto config = NominalConfig(scenario.value());
  ASSERT_TRUE(config.ok()) << config.status().message();
  const estimator::EstimatorConfig& c = config.value();
  EXPECT_EQ(c.master, "odometer");
  EXPECT_EQ(c.streams.at("odometer").model, "differential_drive");
  EXPECT_EQ(c.streams.at("odometer").parameters.at("radius_left"), "odometer.radius");
  EXPECT_EQ(c.streams.at("odometer").parameters.at("radius_right"), "odometer.radius");
  EXPECT_TRUE(c.parameters.at("odometer.radius").free);
  EXPECT_FALSE(c.parameters.at("odometer.baseline").free);
  EXPECT_NEAR((*c.parameters.at("odometer.baseline").value)[0], 0.4, 1e-6);
  EXPECT_TRUE(c.streams.count("gyroscope"));
}

TEST(NominalConfigTest, OtherRobotKindsAreRefused) {
  auto scenario = sim::LoadScenario(Source("scenarios/indoor_omni_slip.yaml"));
  ASSERT_TRUE(scenario.ok()) << scenario.status().message();
  auto config = NominalConfig(scenario.value());
  ASSERT_FALSE(config.ok());
  EXPECT_NE(config.status().message().find("ackermann and differential_drive robots only"), std::string::npos);
}

}  // namespace
}  // namespace roamlab::gap
