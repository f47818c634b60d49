#include "estimator/odometry/training_data.h"

#include <unistd.h>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "estimator/odometry/odometry_model.h"
#include "estimator/odometry/parametric.h"
#include "recording/wheel_kinematics.h"

namespace roamlab::estimator::odometry {
namespace {

// A differential drive with constant wheel speeds, 20 Hz encoders (rad) and a 20 Hz pose stream of the sensor.
recording::Recording MakeRecording(const WheelKinematics& truth, const Eigen::Vector2d& speed_radps, int samples) {
  recording::Recording rec;
  rec.platform.kind = "differential_drive";
  recording::Stream enc;
  enc.info.name = "wheel_encoders";
  enc.info.type = recording::StreamType::kWheelEncoders;
  enc.info.rate_hz = 20.0;
  enc.info.columns = {"right", "left"};
  enc.info.units = "rad";
  recording::Stream pose;
  pose.info.name = "mocap";
  pose.info.type = recording::StreamType::kPose;
  pose.info.rate_hz = 20.0;
  pose.info.units = "m";
  pose.info.noise = {{"position_m", 0.002}, {"orientation_rad", 0.01}};
  enc.values.resize(samples, 2);
  pose.values.resize(samples, 7);
  Pose2 sensor = Pose2(1.0, 2.0, 0.3);
  for (int k = 0; k < samples; ++k) {
    const Time t = Time::FromNanoseconds(50'000'000LL * k);
    enc.t.push_back(t);
    pose.t.push_back(t);
    enc.values.row(k) = (0.05 * k * speed_radps).transpose();
    if (k > 0) sensor = Compose(sensor, truth.Displacement(0.05 * speed_radps));
    const Eigen::Quaterniond q(Eigen::AngleAxisd(sensor[2], Eigen::Vector3d::UnitZ()));
    pose.values.row(k) << sensor[0], sensor[1], 0.0, q.x(), q.y(), q.z(), q.w();
  }
  rec.streams = {enc, pose};
  return rec;
}

TEST(TrainingDataTest, PairsHoldWheelRotationsAndSensorDisplacements) {
  const WheelKinematics truth = DifferentialDrive({"right", "left"}, 0.042, 0.041, 0.2, Pose2(0.1, 0.02, 0.05));
  const Eigen::Vector2d speed(6.0, 4.0);
  const recording::Recording rec = MakeRecording(truth, speed, 101);  // 5 s
  KeyTimeOptions options;
  options.interval_s = 0.25;
  Result<KeySequence> seq = CutAtKeyTimes(rec, "rec", options, true);
  ASSERT_TRUE(seq.ok()) << seq.status().message();
  EXPECT_EQ(seq.value().size(), 21);
  EXPECT_DOUBLE_EQ(seq.value().sensor_step_sigma(0, 0), std::sqrt(2.0) * 0.002);
  Result<TrainingSet> set = MakeTrainingSet({seq.value()});
  ASSERT_TRUE(set.ok()) << set.status().message();
  ASSERT_EQ(set.value().size(), 20);
  // Five encoder cycles per pair: delta = 0.25 s x speed; s = five composed cycle displacements.
  const Pose2 cycle = truth.Displacement(0.05 * speed);
  Pose2 expected = Pose2::Zero();
  for (int i = 0; i < 5; ++i) expected = Compose(expected, cycle);
  for (int k = 0; k < set.value().size(); ++k) {
    EXPECT_LT((set.value().delta.row(k).transpose() - 0.25 * speed).norm(), 1e-12);
    EXPECT_LT((set.value().s.row(k).transpose() - expected).norm(), 1e-12);
    EXPECT_NEAR(set.value().s_sigma(k, 2), std::sqrt(2.0) * 0.01, 1e-15);
  }
}

TEST(TrainingDataTest, NamesTheMissingStream) {
  const WheelKinematics truth = DifferentialDrive({"right", "left"}, 0.042, 0.041, 0.2, Pose2::Zero());
  recording::Recording rec = MakeRecording(truth, Eigen::Vector2d(1.0, 1.0), 30);
  rec.streams.pop_back();
  Result<KeySequence> seq = CutAtKeyTimes(rec, "REC", {}, true);
  ASSERT_FALSE(seq.ok());
  EXPECT_EQ(seq.status().message(), "REC: no pose stream");
  EXPECT_TRUE(CutAtKeyTimes(rec, "REC", {}, false).ok());  // evaluation needs no sensor
}

// The same drive seen by a 10 Hz scan matcher mounted off O (lever arm and yaw): each row the laser frame's velocity
// over its scan interval (rotate half, translate, rotate half), stamped at the interval's middle. One row is missing
// (a failed match). Expected: body displacements q = l (+) s (+) (-)l of the composed rows, the key interval with the
// gap dropped, covariance grown with the rows composed.
TEST(TrainingDataTest, ScanMatchingIncrementsAreComposedAndCarriedToTheBody) {
  const WheelKinematics truth = DifferentialDrive({"right", "left"}, 0.042, 0.041, 0.2, Pose2::Zero());
  const Eigen::Vector2d speed(6.0, 4.0);
  recording::Recording rec = MakeRecording(truth, speed, 101);  // 5 s of 20 Hz encoders
  rec.streams.pop_back();
  const Pose2 mounting(0.15, -0.05, 0.3);
  recording::Stream scans;
  scans.info.name = "scan_matching";
  scans.info.type = recording::StreamType::kScanMatching;
  scans.info.rate_hz = 10.0;
  scans.info.columns = recording::FixedColumns(recording::StreamType::kScanMatching);
  scans.info.units = "m/s,rad/s";
  scans.info.noise = {{"sigma_mps", 0.01}, {"sigma_radps", 0.02}};
  scans.info.mounting = recording::Mounting{};
  scans.info.mounting->p_body_sensor = Eigen::Vector3d(mounting[0], mounting[1], 0.2);
  scans.info.mounting->q_body_sensor = Eigen::AngleAxisd(mounting[2], Eigen::Vector3d::UnitZ());
  const Pose2 body_step = truth.Displacement(0.1 * speed);  // 0.1 s of body motion
  const Pose2 laser_step = Compose(Compose(Inverse(mounting), body_step), mounting);
  const double theta = laser_step[2];
  const Eigen::Vector2d v = Eigen::Rotation2Dd(-0.5 * theta) * laser_step.head<2>() / 0.1;
  const int rows = 50;
  const int missing = 17;  // the row covering [1.7, 1.8] s, inside the key interval [1.5, 1.8]
  scans.values.resize(rows - 1, 6);
  for (int k = 0, r = 0; k < rows; ++k) {
    if (k == missing) continue;
    scans.t.push_back(Time::FromNanoseconds(50'000'000LL + 100'000'000LL * k));
    scans.values.row(r++) << v.x(), v.y(), 0.0, 0.0, 0.0, theta / 0.1;
  }
  rec.streams.push_back(scans);

  KeyTimeOptions options;
  options.interval_s = 0.3;
  Result<KeySequence> seq = CutAtKeyTimes(rec, "rec", options, true);
  ASSERT_TRUE(seq.ok()) << seq.status().message();
  EXPECT_EQ(seq.value().size(), 17);  // 0 to 4.8 s
  Result<TrainingSet> set = MakeTrainingSet({seq.value()});
  ASSERT_TRUE(set.ok()) << set.status().message();
  ASSERT_EQ(set.value().size(), 15);  // 16 intervals, one with the gap
  const Pose2 expected = Compose(Compose(body_step, body_step), body_step);
  for (int k = 0; k < set.value().size(); ++k) {
    EXPECT_LT((set.value().delta.row(k).transpose() - 0.3 * speed).norm(), 1e-12);
    EXPECT_LT((set.value().s.row(k).transpose() - expected).norm(), 1e-12) << k;
  }
  // Heading variance: three rows of (0.02 rad/s x 0.1 s)^2, unchanged by the mounting; translation grows with the
  // lever arm's swing.
  EXPECT_NEAR(set.value().s_sigma(0, 2), std::sqrt(3.0) * 0.002, 1e-12);
  EXPECT_GT(set.value().s_sigma(0, 1), std::sqrt(3.0) * 0.001);

  // Key times off the rows' grid: no interval is tiled by whole rows.
  options.interval_s = 0.25;
  Result<KeySequence> off = CutAtKeyTimes(rec, "rec", options, true);
  ASSERT_FALSE(off.ok());
  EXPECT_NE(off.status().message().find("multiple of 1 / rate_hz"), std::string::npos) << off.status().message();
}

// A saved model predicts what the trained one does.
// A tricycle driving at a constant wheel rate with the steering stepping between two angles, its motion-capture pose
// at O (the rear axle's centre), 20 Hz; the true steering angle is the measured one plus `offset`. Over each encoder
// cycle the robot steers at the mean of the cycle's two readings (what the training columns assume).
recording::Recording MakeTricycle(double radius_m, double wheel_to_axle_m, double offset_rad, int samples) {
  recording::Recording rec;
  rec.platform.kind = "tricycle";
  rec.platform.geometry = {
      {"wheel_radius_front_m", radius_m}, {"wheel_to_axle_m", wheel_to_axle_m}, {"steering_offset_rad", offset_rad}};
  const auto stream = [samples](const std::string& name, recording::StreamType type, int columns) {
    recording::Stream s;
    s.info.name = name;
    s.info.type = type;
    s.info.rate_hz = 20.0;
    s.info.units = type == recording::StreamType::kPose ? "m" : "rad";
    s.values.resize(samples, columns);
    return s;
  };
  recording::Stream enc = stream("wheel_encoders", recording::StreamType::kWheelEncoders, 1);
  recording::Stream steering = stream("steering", recording::StreamType::kSteering, 1);
  recording::Stream pose = stream("mocap", recording::StreamType::kPose, 7);
  enc.info.columns = {"front"};
  steering.info.columns = {"angle"};
  const auto measured = [](int k) { return (k / 7) % 2 == 0 ? 0.3 : -0.2; };
  const double rate_radps = 5.0;
  Pose2 body = Pose2::Zero();
  for (int k = 0; k < samples; ++k) {
    const Time t = Time::FromNanoseconds(50'000'000LL * k);
    enc.t.push_back(t);
    steering.t.push_back(t);
    pose.t.push_back(t);
    steering.values(k, 0) = measured(k);
    enc.values(k, 0) = 0.05 * k * rate_radps;
    if (k > 0) {
      const double steer = 0.5 * (measured(k - 1) + measured(k)) + offset_rad;
      body = Compose(body, ExpTwist(0.05 * recording::TricycleTwist(rate_radps, steer, radius_m, wheel_to_axle_m)));
    }
    const Eigen::Quaterniond q(Eigen::AngleAxisd(body[2], Eigen::Vector3d::UnitZ()));
    pose.values.row(k) << body[0], body[1], 0.0, q.x(), q.y(), q.z(), q.w();
  }
  rec.streams = {enc, steering, pose};
  return rec;
}

TEST(TrainingDataTest, TricycleColumnsMakeItsMotionLinearAndTheNominalModelExact) {
  const recording::Recording rec = MakeTricycle(0.033, 0.16, -0.03, 101);
  KeyTimeOptions options;
  options.interval_s = 0.25;
  Result<KeySequence> seq = CutAtKeyTimes(rec, "rec", options, true);
  ASSERT_TRUE(seq.ok()) << seq.status().message();
  EXPECT_EQ(seq.value().wheels, (std::vector<std::string>{"front_cos_steering", "front_sin_steering"}));
  Result<WheelKinematics> nominal = NominalKinematics(rec.platform, seq.value().wheels);
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();
  // Over a key interval of constant steering (5 cycles; the steering switches every 7 samples) the motion is one arc,
  // which the nominal rows on the two columns reproduce exactly; where it switches the arcs differ and a single
  // interval twist is only an approximation.
  const Eigen::MatrixXd delta = seq.value().WheelIncrements();
  const Eigen::MatrixXd& angle = rec.streams[1].values;
  int exact = 0;
  for (int k = 0; k + 1 < seq.value().size(); ++k) {
    if (angle.col(0).segment(5 * k, 6).maxCoeff() != angle.col(0).segment(5 * k, 6).minCoeff()) continue;
    const Pose2 predicted = nominal.value().Displacement(delta.row(k).transpose());
    EXPECT_LT((predicted - seq.value().sensor_step[static_cast<std::size_t>(k)]).norm(), 1e-9) << k;
    ++exact;
  }
  EXPECT_GE(exact, 5);
  // Without its steering stream a tricycle recording is refused, naming the problem.
  recording::Recording no_steering = rec;
  no_steering.streams.erase(no_steering.streams.begin() + 1);
  Result<KeySequence> refused = CutAtKeyTimes(no_steering, "rec", options, true);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("no steering stream"), std::string::npos) << refused.status().message();
}

TEST(OdometryModelTest, SaveAndLoadKeepPredictions) {
  const WheelKinematics truth = DifferentialDrive({"right", "left"}, 0.042, 0.041, 0.2, Pose2(0.1, 0.0, 0.0));
  Eigen::MatrixXd X(30, 2), Y(30, 3);
  for (int k = 0; k < 30; ++k) {
    X.row(k) << 1.0 + 0.1 * k, 2.0 - 0.07 * k;
    Y.row(k) = truth.Displacement(X.row(k).transpose()).transpose();
  }
  Result<GaussianProcess> gp = GaussianProcess::Train(X, Y, Eigen::MatrixXd::Constant(30, 3, 1e-8), {});
  ASSERT_TRUE(gp.ok()) << gp.status().message();
  const std::string path =
      (std::filesystem::temp_directory_path() / ("roamlab_odometry_model_" + std::to_string(::getpid()) + ".json"))
          .string();
  for (ModelKind kind : {ModelKind::kGp, ModelKind::kLinear, ModelKind::kNominal}) {
    OdometryModel model;
    model.kind = kind;
    model.platform = "differential_drive";
    model.wheels = {"right", "left"};
    model.gp = kind == ModelKind::kGp ? std::optional<GaussianProcess>(gp.value()) : std::nullopt;
    model.W = Eigen::MatrixXd::Random(3, 2);
    model.kinematics = truth;
    ASSERT_TRUE(SaveOdometryModel(model, path).ok());
    Result<OdometryModel> loaded = LoadOdometryModel(path);
    ASSERT_TRUE(loaded.ok()) << loaded.status().message();
    EXPECT_EQ(loaded.value().kind, kind);
    const Eigen::Vector2d delta(1.3, 1.7);
    EXPECT_LT((loaded.value().Predict(delta) - model.Predict(delta)).norm(), 1e-12) << ModelKindName(kind);
  }
  std::filesystem::remove(path);
  EXPECT_FALSE(LoadOdometryModel(path).ok());
}

}  // namespace
}  // namespace roamlab::estimator::odometry
