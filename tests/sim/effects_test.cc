// Physical effects of a scenario (sim/scenario.h): each changes exactly what it says, against the same drive
// without it (noise off, so that the difference is the effect alone), and is stated in truth.yaml only.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <GeographicLib/LocalCartesian.hpp>

#include "recording/recording.h"
#include "sim/simulator.h"
#include "tests/sim/sim_testing.h"

namespace roamlab::sim {
namespace {

constexpr double kDurationS = 2.0;
constexpr double kPi = 3.14159265358979323846;

// The shortened ATV drive, sensors at 100 Hz (GPS too, so that a shift of whole samples can be compared row to row).
Scenario Drive(const std::vector<EffectOptions>& effects) {
  Scenario s = testing::AtvHills(kDurationS);
  s.sensors.gps->rate_hz = 100.0;
  s.effects = effects;
  return s;
}

Simulation Simulated(const Scenario& scenario) {
  SimulateOptions options;
  options.noise = false;
  auto sim = Simulate(scenario, options);
  EXPECT_TRUE(sim.ok()) << sim.status().message();
  return std::move(sim).value();
}

const recording::Stream& StreamOf(const Simulation& sim, const std::string& name) {
  const recording::Stream* s = sim.recording.Find(name);
  EXPECT_NE(s, nullptr) << name;
  return *s;
}

class EffectsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { nominal_ = new Simulation(Simulated(Drive({}))); }
  static void TearDownTestSuite() {
    delete nominal_;
    nominal_ = nullptr;
  }
  static Simulation* nominal_;
};
Simulation* EffectsTest::nominal_ = nullptr;

TEST_F(EffectsTest, GyroScaleMultipliesEachAxisAndNothingElse) {
  const Simulation sim = Simulated(Drive({{"gyro_scale_error", {{"scale_x", 0.98}, {"scale_z", 1.03}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "imu");
  const recording::Stream& b = StreamOf(sim, "imu");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  EXPECT_GT(a.values.col(2).cwiseAbs().maxCoeff(), 0.05);  // the drive turns
  for (Eigen::Index k = 0; k < a.values.rows(); ++k) {
    EXPECT_NEAR(b.values(k, 0), 0.98 * a.values(k, 0), 1e-12);
    EXPECT_NEAR(b.values(k, 1), a.values(k, 1), 1e-12);  // default scale 1
    EXPECT_NEAR(b.values(k, 2), 1.03 * a.values(k, 2), 1e-12);
    EXPECT_NEAR(b.values(k, 3), a.values(k, 3), 1e-12);  // accelerometer untouched
  }
  ASSERT_EQ(sim.truth.effects.size(), 1u);
  EXPECT_EQ(sim.truth.effects[0].name, "gyro_scale_error");
  EXPECT_EQ(sim.truth.effects[0].parameters.at("scale_y"), 1.0);  // defaults are written out
  EXPECT_EQ(sim.truth.effects[0].parameters.at("scale_z"), 1.03);
  EXPECT_TRUE(nominal_->truth.effects.empty());
}

// The bias starts at `initial` and its increments sample by sample are N(0, random_walk^2 dt) per axis; nothing but
// the gyroscope changes. The variance test uses the chi-square spread of a sample variance: relative std sqrt(2 / n).
TEST_F(EffectsTest, GyroBiasDriftStartsAtItsInitialValueAndWalks) {
  const double walk = 0.01;  // rad/s/sqrt(s)
  const Simulation sim =
      Simulated(Drive({{"gyro_bias_drift", {{"initial_x", 0.02}, {"initial_z", -0.01}, {"random_walk", walk}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "imu");
  const recording::Stream& b = StreamOf(sim, "imu");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  const Eigen::MatrixXd bias = b.values.leftCols(3) - a.values.leftCols(3);
  EXPECT_NEAR(bias(0, 0), 0.02, 1e-12);
  EXPECT_NEAR(bias(0, 1), 0.0, 1e-12);
  EXPECT_NEAR(bias(0, 2), -0.01, 1e-12);
  EXPECT_LT((b.values.rightCols(3) - a.values.rightCols(3)).cwiseAbs().maxCoeff(), 1e-12);  // accelerometer
  const Eigen::MatrixXd steps = bias.bottomRows(bias.rows() - 1) - bias.topRows(bias.rows() - 1);
  const double n = static_cast<double>(steps.size());
  const double dt_s = 0.01;  // the IMU's 100 Hz
  const double ratio = steps.squaredNorm() / n / (walk * walk * dt_s);
  EXPECT_NEAR(ratio, 1.0, 4.0 * std::sqrt(2.0 / n));
  EXPECT_EQ(sim.truth.effects.at(0).parameters.at("initial_y"), 0.0);
}

TEST_F(EffectsTest, SteeringOffsetShiftsTheHandlebarReadingByOffsetOverKTheta) {
  const Simulation sim = Simulated(Drive({{"steering_offset", {{"offset_rad", 0.03}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "steering");
  const recording::Stream& b = StreamOf(sim, "steering");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  // z_theta = (delta - k_gamma - offset) / k_theta with k_theta = 1 in atv_hills.yaml.
  for (Eigen::Index k = 0; k < a.values.rows(); ++k) EXPECT_NEAR(b.values(k, 0), a.values(k, 0) - 0.03, 1e-12);
}

TEST_F(EffectsTest, GpsLatencyReportsTheAntennaPositionTauEarlier) {
  const Simulation sim = Simulated(Drive({{"gps_latency", {{"latency_s", 0.05}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "gps");
  const recording::Stream& b = StreamOf(sim, "gps");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  EXPECT_EQ(a.t, b.t);  // the stamps do not say it
  // At 100 Hz, 0.05 s is 5 rows: the fix stamped t_k is the nominal fix of t_k - 0.05.
  for (Eigen::Index k = 5; k < a.values.rows(); ++k)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(b.values(k, c), a.values(k - 5, c), 1e-9) << k;
  // Moving at about 4 m/s, that is about 0.2 m: the first rows differ from the nominal ones.
  EXPECT_GT(std::abs(b.values(10, 1) - a.values(10, 1)) * 111e3 * std::cos(45.46 * M_PI / 180.0), 0.1);
}

TEST_F(EffectsTest, ImuTimeOffsetStampsReadingsAheadAndTheMagnetometerFollows) {
  const Simulation late = Simulated(Drive({{"imu_time_offset", {{"offset_s", 0.02}}}}));
  const Simulation early = Simulated(Drive({{"imu_time_offset", {{"offset_s", -0.03}}}}));
  for (const std::string name : {"imu", "magnetometer"}) {
    const recording::Stream& a = StreamOf(*nominal_, name);
    const recording::Stream& b = StreamOf(late, name);
    const recording::Stream& c = StreamOf(early, name);
    ASSERT_EQ(a.values.rows(), b.values.rows());
    ASSERT_EQ(a.values.rows(), c.values.rows());  // samples taken after the end: the physics runs on
    for (Eigen::Index k = 0; k + 3 < a.values.rows(); ++k) {
      if (k >= 2) {
        EXPECT_NEAR((b.values.row(k) - a.values.row(k - 2)).norm(), 0.0, 1e-9) << name << " " << k;
      }
      EXPECT_NEAR((c.values.row(k) - a.values.row(k + 3)).norm(), 0.0, 1e-9) << name << " " << k;
    }
  }
  // The other streams keep their clock. (Samples taken during the lead-in add state evaluations, mj_forward, that
  // can change the physics at round-off level.)
  EXPECT_LT((StreamOf(late, "rear_wheel").values - StreamOf(*nominal_, "rear_wheel").values).cwiseAbs().maxCoeff(),
            1e-9);
}

TEST_F(EffectsTest, MagnetometerInterferenceIsABiasAlongItsDirectionThatFollowsTheTorque) {
  const Eigen::Vector3d per_nm(2e-4, -1e-4, 3e-4);
  const Simulation sim =
      Simulated(Drive({{"magnetometer_motor_interference",
                        {{"b_per_nm_x", per_nm.x()}, {"b_per_nm_y", per_nm.y()}, {"b_per_nm_z", per_nm.z()}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "magnetometer");
  const recording::Stream& b = StreamOf(sim, "magnetometer");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  double min_torque = 1e9, max_torque = -1e9;
  for (Eigen::Index k = 0; k < a.values.rows(); ++k) {
    const Eigen::Vector3d d = (b.values.row(k) - a.values.row(k)).transpose();
    const double torque_nm = d.dot(per_nm) / per_nm.squaredNorm();
    EXPECT_NEAR((d - torque_nm * per_nm).norm(), 0.0, 1e-12) << k;  // along b_per_nm
    EXPECT_LE(std::abs(torque_nm), 400.0 + 1e-9);                   // within the torque limit
    min_torque = std::min(min_torque, torque_nm);
    max_torque = std::max(max_torque, torque_nm);
  }
  EXPECT_GT(max_torque - min_torque, 5.0);  // the speed controller works
}

// Mean yaw rate [rad/s] and mean crab angle (course minus heading, [rad]) of O over [t0, end] of the ground truth.
struct Crab {
  double yaw_rate_radps = 0.0;
  double crab_rad = 0.0;
  double speed_mps = 0.0;
};
Crab CrabOf(const Trajectory& truth, double t0_s) {
  Crab out;
  int n = 0;
  const auto yaw = [](const StampedPose& p) -> Eigen::Vector2d {
    return (p.q_world_body * Eigen::Vector3d::UnitX()).head<2>();
  };
  for (std::size_t k = 0; k + 1 < truth.size(); ++k) {
    if (truth[k].t.seconds() < t0_s) continue;
    const double dt = truth[k + 1].t.seconds() - truth[k].t.seconds();
    const Eigen::Vector2d h0 = yaw(truth[k]), h1 = yaw(truth[k + 1]);
    const Eigen::Vector2d v = (truth[k + 1].p_world_body - truth[k].p_world_body).head<2>() / dt;
    const Eigen::Vector2d h = (h0 + h1).normalized();
    out.yaw_rate_radps += std::atan2(h0.x() * h1.y() - h0.y() * h1.x(), h0.dot(h1)) / dt;
    out.crab_rad += std::atan2(h.x() * v.y() - h.y() * v.x(), h.dot(v));
    out.speed_mps += v.norm();
    ++n;
  }
  out.yaw_rate_radps /= n;
  out.crab_rad /= n;
  out.speed_mps /= n;
  return out;
}

TEST(AxleMisalignmentTest, AtvRearAxleThrustAngleCrabsAndTurnsAtZeroHandlebar) {
  // Straight ahead at 4 m/s with the handlebar at zero on flat ground: a rear axle turned by alpha = 2 deg rolls
  // along alpha, so the vehicle crabs (course = heading + alpha) and turns at -v tan(alpha) / L
  // (estimator/models/ackermann_velocity.h); without it, it goes straight.
  const auto drive = [](const std::vector<EffectOptions>& effects) {
    Scenario s = testing::AtvHills(6.0);
    s.terrain.type = TerrainOptions::Type::kFlat;
    s.driver.speed_mps = Profile::Constant(4.0);
    s.driver.handlebar_rad = Profile::Constant(0.0);
    s.effects = effects;
    return CrabOf(*Simulated(s).recording.ground_truth, 2.0);
  };
  const double alpha = 2.0 * kPi / 180.0, wheelbase_m = 1.25;
  const Crab straight = drive({});
  const Crab crab = drive({{"axle_misalignment", {{"yaw_deg", 2.0}}}});
  std::cout << "nominal yaw rate " << straight.yaw_rate_radps << " crab " << straight.crab_rad << "; thrust: yaw rate "
            << crab.yaw_rate_radps << " (kinematic " << -crab.speed_mps * std::tan(alpha) / wheelbase_m << ") crab "
            << crab.crab_rad << " (" << alpha << ")\n";
  EXPECT_LT(std::abs(straight.yaw_rate_radps), 0.002);
  EXPECT_LT(std::abs(straight.crab_rad), 0.002);
  // Within 10 % of the kinematic values: the tires' cornering compliance (about 0.015 s, slip under the 0.45 m/s^2 of
  // the turn) is what the rigid kinematics leave out.
  EXPECT_NEAR(crab.yaw_rate_radps, -crab.speed_mps * std::tan(alpha) / wheelbase_m,
              0.1 * crab.speed_mps * std::tan(alpha) / wheelbase_m);
  EXPECT_NEAR(crab.crab_rad, alpha, 0.1 * alpha);
}

TEST(LateralSlipTest, SofterTiresRaiseTheCorneringCompliance) {
  // A steady turn on flat ground (4 m/s, handlebar 0.15 rad): the rear axle drifts outwards, v_y = -c_rear a_y with
  // a_y = v omega_z (estimator/models/ackermann_velocity.h). Softer tires (contact time constant times k) let the
  // sideways force through at a proportionally larger slip velocity (MuJoCo's soft contact), so c_rear grows about
  // as k.
  // The physics is deterministic (noise plays no part); the bounds check the proportionality, not a tolerance.
  const auto compliance = [](double scale) {
    Scenario s = testing::AtvHills(6.0);
    s.terrain.type = TerrainOptions::Type::kFlat;
    s.driver.speed_mps = Profile::Constant(4.0);
    s.driver.handlebar_rad = Profile::Constant(0.15);
    if (scale != 1.0) s.effects = {{"lateral_slip", {{"contact_time_scale", scale}}}};
    const Crab turn = CrabOf(*Simulated(s).recording.ground_truth, 3.0);
    const double a_y = turn.speed_mps * turn.yaw_rate_radps;
    EXPECT_GT(a_y, 1.0);  // a real turn
    return -turn.speed_mps * std::sin(turn.crab_rad) / a_y;
  };
  const double nominal = compliance(1.0), soft = compliance(3.0);
  std::cout << "c_rear: nominal " << nominal << " s, contact time x3 " << soft << " s\n";
  EXPECT_GT(nominal, 0.0);  // outwards
  EXPECT_GT(soft / nominal, 2.5);
  EXPECT_LT(soft / nominal, 3.5);
}

TEST_F(EffectsTest, AccelerometerScaleMultipliesEachAxisAndNothingElse) {
  const Simulation sim = Simulated(Drive({{"accelerometer_scale_error", {{"scale_y", 0.97}, {"scale_z", 1.04}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "imu");
  const recording::Stream& b = StreamOf(sim, "imu");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  for (Eigen::Index k = 0; k < a.values.rows(); ++k) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(b.values(k, c), a.values(k, c), 1e-12);  // gyroscope untouched
    EXPECT_NEAR(b.values(k, 3), a.values(k, 3), 1e-12);                              // default scale 1
    EXPECT_NEAR(b.values(k, 4), 0.97 * a.values(k, 4), 1e-12);
    EXPECT_NEAR(b.values(k, 5), 1.04 * a.values(k, 5), 1e-12);
  }
  EXPECT_EQ(sim.truth.effects.at(0).parameters.at("scale_x"), 1.0);
}

// The fix error e_k = fix - nominal fix (ENU) obeys e_k+1 = a e_k + sigma sqrt(1 - a^2) n: the innovations have
// variance sigma^2 (1 - a^2) per axis (chi-square spread sqrt(2 / n) of a sample variance), and the other streams are
// untouched.
TEST_F(EffectsTest, GpsMultipathIsAGaussMarkovErrorOfTheFix) {
  const double sigma_m = 1.5, correlation_s = 0.2;
  const Simulation sim =
      Simulated(Drive({{"gps_multipath", {{"sigma_m", sigma_m}, {"correlation_s", correlation_s}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "gps");
  const recording::Stream& b = StreamOf(sim, "gps");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  const recording::GeodeticOrigin& o = testing::AtvHills(1.0).origin;
  const GeographicLib::LocalCartesian local(o.latitude_deg, o.longitude_deg, o.altitude_m);
  std::vector<Eigen::Vector3d> error;
  for (Eigen::Index k = 0; k < a.values.rows(); ++k) {
    Eigen::Vector3d pa, pb;
    local.Forward(a.values(k, 0), a.values(k, 1), a.values(k, 2), pa.x(), pa.y(), pa.z());
    local.Forward(b.values(k, 0), b.values(k, 1), b.values(k, 2), pb.x(), pb.y(), pb.z());
    error.push_back(pb - pa);
  }
  const double a_k = std::exp(-0.01 / correlation_s);  // the 100 Hz GPS of Drive
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k + 1 < error.size(); ++k, n += 3) sum += (error[k + 1] - a_k * error[k]).squaredNorm();
  const double ratio = sum / n / (sigma_m * sigma_m * (1.0 - a_k * a_k));
  EXPECT_NEAR(ratio, 1.0, 4.0 * std::sqrt(2.0 / n));
  EXPECT_GT(error.front().norm(), 1e-3);  // starts in the stationary distribution, not at zero
  EXPECT_LT((StreamOf(sim, "imu").values - StreamOf(*nominal_, "imu").values).cwiseAbs().maxCoeff(), 1e-12);
}

// At ground speed v = z_v_nominal kv_over_L L the reading is z_v_nominal / (1 + c v^2).
TEST_F(EffectsTest, TireGrowthMakesTheSpeedSensorUnderReadWithTheSquareOfTheSpeed) {
  const double c = 0.004;
  const Simulation sim = Simulated(Drive({{"tire_growth", {{"growth_per_mps2", c}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "rear_wheel");
  const recording::Stream& b = StreamOf(sim, "rear_wheel");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  auto geometry = NominalPlatformGeometry(Drive({}));
  ASSERT_TRUE(geometry.ok()) << geometry.status().message();
  const double kv = Drive({}).sensors.odometer->kv_over_L * geometry.value().at("wheelbase_m");
  double min_ratio = 1.0;
  for (Eigen::Index k = 0; k < a.values.rows(); ++k) {
    const double v_mps = a.values(k, 0) * kv;
    EXPECT_NEAR(b.values(k, 0), a.values(k, 0) / (1.0 + c * v_mps * v_mps), 1e-9) << k;
    min_ratio = std::min(min_ratio, b.values(k, 0) / a.values(k, 0));
  }
  EXPECT_LT(min_ratio, 0.95);  // about 4 m/s: a 6 % under-reading
  EXPECT_LT((StreamOf(sim, "steering").values - StreamOf(*nominal_, "steering").values).cwiseAbs().maxCoeff(), 1e-12);
}

// The rear-wheel reading over-reads the nominal one by 1 + s f_x, f_x O's forward specific force: with noise off
// and the IMU at O (atv_hills: lever arm 0), exactly the IMU's reading turned into O (the estimator's proxy,
// models/ackermann_velocity.h), sampled at the same instant.
TEST_F(EffectsTest, LongitudinalSlipOverReadsTheRearWheelWithTheForwardSpecificForce) {
  const double s = 0.05;  // [s^2/m]
  const Simulation sim = Simulated(Drive({{"longitudinal_slip", {{"slip_per_mps2", s}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "rear_wheel");
  const recording::Stream& b = StreamOf(sim, "rear_wheel");
  const recording::Stream& imu = StreamOf(sim, "imu");
  ASSERT_EQ(a.values.rows(), b.values.rows());
  ASSERT_EQ(imu.values.rows(), a.values.rows());
  const Eigen::Vector3d forward_in_imu = Drive({}).sensors.imu->misalignment.conjugate() * Eigen::Vector3d::UnitX();
  double max_abs_f_x = 0.0;
  for (Eigen::Index k = 0; k < a.values.rows(); ++k) {
    ASSERT_EQ(imu.t[static_cast<std::size_t>(k)], a.t[static_cast<std::size_t>(k)]);
    const double f_x = forward_in_imu.dot(imu.values.row(k).segment<3>(3).transpose());
    EXPECT_NEAR(b.values(k, 0), a.values(k, 0) * (1.0 + s * f_x), 1e-9) << k;
    max_abs_f_x = std::max(max_abs_f_x, std::abs(f_x));
  }
  EXPECT_GT(max_abs_f_x, 0.5);  // the hills and the speed changes pull
  EXPECT_LT((StreamOf(sim, "steering").values - StreamOf(*nominal_, "steering").values).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((imu.values - StreamOf(*nominal_, "imu").values).cwiseAbs().maxCoeff(), 1e-12);
  ASSERT_EQ(sim.truth.effects.size(), 1u);
  EXPECT_EQ(sim.truth.effects[0].parameters.at("slip_per_mps2"), s);
}

// The slope's part only: the reading over-reads by 1 + s g sin(pitch), pitch that of the true pose (O's x above the
// horizontal) at the reading's instant.
TEST_F(EffectsTest, SlopeSlipOverReadsTheRearWheelWithTheSlope) {
  const double s = 0.05;  // [s^2/m]
  const Simulation sim = Simulated(Drive({{"slope_slip", {{"slip_per_mps2", s}}}}));
  const recording::Stream& a = StreamOf(*nominal_, "rear_wheel");
  const recording::Stream& b = StreamOf(sim, "rear_wheel");
  ASSERT_TRUE(sim.recording.ground_truth.has_value());
  const Trajectory& poses = *sim.recording.ground_truth;
  ASSERT_EQ(a.values.rows(), b.values.rows());
  ASSERT_EQ(poses.size(), static_cast<std::size_t>(a.values.rows()));
  double max_abs_sin = 0.0;
  for (Eigen::Index k = 0; k < a.values.rows(); ++k) {
    const auto& pose = poses[static_cast<std::size_t>(k)];
    ASSERT_EQ(pose.t, a.t[static_cast<std::size_t>(k)]);
    const double sin_pitch = (pose.q_world_body * Eigen::Vector3d::UnitX()).z();
    EXPECT_NEAR(b.values(k, 0), a.values(k, 0) * (1.0 + s * 9.80665 * sin_pitch), 1e-9) << k;
    max_abs_sin = std::max(max_abs_sin, std::abs(sin_pitch));
  }
  EXPECT_GT(max_abs_sin, 0.03);  // the hills
}

TEST(EffectsValidationTest, UnknownNamesParametersAndRangesAreErrors) {
  const auto problem = [](const std::vector<EffectOptions>& effects) {
    Scenario s = testing::AtvHills(1.0);
    s.effects = effects;
    const auto p = s.Validate();
    return p ? p->key + ": " + p->message : std::string();
  };
  EXPECT_EQ(problem({{"gps_latency", {{"latency_s", 0.1}}}}), "");
  EXPECT_NE(problem({{"flux_capacitor", {}}}).find("effects[0].name: unknown effect 'flux_capacitor'"),
            std::string::npos);
  EXPECT_NE(problem({{"gps_latency", {{"latency", 0.1}}}}).find("effects[0].parameters.latency: unknown parameter"),
            std::string::npos);
  EXPECT_NE(problem({{"gps_latency", {{"latency_s", -0.1}}}}).find("must be in [0, 1]"), std::string::npos);
  EXPECT_NE(problem({{"imu_time_offset", {{"offset_s", 0.7}}}}).find("must be in [-0.5, 0.5]"), std::string::npos);
  EXPECT_NE(problem({{"steering_offset", {}}, {"steering_offset", {}}}).find("appears twice"), std::string::npos);
  EXPECT_NE(problem({{"gyro_bias_drift", {{"random_walk", -0.01}}}}).find("random_walk: must be >= 0"),
            std::string::npos);
  EXPECT_NE(problem({{"gyro_bias_drift", {{"initial_y", 0.6}}}}).find("initial_y: must be in [-0.5, 0.5]"),
            std::string::npos);
  EXPECT_EQ(problem({{"axle_misalignment", {{"yaw_deg", 1.5}}}}), "");
  EXPECT_EQ(problem({{"axle_misalignment", {{"yaw_deg", 6.0}}}}),
            "effects[0].parameters.yaw_deg: must be within +-5 on the ackermann rear axle");
  EXPECT_EQ(problem({{"axle_misalignment", {{"wheel", 1}, {"yaw_deg", 1.0}}}}),
            "effects[0].parameters.wheel: ackermann: axle_misalignment turns the rear axle (both rear wheels); no "
            "wheel index");
  EXPECT_NE(problem({{"accelerometer_scale_error", {{"scale_x", 1.6}}}}).find("scale_x: must be in [0.5, 1.5]"),
            std::string::npos);
  EXPECT_NE(problem({{"gps_multipath", {{"sigma_m", -1.0}}}}).find("sigma_m: must be in [0, 10] m"), std::string::npos);
  EXPECT_NE(problem({{"gps_multipath", {{"correlation_s", 0.0}}}}).find("correlation_s: must be in [0.1, 600] s"),
            std::string::npos);
  EXPECT_NE(problem({{"tire_growth", {{"growth_per_mps2", 0.02}}}}).find("growth_per_mps2: must be in [0, 0.01]"),
            std::string::npos);
  EXPECT_EQ(problem({{"longitudinal_slip", {{"slip_per_mps2", -0.01}}}}),
            "effects[0].parameters.slip_per_mps2: must be in [0, 0.2] s^2/m");
  EXPECT_EQ(problem({{"slope_slip", {{"slip_per_mps2", 0.3}}}}),
            "effects[0].parameters.slip_per_mps2: must be in [0, 0.2] s^2/m");
  EXPECT_EQ(problem({{"slope_slip", {{"slip_per_mps2", 0.05}}}}), "");
  EXPECT_EQ(problem({{"lateral_slip", {{"contact_time_scale", 0.5}}}}),
            "effects[0].parameters.contact_time_scale: must be in [1, 4]");
  EXPECT_EQ(problem({{"lateral_slip", {{"contact_time_scale", 2.0}}}}), "");
  Scenario no_gps = testing::AtvHills(1.0);
  no_gps.sensors.gps.reset();
  no_gps.effects = {{"gps_multipath", {{"sigma_m", 1.0}}}};
  ASSERT_TRUE(no_gps.Validate().has_value());
  EXPECT_EQ(no_gps.Validate()->message, "gps_multipath needs sensors.gps");
  // Not a whole number of 1 ms physics steps: refused when the simulator is created.
  Scenario s = testing::AtvHills(1.0);
  s.effects = {{"gps_latency", {{"latency_s", 0.0105}}}};
  auto sim = Simulator::Create(s);
  ASSERT_FALSE(sim.ok());
  EXPECT_NE(sim.status().message().find("gps_latency.latency_s"), std::string::npos) << sim.status().message();
}

}  // namespace
}  // namespace roamlab::sim
