#include "estimator/models/process.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::RandomPoint;

TEST(RandomWalkErrorTest, ZeroWhenUnchangedAndDifferenceOtherwise) {
  std::mt19937 rng(31);
  const Eigen::VectorXd x0 = RandomPoint(Manifold::Euclidean(3), &rng);
  const Eigen::VectorXd x1 = RandomPoint(Manifold::Euclidean(3), &rng);
  const auto factor = MakeFactor(RandomWalkError<3>(0.02));
  EXPECT_LT(testing::Evaluate(*factor, {x0, x0}).error.norm(), 1e-15);
  const testing::Linearization lin = testing::Evaluate(*factor, {x0, x1});
  EXPECT_LT((lin.error - (x1 - x0)).norm(), 1e-15);
  EXPECT_TRUE(lin.jacobians[0].isApprox(-Eigen::Matrix3d::Identity()));
  EXPECT_TRUE(lin.jacobians[1].isApprox(Eigen::Matrix3d::Identity()));
  EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::Matrix3d::Identity()));
}

TEST(RandomWalkErrorTest, NoiseVarianceGrowsWithDt) {
  // Density 0.01 u/sqrt(s) over 0.04 s: variance 0.01^2 * 0.04.
  EXPECT_DOUBLE_EQ(RandomWalkError<1>(0.04).NoiseVariance(0.01), 4e-6);
  EXPECT_DOUBLE_EQ(RandomWalkError<1>(0.16).NoiseVariance(0.01), 16e-6);
}

TEST(RandomWalkErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(32);
  std::uniform_real_distribution<double> dt(0.01, 0.05);
  for (int trial = 0; trial < 5; ++trial) {
    SCOPED_TRACE(trial);
    const RandomWalkError<3> model(dt(rng));
    const std::vector<Eigen::VectorXd> values = {RandomPoint(Manifold::Euclidean(3), &rng),
                                                 RandomPoint(Manifold::Euclidean(3), &rng)};
    testing::ExpectModelJacobiansMatchNumeric(model, values);
  }
}

TEST(GaussMarkovErrorTest, ZeroOnTheDecayedValue) {
  std::mt19937 rng(33);
  const double dt = 0.05, tau = 2.0;
  const double decay = std::exp(-dt / tau);
  const Eigen::VectorXd x0 = RandomPoint(Manifold::Euclidean(3), &rng);
  const auto factor = MakeFactor(GaussMarkovError<3>(dt, tau));
  const Eigen::VectorXd decayed = decay * x0;
  EXPECT_LT(testing::Evaluate(*factor, {x0, decayed}).error.norm(), 1e-15);
  // Holding the value still is an error of (1 - decay) x0: the process pulls towards zero.
  const testing::Linearization lin = testing::Evaluate(*factor, {x0, x0});
  EXPECT_LT((lin.error - (1.0 - decay) * x0).norm(), 1e-15);
  EXPECT_GT(lin.error.norm(), 1e-3 * x0.norm());
  EXPECT_TRUE(lin.jacobians[0].isApprox(-decay * Eigen::Matrix3d::Identity()));
  EXPECT_TRUE(lin.jacobians[1].isApprox(Eigen::Matrix3d::Identity()));
}

TEST(GaussMarkovErrorTest, NoiseVarianceKeepsTheProcessStationary) {
  // var(x1) = decay^2 var(x0) + var(eta) must equal var(x0) = sigma^2 for the stationary process.
  const double sigma = 0.3;
  const GaussMarkovError<1> model(0.05, 2.0);
  EXPECT_NEAR(model.decay() * model.decay() * sigma * sigma + model.NoiseVariance(sigma), sigma * sigma, 1e-15);
  EXPECT_NEAR(model.NoiseVariance(sigma), sigma * sigma * (1.0 - std::exp(-2.0 * 0.05 / 2.0)), 1e-15);
}

TEST(GaussMarkovErrorTest, ApproachesRandomWalkForDtMuchSmallerThanTau) {
  // Residual: decay = 1 - dt/tau + ..., so the two errors differ by about (dt / tau) x0. Noise: sigma^2 (1 -
  // exp(-2 dt / tau)) = (sigma sqrt(2 / tau))^2 dt (1 - dt / tau + ...).
  std::mt19937 rng(34);
  const double dt = 0.01, tau = 1e4, sigma = 0.5;
  const Eigen::VectorXd x0 = RandomPoint(Manifold::Euclidean(3), &rng);
  const Eigen::VectorXd x1 = RandomPoint(Manifold::Euclidean(3), &rng);
  const GaussMarkovError<3> gauss_markov(dt, tau);
  const RandomWalkError<3> random_walk(dt);
  const testing::Linearization gm = testing::Evaluate(*MakeFactor(gauss_markov), {x0, x1});
  const testing::Linearization rw = testing::Evaluate(*MakeFactor(random_walk), {x0, x1});
  EXPECT_LT((gm.error - rw.error).norm(), 1.01 * dt / tau * x0.norm());
  EXPECT_GT((gm.error - rw.error).norm(), 0.99 * dt / tau * x0.norm());
  const double rw_density = sigma * std::sqrt(2.0 / tau);
  EXPECT_NEAR(gauss_markov.NoiseVariance(sigma) / random_walk.NoiseVariance(rw_density), 1.0, 2.0 * dt / tau);
}

TEST(GaussMarkovErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(35);
  std::uniform_real_distribution<double> dt(0.01, 0.05), tau(0.5, 100.0);
  for (int trial = 0; trial < 5; ++trial) {
    SCOPED_TRACE(trial);
    const GaussMarkovError<3> model(dt(rng), tau(rng));
    const std::vector<Eigen::VectorXd> values = {RandomPoint(Manifold::Euclidean(3), &rng),
                                                 RandomPoint(Manifold::Euclidean(3), &rng)};
    testing::ExpectModelJacobiansMatchNumeric(model, values);
  }
}

// Components with their own correlation times (the odometer's speed, lateral and vertical disturbance): each decays
// by its own exp(-dt / tau_i) and keeps its own stationary spread.
TEST(GaussMarkovErrorTest, PerComponentCorrelationTimes) {
  std::mt19937 rng(36);
  const double dt = 0.01;
  const Eigen::Vector3d tau(0.68, 1.18, 1.82), sigma(0.0061, 0.0020, 0.0253);
  const GaussMarkovError<3> model(dt, tau);
  const Eigen::VectorXd x0 = RandomPoint(Manifold::Euclidean(3), &rng);
  const Eigen::Vector3d decay = (-dt / tau.array()).exp();
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(model), {x0, x0});
  EXPECT_LT((lin.error - (Eigen::Vector3d::Ones() - decay).cwiseProduct(x0)).norm(), 1e-15);
  EXPECT_TRUE(lin.jacobians[0].isApprox(-Eigen::Matrix3d(decay.asDiagonal())));
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(model.decay(i), decay[i]);
    EXPECT_NEAR(decay[i] * decay[i] * sigma[i] * sigma[i] + model.NoiseVariance(sigma[i], i), sigma[i] * sigma[i],
                1e-18);
  }
  testing::ExpectModelJacobiansMatchNumeric(model, {x0, RandomPoint(Manifold::Euclidean(3), &rng)});
}

TEST(ProcessErrorDeathTest, RejectsNonPositiveTimes) {
  EXPECT_DEATH(RandomWalkError<1>(0.0), "dt");
  EXPECT_DEATH(GaussMarkovError<1>(0.01, -1.0), "tau");
}

}  // namespace
}  // namespace roamlab::estimator
