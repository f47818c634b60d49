// The holonomic indoor robots in MuJoCo: the three-wheel omni robot of scenarios/indoor_omni_slip.yaml (seed Section
// VI, Triskar2) slips at the square waves' reversals and its rollers shake the body; the mecanum robot of
// models/mecanum.xml moves sideways and turns in place as commanded; the wheel rows measured on both models are the
// nominal kinematics of recording/wheel_kinematics.h (which catches a mecanum roller layout that cannot turn).
#include <cmath>

#include <gtest/gtest.h>

#include "recording/wheel_kinematics.h"
#include "sim/mujoco_model.h"
#include "sim/simulator.h"
#include "sim/wheeled_robot.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

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

Result<WheeledRobot> BindModel(const std::string& file, const std::string& kind) {
  auto model = LoadModelFromString(testing::ReadText(testing::SourcePath(file)), file);
  if (!model.ok()) return model.status();
  return WheeledRobot::Bind(model.value().get(), kind, file);
}

TEST(HolonomicRobotTest, MeasuredWheelRowsAreTheNominalKinematics) {
  for (const auto& [file, kind, geometry] :
       std::vector<std::tuple<std::string, std::string, std::map<std::string, double>>>{
           {"models/omni3.xml", "omni3", {{"wheel_radius_m", 0.05}, {"wheel_distance_m", 0.2}}},
           {"models/mecanum.xml",
            "mecanum",
            {{"wheel_radius_m", 0.05}, {"half_length_m", 0.2}, {"half_width_m", 0.18}}}}) {
    auto robot = BindModel(file, kind);
    ASSERT_TRUE(robot.ok()) << robot.status().message();
    recording::Platform platform;
    platform.kind = kind;
    platform.geometry = geometry;
    auto nominal = recording::NominalWheelKinematics(platform);
    ASSERT_TRUE(nominal.ok()) << nominal.status().message();
    EXPECT_LT((robot.value().J_rates_twist() - nominal.value().J_rates_twist).cwiseAbs().maxCoeff(), 1e-4)
        << kind << "\nmeasured\n"
        << robot.value().J_rates_twist() << "\nnominal\n"
        << nominal.value().J_rates_twist;
    for (const auto& [key, value] : robot.value().PlatformGeometry()) EXPECT_NEAR(value, geometry.at(key), 1e-5) << key;
    // Full rank with a yaw column: the robot can turn in place.
    const Eigen::MatrixXd& J = robot.value().J_rates_twist();
    EXPECT_EQ(Eigen::FullPivLU<Eigen::MatrixXd>(J).rank(), 3) << kind;
  }
}

TEST(HolonomicRobotTest, ChangedMountingTurnsTheWheelAndBindRefusesAWrongLayout) {
  const std::string file = "models/mecanum.xml";
  auto model = LoadModelFromString(testing::ReadText(testing::SourcePath(file)), file);
  ASSERT_TRUE(model.ok()) << model.status().message();
  // Axle 3 deg out of alignment: wheel 1's rolling direction turns by 3 deg.
  ASSERT_TRUE(WheeledRobot::ChangeMounting(model.value().get(), {{1, 3.0 * M_PI / 180.0, 0.0}}, file).ok());
  auto robot = WheeledRobot::Bind(model.value().get(), "mecanum", file);
  ASSERT_TRUE(robot.ok()) << robot.status().message();
  const Eigen::Vector2d d = robot.value().wheels()[1].drive_direction;
  EXPECT_NEAR(std::atan2(d.y(), d.x()) * 180.0 / M_PI, 3.0, 1e-6);
  EXPECT_NEAR(robot.value().wheels()[0].drive_direction.y(), 0.0, 1e-9);
  EXPECT_FALSE(WheeledRobot::ChangeMounting(model.value().get(), {{7, 0.0, 0.0}}, file).ok());

  // Wheel 0's rollers tilted the other way (axle component +1/sqrt(2) instead of -1/sqrt(2)): the bottom roller's
  // axis lies along the diagonal through the wheel, the layout in which the wheels cannot turn the body.
  std::string xml = testing::ReadText(testing::SourcePath(file));
  const std::size_t begin = xml.find("<body name=\"wheel_body_0\"");
  const std::size_t end = xml.find("<body name=\"wheel_body_1\"");
  ASSERT_TRUE(begin != std::string::npos && end != std::string::npos);
  int flipped = 0;
  for (std::size_t at = xml.find(" -0.707107 ", begin); at < end; at = xml.find(" -0.707107 ", at)) {
    xml.replace(at, 11, " 0.707107 ");
    ++flipped;
  }
  EXPECT_EQ(flipped, 12);
  auto wrong_model = LoadModelFromString(xml, "flipped rollers");
  ASSERT_TRUE(wrong_model.ok()) << wrong_model.status().message();
  auto wrong = WheeledRobot::Bind(wrong_model.value().get(), "mecanum", file);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.status().message().find("wheel_0"), std::string::npos) << wrong.status().message();
}

TEST(HolonomicRobotTest, MovedWheelMovesInThePhysicsOnlyAndTheTrueLeverArmFollows) {
  const std::string file = "models/mecanum.xml";
  auto model = LoadModelFromString(testing::ReadText(testing::SourcePath(file)), file);
  ASSERT_TRUE(model.ok()) << model.status().message();
  mjModel* m = model.value().get();
  auto bound = WheeledRobot::Bind(m, "mecanum", file);
  ASSERT_TRUE(bound.ok()) << bound.status().message();
  WheeledRobot robot = bound.value();
  const Eigen::MatrixXd nominal_rows = robot.J_rates_twist();
  // The front right wheel 3 cm back and 1 cm out, placed in the world turned by 30 deg: its tire centre in O moves
  // by the offset, the other wheels stay.
  const Eigen::Vector2d offset_m(-0.03, -0.01);
  ASSERT_TRUE(robot.MoveWheels(m, {{1, offset_m}}, file).ok());
  DataPtr data = MakeData(m);
  robot.Place(m, data.get(), 1.0, 2.0, 30.0 * M_PI / 180.0, 0.01);
  const int odom = robot.odom_site();
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R_world_odom(data->site_xmat + 9 * odom);
  for (int i = 0; i < 4; ++i) {
    const int tire = IdOf(m, mjOBJ_GEOM, "tire_" + std::to_string(i));
    const Eigen::Vector3d p_odom_m = R_world_odom.transpose() * (Eigen::Vector3d(data->geom_xpos + 3 * tire) -
                                                                 Eigen::Vector3d(data->site_xpos + 3 * odom));
    const Eigen::Vector2d expected = robot.wheels()[i].p_body_m + (i == 1 ? offset_m : Eigen::Vector2d::Zero());
    EXPECT_LT((p_odom_m.head<2>() - expected).norm(), 1e-9) << "wheel " << i << ": " << p_odom_m.transpose();
  }
  // The driver and the platform geometry keep the nominal robot; the true lx + ly is the mean yaw lever arm: the
  // front right wheel's |x| + |y| drops from 0.38 to 0.36 m.
  EXPECT_EQ(robot.J_rates_twist(), nominal_rows);
  EXPECT_NEAR(robot.PlatformGeometry().at("half_length_m"), 0.2, 1e-5);
  EXPECT_NEAR(robot.TrueOdometerCalibration().at("odometer.lx_plus_ly")[0], 0.38 - 0.02 / 4.0, 1e-5);
  const Status missing = robot.MoveWheels(m, {{4, offset_m}}, "F");
  EXPECT_EQ(missing.message(), "F: robot.wheel_offset: wheel 4: the mecanum robot has 4 wheels");
}

// 8 s of scenarios/indoor_omni_slip.yaml.
class OmniSimulationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto scenario = LoadScenario(testing::SourcePath("scenarios/indoor_omni_slip.yaml"));
    ASSERT_TRUE(scenario.ok()) << scenario.status().message();
    Scenario s = scenario.value();
    s.duration_s = 8.0;
    auto result = Simulate(s);
    ASSERT_TRUE(result.ok()) << result.status().message();
    simulation_ = new Simulation(std::move(result).value());
  }
  static void TearDownTestSuite() { delete simulation_; }
  static Simulation* simulation_;
};
Simulation* OmniSimulationTest::simulation_ = nullptr;

TEST_F(OmniSimulationTest, SquareWavesMakeTheWheelsSlip) {
  const recording::Recording& rec = simulation_->recording;
  const recording::Stream* encoders = rec.Find("wheel_encoders");
  ASSERT_NE(encoders, nullptr);
  ASSERT_EQ(encoders->values.cols(), 3);
  auto kinematics = recording::NominalWheelKinematics(rec.platform);
  ASSERT_TRUE(kinematics.ok()) << kinematics.status().message();
  const Trajectory& truth = *rec.ground_truth;
  ASSERT_EQ(truth.size(), encoders->t.size());

  // Encoder planar velocity against the true one, interval by interval. Quantization alone: each rate has the
  // difference of two uniform one-tick errors over dt (std tick / dt / sqrt(6)); through the 3 x 3 inverse rows
  // (gain at most r * 0.82 per wheel on v_x, v_y) the speed error stays below r tick / dt; 10 of those is far beyond.
  const double dt = SecondsBetween(encoders->t[0], encoders->t[1]);
  const double tick_rad = 2.0 * M_PI / encoders->info.attributes.at("ticks_per_revolution");
  const double quantization_mps = rec.platform.geometry.at("wheel_radius_m") * tick_rad / dt;
  int beyond = 0, intervals = 0;
  double max_difference = 0.0;
  for (std::size_t k = 0; k + 1 < truth.size(); ++k) {
    const Eigen::VectorXd rates = (encoders->values.row(k + 1) - encoders->values.row(k)).transpose() / dt;
    const Eigen::Vector3d twist = kinematics.value().TwistFromRates(rates);
    const double difference = (twist.head<2>() - TrueTwist(truth[k], truth[k + 1]).head<2>()).norm();
    max_difference = std::max(max_difference, difference);
    beyond += difference > 10.0 * quantization_mps ? 1 : 0;
    ++intervals;
  }
  EXPECT_GT(max_difference, 0.5) << "no reversal slipped";
  EXPECT_GT(static_cast<double>(beyond) / intervals, 0.1) << beyond << " of " << intervals;
  EXPECT_GT(simulation_->stats.max_wheel_slip_mps, 0.5);
  // The robot does move sideways (holonomic), as commanded.
  EXPECT_GT(simulation_->stats.max_lateral_speed_mps, 0.3);
}

TEST_F(OmniSimulationTest, RollersShakeTheBody) {
  // Vertical specific force: its spread about g is far beyond the accelerometer's white noise (0.05 m/s^2).
  const recording::Stream* imu = simulation_->recording.Find("imu");
  ASSERT_NE(imu, nullptr);
  const Eigen::VectorXd az = imu->values.col(5);
  const double mean = az.mean();
  const double spread = std::sqrt((az.array() - mean).square().mean());
  EXPECT_NEAR(mean, 9.80665, 0.1);
  EXPECT_GT(spread, 10.0 * 0.05);
}

TEST(MecanumSimulationTest, MovesSidewaysAndTurnsInPlaceAsCommanded) {
  Scenario s;
  s.name = "mecanum_moves";
  s.duration_s = 6.0;
  s.robot.kind = "mecanum";
  s.robot.model_file = testing::SourcePath("models/mecanum.xml");
  s.terrain.type = TerrainOptions::Type::kFlat;
  s.terrain.friction = 0.6;
  s.driver.type = "body_velocity";
  s.driver.lead_in_s = 1.0;
  s.driver.linear_mps = Profile::Constant(0.0);
  ProfileTerm sideways, turn;
  sideways.value = 0.3;
  sideways.windowed = true;
  sideways.window_begin_s = 0.0;
  sideways.window_end_s = 3.0;
  turn.value = 1.0;
  turn.windowed = true;
  turn.window_begin_s = 3.0;
  turn.window_end_s = 6.0;
  s.driver.lateral_mps.terms = {sideways};
  s.driver.angular_radps.terms = {turn};
  auto result = Simulate(s);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const Trajectory& truth = *result.value().recording.ground_truth;
  // Mean velocities over [0.5, 2.5] s (sideways) and [3.5, 5.5] s (turning), away from the switch.
  const auto mean_twist = [&truth](double a, double b) {
    const auto index = [&truth](double t) { return static_cast<std::size_t>(std::lround(t * 100.0)); };
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t k = index(a); k < index(b); ++k) sum += TrueTwist(truth[k], truth[k + 1]);
    return Eigen::Vector3d(sum / static_cast<double>(index(b) - index(a)));
  };
  // Within slip: a few per cent of the set-point, and the other components near zero.
  const Eigen::Vector3d sideways_twist = mean_twist(0.5, 2.5);
  EXPECT_NEAR(sideways_twist.y(), 0.3, 0.03);
  EXPECT_NEAR(sideways_twist.x(), 0.0, 0.02);
  EXPECT_NEAR(sideways_twist.z(), 0.0, 0.05);
  const Eigen::Vector3d turning = mean_twist(3.5, 5.5);
  EXPECT_NEAR(turning.z(), 1.0, 0.1);
  EXPECT_LT(turning.head<2>().norm(), 0.03);
}

}  // namespace
}  // namespace roamlab::sim
