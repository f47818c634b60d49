// The wheeled robots' physical effects (sim/scenario.h): each changes the physics as it says, against the
// same drive without it (noise off), keeps the recording's platform geometry nominal and is stated in truth.yaml only;
// the robot-independent IMU effects apply to wheeled robots too; bad parameters are one-line validation errors.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "sim/mujoco_model.h"
#include "sim/simulator.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDurationS = 4.0;
// The yaw rate and wheel rates are averaged from here on (the set-points' ramp and the servos have settled).
constexpr double kSettledS = 1.0;

// The differential drive of indoor_diffdrive_slip.yaml on the bare floor (no room, laser or camera: fast), at constant
// set-points.
Scenario DiffDrive(double linear_mps, double angular_radps, const std::vector<EffectOptions>& effects) {
  auto loaded = LoadScenario(testing::SourcePath("scenarios/indoor_diffdrive_slip.yaml"));
  EXPECT_TRUE(loaded.ok()) << loaded.status().message();
  Scenario s = loaded.value();
  s.duration_s = kDurationS;
  s.world_model_file.clear();
  s.sensors.laser.reset();
  s.sensors.camera.reset();
  s.driver.linear_mps = Profile::Constant(linear_mps);
  s.driver.angular_radps = Profile::Constant(angular_radps);
  s.effects = effects;
  return s;
}

Simulation Simulated(const Scenario& scenario, const SimulateOptions& base = {}) {
  SimulateOptions options = base;
  options.noise = false;
  auto sim = Simulate(scenario, options);
  EXPECT_TRUE(sim.ok()) << sim.status().message();
  return std::move(sim).value();
}

// Mean yaw rate of O [rad/s] and mean encoder rates [rad/s] (left, right) from kSettledS to the end.
struct Rates {
  double yaw_radps = 0.0;
  double left_radps = 0.0;
  double right_radps = 0.0;
};
Rates MeanRates(const Simulation& sim) {
  const Trajectory& truth = *sim.recording.ground_truth;
  const recording::Stream& enc = *sim.recording.Find("wheel_encoders");
  const auto index = [](const std::vector<Time>& t, double s) {
    std::size_t k = 0;
    while (k + 1 < t.size() && t[k].seconds() < s) ++k;
    return k;
  };
  std::vector<Time> truth_t;
  for (const StampedPose& p : truth) truth_t.push_back(p.t);
  const std::size_t a = index(truth_t, kSettledS), b = truth.size() - 1;
  const double dt = SecondsBetween(truth[a].t, truth[b].t);
  // Unwrapped yaw: sum of the relative turns sample to sample.
  double yaw = 0.0;
  for (std::size_t k = a; k < b; ++k) {
    const Eigen::AngleAxisd turn(truth[k].q_world_body.conjugate() * truth[k + 1].q_world_body);
    yaw += turn.angle() * turn.axis().z();
  }
  const std::size_t ea = index(enc.t, kSettledS), eb = enc.t.size() - 1;
  const double edt = SecondsBetween(enc.t[ea], enc.t[eb]);
  return {yaw / dt, (enc.values(static_cast<Eigen::Index>(eb), 0) - enc.values(static_cast<Eigen::Index>(ea), 0)) / edt,
          (enc.values(static_cast<Eigen::Index>(eb), 1) - enc.values(static_cast<Eigen::Index>(ea), 1)) / edt};
}

void ExpectNominalPlatform(const Simulation& sim, const Simulation& nominal) {
  EXPECT_EQ(sim.recording.platform.geometry, nominal.recording.platform.geometry);
}

class WheelEffectsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    straight_ = new Simulation(Simulated(DiffDrive(0.3, 0.0, {})));
    turning_ = new Simulation(Simulated(DiffDrive(0.2, 0.8, {})));
  }
  static void TearDownTestSuite() {
    delete straight_;
    delete turning_;
  }
  static Simulation* straight_;
  static Simulation* turning_;
};
Simulation* WheelEffectsTest::straight_ = nullptr;
Simulation* WheelEffectsTest::turning_ = nullptr;

// At equal wheel rates omega the right wheel rolls rho r omega, the left r omega: yaw rate r omega (rho - 1) / B. The
// nominal drive at the same set-points goes straight.
TEST_F(WheelEffectsTest, RadiusAsymmetryCurvesAStraightDriveAsTheRatioPredicts) {
  const double rho = 1.02;
  const Simulation sim = Simulated(DiffDrive(0.3, 0.0, {{"wheel_radius_asymmetry", {{"ratio_right_left", rho}}}}));
  const auto& g = straight_->recording.platform.geometry;
  const double r = g.at("wheel_radius_m"), B = g.at("baseline_m");
  const Rates nominal = MeanRates(*straight_), with = MeanRates(sim);
  EXPECT_LT(std::abs(nominal.yaw_radps), 1e-3);
  EXPECT_NEAR(with.left_radps, with.right_radps, 1e-3 * with.left_radps);  // the driver does not know
  const double predicted = r * (rho * with.right_radps - with.left_radps) / B;
  EXPECT_GT(predicted, 0.01);
  EXPECT_NEAR(with.yaw_radps, predicted, 0.05 * predicted) << "predicted " << predicted;

  ExpectNominalPlatform(sim, *straight_);
  const auto& cal = sim.truth.calibration;
  EXPECT_NEAR(cal.at("odometer.radius_right")[0] / cal.at("odometer.radius_left")[0], rho, 1e-9);
  EXPECT_NEAR(cal.at("odometer.radius_left")[0], r, 1e-6);
  ASSERT_EQ(sim.truth.effects.size(), 1u);
  EXPECT_EQ(sim.truth.effects[0].name, "wheel_radius_asymmetry");
  EXPECT_EQ(sim.truth.effects[0].parameters.at("ratio_right_left"), rho);
}

// Every tire's radius times s: the yaw rate per unit of wheel-rate difference, r s / B, is s times the nominal one;
// the platform geometry stays nominal and the true radii are s r.
TEST_F(WheelEffectsTest, RadiusScaleScalesTheYawRatePerWheelRateDifference) {
  const double scale = 1.05;
  const Simulation sim = Simulated(DiffDrive(0.2, 0.8, {{"wheel_radius_scale", {{"scale", scale}}}}));
  const double r = turning_->recording.platform.geometry.at("wheel_radius_m");
  const Rates nominal = MeanRates(*turning_), with = MeanRates(sim);
  const double k_nominal = nominal.yaw_radps / (nominal.right_radps - nominal.left_radps);
  const double k_with = with.yaw_radps / (with.right_radps - with.left_radps);
  EXPECT_NEAR(k_with / k_nominal, scale, 0.01) << "k " << k_nominal << " -> " << k_with;
  ExpectNominalPlatform(sim, *turning_);
  const auto& cal = sim.truth.calibration;
  EXPECT_NEAR(cal.at("odometer.radius_left")[0], scale * r, 1e-6);
  EXPECT_NEAR(cal.at("odometer.radius_right")[0], scale * r, 1e-6);
  const auto problem = DiffDrive(0.2, 0.0, {{"wheel_radius_scale", {{"scale", 0.7}}}}).Validate();
  ASSERT_TRUE(problem);
  EXPECT_EQ(problem->key + ": " + problem->message, "effects[0].parameters.scale: must be in [0.8, 1.2]");
}

// Roller wheels (the OptiOdom omni3 model) of a radius 5 % large: at the same wheel rates (the driver does not know)
// the robot drives 5 % further; the true radii follow: the envelope exactly, the travel per radian within the change
// of the axle's dip between rollers ((scale - 1) rho (1 - sin(x) / x), rho the roller's radius, a micrometre here)
// and the measurement's scatter (a few micrometres).
TEST(WheelRadiusScaleTest, ScaledRollerWheelsCarryTheOmniFurther) {
  auto loaded = LoadScenario(testing::SourcePath("scenarios/real/optiodom_omni3.yaml"));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  Scenario s = loaded.value();
  s.duration_s = 4.0;
  s.driver.linear_mps = Profile::Constant(0.15);
  s.driver.lateral_mps = Profile::Constant(0.0);
  s.driver.angular_radps = Profile::Constant(0.0);
  const double scale = 1.05;
  const Simulation nominal = Simulated(s);
  s.effects = {{"wheel_radius_scale", {{"scale", scale}}}};
  const Simulation scaled = Simulated(s);
  const auto travel = [](const Simulation& sim) {
    const Trajectory& truth = *sim.recording.ground_truth;
    std::size_t a = 0;
    while (a + 1 < truth.size() && truth[a].t.seconds() < kSettledS) ++a;
    return (truth.back().p_world_body - truth[a].p_world_body).head<2>().norm();
  };
  EXPECT_GT(travel(nominal), 0.3);
  EXPECT_NEAR(travel(scaled) / travel(nominal), scale, 0.01) << travel(nominal) << " -> " << travel(scaled);
  EXPECT_NEAR(scaled.truth.calibration.at("odometer.radius_envelope_0")[0],
              scale * nominal.truth.calibration.at("odometer.radius_envelope_0")[0], 1e-9);
  EXPECT_NEAR(scaled.truth.calibration.at("odometer.radius_0")[0],
              scale * nominal.truth.calibration.at("odometer.radius_0")[0], 2e-5);
}

// The yaw rate per unit of wheel-rate difference is r / B: B_nom / B_true of the nominal one.
TEST_F(WheelEffectsTest, TrackWidthErrorScalesTheYawRatePerWheelRateDifference) {
  const double error_m = 0.04;
  const Simulation sim = Simulated(DiffDrive(0.2, 0.8, {{"track_width_error", {{"track_error_m", error_m}}}}));
  const double B = turning_->recording.platform.geometry.at("baseline_m");
  const Rates nominal = MeanRates(*turning_), with = MeanRates(sim);
  const double k_nominal = nominal.yaw_radps / (nominal.right_radps - nominal.left_radps);
  const double k_with = with.yaw_radps / (with.right_radps - with.left_radps);
  EXPECT_GT(nominal.yaw_radps, 0.5);
  EXPECT_NEAR(k_with / k_nominal, B / (B + error_m), 0.01) << "k " << k_nominal << " -> " << k_with;

  ExpectNominalPlatform(sim, *turning_);
  EXPECT_NEAR(sim.truth.calibration.at("odometer.baseline")[0], B + error_m, 1e-6);
  EXPECT_NEAR(turning_->truth.calibration.at("odometer.baseline")[0], B, 1e-6);
}

// The axle of the chosen wheel, seen from O, is turned by yaw_deg about z; the other stays along y.
TEST_F(WheelEffectsTest, AxleMisalignmentTurnsTheWheelAxle) {
  const double yaw_deg = 3.0;
  Eigen::Vector3d axle_odom[2];
  bool seen = false;
  SimulateOptions options;
  options.observer = [&](Time, const mjModel* m, const mjData* d) {
    if (seen) return;
    seen = true;
    const int odom = IdOf(m, mjOBJ_SITE, "odom");
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R_world_odom(d->site_xmat + 9 * odom);
    for (int i = 0; i < 2; ++i) {
      const int joint = IdOf(m, mjOBJ_JOINT, "wheel_" + std::to_string(i));
      axle_odom[i] = R_world_odom.transpose() * Eigen::Vector3d(d->xaxis + 3 * joint);
    }
  };
  const Simulation sim =
      Simulated(DiffDrive(0.3, 0.0, {{"axle_misalignment", {{"wheel", 1}, {"yaw_deg", yaw_deg}}}}), options);
  ASSERT_TRUE(seen);
  EXPECT_NEAR(std::atan2(-axle_odom[1].x(), axle_odom[1].y()) * 180.0 / kPi, yaw_deg, 0.05);
  EXPECT_NEAR(std::atan2(-axle_odom[0].x(), axle_odom[0].y()) * 180.0 / kPi, 0.0, 0.05);
  // The drive no longer goes straight: the scrubbing wheel turns the robot.
  EXPECT_GT(std::abs(MeanRates(sim).yaw_radps), 10.0 * std::abs(MeanRates(*straight_).yaw_radps) + 1e-3);
  ExpectNominalPlatform(sim, *straight_);
}

// An out-of-round tire lifts its axle over a range of its ovality twice per revolution; the effect keeps its mean
// rolling radius (the oval's perimeter / 2 pi) at the nominal radius.
TEST_F(WheelEffectsTest, WheelDeformationMakesTheAxleHeightPeriodic) {
  const double ovality_m = 0.01;
  // The range of wheel_0's centre height after the ramp.
  const auto height_range = [](double* lo, double* hi) {
    SimulateOptions options;
    options.observer = [lo, hi](Time t, const mjModel* m, const mjData* d) {
      if (t.seconds() < kSettledS) return;
      const double z = d->xpos[3 * m->jnt_bodyid[IdOf(m, mjOBJ_JOINT, "wheel_0")] + 2];
      *lo = std::min(*lo, z);
      *hi = std::max(*hi, z);
    };
    return options;
  };
  double lo = 1e9, hi = -1e9, lo0 = 1e9, hi0 = -1e9;
  const Simulation sim = Simulated(
      DiffDrive(0.3, 0.0, {{"wheel_deformation", {{"wheel", 0}, {"ovality_m", ovality_m}}}}), height_range(&lo, &hi));
  Simulated(DiffDrive(0.3, 0.0, {}), height_range(&lo0, &hi0));
  EXPECT_NEAR(hi - lo, ovality_m, 0.2 * ovality_m);
  EXPECT_LT(hi0 - lo0, 0.1 * ovality_m);
  const double r = straight_->recording.platform.geometry.at("wheel_radius_m");
  EXPECT_NEAR(sim.truth.calibration.at("odometer.radius_left")[0], r, 1e-9);
  EXPECT_NEAR(sim.truth.calibration.at("odometer.radius_right")[0], r, 1e-6);
  ExpectNominalPlatform(sim, *straight_);
}

// The IMU synthesis is shared: a gyroscope scale error scales a wheeled robot's gyroscope too.
TEST_F(WheelEffectsTest, GyroScaleErrorAppliesToWheeledRobots) {
  const Simulation sim = Simulated(DiffDrive(0.2, 0.8, {{"gyro_scale_error", {{"scale_z", 1.03}}}}));
  const recording::Stream& a = *turning_->recording.Find("imu");
  const recording::Stream& b = *sim.recording.Find("imu");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  EXPECT_GT(a.values.col(2).cwiseAbs().maxCoeff(), 0.5);
  for (Eigen::Index k = 0; k < a.values.rows(); ++k) EXPECT_NEAR(b.values(k, 2), 1.03 * a.values(k, 2), 1e-12);
}

// The turning drive with motion capture at 100 Hz, so that a shift of whole samples compares row to row.
Scenario WithMocap(const std::vector<EffectOptions>& effects) {
  Scenario s = DiffDrive(0.2, 0.8, effects);
  MocapOptions mocap;
  mocap.rate_hz = 100.0;
  s.sensors.mocap = mocap;
  return s;
}

// pose_time_offset's sign: positive stamps the motion capture late (the pose stamped t is O's pose at t - offset_s),
// negative early; the wheel encoders keep their clock.
TEST(PoseTimeOffsetTest, ThePoseStampedTIsThePoseAtTMinusTheOffset) {
  const Simulation nominal = Simulated(WithMocap({}));
  const Simulation late = Simulated(WithMocap({{"pose_time_offset", {{"offset_s", 0.02}}}}));
  const Simulation early = Simulated(WithMocap({{"pose_time_offset", {{"offset_s", -0.03}}}}));
  const recording::Stream& a = *nominal.recording.Find("mocap");
  const recording::Stream& b = *late.recording.Find("mocap");
  const recording::Stream& c = *early.recording.Find("mocap");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  ASSERT_EQ(a.values.rows(), c.values.rows());  // samples taken after the end: the physics runs on
  EXPECT_EQ(a.t, b.t);                          // the stamps do not say it
  for (Eigen::Index k = 2; k + 3 < a.values.rows(); ++k) {
    EXPECT_NEAR((b.values.row(k) - a.values.row(k - 2)).norm(), 0.0, 1e-9) << k;
    EXPECT_NEAR((c.values.row(k) - a.values.row(k + 3)).norm(), 0.0, 1e-9) << k;
  }
  // Moving at 0.2 m/s, 20 ms is 4 mm: the rows differ from the nominal ones at the same stamp.
  const Eigen::Index mid = a.values.rows() / 2;
  EXPECT_GT((b.values.row(mid).head<2>() - a.values.row(mid).head<2>()).norm(), 0.003);
  const recording::Stream& encoders = *late.recording.Find("wheel_encoders");
  EXPECT_LT((encoders.values - nominal.recording.Find("wheel_encoders")->values).cwiseAbs().maxCoeff(), 1e-9);
  ASSERT_EQ(late.truth.effects.size(), 1u);
  EXPECT_EQ(late.truth.effects[0].parameters.at("offset_s"), 0.02);
}

std::string ProblemOf(Scenario s) {
  const auto p = s.Validate();
  return p ? p->key + ": " + p->message : "";
}

TEST(WheelEffectsValidation, OneLineErrors) {
  const Scenario drive = DiffDrive(0.3, 0.0, {});
  Scenario s = drive;
  s.effects = {{"axle_misalignment", {{"wheel", 2}, {"yaw_deg", 1}}}};
  EXPECT_EQ(ProblemOf(s), "effects[0].parameters.wheel: no such wheel: the differential_drive robot has wheels 0 to 1");
  s.effects = {{"wheel_deformation", {{"wheel", 0.5}}}};
  EXPECT_EQ(ProblemOf(s), "effects[0].parameters.wheel: no such wheel: the differential_drive robot has wheels 0 to 1");
  s.effects = {{"wheel_radius_asymmetry", {{"ratio_right_left", 1.5}}}};
  EXPECT_EQ(ProblemOf(s), "effects[0].parameters.ratio_right_left: must be in [0.8, 1.2]");
  s.effects = {{"track_width_error", {{"track_error_m", -0.2}}}};
  EXPECT_EQ(ProblemOf(s), "effects[0].parameters.track_error_m: must be in [-0.1, 0.1] m");
  s.effects = {{"wheel_deformation", {{"ovality_m", 0.05}}}};
  EXPECT_EQ(ProblemOf(s), "effects[0].parameters.ovality_m: must be in [0, 0.02] m");
  s.effects = {{"axle_misalignment", {{"yaw_deg", 30}}}};
  EXPECT_EQ(ProblemOf(s), "effects[0].parameters.yaw_deg: must be within +-20");
  s.effects = {{"axle_misalignment", {{"roll_deg", 1}}}};
  EXPECT_EQ(ProblemOf(s), "effects[0].parameters.roll_deg: unknown parameter of axle_misalignment");
  s.effects = {{"magnetometer_motor_interference", {}}};
  EXPECT_NE(ProblemOf(s).find("needs sensors.magnetometer"), std::string::npos);
  s.effects = {{"gyro_bias_drift", {{"initial_z", 0.01}}}, {"imu_time_offset", {{"offset_s", 0.01}}}};
  EXPECT_EQ(ProblemOf(s), "");
  s.effects = {{"pose_time_offset", {{"offset_s", -0.03}}}};
  EXPECT_EQ(ProblemOf(s), "effects[0].name: pose_time_offset needs sensors.mocap");
  EXPECT_EQ(ProblemOf(WithMocap({{"pose_time_offset", {{"offset_s", -0.03}}}})), "");
  EXPECT_EQ(ProblemOf(WithMocap({{"pose_time_offset", {{"offset_s", 0.6}}}})),
            "effects[0].parameters.offset_s: must be in [-0.5, 0.5]");
  s.effects = {{"drive_time_offset", {{"offset_s", 0.01}, {"drift_ppm", -1200}}}};
  EXPECT_EQ(ProblemOf(s), "");
  s.effects = {{"drive_time_offset", {{"drift_ppm", 20000}}}};
  EXPECT_EQ(ProblemOf(s), "effects[0].parameters.drift_ppm: must be in [-10000, 10000]");

  Scenario omni = s;
  omni.robot.kind = "omni3";
  omni.effects = {{"track_width_error", {{"track_error_m", 0.01}}}};
  EXPECT_EQ(ProblemOf(omni), "effects[0].name: track_width_error is for differential_drive and mecanum robots only");
  omni.effects = {{"wheel_radius_asymmetry", {}}};
  EXPECT_EQ(ProblemOf(omni), "effects[0].name: wheel_radius_asymmetry is for differential_drive robots only");
  omni.effects = {{"skid_steer_track", {{"track_ratio", 0.9}}}};
  EXPECT_EQ(ProblemOf(omni), "effects[0].name: skid_steer_track is for skid_steer robots only");
  Scenario skid = omni;
  skid.robot.kind = "skid_steer";
  skid.effects = {{"skid_steer_track", {{"track_ratio", 0.5}}}};
  EXPECT_EQ(ProblemOf(skid), "effects[0].parameters.track_ratio: must be in [0.7, 1.5]");

  Scenario atv = testing::AtvHills(2.0);
  atv.effects = {{"wheel_deformation", {{"ovality_m", 0.001}}}};
  EXPECT_EQ(ProblemOf(atv), "effects[0].name: wheel_deformation is for wheeled indoor robots, not 'ackermann'");
}

}  // namespace
}  // namespace roamlab::sim
