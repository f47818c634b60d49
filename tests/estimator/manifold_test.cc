#include "estimator/manifold.h"

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tests/estimator/factor_testing.h"
#include "tests/estimator/manifold_testing.h"

namespace roamlab::estimator {
namespace {

// Points at which each manifold's invariants are checked: the identity and a few seeded random points.
std::vector<Eigen::VectorXd> TestPoints(const Manifold& manifold, std::uint32_t seed, double scale) {
  std::mt19937 rng(seed);
  std::vector<Eigen::VectorXd> points = {manifold.Identity()};
  for (int k = 0; k < 4; ++k) points.push_back(testing::RandomPoint(manifold, &rng, scale));
  return points;
}

template <typename Block>
void ExpectInvariantsAtTestPoints(std::uint32_t seed, double scale) {
  int k = 0;
  for (const Eigen::VectorXd& x : TestPoints(Block::manifold(), seed, scale)) {
    SCOPED_TRACE(::testing::Message() << "point " << k << ": " << x.transpose());
    testing::ExpectBlockInvariantsHold<Block>(x, seed + static_cast<std::uint32_t>(++k), 8, scale);
  }
}

TEST(ManifoldTest, EuclideanInvariantsHold) {
  ExpectInvariantsAtTestPoints<ScalarBlock>(1, 3.0);
  ExpectInvariantsAtTestPoints<Vector3Block>(2, 3.0);
  ExpectInvariantsAtTestPoints<Matrix3Block>(3, 3.0);
  // Dimensions with no compile-time block: the runtime invariants only.
  for (const int dim : {2, 6}) {
    const Manifold manifold = Manifold::Euclidean(dim);
    for (const Eigen::VectorXd& x : TestPoints(manifold, 4, 3.0)) testing::ExpectManifoldInvariantsHold(manifold, x, 5);
  }
}

TEST(ManifoldTest, UnitQuaternionInvariantsHold) { ExpectInvariantsAtTestPoints<QuaternionBlock>(11, 1.0); }

TEST(ManifoldTest, PoseInvariantsHold) {
  ExpectInvariantsAtTestPoints<PoseBlock>(21, 1.0);
  ExpectInvariantsAtTestPoints<PoseBlock>(22, 100.0);  // far from the origin, as a pose in a recording's world frame
}

// Rotations of almost pi: x [-] y of two quaternions whose relative rotation is near the cut of Log.
TEST(ManifoldTest, UnitQuaternionMinusNearAHalfTurn) {
  const Manifold manifold = Manifold::UnitQuaternion();
  std::mt19937 rng(31);
  for (const double gap : {1e-3, 1e-6, 1e-9}) {
    const Eigen::VectorXd x = testing::RandomPoint(manifold, &rng);
    const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
    const Eigen::VectorXd d = (M_PI - gap) * axis;
    const Eigen::VectorXd y = testing::Plus(manifold, x, d);
    EXPECT_LE((testing::Minus(manifold, y, x) - d).norm(), testing::kRoundingUlps * testing::kEpsilon * M_PI)
        << "gap " << gap;
  }
}

TEST(ManifoldTest, NamesAndIdentities) {
  EXPECT_EQ(Manifold::Euclidean(3).Name(), "R3");
  EXPECT_EQ(Manifold::UnitQuaternion().Name(), "S3");
  EXPECT_EQ(Manifold::Pose().Name(), "SE3");
  EXPECT_EQ(Manifold::UnitQuaternion().Identity(), Eigen::Vector4d(1, 0, 0, 0));
  Eigen::VectorXd pose_identity(7);
  pose_identity << 0, 0, 0, 1, 0, 0, 0;
  EXPECT_EQ(Manifold::Pose().Identity(), pose_identity);
  EXPECT_EQ(Manifold::Euclidean(2).Identity(), Eigen::Vector2d::Zero());
  EXPECT_TRUE(Manifold::Pose() == PoseBlock::manifold());
  EXPECT_FALSE(Manifold::Euclidean(3) == Manifold::Euclidean(4));
  EXPECT_FALSE(Manifold::Euclidean(4) == Manifold::UnitQuaternion());
}

}  // namespace
}  // namespace roamlab::estimator
