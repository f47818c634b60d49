// `roamlab design` on the indoor robots: the body-velocity family (experiment/drive_family.h) within the robot's
// envelope (sim/drive_envelope.h), on short drives with small budgets.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "experiment/design.h"
#include "sim/drive_envelope.h"
#include "sim/simulator.h"
#include "tests/experiment/design_testing.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab::experiment {
namespace {

// 8 s of the differential-drive robot with motion capture, driving forward and barely turning (0.1 rad/s): the
// baseline, which the wheels' rate difference measures against the yaw rate, is poorly measured.
std::string GentleDiffDrive() {
  return "name: gentle\nduration_s: 8.0\nseed: 1\nground_truth_rate_hz: 100\nrobot:\n  kind: differential_drive\n"
         "  model: " +
         roamlab::testing::SourceDir() +
         "/models/diffdrive.xml\n  start: {position_m: [0.0, 0.0], heading_deg: 0.0}\n"
         "world:\n  terrain: {type: flat, friction: 0.6}\n"
         "driver:\n  type: body_velocity\n  lead_in_s: 1.0\n  linear_mps: 0.2\n"
         "  angular_radps:\n    - sine: {amplitude: 0.1, period_s: 8.0, phase_rad: 0.0}\n"
         "sensors:\n  imu: {rate_hz: 100, gyro_sigma_radps: 0.01, accel_sigma_mps2: 0.05}\n"
         "  wheel_encoders: {rate_hz: 100, ticks_per_revolution: 2048}\n"
         "  mocap: {rate_hz: 20, position_sigma_m: 0.001, orientation_sigma_rad: 0.005}\n";
}

// 6 s of the mecanum robot with position fixes, moving forward only.
std::string StraightMecanum() {
  return "name: straight\nduration_s: 6.0\nseed: 1\nground_truth_rate_hz: 100\nrobot:\n  kind: mecanum\n  model: " +
         roamlab::testing::SourceDir() +
         "/models/mecanum.xml\n  start: {position_m: [0.0, 0.0], heading_deg: 0.0}\n"
         "world:\n  terrain: {type: flat, friction: 0.6}\n"
         "driver:\n  type: body_velocity\n  lead_in_s: 1.0\n  linear_mps: 0.15\n  angular_radps: 0.1\n"
         "sensors:\n  imu: {rate_hz: 100, gyro_sigma_radps: 0.01, accel_sigma_mps2: 0.05}\n"
         "  wheel_encoders: {rate_hz: 100, ticks_per_revolution: 2048}\n"
         "  gps: {rate_hz: 10, sigma_m: 0.01, lever_arm_m: [0.0, 0.0, 0.1]}\n";
}

class DesignIndoorTest : public ::testing::Test {
 protected:
  void Use(const std::string& scenario_text, const std::string& config) {
    std::ofstream(dir_.File("scenario.yaml")) << scenario_text;
    request_.scenario = dir_.File("scenario.yaml");
    request_.config = testing::ConfigWithoutTargets(config, dir_);  // the test's targets only
    request_.out = dir_.File("designed.yaml");
  }
  testing::TempDir dir_;
  DesignRequest request_;
};

TEST_F(DesignIndoorTest, DifferentialDriveDesignBeatsItsStartAndSimulates) {
  Use(GentleDiffDrive(), "indoor_diffdrive_mocap_calibration.yaml");
  request_.targets = {{"odometer.baseline", 1e-4}};
  request_.budget = 12;  // the start, the grid of 9, two steps of the pattern search
  DesignResult result;
  const Outcome outcome = DesignToFile(request_, &result);
  ASSERT_TRUE(outcome.ok()) << outcome.status.message();
  // The robot's envelope: forward -0.3 to 0.6 m/s, yaw rate 1.2 rad/s, side slip 0.05 m/s.
  EXPECT_DOUBLE_EQ(result.limits.min_speed_mps, -0.3);
  EXPECT_DOUBLE_EQ(result.limits.max_yaw_rate_radps, 1.2);
  EXPECT_DOUBLE_EQ(result.limits.max_side_slip_mps, 0.05);
  const DesignCandidate& start = result.candidates.front();
  ASSERT_TRUE(start.infeasible.empty()) << start.infeasible;
  EXPECT_NEAR(start.drive.at("yaw_rate_amplitude_radps"), 0.1, 1e-12);
  ASSERT_GE(result.best, 0);
  const DesignCandidate& best = result.candidates[static_cast<std::size_t>(result.best)];
  // The wheels' predicted std finite; the baseline's below the start drive's. (The design looks at the targets only:
  // the IMU misalignment, not targeted, may be unobservable on the chosen drive.)
  for (const auto& [label, std] : best.crb_std) {
    if (label.rfind("odometer.", 0) == 0) {
      EXPECT_TRUE(std::isfinite(std) && std > 0.0) << label;
    }
  }
  EXPECT_EQ(best.worst, "odometer.baseline");
  EXPECT_LT(best.objective, 0.8 * start.objective);
  EXPECT_LE(best.max_lateral_accel_mps2, result.limits.max_lateral_accel_mps2);
  EXPECT_GT(best.max_velocity_error_mps, 0.0);  // measured: the servos lag their set-points a little
  EXPECT_LE(best.max_velocity_error_mps, result.limits.max_velocity_error_mps);

  // The written scenario reads back as the best drive and simulates in MuJoCo, with noise, within the side-slip limit.
  auto loaded = sim::LoadScenario(request_.out);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  const auto written = StartDrive(loaded.value(), request_.limits);
  ASSERT_TRUE(written.ok()) << written.status().message();
  for (const auto& [name, value] : best.drive.values) EXPECT_NEAR(written.value().at(name), value, 1e-9) << name;
  auto simulated = sim::Simulate(loaded.value());
  ASSERT_TRUE(simulated.ok()) << simulated.status().message();
  EXPECT_LE(simulated.value().stats.max_lateral_speed_mps, result.limits.max_side_slip_mps);
}

// No target in the request: the configuration's (configs/indoor_diffdrive_mocap_calibration.yaml: the wheels') are the
// objective's, and the designed scenario's header repeats them as the equivalent --target options.
TEST_F(DesignIndoorTest, WithoutTargetsTheConfigurationsAreTheObjectives) {
  Use(GentleDiffDrive(), "indoor_diffdrive_mocap_calibration.yaml");
  request_.config = roamlab::testing::SourceDir() + "/configs/indoor_diffdrive_mocap_calibration.yaml";
  request_.budget = 1;
  DesignResult result;
  const Outcome outcome = DesignToFile(request_, &result);
  ASSERT_TRUE(outcome.ok()) << outcome.status.message();
  const std::map<std::string, double> expected = {
      {"odometer.baseline", 3e-4}, {"odometer.radius_left", 2e-5}, {"odometer.radius_right", 2e-5}};
  EXPECT_EQ(result.targets, expected);
  const DesignCandidate& start = result.candidates.front();
  double worst = 0.0;
  for (const auto& [label, std] : start.crb_std) {
    const auto target = expected.find(label);
    if (target != expected.end()) worst = std::max(worst, std / target->second);
  }
  EXPECT_TRUE(std::isfinite(worst));
  EXPECT_DOUBLE_EQ(start.objective, worst);
  std::ifstream written(request_.out);
  const std::string header((std::istreambuf_iterator<char>(written)), std::istreambuf_iterator<char>());
  EXPECT_NE(header.find("--target odometer.baseline=0.0003 --target odometer.radius_left=2e-05"), std::string::npos)
      << header.substr(0, 400);
}

TEST_F(DesignIndoorTest, HolonomicRobotsGetASidewaysTerm) {
  Use(StraightMecanum(), "indoor_mecanum_calibration.yaml");
  request_.targets = {{"odometer.lx_plus_ly", 1e-3}};
  request_.budget = 2;
  DesignResult result;
  const Outcome outcome = DesignToFile(request_, &result);
  ASSERT_TRUE(outcome.ok()) << outcome.status.message();
  EXPECT_DOUBLE_EQ(result.limits.max_lateral_mps, 0.3);
  EXPECT_TRUE(std::isinf(result.limits.max_side_slip_mps));  // the sideways speed is commanded
  const DesignCandidate& best = result.candidates[static_cast<std::size_t>(result.best)];
  EXPECT_EQ(best.drive.values.count("lateral_amplitude_mps"), 1u);
  auto loaded = sim::LoadScenario(request_.out);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_FALSE(loaded.value().driver.lateral_mps.terms.empty());
}

// 12 s of the omni robot at 0.5 m/s straight ahead from the middle of the 8 m room: it meets the east wall after 7 s.
std::string OmniIntoTheWall() {
  return "name: wall\nduration_s: 12.0\nseed: 1\nground_truth_rate_hz: 100\nrobot:\n  kind: omni3\n  model: " +
         roamlab::testing::SourceDir() +
         "/models/omni3.xml\n  start: {position_m: [0.0, 0.0], heading_deg: 0.0}\n"
         "world:\n  terrain: {type: flat, friction: 0.6}\n  model: " +
         roamlab::testing::SourceDir() +
         "/models/indoor_room.xml\n"
         "driver:\n  type: body_velocity\n  lead_in_s: 1.0\n  linear_mps: 0.5\n  angular_radps: 0.0\n"
         "sensors:\n  imu: {rate_hz: 100, gyro_sigma_radps: 0.01, accel_sigma_mps2: 0.05}\n"
         "  wheel_encoders: {rate_hz: 100, ticks_per_revolution: 2048}\n"
         "  laser: {rate_hz: 10, beams: 683, fov_deg: 240, min_range_m: 0.02, max_range_m: 4.0, sigma_m: 0.01}\n";
}

TEST_F(DesignIndoorTest, ADriveIntoAWallIsInfeasible) {
  Use(OmniIntoTheWall(), "indoor_omni_calibration.yaml");
  request_.targets = {{"odometer.distance", 1e-3}};
  request_.budget = 1;
  DesignResult result;
  const Outcome outcome = DesignToFile(request_, &result);
  ASSERT_FALSE(outcome.ok());
  EXPECT_FALSE(outcome.bad_input) << outcome.status.message();
  ASSERT_EQ(result.candidates.size(), 1u);
  EXPECT_NE(result.candidates.front().infeasible.find("velocity error"), std::string::npos)
      << result.candidates.front().infeasible;
  EXPECT_GT(result.candidates.front().max_velocity_error_mps, 0.4);  // it stops against the wall
}

TEST_F(DesignIndoorTest, ASidewaysLimitForADifferentialDriveIsBadInput) {
  Use(GentleDiffDrive(), "indoor_diffdrive_mocap_calibration.yaml");
  request_.targets = {{"odometer.baseline", 1e-4}};
  request_.limits.max_lateral_mps = 0.2;
  Outcome outcome = DesignToFile(request_);
  EXPECT_TRUE(outcome.bad_input);
  EXPECT_NE(outcome.status.message().find("--max-lateral-speed"), std::string::npos) << outcome.status.message();
  request_.limits.max_lateral_mps = DesignLimits::kRobotDefault;
  request_.limits.max_yaw_rate_radps = -1.0;
  outcome = DesignToFile(request_);
  EXPECT_TRUE(outcome.bad_input);
  EXPECT_NE(outcome.status.message().find("--max-yaw-rate"), std::string::npos) << outcome.status.message();
}

TEST(DriveEnvelopeTest, EachIndoorKindHasItsOwnAndOthersNone) {
  for (const char* kind : {"ackermann", "differential_drive", "omni3", "mecanum"}) {
    const auto e = sim::DesignEnvelope(kind);
    ASSERT_TRUE(e.ok()) << kind;
    EXPECT_LT(e.value().min_speed_mps, e.value().max_speed_mps) << kind;
    EXPECT_GT(e.value().max_turn, 0.0) << kind;
  }
  EXPECT_EQ(sim::DesignEnvelope("differential_drive").value().max_lateral_mps, 0.0);
  EXPECT_GT(sim::DesignEnvelope("omni3").value().max_lateral_mps, 0.0);
  const auto none = sim::DesignEnvelope("tricycle");
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("no drive family for a tricycle"), std::string::npos);
}

}  // namespace
}  // namespace roamlab::experiment
