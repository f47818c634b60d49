#include "estimator/models/ackermann_velocity.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

constexpr double kL = 1.25;

// Pose after dt on a planar arc at speed v and yaw rate omega, from pose0 (eq. 7 is exact for a constant twist only
// up to the chord; VelocitiesBetween inverts eq. 7 exactly, so build pose1 with PredictPose).
Eigen::VectorXd Step(const Eigen::VectorXd& pose0, double v, double omega, double dt) {
  const Pose<double> p1 = PredictPose<double>(PoseFromArray(pose0.data()), Eigen::Vector3d(v, 0, 0),
                                              Eigen::Vector3d(0, 0, omega), dt);
  Eigen::VectorXd out(7);
  PoseToArray(p1, out.data());
  return out;
}

TEST(AckermannVelocityErrorTest, ZeroAtTruthForTableIAndSkewedGains) {
  std::mt19937 rng(11);
  for (const auto& [kv_over_l, k_theta, k_gamma] :
       std::vector<std::tuple<double, double, double>>{{0.8, 1.0, 0.0}, {0.8, 1.05, 0.02}}) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 10.0);
    const double v = 4.0, delta = 0.2, dt = 0.01;
    const double omega = v * std::tan(delta) / kL;
    const double z_v = v / (kv_over_l * kL);
    const double z_theta = (delta - k_gamma) / k_theta;
    const auto factor = MakeFactor(AckermannVelocityError(z_v, z_theta, kL, dt));
    const auto lin = testing::Evaluate(*factor, {pose0, Step(pose0, v, omega, dt), Eigen::VectorXd::Constant(1, kv_over_l),
                                                 Eigen::VectorXd::Constant(1, k_theta),
                                                 Eigen::VectorXd::Constant(1, k_gamma)});
    EXPECT_LT(lin.error.norm(), 1e-10);
    EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::MatrixXd::Identity(4, 4)));
  }
}

TEST(AckermannVelocityErrorTest, SpeedErrorScalesWithGain) {
  // 10% too large a gain predicts a reading 1/1.1 of the one taken.
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  const auto factor = MakeFactor(AckermannVelocityError(4.0 / kL / 0.8, 0.0, kL, 0.01));
  const auto lin = testing::Evaluate(*factor, {pose0, Step(pose0, 4.0, 0.0, 0.01), Eigen::VectorXd::Constant(1, 0.88),
                                               Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, 0.0)});
  EXPECT_NEAR(lin.error[0], 4.0 / kL / 0.88 - 4.0 / kL / 0.8, 1e-12);
}

TEST(AckermannVelocityErrorTest, SteeringIgnoredAtStandstill) {
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  const auto factor = MakeFactor(AckermannVelocityError(0.0, 0.3, kL, 0.01));
  const auto lin = testing::Evaluate(*factor, {pose0, pose0, Eigen::VectorXd::Constant(1, 0.8),
                                               Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, 0.0)});
  EXPECT_LT(lin.error.norm(), 1e-12);
}

TEST(AckermannVelocityErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd pose1 = testing::Perturb(Manifold::Pose(), Step(pose0, 3.0 + trial, 0.2, 0.02), 0.002, &rng);
    const auto factor = MakeFactor(AckermannVelocityError(4.0, 0.1, kL, 0.02));
    testing::ExpectJacobiansMatchNumeric(
        *factor, {pose0, pose1, Eigen::VectorXd::Constant(1, 0.78), Eigen::VectorXd::Constant(1, 1.02),
                  Eigen::VectorXd::Constant(1, 0.01)},
        1e-5);
  }
}

TEST(AckermannVelocityErrorTest, SmallSolveRecoversSpeedAndSteeringCalibration) {
  testing::SmallProblem problem = testing::AckermannProblem<AckermannVelocityError>(false, 17);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(AckermannVelocityErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = testing::AckermannProblem<AckermannVelocityError>(true, 18);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: every standard deviation is below a third of the smallest offset the solve started from (0.02 1/m,
  // 0.05, 0.02 rad).
  EXPECT_LT(sigma.maxCoeff(), 0.02 / 3.0) << sigma.transpose();
}

}  // namespace
}  // namespace roamlab::estimator
