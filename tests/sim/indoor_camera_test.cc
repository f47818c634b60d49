// The camera of the indoor scenario (sensors.camera): the simulator renders the robot's camera, runs the visual
// odometry at 15 Hz on the robot's real (slipping, vibrating) motion and writes the visual_odometry stream; its
// per-pair accuracy is held to the VO's accuracy targets against the ground truth (eval/visual_odometry.h).
#include <gtest/gtest.h>

#include "eval/visual_odometry.h"
#include "sim/simulator.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

TEST(IndoorCameraTest, VisualOdometryOnTheSquareWaveDriveMeetsTheAccuracyTargets) {
  auto scenario = LoadScenario(testing::SourcePath("scenarios/indoor_diffdrive_slip.yaml"));
  ASSERT_TRUE(scenario.ok()) << scenario.status().message();
  Scenario s = scenario.value();
  s.duration_s = 5.0;  // two reversals of each square wave
  ASSERT_TRUE(s.sensors.camera.has_value());
  s.sensors.laser.reset();
  auto result = Simulate(s);
  if (!result.ok() && result.status().message().find("EGL:") != std::string::npos)
    GTEST_SKIP() << "no headless OpenGL: " << result.status().message();
  ASSERT_TRUE(result.ok()) << result.status().message();
  const Simulation& sim = result.value();

  const recording::Stream* vo = sim.recording.Find("visual_odometry");
  ASSERT_NE(vo, nullptr);
  EXPECT_EQ(vo->info.type, recording::StreamType::kVisualOdometry);
  EXPECT_EQ(vo->values.cols(), 27);
  ASSERT_TRUE(vo->info.mounting.has_value());
  // models/diffdrive.xml: the camera 0.25 m ahead of the base's origin, looking forward (C's z along O's x).
  const Eigen::Vector3d forward = vo->info.mounting->q_body_sensor * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(forward.x(), 1.0, 1e-6);
  EXPECT_EQ(sim.truth.calibration.count("visual_odometry.lever_arm"), 1u);
  ASSERT_TRUE(sim.stats.visual_odometry.has_value());
  EXPECT_EQ(sim.stats.visual_odometry->frames, 76);  // 0 to 5 s at 15 Hz
  EXPECT_EQ(sim.stats.visual_odometry->estimates, static_cast<int>(vo->t.size()));

  const auto errors = eval::CompareVisualOdometry(*vo, *sim.recording.ground_truth);
  ASSERT_TRUE(errors.has_value());
  EXPECT_EQ(errors->pairs, 75);
  EXPECT_LE(errors->failure_rate, 0.05);
  EXPECT_LE(errors->rotation_deg.median, 0.2);
  EXPECT_NEAR(errors->speed_ratio.median, 1.0, 0.05);
}

}  // namespace
}  // namespace roamlab::sim
