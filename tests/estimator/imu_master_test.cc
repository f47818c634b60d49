// The IMU master (problem.h "IMU master", config.h PosesConfig): its configuration errors, and the calibration of a
// GPS lever arm and a gyro bias on a synthesized drive with the IMU as the only motion sensor, and of the IMU
// misalignment's yaw and pitch once the non-holonomic rows (models/non_holonomic.h) tie the body to its travel.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/calibration.h"
#include "estimator/config.h"
#include "estimator/geometry.h"
#include "estimator/problem.h"
#include "estimator/tracking.h"
#include "eval/ellipsoid_fit.h"
#include "recording/recording.h"

namespace roamlab::estimator {
namespace {

constexpr const char* kStreams = R"(
streams:
  imu:
    model: gyroscope
    source: imu
    noise: {sigma_radps: 0.005}
  accel:
    model: accelerometer
    source: imu
    noise: {sigma_mps2: 0.05}
  gps:
    model: gps
    source: gps
    noise: {sigma_m: 0.05}
)";

TEST(ImuMasterConfigTest, AcceptsAGyroscopeMasterWithARate) {
  const auto c = ParseEstimatorConfig(std::string("master: imu\nposes: {rate_hz: 20}\n") + kStreams, "est.yaml");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c.value().poses.rate_hz, 20.0);
}

TEST(ImuMasterConfigTest, RejectsANonPositiveRate) {
  for (const char* rate : {"0", "-5"}) {
    const auto c =
        ParseEstimatorConfig(std::string("master: imu\nposes: {rate_hz: ") + rate + "}\n" + kStreams, "est.yaml");
    ASSERT_FALSE(c.ok()) << rate;
    EXPECT_NE(c.status().message().find("poses.rate_hz must be a positive"), std::string::npos) << c.status().message();
    EXPECT_NE(c.status().message().find("est.yaml"), std::string::npos);
  }
  const auto sigma = ParseEstimatorConfig(std::string("master: imu\nposes: {position_sigma_m: 0}\n") + kStreams, "e");
  EXPECT_FALSE(sigma.ok());
}

TEST(ImuMasterConfigTest, RejectsAMissingImuStreamOrAccelerometer) {
  const auto missing = ParseEstimatorConfig(std::string("master: imu_left\n") + kStreams, "est.yaml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("master stream 'imu_left' is not in streams"), std::string::npos);
  const auto no_accel = ParseEstimatorConfig(R"(
master: imu
streams:
  imu: {model: gyroscope, source: imu, noise: {sigma_radps: 0.005}}
  gps: {model: gps, source: gps, noise: {sigma_m: 0.05}}
)",
                                             "est.yaml");
  ASSERT_FALSE(no_accel.ok());
  EXPECT_NE(no_accel.status().message().find("needs an accelerometer stream"), std::string::npos)
      << no_accel.status().message();
  const auto gps_master = ParseEstimatorConfig(std::string("master: gps\n") + kStreams, "est.yaml");
  ASSERT_FALSE(gps_master.ok());
  const auto poses_without_imu = ParseEstimatorConfig(R"(
master: odo
poses: {rate_hz: 10}
streams:
  odo: {model: odometer, source: odo, noise: {linear_mps: 0.1, angular_radps: 0.1}}
)",
                                                      "est.yaml");
  ASSERT_FALSE(poses_without_imu.ok());
  EXPECT_NE(poses_without_imu.status().message().find("poses is for an IMU master"), std::string::npos);
}

// A drive at 2 m/s whose heading theta(t) = 0.3 t + sin(0.4 t) turns both ways (yaw rate -0.1 to 0.7 rad/s) while the
// body rolls 0.2 rad at 0.2 Hz; IMU (frame = body) at 100 Hz with a gyro bias, position fixes of an antenna at a lever
// arm at 5 Hz. The gyroscope reads the mean rate over its interval (what the model holds between samples), the
// accelerometer the specific force at its stamp. (On a circle at a constant rate the lever arm's forward component
// and the yaw would trade off: the track turned about the centre with the antenna moved along it fits as well.)
struct Drive {
  recording::Recording recording;
  Eigen::Quaterniond q_body_imu = Eigen::Quaterniond::Identity();
  Eigen::Vector3d lever_arm{0.5, -0.3, 0.0};
  Eigen::Vector3d gyro_bias{0.01, -0.02, 0.005};
  Trajectory truth;
};

Drive SynthesizeDrive(double seconds, std::uint32_t seed,
                      const Eigen::Quaterniond& q_body_imu = Eigen::Quaterniond::Identity()) {
  Drive d;
  d.q_body_imu = q_body_imu;
  const double speed = 2.0, roll_amplitude = 0.2, roll_angular_frequency = 2.0 * M_PI * 0.2;
  const auto heading = [](double t) { return 0.3 * t + std::sin(0.4 * t); };
  const auto heading_rate = [](double t) { return 0.3 + 0.4 * std::cos(0.4 * t); };
  // Positions on a 0.1 ms grid by the midpoint rule (error below 1e-8 m).
  const double h = 1e-4;
  std::vector<Eigen::Vector3d> positions(1, Eigen::Vector3d::Zero());
  for (int i = 0; i * h < seconds + 1.0; ++i) {
    const double theta = heading((i + 0.5) * h);
    positions.push_back(positions.back() + h * speed * Eigen::Vector3d(std::cos(theta), std::sin(theta), 0.0));
  }
  const auto pose_at = [&](double t) {
    const Eigen::Quaterniond q =
        Eigen::AngleAxisd(heading(t), Eigen::Vector3d::UnitZ()) *
        Eigen::AngleAxisd(roll_amplitude * std::sin(roll_angular_frequency * t), Eigen::Vector3d::UnitX());
    return Pose<double>{positions[static_cast<std::size_t>(std::llround(t / h))], q};
  };
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const auto noise = [&](double sigma) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = sigma * normal(rng);
    return v;
  };

  recording::Stream imu;
  imu.info.name = "imu";
  imu.info.type = recording::StreamType::kImu;
  imu.info.rate_hz = 100.0;
  imu.info.columns = recording::FixedColumns(recording::StreamType::kImu);
  recording::Stream gps;
  gps.info.name = "gps";
  gps.info.type = recording::StreamType::kPosition;
  gps.info.rate_hz = 5.0;
  gps.info.columns = recording::FixedColumns(recording::StreamType::kPosition);
  const int imu_samples = static_cast<int>(seconds * 100.0);
  const int gps_samples = static_cast<int>(seconds * 5.0);
  imu.values.resize(imu_samples, 6);
  gps.values.resize(gps_samples, 3);
  const double dt = 0.01;
  for (int k = 0; k < imu_samples; ++k) {
    const double t = k * dt;
    const Pose<double> p = pose_at(t);
    const Eigen::Vector3d mean_rate =
        QuaternionLog<double>(p.q_world_body.conjugate() * pose_at(t + dt).q_world_body) / dt;
    const Eigen::Vector3d a_world =  // centripetal (constant speed)
        speed * heading_rate(t) * Eigen::Vector3d(-std::sin(heading(t)), std::cos(heading(t)), 0.0);
    const Eigen::Vector3d f_body = p.q_world_body.conjugate() * (a_world + kSpecificForceAtRest_world);
    imu.t.push_back(Time::FromNanoseconds(10'000'000LL * k + 1'000'000'000LL));
    const Eigen::Vector3d rate_imu = q_body_imu.conjugate() * mean_rate, f_imu = q_body_imu.conjugate() * f_body;
    imu.values.row(k) << (rate_imu + d.gyro_bias + noise(0.005)).transpose(), (f_imu + noise(0.05)).transpose();
    d.truth.push_back({imu.t.back(), p.p_world_body, p.q_world_body});
  }
  for (int k = 0; k < gps_samples; ++k) {
    const double t = k * 0.2 + 0.005;
    const Pose<double> p = pose_at(t);
    gps.t.push_back(Time::FromNanoseconds(std::llround(t * 1e9) + 1'000'000'000LL));
    gps.values.row(k) = (p.p_world_body + p.q_world_body * d.lever_arm + noise(0.05)).transpose();
  }
  d.recording.streams = {imu, gps};
  return d;
}

EstimatorConfig DriveConfig(double rate_hz) {
  const std::string yaml = "master: imu\nposes: {rate_hz: " + std::to_string(rate_hz) + "}\n" +
                           "parameters:\n  gps.lever_arm: {free: true}\n  imu.bias: {free: true}\n" + kStreams;
  auto c = ParseEstimatorConfig(yaml, "drive.yaml");
  EXPECT_TRUE(c.ok()) << c.status().message();
  return c.value();
}

const ParameterEstimate* Find(const CalibrationResult& r, const std::string& name) {
  for (const ParameterEstimate& p : r.parameters)
    if (p.name == name) return &p;
  return nullptr;
}

TEST(ImuMasterTest, PosesOnTheGridJoinedByTheImu) {
  const Drive d = SynthesizeDrive(2.0, 1);
  auto builder = ProblemBuilder::Create(DriveConfig(20.0), d.recording);
  ASSERT_TRUE(builder.ok()) << builder.status().message();
  for (const MeasurementRef& m : builder.value()->Measurements()) builder.value()->Add(m);
  builder.value()->Finish();
  // 2 s of IMU at 100 Hz: grid poses at 0, 0.05, ..., 1.95 s (the last sample at 1.99 s).
  const auto& poses = builder.value()->poses();
  ASSERT_EQ(poses.size(), 40u);
  EXPECT_NEAR(SecondsBetween(poses[0].t, poses[1].t), 0.05, 1e-9);
  // Five gyroscope samples per interval; the samples after the last pose are outside.
  const StreamCounts& gyro = builder.value()->counts().at("imu");
  EXPECT_EQ(gyro.attached, 39 * 5);
  EXPECT_EQ(gyro.outside, 5);
  // The first pose is gravity-aligned: it turns the accelerometer's mean over the first second onto the world's up.
  const recording::Stream& imu = d.recording.streams[0];
  const Eigen::Vector3d f_mean = imu.values.topRows(101).rightCols<3>().colwise().mean().transpose();
  const Pose<double> first = PoseFromArray(builder.value()->graph().variable(poses[0].id).value.data());
  EXPECT_NEAR((first.q_world_body * f_mean).normalized().z(), 1.0, 1e-12);
}

TEST(ImuMasterTest, RecoversLeverArmAndGyroBiasWithinThreeSigma) {
  const Drive d = SynthesizeDrive(30.0, 7);
  auto result = Calibrate(DriveConfig(50.0), d.recording);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const ParameterEstimate* lever = Find(result.value(), "gps.lever_arm");
  const ParameterEstimate* bias = Find(result.value(), "imu.bias");
  ASSERT_NE(lever, nullptr);
  ASSERT_NE(bias, nullptr);
  for (int i = 0; i < 3; ++i) {
    std::cout << "lever[" << i << "] = " << lever->estimate[i] << " +- " << lever->std[i] << " (truth "
              << d.lever_arm[i] << "); bias[" << i << "] = " << bias->estimate[i] << " +- " << bias->std[i]
              << " (truth " << d.gyro_bias[i] << ")\n";
    ASSERT_TRUE(std::isfinite(bias->std[i]));
    EXPECT_LT(std::abs(bias->estimate[i] - d.gyro_bias[i]), 3.0 * bias->std[i]) << i;
  }
  // The horizontal lever arm is seen through the turn; its height only through the roll's cosine.
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(std::isfinite(lever->std[i]));
    EXPECT_LT(std::abs(lever->estimate[i] - d.lever_arm[i]), 3.0 * lever->std[i]) << i;
  }
  if (std::isfinite(lever->std[2])) {
    EXPECT_LT(std::abs(lever->estimate[2] - d.lever_arm[2]), 3.0 * lever->std[2]);
  }
  // The smoothed positions are better known than any single fix (each pose lies between fixes that the accelerometer
  // and the gyroscope tie together): their 3-D rms error below one fix's, sqrt(3) 0.05 m.
  double sum_squared = 0.0;
  for (const StampedPose& p : result.value().trajectory) {
    const auto it =
        std::lower_bound(d.truth.begin(), d.truth.end(), p.t, [](const StampedPose& s, Time t) { return s.t < t; });
    ASSERT_NE(it, d.truth.end());
    sum_squared += (it->p_world_body - p.p_world_body).squaredNorm();
  }
  const double rms = std::sqrt(sum_squared / static_cast<double>(result.value().trajectory.size()));
  std::cout << "position rms error " << rms << " m\n";
  EXPECT_LT(rms, std::sqrt(3.0) * 0.05);
}

TEST(ImuMasterTest, TracksTheDrive) {
  const Drive d = SynthesizeDrive(12.0, 3);
  EstimatorConfig config = DriveConfig(20.0);
  config.tracking.window = 20;
  config.tracking.initialization_s = 4.0;
  const std::map<std::string, Eigen::VectorXd> calibration = {{"gps.lever_arm", d.lever_arm},
                                                              {"imu.bias", d.gyro_bias}};
  auto result = Track(config, d.recording, calibration);
  ASSERT_TRUE(result.ok()) << result.status().message();
  ASSERT_GT(result.value().trajectory.size(), 200u);
  double sum_nees = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < result.value().trajectory.size(); ++i) {
    const StampedPose& p = result.value().trajectory[i];
    const auto it =
        std::lower_bound(d.truth.begin(), d.truth.end(), p.t, [](const StampedPose& s, Time t) { return s.t < t; });
    ASSERT_NE(it, d.truth.end());
    const Eigen::Vector3d e = it->p_world_body - p.p_world_body;
    sum_nees += e.dot(result.value().position_covariance[i].ldlt().solve(e));
    ++n;
  }
  // Position NEES per pose averages 3 when the reported covariance is right; consecutive poses are correlated, so
  // only a factor-of-three band is asserted.
  const double mean_nees = sum_nees / n;
  std::cout << "tracking: " << n << " poses, mean position NEES " << mean_nees << "\n";
  EXPECT_LT(mean_nees, 9.0);
}

// The non-holonomic pseudo-measurement (models/non_holonomic.h) on the drive, whose body moves along its x axis, with
// the IMU mounted turned by 3 deg of yaw, 2 deg of pitch and 1.5 deg of roll, the misalignment free from identity and
// shared by the gyroscope and the accelerometer. Without the rows it is a gauge freedom; with them its yaw and pitch
// are recovered within 3 reported sigma, and its roll (a turn about the direction of travel) is reported
// unobservable. The rows are one per IMU sample, two per pose interval.
TEST(ImuMasterTest, NonHolonomicRowsMakeTheMisalignmentsYawAndPitchObservable) {
  const Eigen::Quaterniond q_body_imu = Eigen::AngleAxisd(0.05236, Eigen::Vector3d::UnitZ()) *
                                        Eigen::AngleAxisd(0.03491, Eigen::Vector3d::UnitY()) *
                                        Eigen::AngleAxisd(0.02618, Eigen::Vector3d::UnitX());
  const Drive d = SynthesizeDrive(30.0, 11, q_body_imu);
  const std::string yaml = std::string("master: imu\nposes: {rate_hz: 50}\n") +
                           "parameters:\n  gps.lever_arm: {free: true}\n  imu.bias: {free: true}\n"
                           "  imu.misalignment: {value: [1, 0, 0, 0], free: true}\n" +
                           R"(
streams:
  imu: {model: gyroscope, source: imu, noise: {sigma_radps: 0.005}}
  accel:
    model: accelerometer
    source: imu
    noise: {sigma_mps2: 0.05}
    parameters: {misalignment: imu.misalignment}
  gps: {model: gps, source: gps, noise: {sigma_m: 0.05}}
  travel: {model: non_holonomic, source: imu, noise: {lateral_mps: 0.02, vertical_mps: 0.02}}
)";
  auto config = ParseEstimatorConfig(yaml, "nhc.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  auto result = Calibrate(config.value(), d.recording);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const ParameterEstimate* misalignment = Find(result.value(), "imu.misalignment");
  ASSERT_NE(misalignment, nullptr);
  ASSERT_EQ(misalignment->components.size(), 3u);
  // The calibration reports the slot's components in its tangent, a turn about the IMU's axes (q Exp(delta)): the
  // unobservable turn is about the body's x axis, which is the IMU's x turned by the misalignment, so it is reported
  // unobservable in the roll component (and may load on the others: the analysis normalizes the information to unit
  // diagonal, where the near-null roll's small diagonal magnifies the others' share of the null direction).
  EXPECT_EQ(misalignment->components[0], Observability::kUnobservable);
  // Yaw and pitch about the body's axes: the misalignment's marginal information (the other parameters eliminated)
  // turned into the body's axes, delta_body = R delta_imu (Exp(delta_body) q = q Exp(delta_imu)).
  int offset = 0, at = -1;
  for (const ParameterEstimate& p : result.value().parameters) {
    if (&p == misalignment) at = offset;
    offset += p.manifold.tangent_dim();
  }
  ASSERT_GE(at, 0);
  const Eigen::MatrixXd& information = result.value().information;
  std::vector<int> others;
  for (int i = 0; i < information.rows(); ++i)
    if (i < at || i >= at + 3) others.push_back(i);
  const Eigen::MatrixXd I_oo = information(others, others);
  const Eigen::MatrixXd I_mo = information.block(at, 0, 3, information.cols())(Eigen::all, others);
  const Eigen::Matrix3d I_imu = information.block<3, 3>(at, at) - I_mo * I_oo.ldlt().solve(I_mo.transpose());
  const Eigen::Quaterniond estimate(misalignment->estimate[0], misalignment->estimate[1], misalignment->estimate[2],
                                    misalignment->estimate[3]);
  const Eigen::Matrix3d R = estimate.normalized().toRotationMatrix();
  const Eigen::Matrix3d I_body = R * I_imu * R.transpose();
  // About the body's x the information is nothing against pitch's and yaw's (what is left comes from the residual
  // sideways and vertical velocities, second order): a roll std more than 30 times the yaw's.
  EXPECT_LT(I_body(0, 0), 1e-3 * std::min(I_body(1, 1), I_body(2, 2))) << I_body;
  const Eigen::Vector2d std_body = I_body.bottomRightCorner<2, 2>().inverse().diagonal().cwiseSqrt();
  const Eigen::Vector3d error_body = QuaternionLog<double>(estimate.normalized() * q_body_imu.conjugate());
  std::cout << "misalignment error about the body's axes [" << error_body.transpose() << "] rad; pitch, yaw std ["
            << std_body.transpose() << "] rad; body-frame information\n"
            << I_body << "\n";
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(std::isfinite(std_body[i])) << i;
    EXPECT_LT(std::abs(error_body[i + 1]), 3.0 * std_body[i]) << i;
  }
  // The test has power: the pitch and yaw set are many std from the identity the calibration started at.
  EXPECT_GT(0.03491, 10.0 * std_body[0]);
  EXPECT_GT(0.05236, 10.0 * std_body[1]);
}

// A handheld IMU + magnetometer turned through every orientation at a fixed place (no position sensor: the weak
// position prior holds the positions): 60 s at 100 Hz of q(t) = Rz(0.5 t) Rx(0.37 t), the magnetometer reading
// z = A h^(S) + b + noise with a known symmetric soft-iron A and hard-iron b. The calibration's A and b agree with the
// truth within 3 reported sigma, and with the ellipsoid fit of the raw samples in the fit's convention
// (eval/ellipsoid_fit.h): b within 0.5 uT of the fit's centre and SymmetricFactor(A) |h| / r, which the fit's scale
// normalization makes comparable, within 0.02 of W^-1 element-wise. Poses at every IMU sample: each magnetometer
// reading then sits on its own pose (on a pose 10 ms away, as at a lower pose rate, it would see the field turned by
// the rotation in between, a bias in A).
TEST(ImuMasterTest, HandheldMagnetometerCalibrationAgreesWithTheEllipsoidFit) {
  const Eigen::Vector3d h_world(0.0, 18.0, -42.0);  // [uT]
  Eigen::Matrix3d A_true;
  A_true << 1.10, 0.04, -0.02, 0.04, 0.93, 0.03, -0.02, 0.03, 1.02;
  const Eigen::Vector3d b_true(4.7, 0.1, -1.8);
  const Eigen::Vector3d gyro_bias(0.004, -0.006, 0.002);
  const auto q_at = [](double t) {
    return Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * t, Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(0.37 * t, Eigen::Vector3d::UnitX()));
  };
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  const auto noise = [&](double sigma) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = sigma * normal(rng);
    return v;
  };
  recording::Stream imu, mag;
  imu.info.name = "imu";
  imu.info.type = recording::StreamType::kImu;
  imu.info.rate_hz = 100.0;
  imu.info.columns = recording::FixedColumns(recording::StreamType::kImu);
  mag.info.name = "mag";
  mag.info.type = recording::StreamType::kMagnetometer;
  mag.info.rate_hz = 100.0;
  mag.info.columns = recording::FixedColumns(recording::StreamType::kMagnetometer);
  const int samples = 6000;
  imu.values.resize(samples, 6);
  mag.values.resize(samples, 3);
  std::vector<Eigen::Vector3d> raw;
  for (int k = 0; k < samples; ++k) {
    const double t = 0.01 * k;
    const Eigen::Quaterniond q = q_at(t);
    const Eigen::Vector3d rate = QuaternionLog<double>(q.conjugate() * q_at(t + 0.01)) / 0.01;
    const Time stamp = Time::FromNanoseconds(10'000'000LL * k + 1'000'000'000LL);
    imu.t.push_back(stamp);
    mag.t.push_back(stamp);
    imu.values.row(k) << (rate + gyro_bias + noise(0.005)).transpose(),
        (q.conjugate() * kSpecificForceAtRest_world + noise(0.05)).transpose();
    raw.push_back(A_true * (q.conjugate() * h_world) + b_true + noise(0.5));
    mag.values.row(k) = raw.back().transpose();
  }
  recording::Recording rec;
  rec.streams = {imu, mag};
  const auto config = ParseEstimatorConfig(R"(
master: imu
poses: {position_sigma_m: 0.5}
parameters:
  imu.bias: {free: true}
  mag.A: {free: true}
  mag.b: {free: true}
streams:
  imu: {model: gyroscope, source: imu, noise: {sigma_radps: 0.005}}
  accel: {model: accelerometer, source: imu, noise: {sigma_mps2: 0.05}}
  mag: {model: magnetometer, source: mag, noise: {sigma: 0.5}, options: {field_world: [0, 18, -42]}}
)",
                                           "handheld.yaml");
  ASSERT_TRUE(config.ok()) << config.status().message();
  auto result = Calibrate(config.value(), rec);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const ParameterEstimate* A = Find(result.value(), "mag.A");
  const ParameterEstimate* b = Find(result.value(), "mag.b");
  ASSERT_NE(A, nullptr);
  ASSERT_NE(b, nullptr);
  const Eigen::Matrix3d A_est = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(A->estimate.data());
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::abs(b->estimate[i] - b_true[i]), 3.0 * b->std[i]) << "b[" << i << "]";
  for (int i = 0; i < 9; ++i) {
    std::cout << "A[" << i << "] = " << A->estimate[i] << " +- " << A->std[i] << " (truth " << A_true(i / 3, i % 3)
              << ")\n";
    EXPECT_LT(std::abs(A->estimate[i] - A_true(i / 3, i % 3)), 3.0 * A->std[i]) << "A[" << i << "]";
  }

  // Against the ellipsoid fit: the fit's W maps onto a sphere of radius r; the estimator's A onto one of |h_world|.
  const auto fit = eval::FitEllipsoid(raw);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  const Eigen::Matrix3d P = eval::SymmetricFactor(A_est) * (h_world.norm() / fit.value().radius);
  const double b_difference = (b->estimate - fit.value().centre).norm();
  const double A_difference = (P - fit.value().correction.inverse()).cwiseAbs().maxCoeff();
  std::cout << "handheld: |b - centre| " << b_difference << " uT, max |P - W^-1| " << A_difference << "\n";
  EXPECT_LT(b_difference, 0.5);
  EXPECT_LT(A_difference, 0.02);
}

}  // namespace
}  // namespace roamlab::estimator
