#include "estimator/models/gyroscope.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::Perturb;
using testing::PoseVector;
using testing::QuaternionVector;
using testing::RandomPoint;
using testing::RotationAbout;

constexpr double kPi = 3.14159265358979323846;

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
  const Eigen::Matrix3d expected_noise_jacobian =
      -dt * q1.toRotationMatrix() * q_body_sensor.toRotationMatrix() * scale.cwiseInverse().asDiagonal();
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
  const std::vector<Eigen::VectorXd> values = {
      PoseVector(Eigen::Vector3d::Zero(), q0), PoseVector(Eigen::Vector3d::Zero(), q1),
      QuaternionVector(Eigen::Quaterniond::Identity()), Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};
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
    return testing::Evaluate(*factor,
                             {PoseVector(Eigen::Vector3d::Zero(), q0), PoseVector(Eigen::Vector3d::Zero(), q1),
                              QuaternionVector(q_body_sensor), Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()})
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
    const Eigen::VectorXd q_body_sensor =
        Perturb(Manifold::UnitQuaternion(), Manifold::UnitQuaternion().Identity(), 0.3, &rng);
    const Eigen::VectorXd bias = RandomPoint(Manifold::Euclidean(3), &rng, 0.1);
    const Eigen::VectorXd scale = Eigen::Vector3d::Ones() + RandomPoint(Manifold::Euclidean(3), &rng, 0.05);
    const Eigen::Vector3d z = RandomPoint(Manifold::Euclidean(3), &rng, 1.0);
    const GyroscopeError model(z, dt_dist(rng));
    const std::vector<Eigen::VectorXd> values = {pose0, pose1, q_body_sensor, bias, scale};
    testing::ExpectModelJacobiansMatchNumeric(model, values);
  }
}

// The gyroscope's small end-to-end problem: a misaligned, biased, scaled gyroscope on the smooth 3-D motion, one
// reading per interval from the motion's own body rate through the sensor model, z = k_s o (R_S^O)^T omega + b + eta.
// The gyroscope sees relative orientations only, so pose priors hold the poses. Misalignment, bias and scale start at
// their nominal values (identity, 0, 1).
testing::SmallProblem GyroscopeProblem(bool noisy, std::uint32_t seed) {
  const double sigma = 0.005;  // [rad/s]
  const Eigen::Quaterniond q_body_sensor = RotationAbout(Eigen::Vector3d(0.1, -0.2, 0.15));
  const Eigen::Vector3d bias(0.02, -0.01, 0.03);
  const Eigen::Vector3d scale(1.03, 0.97, 1.01);
  const testing::TwistTrajectory motion = testing::SmoothMotion(50);

  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.005, 0.0005, noisy, &rng, &problem);
  const VariableId misalignment = testing::AddFreeParameter("misalignment", Manifold::UnitQuaternion(),
                                                            QuaternionVector(Eigen::Quaterniond::Identity()),
                                                            QuaternionVector(q_body_sensor), &problem);
  const VariableId bias_id =
      testing::AddFreeParameter("bias", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), bias, &problem);
  const VariableId scale_id =
      testing::AddFreeParameter("scale", Manifold::Euclidean(3), Eigen::Vector3d::Ones(), scale, &problem);
  for (std::size_t k = 0; k < motion.omega_body.size(); ++k) {
    const Eigen::Vector3d z = scale.cwiseProduct(q_body_sensor.conjugate() * motion.omega_body[k]) + bias +
                              testing::GaussianNoise(3, testing::NoiseSigma(noisy, sigma), &rng);
    problem.graph.AddFactor(MakeFactor(GyroscopeError(z, motion.dt_s)),
                            {problem.poses[k], problem.poses[k + 1], misalignment, bias_id, scale_id},
                            Eigen::Matrix3d::Identity() * sigma * sigma, Loss::Trivial(), "gyroscope",
                            Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

TEST(GyroscopeErrorTest, SmallSolveRecoversMisalignmentBiasAndScale) {
  testing::SmallProblem problem = GyroscopeProblem(false, 13);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(GyroscopeErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = GyroscopeProblem(true, 14);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: every standard deviation is below a third of the smallest offset the solve started from (0.01).
  EXPECT_LT(sigma.maxCoeff(), 0.01 / 3.0) << sigma.transpose();
}

}  // namespace
}  // namespace roamlab::estimator
