#include "estimator/odometry/trajectory.h"

#include <cmath>

#include <gtest/gtest.h>

namespace roamlab::estimator::odometry {
namespace {

TEST(Se2Test, InverseAndBetween) {
  const Pose2 a(1.0, -2.0, 0.7);
  const Pose2 b(0.3, 0.5, -2.9);
  EXPECT_LT(Compose(Inverse(a), a).norm(), 1e-15);
  EXPECT_LT((Compose(a, Between(a, b)) - Pose2(b[0], b[1], b[2])).head<2>().norm(), 1e-14);
  EXPECT_NEAR(WrapAngle(Compose(a, Between(a, b))[2] - b[2]), 0.0, 1e-14);
  // Table I by hand: a (+) b.
  const Pose2 c = Compose(Pose2(1.0, 0.0, M_PI / 2), Pose2(1.0, 0.0, 0.0));
  EXPECT_NEAR(c[0], 1.0, 1e-15);
  EXPECT_NEAR(c[1], 1.0, 1e-15);
}

// A model with a 1 % scale error driving straight: ATE (eq. 11) and RPE (eq. 10) by hand.
TEST(TrajectoryTest, AteAndRpeOfAScaledStraightLine) {
  const DisplacementFunction truth = [](const Eigen::VectorXd& d) { return Pose2(0.1 * d[0], 0.0, 0.0); };
  const DisplacementFunction scaled = [](const Eigen::VectorXd& d) { return Pose2(0.101 * d[0], 0.0, 0.0); };
  const Eigen::MatrixXd delta = Eigen::MatrixXd::Ones(10, 1);
  const Pose2 start(2.0, 3.0, M_PI / 2);
  const std::vector<Pose2> ref = PredictTrajectory(truth, delta, start);
  const std::vector<Pose2> est = PredictTrajectory(scaled, delta, start);
  ASSERT_EQ(ref.size(), 11u);
  EXPECT_NEAR(ref.back()[1], 4.0, 1e-12);  // heading north: 10 x 0.1 m along y
  EXPECT_LT(RootMeanSquare(AbsoluteErrors(ref, ref)), 1e-15);
  double sum = 0.0;
  for (int k = 0; k <= 10; ++k) sum += std::pow(0.001 * k, 2);
  EXPECT_NEAR(RootMeanSquare(AbsoluteErrors(est, ref)), std::sqrt(sum / 11.0), 1e-12);
  EXPECT_NEAR(RootMeanSquare(RelativeErrors(est, ref)), 0.001, 1e-12);
}

}  // namespace
}  // namespace roamlab::estimator::odometry
