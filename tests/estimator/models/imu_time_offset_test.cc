#include "estimator/models/imu_time_offset.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "estimator/models/accelerometer.h"
#include "estimator/models/gyroscope.h"
#include "estimator/models/magnetometer.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::Perturb;
using testing::PoseVector;
using testing::QuaternionVector;
using testing::RandomPoint;
using testing::RotationAbout;

const Eigen::Vector3d kFieldWorld(0.0, 0.6, -0.8);
const Eigen::Quaterniond kQBodySensor(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 2.0, -1.0).normalized()));

Eigen::VectorXd Scalar(double x) { return Eigen::VectorXd::Constant(1, x); }

// Seven poses at uneven steps around a random start, turning and moving by a few centimetres and degrees per step.
std::vector<Eigen::VectorXd> PoseChain(std::mt19937* rng) {
  std::vector<Eigen::VectorXd> poses = {RandomPoint(Manifold::Pose(), rng, 5.0)};
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 6; ++i) {
    const Pose<double> p = PoseFromArray(poses.back().data());
    const Eigen::Vector3d step(0.05 + 0.01 * n(*rng), 0.01 * n(*rng), 0.01 * n(*rng));
    const Eigen::Vector3d turn(0.02 * n(*rng), 0.02 * n(*rng), 0.05 + 0.02 * n(*rng));
    poses.push_back(PoseVector(p.p_world_body + p.q_world_body * step, p.q_world_body * RotationAbout(turn)));
  }
  return poses;
}

const double kDt0 = 0.011, kDt1 = 0.009;
const Eigen::Vector3d kRate(0.8, -2.5, 1.3);
const Eigen::VectorXd kA = (Eigen::VectorXd(9) << 1.05, 0.08, -0.02, -0.03, 0.95, 0.06, 0.1, 0.01, 1.1).finished();
const Eigen::Vector3d kDriveK(4e-4, -2e-4, 1e-4), kForce(1.5, -0.7, 9.6);

// Each model at delta is the plain one with the reading moved to z + delta z' (at delta = 0 the plain one).
TEST(ImuTimeOffsetTest, EachModelIsThePlainOneWithTheReadingMovedAlongItsRate) {
  std::mt19937 rng(3);
  const std::vector<Eigen::VectorXd> p = PoseChain(&rng);
  const Eigen::VectorXd q = QuaternionVector(kQBodySensor);
  const Eigen::Vector3d bias(0.01, -0.02, 0.03), scale(1.02, 0.97, 1.01), lever(0.3, -0.2, 0.5);
  const Eigen::Vector3d z(0.3, -0.4, 9.5);
  const auto error = [](const Factor& f, std::vector<Eigen::VectorXd> values, const double* delta) {
    if (delta != nullptr) values.push_back(Scalar(*delta));
    return testing::Evaluate(f, values).error;
  };
  for (double delta : {0.0, -0.023, 0.031}) {
    const Eigen::Vector3d moved = z + delta * kRate;
    const std::vector<Eigen::VectorXd> gyro = {p[1], p[2], q, bias, scale};
    EXPECT_LT((error(*MakeFactor(GyroscopeTimeOffsetError(GyroscopeError(z, kDt1), kRate)), gyro, &delta) -
               error(*MakeFactor(GyroscopeError(moved, kDt1)), gyro, nullptr))
                  .norm(),
              1e-12);
    const std::vector<Eigen::VectorXd> accel = {p[0], p[1], p[2], q, lever, bias, scale};
    EXPECT_LT(
        (error(*MakeFactor(AccelerometerTimeOffsetError(AccelerometerError(z, kDt0, kDt1), kRate)), accel, &delta) -
         error(*MakeFactor(AccelerometerError(moved, kDt0, kDt1)), accel, nullptr))
            .norm(),
        1e-12);
    const std::vector<Eigen::VectorXd> mag = {p[1], q, kA, bias, kDriveK};
    EXPECT_LT((error(*MakeFactor(MagnetometerTimeOffsetError(MagnetometerError(z, kFieldWorld, kForce, 49.6), kRate)),
                     mag, &delta) -
               error(*MakeFactor(MagnetometerError(moved, kFieldWorld, kForce, 49.6)), mag, nullptr))
                  .norm(),
              1e-12);
  }
}

// The jets' Jacobians, the offset's column among them, against central differences at a non-zero offset.
TEST(ImuTimeOffsetTest, JacobiansMatchCentralDifferences) {
  for (std::uint32_t seed : {5u, 6u, 7u}) {
    std::mt19937 rng(seed);
    const std::vector<Eigen::VectorXd> p = PoseChain(&rng);
    const Eigen::VectorXd q = Perturb(Manifold::UnitQuaternion(), QuaternionVector(kQBodySensor), 0.1, &rng);
    const Eigen::Vector3d bias(0.01, -0.02, 0.03), scale(1.02, 0.97, 1.01), lever(0.3, -0.2, 0.5);
    const Eigen::Vector3d z(0.3, -0.4, 9.5);
    const Eigen::VectorXd delta = Scalar(0.03 * (seed - 6.0) + 0.017);
    const GyroscopeTimeOffsetError gyro(GyroscopeError(Eigen::Vector3d(0.2, -0.1, 4.0), kDt1), kRate);
    testing::ExpectModelJacobiansMatchNumeric(gyro, {p[1], p[2], q, bias, scale, delta});
    testing::ExpectJacobiansMatchNumeric(
        *MakeFactor(AccelerometerTimeOffsetError(AccelerometerError(z, kDt0, kDt1), kRate)),
        {p[0], p[1], p[2], q, lever, bias, scale, delta});
    testing::ExpectJacobiansMatchNumeric(
        *MakeFactor(MagnetometerTimeOffsetError(MagnetometerError(z, kFieldWorld, kForce, 49.6), kRate)),
        {p[1], q, kA, bias, kDriveK, delta});
  }
}

// A turn about a fixed axis at a uniformly growing rate omega(t) = w0 + a t: the reading of [t(k), t(k+1)] stamped
// t(k), the mean rate over [t(k) - delta, t(k+1) - delta], moved along its exact rate a is matched exactly; the
// offset's sign is the simulator's (sim/scenario.h).
TEST(ImuTimeOffsetTest, GyroscopeIsExactOnAUniformlyAcceleratingTurn) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  const double w0 = 0.4, a = 2.5, dt = 0.01, delta = 0.027;
  const auto angle = [&](double t) { return w0 * t + 0.5 * a * t * t; };
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.0, 0.6, 0.8)));
  const Eigen::VectorXd p0 = PoseVector(Eigen::Vector3d::Zero(), q0);
  const Eigen::VectorXd p1 = PoseVector(Eigen::Vector3d::Zero(), q0 * RotationAbout(axis * angle(dt)));
  const double mean_rate = (angle(dt - delta) - angle(-delta)) / dt;
  const Eigen::Vector3d z = kQBodySensor.conjugate() * (axis * mean_rate);
  const Eigen::Vector3d z_rate = kQBodySensor.conjugate() * (axis * a);
  const auto factor = MakeFactor(GyroscopeTimeOffsetError(GyroscopeError(z, dt), z_rate));
  std::vector<Eigen::VectorXd> values = {
      p0, p1, QuaternionVector(kQBodySensor), Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), Scalar(delta)};
  EXPECT_LT(testing::Evaluate(*factor, values).error.norm(), 1e-12);
  values.back() = Scalar(-delta);  // the other sign is off by 2 delta a dt
  EXPECT_NEAR(testing::Evaluate(*factor, values).error.norm(), 2.0 * delta * a * dt, 1e-9);
}

}  // namespace
}  // namespace roamlab::estimator
