// The indoor differential-drive scenario in MuJoCo (seed Section VI): the square-wave drive really makes the wheels
// slip, and the scan matcher's velocities follow the true motion of the laser.
#include <cmath>

#include <gtest/gtest.h>

#include "recording/wheel_kinematics.h"
#include "sim/simulator.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

Scenario IndoorDiffDrive(double duration_s) {
  auto scenario = LoadScenario(testing::SourcePath("scenarios/indoor_diffdrive_slip.yaml"));
  EXPECT_TRUE(scenario.ok()) << scenario.status().message();
  Scenario s = scenario.value();
  s.duration_s = duration_s;
  s.sensors.camera.reset();  // rendering: tests/sim/indoor_camera_test.cc
  return s;
}

// True body velocity of O over [a, b] of the ground truth: (v_x, v_y, omega_z) from the chord in the middle frame.
Eigen::Vector3d TrueTwist(const StampedPose& a, const StampedPose& b) {
  const double dt = SecondsBetween(a.t, b.t);
  const Eigen::AngleAxisd turn(a.q_world_body.conjugate() * b.q_world_body);
  const double yaw = turn.angle() * turn.axis().z();
  const Eigen::Quaterniond q_mid =
      a.q_world_body * Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * yaw, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d v = q_mid.conjugate() * (b.p_world_body - a.p_world_body) / dt;
  return Eigen::Vector3d(v.x(), v.y(), yaw / dt);
}

class IndoorSimulationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto result = Simulate(IndoorDiffDrive(8.0));
    ASSERT_TRUE(result.ok()) << result.status().message();
    simulation_ = new Simulation(std::move(result).value());
  }
  static void TearDownTestSuite() { delete simulation_; }
  static Simulation* simulation_;
};
Simulation* IndoorSimulationTest::simulation_ = nullptr;

TEST_F(IndoorSimulationTest, SquareWavesMakeTheWheelsSlip) {
  const recording::Recording& rec = simulation_->recording;
  const recording::Stream* encoders = rec.Find("wheel_encoders");
  ASSERT_NE(encoders, nullptr);
  auto kinematics = recording::NominalWheelKinematics(rec.platform);
  ASSERT_TRUE(kinematics.ok()) << kinematics.status().message();
  const Trajectory& truth = *rec.ground_truth;
  ASSERT_EQ(truth.size(), encoders->t.size());  // both at 100 Hz from t = 0

  // Encoder forward speed against the true speed of O, interval by interval.
  const double dt = SecondsBetween(encoders->t[0], encoders->t[1]);
  const double tick_rad = 2.0 * M_PI / encoders->info.attributes.at("ticks_per_revolution");
  // Quantization alone: each rate has the difference of two uniform errors of one tick over dt, so the speed error
  // (mean of two wheels times r) has std r tick / dt / sqrt(12); 10 of those is far beyond noise.
  const double quantization_sigma_mps = rec.platform.geometry.at("wheel_radius_m") * tick_rad / dt / std::sqrt(12.0);
  int beyond = 0, intervals = 0;
  double max_difference = 0.0;
  for (std::size_t k = 0; k + 1 < truth.size(); ++k) {
    const Eigen::VectorXd rates = (encoders->values.row(k + 1) - encoders->values.row(k)).transpose() / dt;
    const double encoder_speed = kinematics.value().TwistFromRates(rates)[0];
    const double difference = std::abs(encoder_speed - TrueTwist(truth[k], truth[k + 1]).x());
    max_difference = std::max(max_difference, difference);
    beyond += difference > 10.0 * quantization_sigma_mps ? 1 : 0;
    ++intervals;
  }
  EXPECT_GT(max_difference, 0.5) << "no reversal slipped";
  EXPECT_GT(static_cast<double>(beyond) / intervals, 0.1) << beyond << " of " << intervals;
  EXPECT_GT(simulation_->stats.max_wheel_slip_mps, 0.5);
}

TEST_F(IndoorSimulationTest, ScanMatchingFollowsTheLaserMotion) {
  const recording::Recording& rec = simulation_->recording;
  const recording::Stream* scans = rec.Find("scan_matching");
  ASSERT_NE(scans, nullptr);
  ASSERT_TRUE(scans->info.mounting.has_value());
  const Eigen::Vector3d lever = scans->info.mounting->p_body_sensor;
  EXPECT_NEAR(lever.x(), 0.15, 1e-6);
  const Trajectory& truth = *rec.ground_truth;
  EXPECT_GE(scans->t.size(), 75u);  // 80 scan pairs in 8 s, a few may fail
  double sum_v2 = 0.0, sum_w2 = 0.0;
  for (std::size_t k = 0; k < scans->t.size(); ++k) {
    // The sample is stamped mid-interval; the scans were 0.1 s apart at 100 Hz truth indices.
    const long mid = std::lround(scans->t[k].nanoseconds() * 1e-7);
    const Eigen::Vector3d twist =
        TrueTwist(truth[static_cast<std::size_t>(mid - 5)], truth[static_cast<std::size_t>(mid + 5)]);
    // Eq. 5 with S at (lever.x, 0): v_S = v_O + omega x S.
    const Eigen::Vector2d v_laser(twist.x(), twist.y() + twist.z() * lever.x());
    sum_v2 += (scans->values.row(k).head<2>().transpose() - v_laser).squaredNorm();
    sum_w2 += std::pow(scans->values(k, 5) - twist.z(), 2);
  }
  const double n = static_cast<double>(scans->t.size());
  EXPECT_LT(std::sqrt(sum_v2 / n), 0.05);
  EXPECT_LT(std::sqrt(sum_w2 / n), 0.05);
}

}  // namespace
}  // namespace roamlab::sim
