#include "estimator/models/gyroscope.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::Perturb;
using testing::RandomPoint;

constexpr double kPi = 3.14159265358979323846;

Eigen::VectorXd PoseVector(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  Eigen::VectorXd x(7);
  x << p, q.w(), q.x(), q.y(), q.z();
  return x;
}

Eigen::VectorXd QuaternionVector(const Eigen::Quaterniond& q) { return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()); }

// Rotation by angle |w| about w, built with Eigen's angle-axis rather than geometry.h.
Eigen::Quaterniond RotationAbout(const Eigen::Vector3d& w) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(w.norm(), w.normalized()));
}

TEST(GyroscopeErrorTest, ZeroAtTruth) {
  std::mt19937 rng(11);
  const Eigen::VectorXd pose0 = RandomPoint(Manifold::Pose(), &rng, 10.0);
  const Eigen::Quaterniond q_body_sensor(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 2.0, -1.0).normalized()));
  const Eigen::Vector3d bias(0.01, -0.02, 0.005);
  const Eigen::Vector3d scale(1.02, 0.97, 1.05);
  const Eigen::Vector3d omega_sensor(0.4, -0.7, 1.1);
  const double dt = 0.02;

  // The body turns at q_body_sensor * omega_sensor for dt; the sensor reports its rate through gain and bias.
  const Eigen::Vector3d omega_body = q_body_sensor * omega_sensor;
  const Eigen::Quaterniond q0 = PoseFromArray(pose0.data()).q_world_body;
  const Eigen::Quaterniond q1 = q0 * RotationAbout(omega_body * dt);
  const Eigen::VectorXd pose1 = PoseVector(Eigen::Vector3d(3.0, -1.0, 2.0), q1);
  const Eigen::Vector3d z = scale.cwiseProduct(omega_sensor) + bias;

  const GyroscopeError model(z, dt);
  const std::vector<Eigen::VectorXd> values = {pose0, pose1, QuaternionVector(q_body_sensor), bias, scale};
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(model), values);
  EXPECT_LT(lin.error.norm(), 1e-12);

  // At e = 0 the noise Jacobian is -dt R(q1) R(q_body_sensor) diag(1/scale) up to O(|omega dt|).
  const Eigen::Matrix3d expected_noise_jacobian = -dt * q1.toRotationMatrix() * q_body_sensor.toRotationMatrix() *
                                                  scale.cwiseInverse().asDiagonal();
  EXPECT_LT((lin.noise_jacobian - expected_noise_jacobian).norm(), 0.05 * dt);
  EXPECT_LT((lin.noise_jacobian - testing::NumericNoiseJacobian(model, values)).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(GyroscopeErrorTest, ErrorIsWorldRotationFromEstimateToPrediction) {
  // With the pose at t+1 turned back by delta in W from the prediction, e = Log(q_hat q1^-1) = delta.
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.0, 0.6, 0.8)));
  const Eigen::Vector3d omega(0.2, 0.1, -0.3);
  const double dt = 0.05;
  const Eigen::Quaterniond q_hat = q0 * RotationAbout(omega * dt);
  const Eigen::Vector3d delta(0.01, -0.02, 0.015);
  const Eigen::Quaterniond q1 = RotationAbout(delta).conjugate() * q_hat;
  const std::vector<Eigen::VectorXd> values = {PoseVector(Eigen::Vector3d::Zero(), q0),
                                               PoseVector(Eigen::Vector3d::Zero(), q1),
                                               QuaternionVector(Eigen::Quaterniond::Identity()),
                                               Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(GyroscopeError(omega, dt)), values);
  EXPECT_LT((lin.error - delta).norm(), 1e-12);
}

TEST(GyroscopeErrorTest, MisalignmentRoutesSensorAxesToBodyAxes) {
  // q_body_sensor = 90 deg about z maps the sensor's x axis to Rz(90) [1, 0, 0] = [0, 1, 0], the body's y axis: a rate
  // of +0.5 rad/s read on sensor x turns the body about its own +y axis at 0.5 rad/s.
  const Eigen::Quaterniond q_body_sensor(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1.0, 0.0, 1.0).normalized()));
  const double rate = 0.5;
  const double dt = 0.04;
  const GyroscopeError model(Eigen::Vector3d(rate, 0.0, 0.0), dt);
  const auto factor = MakeFactor(model);
  auto error_for_body_axis = [&](const Eigen::Vector3d& axis_body) {
    const Eigen::Quaterniond q1 = q0 * RotationAbout(axis_body * rate * dt);
    return testing::Evaluate(*factor, {PoseVector(Eigen::Vector3d::Zero(), q0),
                                       PoseVector(Eigen::Vector3d::Zero(), q1), QuaternionVector(q_body_sensor),
                                       Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()})
        .error;
  };
  EXPECT_LT(error_for_body_axis(Eigen::Vector3d::UnitY()).norm(), 1e-12);
  // About the body's x axis (no misalignment) or about -y (wrong sign) the error is the angle between the rotations.
  EXPECT_NEAR(error_for_body_axis(Eigen::Vector3d::UnitX()).norm(), std::sqrt(2.0) * rate * dt, 1e-6);
  EXPECT_NEAR(error_for_body_axis(-Eigen::Vector3d::UnitY()).norm(), 2.0 * rate * dt, 1e-6);
}

TEST(GyroscopeErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> dt_dist(0.01, 0.05);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose0 = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd pose1 = Perturb(Manifold::Pose(), pose0, 0.05, &rng);
    const Eigen::VectorXd q_body_sensor = Perturb(Manifold::UnitQuaternion(),
                                                  Manifold::UnitQuaternion().Identity(), 0.3, &rng);
    const Eigen::VectorXd bias = RandomPoint(Manifold::Euclidean(3), &rng, 0.1);
    const Eigen::VectorXd scale = Eigen::Vector3d::Ones() + RandomPoint(Manifold::Euclidean(3), &rng, 0.05);
    const Eigen::Vector3d z = RandomPoint(Manifold::Euclidean(3), &rng, 1.0);
    const GyroscopeError model(z, dt_dist(rng));
    const std::vector<Eigen::VectorXd> values = {pose0, pose1, q_body_sensor, bias, scale};
    const auto factor = MakeFactor(model);
    testing::ExpectJacobiansMatchNumeric(*factor, values);
    const testing::Linearization lin = testing::Evaluate(*factor, values);
    EXPECT_LT((lin.noise_jacobian - testing::NumericNoiseJacobian(model, values)).cwiseAbs().maxCoeff(), 1e-8);
  }
}

}  // namespace
}  // namespace roamlab::estimator
