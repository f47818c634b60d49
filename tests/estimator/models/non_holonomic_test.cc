#include "estimator/models/non_holonomic.h"

#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::RandomPoint;

// A vehicle driving along its x axis while it turns: zero error at the body origin; the same motion seen at a point
// ahead of the origin moves sideways by omega_z times the distance.
TEST(NonHolonomicErrorTest, ZeroAlongTheBodyXAndTheLeverArmsSideSlipInATurn) {
  const double dt = 0.1, v = 1.5, yaw_rate = 0.4;
  const Pose<double> pose0{Eigen::Vector3d(1.0, 2.0, 0.3),
                           Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()))};
  const Pose<double> pose1 = PredictPose<double>(pose0, Eigen::Vector3d(v, 0, 0), Eigen::Vector3d(0, 0, yaw_rate), dt);
  Eigen::VectorXd x0(7), x1(7);
  PoseToArray(pose0, x0.data());
  PoseToArray(pose1, x1.data());
  const auto factor = MakeFactor(NonHolonomicError(dt));
  const testing::Linearization at_origin = testing::Evaluate(*factor, {x0, x1, Eigen::Vector3d::Zero()});
  EXPECT_LT(at_origin.error.norm(), 1e-12);
  EXPECT_TRUE(at_origin.noise_jacobian.isApprox(Eigen::Matrix2d::Identity()));
  const Eigen::Vector3d ahead(0.4, 0.0, 0.0);
  const testing::Linearization at_ahead = testing::Evaluate(*factor, {x0, x1, ahead});
  EXPECT_NEAR(at_ahead.error[0], yaw_rate * ahead.x(), 1e-9);
  EXPECT_NEAR(at_ahead.error[1], 0.0, 1e-12);
}

TEST(NonHolonomicErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose0 = RandomPoint(Manifold::Pose(), &rng, 2.0);
    const Eigen::VectorXd pose1 = RandomPoint(Manifold::Pose(), &rng, 2.0);
    const Eigen::VectorXd lever = RandomPoint(Manifold::Euclidean(3), &rng);
    testing::ExpectJacobiansMatchNumeric(*MakeFactor(NonHolonomicError(0.1)), {pose0, pose1, lever});
  }
}

}  // namespace
}  // namespace roamlab::estimator
