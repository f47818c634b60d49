#include "estimator/models/gps.h"

#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::RandomPoint;

TEST(GpsErrorTest, ZeroAtTruth) {
  std::mt19937 rng(1);
  const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 10.0);
  const Eigen::Vector3d lever(0.57, -0.46, 0.32);
  const Pose<double> T = PoseFromArray(pose.data());
  const Eigen::Vector3d z = T.p_world_body + T.q_world_body * lever;
  const auto factor = MakeFactor(GpsError(z));
  const testing::Linearization lin = testing::Evaluate(*factor, {pose, lever});
  EXPECT_LT(lin.error.norm(), 1e-12);
  EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::Matrix3d::Identity()));
}

TEST(GpsErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd lever = RandomPoint(Manifold::Euclidean(3), &rng);
    const Eigen::Vector3d z = RandomPoint(Manifold::Euclidean(3), &rng, 10.0);
    testing::ExpectJacobiansMatchNumeric(*MakeFactor(GpsError(z)), {pose, lever});
  }
}

}  // namespace
}  // namespace roamlab::estimator
