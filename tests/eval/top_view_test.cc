#include "eval/top_view.h"

#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace roamlab::eval {
namespace {

constexpr double kPi = 3.14159265358979323846;

StampedPose Pose(double seconds, double x, double y, double yaw) {
  StampedPose pose;
  pose.t = Time::FromNanoseconds(static_cast<std::int64_t>(std::llround(seconds * 1e9)));
  pose.p_world_body = Eigen::Vector3d(x, y, 0.5);
  pose.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return pose;
}

Time At(double seconds) { return Time::FromNanoseconds(static_cast<std::int64_t>(std::llround(seconds * 1e9))); }

// Linear in position; the yaw goes the shorter way across +-pi.
TEST(PlanarPoseAtTest, InterpolatesPositionAndYawAlongTheShorterArc) {
  const Trajectory trajectory = {Pose(0.0, 0.0, 0.0, 0.0), Pose(1.0, 2.0, -4.0, 0.5), Pose(2.0, 2.0, -4.0, kPi - 0.1),
                                 Pose(3.0, 2.0, -4.0, -kPi + 0.1)};
  Eigen::Vector3d pose;
  ASSERT_TRUE(PlanarPoseAt(trajectory, At(0.25), &pose));
  EXPECT_NEAR(pose.x(), 0.5, 1e-12);
  EXPECT_NEAR(pose.y(), -1.0, 1e-12);
  EXPECT_NEAR(pose.z(), 0.125, 1e-12);
  ASSERT_TRUE(PlanarPoseAt(trajectory, At(2.5), &pose));
  EXPECT_NEAR(pose.z(), kPi, 1e-9);  // half-way across the seam, not back through zero
  ASSERT_TRUE(PlanarPoseAt(trajectory, At(3.0), &pose));
  EXPECT_NEAR(std::remainder(pose.z() - (-kPi + 0.1), 2.0 * kPi), 0.0, 1e-9);
}

TEST(PlanarPoseAtTest, FalseOutsideTheSpan) {
  const Trajectory trajectory = {Pose(1.0, 0.0, 0.0, 0.0), Pose(2.0, 1.0, 0.0, 0.0)};
  Eigen::Vector3d pose;
  EXPECT_FALSE(PlanarPoseAt(trajectory, At(0.5), &pose));
  EXPECT_FALSE(PlanarPoseAt(trajectory, At(2.5), &pose));
  EXPECT_FALSE(PlanarPoseAt({trajectory.front()}, At(1.0), &pose));
}

}  // namespace
}  // namespace roamlab::eval
