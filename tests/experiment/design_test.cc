// `roamlab design`'s step on a tiny case: 10 s of the ATV on flat ground, a budget of 16 drives (the start, the grid
// of 12 headings and handlebar offsets, three of the pattern search).
#include "experiment/design.h"

#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "sim/simulator.h"
#include "tests/experiment/design_testing.h"
#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab::experiment {
namespace {

// The start drive barely steers (0.05 rad), so the handlebar's gain k_theta is poorly measured.
std::string GentleScenario() {
  return "name: gentle\nduration_s: 10.0\nseed: 1\norigin: {latitude_deg: 45.4642, longitude_deg: 9.19, altitude_m: "
         "120.0}\nground_truth_rate_hz: 100\nrobot:\n  kind: ackermann\n  model: " +
         roamlab::testing::SourceDir() +
         "/models/atv.xml\n  start: {position_m: [0.0, 0.0], heading_deg: 0.0}\n"
         "world:\n  terrain: {type: flat, friction: 0.8}\n"
         "driver:\n  type: ackermann\n  lead_in_s: 2.0\n  speed_mps: 3.0\n"
         "  handlebar_rad:\n    - sine: {amplitude: 0.05, period_s: 8.0, phase_rad: 0.0}\n"
         "sensors:\n  imu: {}\n  magnetometer: {}\n  gps: {}\n  odometer: {}\n";
}

class DesignStepTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::ofstream(dir_.File("gentle.yaml")) << GentleScenario();
    request_.scenario = dir_.File("gentle.yaml");
    request_.config = testing::ConfigWithoutTargets("atv_calibration.yaml", dir_);
    request_.out = dir_.File("designed.yaml");
    request_.targets = {{"odometer.k_theta", 0.002}};
    request_.budget = 16;
  }
  testing::TempDir dir_;
  DesignRequest request_;
};

TEST_F(DesignStepTest, ImprovesOnItsStartAndWritesAScenarioThatSimulates) {
  DesignResult result;
  const Outcome outcome = DesignToFile(request_, &result);
  ASSERT_TRUE(outcome.ok()) << outcome.status.message();
  ASSERT_EQ(result.candidates.size(), 16u);
  const DesignCandidate& start = result.candidates.front();
  ASSERT_EQ(start.stage, "start");
  ASSERT_TRUE(start.infeasible.empty()) << start.infeasible;
  EXPECT_NEAR(start.drive.at("handlebar_amplitude_rad"), 0.05, 1e-12);
  ASSERT_GT(result.best, 0);
  const DesignCandidate& best = result.candidates[static_cast<std::size_t>(result.best)];
  // A wider swing of the handlebar measures k_theta better: the objective is its CRB std over the target.
  EXPECT_LT(best.objective, 0.8 * start.objective);
  EXPECT_EQ(best.worst, "odometer.k_theta");
  for (const DesignCandidate& c : result.candidates) {
    if (c.infeasible.empty()) {
      EXPECT_GE(c.objective, best.objective);
    }
  }

  // The written scenario holds the best drive and simulates as it is, with noise, within the limits.
  auto loaded = sim::LoadScenario(request_.out);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  const auto written = StartDrive(loaded.value(), request_.limits);
  ASSERT_TRUE(written.ok()) << written.status().message();
  ASSERT_EQ(written.value().values.size(), 6u);
  for (const auto& [name, value] : best.drive.values) EXPECT_NEAR(written.value().at(name), value, 1e-9) << name;
  EXPECT_DOUBLE_EQ(loaded.value().duration_s, 10.0);
  auto simulated = sim::Simulate(loaded.value());
  ASSERT_TRUE(simulated.ok()) << simulated.status().message();
  EXPECT_LE(simulated.value().stats.max_lateral_speed_mps, result.limits.max_side_slip_mps);
  EXPECT_DOUBLE_EQ(result.limits.max_side_slip_mps, 0.3);  // the ATV's default

  const nlohmann::json json = nlohmann::json::parse(std::ifstream(dir_.File("design.json")));
  EXPECT_EQ(json["candidates"].size(), 16u);
  EXPECT_EQ(json["best"], result.best);
  EXPECT_NEAR(json["candidates"][result.best]["crb_std"]["odometer.k_theta"].get<double>(), best.objective * 0.002,
              1e-12);
}

// The configuration's target_std entries are the targets of the parameters not given in the request: on this short,
// flat drive the GPS antenna's height is unobservable, and its target, from the configuration, fails the design.
TEST_F(DesignStepTest, TheConfigurationsTargetsJoinTheGivenOnes) {
  request_.config = roamlab::testing::SourceDir() + "/configs/atv_calibration.yaml";
  request_.budget = 1;
  DesignResult result;
  const Outcome outcome = DesignToFile(request_, &result);
  const std::map<std::string, double> expected = {
      {"gps.lever_arm", 0.033},     {"imu.misalignment", 0.0116},    {"magnetometer.A", 0.0067},
      {"magnetometer.b", 0.0033},   {"odometer.kv_over_L", 0.00133}, {"odometer.k_theta", 0.002},  // given
      {"odometer.k_gamma", 0.00167}};
  EXPECT_EQ(result.targets, expected);
  ASSERT_FALSE(outcome.ok());
  EXPECT_FALSE(outcome.bad_input);
  EXPECT_NE(outcome.status.message().find("gps.lever_arm[z] is unobservable"), std::string::npos)
      << outcome.status.message();
}

TEST_F(DesignStepTest, NoFeasibleDriveIsAFailure) {
  request_.limits.max_lateral_accel_mps2 = 1e-3;  // every turning drive exceeds it
  request_.budget = 2;
  DesignResult result;
  const Outcome outcome = DesignToFile(request_, &result);
  ASSERT_FALSE(outcome.ok());
  EXPECT_FALSE(outcome.bad_input);
  EXPECT_NE(outcome.status.message().find("no feasible drive"), std::string::npos) << outcome.status.message();
  EXPECT_NE(result.candidates.front().infeasible.find("lateral acceleration"), std::string::npos);
}

TEST_F(DesignStepTest, BadTargetsAreBadInputNamingThem) {
  const std::vector<std::pair<std::string, std::map<std::string, double>>> cases = {
      {"not a free parameter", {{"odometer.nonsense", 0.01}}},
      {"not a free parameter", {{"odometer.cornering_rear", 0.01}}},  // fixed in the configuration
      {"must be > 0", {{"odometer.k_theta", 0.0}}},
      {"no target", {}}};
  for (const auto& [problem, targets] : cases) {
    request_.targets = targets;
    const Outcome outcome = DesignToFile(request_);
    ASSERT_FALSE(outcome.ok());
    EXPECT_TRUE(outcome.bad_input);
    EXPECT_NE(outcome.status.message().find(problem), std::string::npos) << outcome.status.message();
    if (!targets.empty()) {
      EXPECT_NE(outcome.status.message().find(targets.begin()->first), std::string::npos);
    }
  }
  request_.targets = {{"odometer.k_theta", 0.002}};
  request_.limits.min_speed_mps = 7.0;
  const Outcome outcome = DesignToFile(request_);
  EXPECT_TRUE(outcome.bad_input);
  EXPECT_NE(outcome.status.message().find("--speed-range"), std::string::npos) << outcome.status.message();
}

}  // namespace
}  // namespace roamlab::experiment
