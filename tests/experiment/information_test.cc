// `roamlab information`'s step: a MuJoCo drive with a stop, analysed noise-free at its truth.
#include "experiment/information.h"

#include <cmath>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/recording/temp_dir.h"
#include "tests/support/paths.h"

namespace roamlab::experiment {
namespace {

// 12 s of the ATV on flat ground with the seed's sensors: 3.5 m/s, a stop from 4 to 9 s (the set-point ramps down
// over 3-4 s and up over 9-10 s), turning both ways.
std::string StopScenario() {
  return "name: stop\nduration_s: 12.0\nseed: 1\norigin: {latitude_deg: 45.4642, longitude_deg: 9.19, altitude_m: "
         "120.0}\nground_truth_rate_hz: 100\nrobot:\n  kind: ackermann\n  model: " +
         roamlab::testing::SourceDir() +
         "/models/atv.xml\n  start: {position_m: [0.0, 0.0], heading_deg: 0.0}\n"
         "  speed_controller: {kp_nm_per_mps: 300.0, ki_nm_per_m: 150.0, torque_limit_nm: 400.0}\n"
         "world:\n  terrain: {type: flat, friction: 0.8}\n"
         "driver:\n  type: ackermann\n  lead_in_s: 4.0\n  speed_mps:\n"
         "    - piecewise: {times_s: [0, 3, 4, 9, 10, 12], values: [3.5, 3.5, 0, 0, 3.5, 3.5]}\n"
         "  handlebar_rad:\n    - sine: {amplitude: 0.30, period_s: 6.0, phase_rad: 0.0}\n"
         "sensors:\n  imu: {}\n  magnetometer: {}\n  gps: {}\n  odometer: {}\n";
}

std::string Config() { return roamlab::testing::SourceDir() + "/configs/atv_calibration.yaml"; }

// The speed gain is read from the wheel speed: the odometer's factors in the windows where the vehicle stands (it
// creeps at under 0.05 m/s) measure (next to) none of it, those of the moving windows all of it. Their variance shares
// are not zero at the stop: the speed rows there hold the stopped poses together only as tightly as the configured
// speed noise, which is the same at standstill, and that noise lets the poses slide against the GPS fixes.
TEST(InformationStepTest, AStopMeasuresNoneOfTheSpeedGain) {
  testing::TempDir dir;
  std::ofstream(dir.File("stop.yaml")) << StopScenario();
  InformationRequest request;
  request.scenario = dir.File("stop.yaml");
  request.config = Config();
  request.out = dir.File("out");
  InformationRun run;
  const Outcome outcome = InformationToDirectory(request, &run);
  ASSERT_TRUE(outcome.ok()) << outcome.status.message();
  ASSERT_EQ(run.result.windows, 12);
  const estimator::InformationComponent* kv = nullptr;
  for (const auto& c : run.result.components)
    if (c.label == "odometer.kv_over_L") kv = &c;
  ASSERT_NE(kv, nullptr);
  const std::vector<double>& odometer = kv->measured_by_stream_window.at("odometer");
  // A row's sensitivity to the gain is proportional to the wheel speed it reads, so a window's measured share scales
  // with its speed: a stopped window may hold at most twice its speed's part of a moving window's mean share.
  double moving = 0.0, moving_speed = 0.0;
  int moving_windows = 0;
  for (int k = 0; k < run.result.windows; ++k) {
    if (run.windows[static_cast<std::size_t>(k)].speed_mps <= 3.0) continue;
    moving += odometer[k];
    moving_speed += run.windows[static_cast<std::size_t>(k)].speed_mps;
    ++moving_windows;
  }
  ASSERT_GE(moving_windows, 4);
  EXPECT_GT(moving, 0.5);
  int stopped_windows = 0;
  for (int k = 0; k < run.result.windows; ++k) {
    const WindowDrive& w = run.windows[static_cast<std::size_t>(k)];
    if (w.speed_mps >= 0.05) continue;
    ++stopped_windows;
    const double bound = 2.0 * (w.speed_mps / (moving_speed / moving_windows)) * (moving / moving_windows);
    EXPECT_LT(std::abs(odometer[k]), bound) << "window " << k << ", " << w.speed_mps << " m/s";
    EXPECT_LT(bound, 0.01);
  }
  EXPECT_GE(stopped_windows, 2);
  EXPECT_NEAR(kv->measured_by.at("odometer"), 1.0, 1e-9);

  const nlohmann::json json = nlohmann::json::parse(std::ifstream(dir.File("out/information.json")));
  EXPECT_EQ(json["windows"].size(), 12u);
  EXPECT_EQ(json["parameters"]["gps.lever_arm"]["components"].size(), 3u);
  EXPECT_NEAR(json["parameters"]["odometer.kv_over_L"]["components"][0]["measured_by"]["odometer"].get<double>(), 1.0,
              1e-9);
}

TEST(InformationStepTest, BadInputsAreReportedAsSuch) {
  testing::TempDir dir;
  InformationRequest request;
  request.scenario = dir.File("missing.yaml");
  request.config = Config();
  request.out = dir.File("out");
  Outcome outcome = InformationToDirectory(request);
  EXPECT_FALSE(outcome.ok());
  EXPECT_TRUE(outcome.bad_input);
  std::ofstream(dir.File("stop.yaml")) << StopScenario();
  request.scenario = dir.File("stop.yaml");
  request.window_s = -1.0;
  outcome = InformationToDirectory(request);
  EXPECT_TRUE(outcome.bad_input);
  EXPECT_NE(outcome.status.message().find("--window"), std::string::npos);
}

}  // namespace
}  // namespace roamlab::experiment
