#include "tests/support/synthetic.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/models/enu.h"
#include "recording/recording.h"
#include "recording/truth.h"
#include "tests/recording/temp_dir.h"

namespace roamlab::testing {
namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;
constexpr double kImuDt = 0.01;  // [s], default IMU and ground-truth period

const recording::Stream& Get(const recording::Recording& recording, const std::string& name) {
  const recording::Stream* stream = recording.Find(name);
  ROAMLAB_CHECK(stream != nullptr, "no stream " << name);
  return *stream;
}

SyntheticOptions NoiseFree() {
  SyntheticOptions options;
  options.noise = false;
  return options;
}

// A calibration away from the defaults, so that a gain or offset applied the wrong way round shows.
SyntheticOptions SkewedCalibration() {
  SyntheticOptions options = NoiseFree();
  options.gps_lever_arm_m = Eigen::Vector3d(-0.3, 0.8, 1.1);
  options.q_body_imu = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()));
  options.mag_A << 1.1, 0.05, -0.03, 0.02, 0.93, 0.04, -0.06, 0.01, 1.2;
  options.mag_b = Eigen::Vector3d(0.1, -0.2, 0.05);
  options.kv_over_L = 0.75;
  options.k_theta = 0.9;
  options.k_gamma = 0.02;
  return options;
}

Eigen::Vector3d Row3(const recording::Stream& stream, std::size_t k, int first_column) {
  return stream.values.row(static_cast<Eigen::Index>(k)).segment<3>(first_column).transpose();
}

estimator::Pose<double> PoseOf(const StampedPose& pose) { return {pose.p_world_body, pose.q_world_body}; }

// Pitch and roll [rad] of a body orientation (yaw-pitch-roll, ZYX).
double Pitch(const Eigen::Quaterniond& q) { return -std::asin(std::clamp(q.toRotationMatrix()(2, 0), -1.0, 1.0)); }
double Roll(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  return std::atan2(R(2, 1), R(2, 2));
}

TEST(SyntheticOptionsTest, DefaultsAreValidAndProblemsAreNamed) {
  EXPECT_EQ(SyntheticOptions().Validate(), "");
  SyntheticOptions options;
  options.duration_s = -1.0;
  options.k_theta = 0.0;
  const std::string problems = options.Validate();
  EXPECT_NE(problems.find("duration_s"), std::string::npos) << problems;
  EXPECT_NE(problems.find("k_theta"), std::string::npos) << problems;
}

TEST(SyntheticTest, StreamsHaveTheDeclaredLayout) {
  const SyntheticRecording synthetic = MakeAtvRecording(SyntheticOptions());
  const recording::Recording& rec = synthetic.recording;

  struct Expected {
    const char* name;
    recording::StreamType type;
    std::vector<std::string> columns;
    const char* units;
    std::int64_t period_ns;
    std::size_t count;
  };
  const std::vector<Expected> expected = {
      {"imu", recording::StreamType::kImu, {"wx", "wy", "wz", "ax", "ay", "az"}, "", 10000000, 3001},
      {"magnetometer", recording::StreamType::kMagnetometer, {"mx", "my", "mz"}, "normalized", 10000000, 3001},
      {"gps", recording::StreamType::kGps, {"latitude", "longitude", "altitude"}, "deg", 200000000, 151},
      {"rear_wheel", recording::StreamType::kWheelEncoders, {"rear"}, "m/s", 10000000, 3001},
      {"steering", recording::StreamType::kSteering, {"angle"}, "rad", 10000000, 3001},
  };
  ASSERT_EQ(rec.streams.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const recording::Stream& stream = rec.streams[i];
    SCOPED_TRACE(expected[i].name);
    EXPECT_EQ(stream.info.name, expected[i].name);
    EXPECT_EQ(stream.info.type, expected[i].type);
    EXPECT_EQ(stream.info.columns, expected[i].columns);
    EXPECT_EQ(stream.info.units, expected[i].units);
    EXPECT_DOUBLE_EQ(stream.info.rate_hz, 1e9 / static_cast<double>(expected[i].period_ns));
    ASSERT_EQ(stream.t.size(), expected[i].count);
    EXPECT_EQ(stream.values.rows(), static_cast<Eigen::Index>(expected[i].count));
    EXPECT_EQ(stream.values.cols(), static_cast<Eigen::Index>(expected[i].columns.size()));
    EXPECT_TRUE(stream.values.allFinite());
    for (std::size_t k = 0; k < stream.t.size(); ++k) {
      ASSERT_EQ(stream.t[k].nanoseconds(), static_cast<std::int64_t>(k) * expected[i].period_ns) << "sample " << k;
    }
  }

  // Ground truth at every IMU time; metadata.
  ASSERT_TRUE(rec.ground_truth.has_value());
  const recording::Stream& imu = Get(rec, "imu");
  ASSERT_EQ(rec.ground_truth->size(), imu.t.size());
  for (std::size_t k = 0; k < imu.t.size(); ++k) ASSERT_EQ((*rec.ground_truth)[k].t, imu.t[k]);
  EXPECT_EQ(rec.ground_truth->front().p_world_body, Eigen::Vector3d::Zero());
  EXPECT_EQ(rec.platform.kind, "ackermann");
  EXPECT_EQ(rec.platform.geometry.at("wheelbase_m"), 1.25);
  ASSERT_TRUE(rec.origin.has_value());
  EXPECT_EQ(rec.origin->latitude_deg, 45.4642);
  EXPECT_EQ(rec.origin->longitude_deg, 9.19);
  EXPECT_EQ(rec.origin->altitude_m, 120.0);
  EXPECT_EQ(rec.provenance.source, "simulated");
  EXPECT_EQ(rec.provenance.seed, std::uint64_t{1});
  EXPECT_EQ(Get(rec, "gps").info.noise.at("sigma_m"), 0.33);
}

TEST(SyntheticTest, TruthHoldsTheTrueCalibration) {
  const SyntheticOptions options = SkewedCalibration();
  const recording::Truth truth = MakeAtvRecording(options).truth;
  const Eigen::Quaterniond q = options.q_body_imu.normalized();
  EXPECT_EQ(truth.calibration.at("gps.lever_arm"), (std::vector<double>{-0.3, 0.8, 1.1}));
  EXPECT_EQ(truth.calibration.at("imu.misalignment"), (std::vector<double>{q.w(), q.x(), q.y(), q.z()}));
  EXPECT_EQ(truth.calibration.at("magnetometer.A"),
            (std::vector<double>{1.1, 0.05, -0.03, 0.02, 0.93, 0.04, -0.06, 0.01, 1.2}));
  EXPECT_EQ(truth.calibration.at("magnetometer.b"), (std::vector<double>{0.1, -0.2, 0.05}));
  EXPECT_EQ(truth.calibration.at("odometer.kv_over_L"), std::vector<double>{0.75});
  EXPECT_EQ(truth.calibration.at("odometer.k_theta"), std::vector<double>{0.9});
  EXPECT_EQ(truth.calibration.at("odometer.k_gamma"), std::vector<double>{0.02});
  EXPECT_EQ(truth.calibration.size(), 7u);
  EXPECT_TRUE(truth.effects.empty());

  // The default misalignment is Table I's, normalized.
  const std::vector<double> table_i = MakeAtvRecording(NoiseFree()).truth.calibration.at("imu.misalignment");
  ASSERT_EQ(table_i.size(), 4u);
  EXPECT_NEAR(std::hypot(std::hypot(table_i[0], table_i[1]), std::hypot(table_i[2], table_i[3])), 1.0, 1e-15);
  EXPECT_NEAR(table_i[0], 0.938, 1e-3);
  EXPECT_NEAR(table_i[2], 0.313, 1e-3);
}

// A gyro bias is added to every gyro reading in the IMU's own frame (with the skewed misalignment, a bias added in O
// would differ by q_body_imu), touches nothing else, and is recorded as imu.gyro_bias; without one there is no entry.
TEST(SyntheticTest, GyroBiasIsAddedInTheImuFrameAndRecorded) {
  SyntheticOptions options = SkewedCalibration();
  options.duration_s = 5.0;
  const SyntheticRecording unbiased = MakeAtvRecording(options);
  const Eigen::Vector3d bias(0.02, -0.01, 0.015);
  options.gyro_bias_radps = bias;
  const SyntheticRecording biased = MakeAtvRecording(options);

  const recording::Stream& a = Get(unbiased.recording, "imu");
  const recording::Stream& b = Get(biased.recording, "imu");
  ASSERT_EQ(a.t.size(), b.t.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < a.t.size(); ++k) worst = std::max(worst, (Row3(b, k, 0) - Row3(a, k, 0) - bias).norm());
  EXPECT_LT(worst, 1e-12);
  EXPECT_EQ(a.values.rightCols(3), b.values.rightCols(3));  // the accelerometer is untouched
  EXPECT_EQ(Get(unbiased.recording, "magnetometer").values, Get(biased.recording, "magnetometer").values);

  EXPECT_EQ(biased.truth.calibration.at("imu.gyro_bias"), (std::vector<double>{0.02, -0.01, 0.015}));
  EXPECT_EQ(biased.truth.calibration.size(), unbiased.truth.calibration.size() + 1);
  EXPECT_EQ(unbiased.truth.calibration.count("imu.gyro_bias"), 0u);

  options.gyro_bias_radps.x() = std::nan("");
  EXPECT_NE(options.Validate().find("gyro_bias_radps"), std::string::npos);
}

// The gyro reads the body rate that the ground-truth poses imply. The central difference over +-10 ms differs from
// the instantaneous rate by O(dt^2 |d^2 omega/dt^2|), 3e-5 rad/s on this trajectory; the tolerance is sigma_gyro / 33.
TEST(SyntheticTest, NoiseFreeGyroIsTheBodyRateOfTheGroundTruth) {
  const SyntheticOptions options = SkewedCalibration();
  const SyntheticRecording synthetic = MakeAtvRecording(options);
  const Trajectory& truth = *synthetic.recording.ground_truth;
  const recording::Stream& imu = Get(synthetic.recording, "imu");
  const Eigen::Quaterniond q_body_imu = options.q_body_imu.normalized();
  double max_error = 0.0;
  double max_rate = 0.0;
  for (std::size_t k = 1; k + 1 < truth.size(); ++k) {
    const Eigen::Vector3d omega_body =
        estimator::QuaternionLog<double>(truth[k - 1].q_world_body.conjugate() * truth[k + 1].q_world_body) /
        (2.0 * kImuDt);
    max_error = std::max(max_error, (Row3(imu, k, 0) - q_body_imu.conjugate() * omega_body).norm());
    max_rate = std::max(max_rate, omega_body.norm());
  }
  EXPECT_LT(max_error, 1e-3);
  EXPECT_GT(max_rate, 0.5);  // the vehicle does turn
}

// The accelerometer reads the specific force of the ground truth. The second difference of positions over +-10 ms
// is within O(dt^2 |p''''| / 12) of the acceleration, 1.4e-4 m/s^2 on this trajectory; the tolerance is sigma_acc / 67.
TEST(SyntheticTest, NoiseFreeAccelerometerIsTheSpecificForceOfTheGroundTruth) {
  const SyntheticOptions options = SkewedCalibration();
  const SyntheticRecording synthetic = MakeAtvRecording(options);
  const Trajectory& truth = *synthetic.recording.ground_truth;
  const recording::Stream& imu = Get(synthetic.recording, "imu");
  const Eigen::Quaterniond q_body_imu = options.q_body_imu.normalized();
  double max_error = 0.0;
  double max_acceleration = 0.0;
  for (std::size_t k = 1; k + 1 < truth.size(); ++k) {
    const Eigen::Vector3d a_world =
        (truth[k + 1].p_world_body - 2.0 * truth[k].p_world_body + truth[k - 1].p_world_body) / (kImuDt * kImuDt);
    const Eigen::Vector3d specific_force = q_body_imu.conjugate() * (truth[k].q_world_body.conjugate() *
                                                                     (a_world + estimator::kSpecificForceAtRest_world));
    max_error = std::max(max_error, (Row3(imu, k, 3) - specific_force).norm());
    max_acceleration = std::max(max_acceleration, a_world.norm());
  }
  EXPECT_LT(max_error, 1e-3);
  EXPECT_GT(max_acceleration, 1.0);
}

// Eq. 10 with the calibration read back from the truth.
TEST(SyntheticTest, NoiseFreeMagnetometerFollowsEq10) {
  const SyntheticOptions options = SkewedCalibration();
  const SyntheticRecording synthetic = MakeAtvRecording(options);
  const std::vector<double>& a = synthetic.truth.calibration.at("magnetometer.A");
  const std::vector<double>& b = synthetic.truth.calibration.at("magnetometer.b");
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> A(a.data());
  const Eigen::Quaterniond q_body_imu =
      estimator::QuaternionFromArray(synthetic.truth.calibration.at("imu.misalignment").data());
  const Trajectory& truth = *synthetic.recording.ground_truth;
  const recording::Stream& mag = Get(synthetic.recording, "magnetometer");
  ASSERT_EQ(mag.t.size(), truth.size());
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const Eigen::Vector3d expected =
        A * ((truth[k].q_world_body * q_body_imu).conjugate() * options.field_world) + Eigen::Vector3d(b.data());
    ASSERT_LT((Row3(mag, k, 0) - expected).norm(), 1e-12) << "sample " << k;
  }
}

// Eq. 9: the GPS, converted back to ENU by the estimator's converter, is the antenna of the ground-truth pose.
TEST(SyntheticTest, NoiseFreeGpsIsTheAntennaPosition) {
  const SyntheticOptions options = SkewedCalibration();
  const SyntheticRecording synthetic = MakeAtvRecording(options);
  const estimator::EnuConverter enu(*synthetic.recording.origin);
  const Trajectory& truth = *synthetic.recording.ground_truth;
  const recording::Stream& gps = Get(synthetic.recording, "gps");
  double travelled = 0.0;
  for (std::size_t k = 0; k < gps.t.size(); ++k) {
    const std::size_t i = static_cast<std::size_t>(gps.t[k].nanoseconds() / 10000000);
    ASSERT_EQ(truth[i].t, gps.t[k]);
    const Eigen::Vector3d antenna = truth[i].p_world_body + truth[i].q_world_body * options.gps_lever_arm_m;
    const Eigen::Vector3d measured = enu.ToEnu(gps.values(k, 0), gps.values(k, 1), gps.values(k, 2));
    ASSERT_LT((measured - antenna).norm(), 1e-6) << "sample " << k;
    travelled = std::max(travelled, antenna.head<2>().norm());
  }
  EXPECT_GT(travelled, 10.0);
}

// Eq. 15 with the true kv_over_L, k_theta, k_gamma gives the body yaw rate (read from the noise-free gyro) and the
// speed of the ground truth.
TEST(SyntheticTest, Eq15ReconstructsSpeedAndYawRate) {
  const SyntheticOptions options = SkewedCalibration();
  const SyntheticRecording synthetic = MakeAtvRecording(options);
  const recording::Stream& imu = Get(synthetic.recording, "imu");
  const recording::Stream& wheel = Get(synthetic.recording, "rear_wheel");
  const recording::Stream& steering = Get(synthetic.recording, "steering");
  const Trajectory& truth = *synthetic.recording.ground_truth;
  const Eigen::Quaterniond q_body_imu = options.q_body_imu.normalized();
  const double k_v = options.kv_over_L * options.wheelbase_m;
  ASSERT_EQ(wheel.t.size(), imu.t.size());
  ASSERT_EQ(steering.t.size(), imu.t.size());
  double min_yaw_rate = 0.0, max_yaw_rate = 0.0;
  for (std::size_t k = 0; k < imu.t.size(); ++k) {
    const double z_v = wheel.values(k, 0);
    const double z_theta = steering.values(k, 0);
    const double yaw_rate = options.kv_over_L * z_v * std::tan(options.k_theta * z_theta + options.k_gamma);
    const double omega_z = (q_body_imu * Row3(imu, k, 0)).z();
    ASSERT_NEAR(yaw_rate, omega_z, 1e-6) << "sample " << k;
    min_yaw_rate = std::min(min_yaw_rate, omega_z);
    max_yaw_rate = std::max(max_yaw_rate, omega_z);
  }
  EXPECT_LT(min_yaw_rate, -0.3);  // turns both ways
  EXPECT_GT(max_yaw_rate, 0.3);

  // Speed: k_v z_v against the chord speed of the ground truth (both at the middle of each interval).
  for (std::size_t k = 0; k + 1 < truth.size(); ++k) {
    Eigen::Vector3d v_body, omega_body;
    estimator::VelocitiesBetween(PoseOf(truth[k]), PoseOf(truth[k + 1]), kImuDt, &v_body, &omega_body);
    const double speed = 0.5 * k_v * (wheel.values(k, 0) + wheel.values(k + 1, 0));
    ASSERT_NEAR(speed, v_body.norm(), 1e-3 * v_body.norm()) << "interval " << k;
    ASSERT_GT(speed, 3.0);
  }
}

// The body frame moves along its x axis only (no side slip, no motion along the terrain normal).
TEST(SyntheticTest, BodyVelocityIsAlongX) {
  for (bool hilly : {true, false}) {
    SCOPED_TRACE(hilly ? "hilly" : "flat");
    SyntheticOptions options = NoiseFree();
    options.hilly = hilly;
    const Trajectory truth = *MakeAtvRecording(options).recording.ground_truth;
    for (std::size_t k = 0; k + 1 < truth.size(); ++k) {
      Eigen::Vector3d v_body, omega_body;
      estimator::VelocitiesBetween(PoseOf(truth[k]), PoseOf(truth[k + 1]), kImuDt, &v_body, &omega_body);
      ASSERT_GT(v_body.x(), 0.0) << "interval " << k;
      ASSERT_LT(std::abs(v_body.y()), 1e-3 * v_body.norm()) << "interval " << k;
      ASSERT_LT(std::abs(v_body.z()), 1e-3 * v_body.norm()) << "interval " << k;
    }
  }
}

TEST(SyntheticTest, HillyTerrainPitchesAndRolls) {
  const Trajectory truth = *MakeAtvRecording(NoiseFree()).recording.ground_truth;
  double max_pitch = 0.0, max_roll = 0.0, min_z = 0.0, max_z = 0.0;
  for (const StampedPose& pose : truth) {
    max_pitch = std::max(max_pitch, std::abs(Pitch(pose.q_world_body)));
    max_roll = std::max(max_roll, std::abs(Roll(pose.q_world_body)));
    min_z = std::min(min_z, pose.p_world_body.z());
    max_z = std::max(max_z, pose.p_world_body.z());
  }
  EXPECT_GT(max_pitch, 3.0 * kDegree);
  EXPECT_GT(max_roll, 3.0 * kDegree);
  EXPECT_LT(max_pitch, 20.0 * kDegree);
  EXPECT_LT(max_roll, 20.0 * kDegree);
  EXPECT_GT(max_z - min_z, 1.0);
}

TEST(SyntheticTest, FlatTerrainStaysAtZeroHeight) {
  SyntheticOptions options = NoiseFree();
  options.hilly = false;
  const Trajectory truth = *MakeAtvRecording(options).recording.ground_truth;
  for (const StampedPose& pose : truth) {
    ASSERT_EQ(pose.p_world_body.z(), 0.0);
    ASSERT_LT(std::abs(Pitch(pose.q_world_body)), 1e-12);
    ASSERT_LT(std::abs(Roll(pose.q_world_body)), 1e-12);
  }
}

TEST(SyntheticTest, SameOptionsGiveIdenticalRecordings) {
  const SyntheticRecording a = MakeAtvRecording(SyntheticOptions());
  const SyntheticRecording b = MakeAtvRecording(SyntheticOptions());
  ASSERT_EQ(a.recording.streams.size(), b.recording.streams.size());
  for (std::size_t i = 0; i < a.recording.streams.size(); ++i) {
    EXPECT_EQ(a.recording.streams[i].t, b.recording.streams[i].t);
    EXPECT_EQ(a.recording.streams[i].values, b.recording.streams[i].values) << a.recording.streams[i].info.name;
  }
  ASSERT_EQ(a.recording.ground_truth->size(), b.recording.ground_truth->size());
  for (std::size_t k = 0; k < a.recording.ground_truth->size(); ++k) {
    ASSERT_EQ((*a.recording.ground_truth)[k].p_world_body, (*b.recording.ground_truth)[k].p_world_body);
    ASSERT_EQ((*a.recording.ground_truth)[k].q_world_body.coeffs(),
              (*b.recording.ground_truth)[k].q_world_body.coeffs());
  }
  EXPECT_EQ(a.truth.calibration, b.truth.calibration);

  // Another seed changes every noisy stream but not the trajectory.
  SyntheticOptions other_seed;
  other_seed.seed = 2;
  const SyntheticRecording c = MakeAtvRecording(other_seed);
  for (std::size_t i = 0; i < a.recording.streams.size(); ++i) {
    EXPECT_NE(a.recording.streams[i].values, c.recording.streams[i].values) << a.recording.streams[i].info.name;
  }
  EXPECT_EQ(a.recording.ground_truth->back().p_world_body, c.recording.ground_truth->back().p_world_body);
}

// The fixes' slow error (gps_bias_sigma_m, gps_bias_tau_s), alone (sigma_gps_m 0): per ENU axis a first-order
// Gauss-Markov process sampled at the fixes, its lag-1 correlation a = exp(-period / tau) and its stationary std the
// configured one. Tolerances are five standard errors of an AR(1) sample of n values: sqrt((1 - a^2) / n) for the
// lag-1 correlation, sigma sqrt((1 + a^2) / (2 n (1 - a^2))) for the standard deviation.
TEST(SyntheticTest, GpsBiasIsAGaussMarkovProcessOfTheConfiguredStdAndCorrelationTime) {
  SyntheticOptions options;
  options.duration_s = 300.0;  // 1501 fixes
  options.sigma_gps_m = 0.0;
  options.gps_bias_sigma_m = 1.0;
  options.gps_bias_tau_s = 1.0;
  SyntheticOptions noise_free = options;
  noise_free.noise = false;
  const SyntheticRecording biased = MakeAtvRecording(options);
  const SyntheticRecording clean = MakeAtvRecording(noise_free);
  const estimator::EnuConverter enu(*biased.recording.origin);
  const recording::Stream& gps_biased = Get(biased.recording, "gps");
  const recording::Stream& gps_clean = Get(clean.recording, "gps");
  const Eigen::Index n = gps_biased.values.rows();
  Eigen::MatrixXd bias(3, n);
  for (Eigen::Index k = 0; k < n; ++k)
    bias.col(k) = enu.ToEnu(gps_biased.values(k, 0), gps_biased.values(k, 1), gps_biased.values(k, 2)) -
                  enu.ToEnu(gps_clean.values(k, 0), gps_clean.values(k, 1), gps_clean.values(k, 2));
  const double a = std::exp(-0.2 / options.gps_bias_tau_s);
  const double samples = 3.0 * static_cast<double>(n);
  double lag1 = 0.0, variance = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::RowVectorXd x = bias.row(axis).array() - bias.row(axis).mean();
    variance += x.squaredNorm();
    lag1 += x.head(n - 1).dot(x.tail(n - 1));
  }
  EXPECT_NEAR(lag1 / variance, a, 5.0 * std::sqrt((1.0 - a * a) / samples));
  EXPECT_NEAR(std::sqrt(variance / samples), options.gps_bias_sigma_m,
              5.0 * options.gps_bias_sigma_m * std::sqrt((1.0 + a * a) / (2.0 * samples * (1.0 - a * a))));
  options.gps_bias_tau_s = 0.0;
  EXPECT_NE(options.Validate().find("gps_bias_tau_s"), std::string::npos);
}

// Noise of one source: the differences noisy - noise-free, stacked.
struct NoiseSample {
  const char* name;
  double sigma;
  std::vector<double> values;
};

// Each source has zero mean and the configured sigma. Tolerances are five standard errors: sigma / sqrt(n) for the
// mean and sigma / sqrt(2 n) for the sample standard deviation. Distinct sources are uncorrelated (separate
// generators): |correlation| below five standard errors, 5 / sqrt(n), for the first component of each pair.
TEST(SyntheticTest, NoiseHasTheConfiguredSigmaPerSource) {
  SyntheticOptions options;
  options.duration_s = 60.0;  // 301 GPS fixes
  SyntheticOptions noise_free = options;
  noise_free.noise = false;
  const SyntheticRecording noisy = MakeAtvRecording(options);
  const SyntheticRecording clean = MakeAtvRecording(noise_free);

  const auto difference = [&](const std::string& stream, int first_column, int columns) {
    const Eigen::MatrixXd d = Get(noisy.recording, stream).values.middleCols(first_column, columns) -
                              Get(clean.recording, stream).values.middleCols(first_column, columns);
    std::vector<double> values;
    for (Eigen::Index k = 0; k < d.rows(); ++k) {
      for (Eigen::Index j = 0; j < d.cols(); ++j) values.push_back(d(k, j));
    }
    return values;
  };
  // GPS noise in ENU metres.
  std::vector<double> gps_noise;
  const estimator::EnuConverter enu(*noisy.recording.origin);
  const recording::Stream& gps_noisy = Get(noisy.recording, "gps");
  const recording::Stream& gps_clean = Get(clean.recording, "gps");
  for (Eigen::Index k = 0; k < gps_noisy.values.rows(); ++k) {
    const Eigen::Vector3d d = enu.ToEnu(gps_noisy.values(k, 0), gps_noisy.values(k, 1), gps_noisy.values(k, 2)) -
                              enu.ToEnu(gps_clean.values(k, 0), gps_clean.values(k, 1), gps_clean.values(k, 2));
    for (int j = 0; j < 3; ++j) gps_noise.push_back(d(j));
  }

  const std::vector<NoiseSample> sources = {
      {"gyro", options.sigma_gyro_radps, difference("imu", 0, 3)},
      {"accel", options.sigma_acc_mps2, difference("imu", 3, 3)},
      {"magnetometer", options.sigma_mag, difference("magnetometer", 0, 3)},
      {"gps", options.sigma_gps_m, gps_noise},
      {"speed", options.sigma_speed_mps, difference("rear_wheel", 0, 1)},
      {"steering", options.sigma_steering_rad, difference("steering", 0, 1)},
  };
  for (const NoiseSample& source : sources) {
    SCOPED_TRACE(source.name);
    const double n = static_cast<double>(source.values.size());
    double sum = 0.0, sum_sq = 0.0;
    for (double x : source.values) sum += x;
    const double mean = sum / n;
    for (double x : source.values) sum_sq += (x - mean) * (x - mean);
    const double std_dev = std::sqrt(sum_sq / (n - 1.0));
    EXPECT_NEAR(mean, 0.0, 5.0 * source.sigma / std::sqrt(n));
    EXPECT_NEAR(std_dev, source.sigma, 5.0 * source.sigma / std::sqrt(2.0 * n));
  }

  // Pairwise independence, on the first value of each sample of the 100 Hz sources (gyro x, accel x, mag x, speed,
  // steering).
  const std::vector<std::pair<const char*, std::vector<double>>> first = {
      {"gyro", difference("imu", 0, 1)},
      {"accel", difference("imu", 3, 1)},
      {"magnetometer", difference("magnetometer", 0, 1)},
      {"speed", difference("rear_wheel", 0, 1)},
      {"steering", difference("steering", 0, 1)},
  };
  for (std::size_t i = 0; i < first.size(); ++i) {
    for (std::size_t j = i + 1; j < first.size(); ++j) {
      const Eigen::Map<const Eigen::VectorXd> x(first[i].second.data(),
                                                static_cast<Eigen::Index>(first[i].second.size()));
      const Eigen::Map<const Eigen::VectorXd> y(first[j].second.data(),
                                                static_cast<Eigen::Index>(first[j].second.size()));
      const Eigen::VectorXd xc = x.array() - x.mean();
      const Eigen::VectorXd yc = y.array() - y.mean();
      const double correlation = xc.dot(yc) / (xc.norm() * yc.norm());
      EXPECT_LT(std::abs(correlation), 5.0 / std::sqrt(static_cast<double>(x.size())))
          << first[i].first << " vs " << first[j].first;
    }
  }
}

// The generated recording is one the reader accepts, and it comes back unchanged (values are written with 17
// significant digits, time with nine fractional digits).
TEST(SyntheticTest, SurvivesWriteAndRead) {
  SyntheticOptions options;
  options.duration_s = 5.0;
  const SyntheticRecording synthetic = MakeAtvRecording(options);
  TempDir dir;
  const Status written = recording::WriteRecording(synthetic.recording, dir.path());
  ASSERT_TRUE(written.ok()) << written.message();
  ASSERT_TRUE(recording::WriteTruth(synthetic.truth, dir.path()).ok());

  const Result<recording::Recording> read = recording::ReadRecording(dir.path());
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read.value().streams.size(), synthetic.recording.streams.size());
  for (std::size_t i = 0; i < synthetic.recording.streams.size(); ++i) {
    const recording::Stream& original = synthetic.recording.streams[i];
    const recording::Stream& back = read.value().streams[i];
    SCOPED_TRACE(original.info.name);
    EXPECT_EQ(back.info.name, original.info.name);
    EXPECT_EQ(back.info.type, original.info.type);
    EXPECT_EQ(back.info.columns, original.info.columns);
    EXPECT_EQ(back.t, original.t);
    EXPECT_EQ(back.values, original.values);
  }
  ASSERT_TRUE(read.value().ground_truth.has_value());
  EXPECT_EQ(read.value().ground_truth->size(), synthetic.recording.ground_truth->size());

  const Result<recording::Truth> truth = recording::ReadTruth(dir.path());
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  EXPECT_EQ(truth.value().calibration, synthetic.truth.calibration);
}

}  // namespace
}  // namespace roamlab::testing
