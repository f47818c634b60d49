#include "eval/montecarlo.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace roamlab::eval {
namespace {

Time At(double seconds) { return Time::FromNanoseconds(static_cast<std::int64_t>(std::llround(seconds * 1e9))); }

StampedPose Pose(double seconds, const Eigen::Vector3d& p) {
  StampedPose pose;
  pose.t = At(seconds);
  pose.p_world_body = p;
  return pose;
}

// Only the estimate's poses with a truth pose at the same stamp count; the NEES is e^T C^-1 e with the given
// covariance, the ATE the root mean square of |e| over those poses.
TEST(MatchedNeesTest, PairsEqualStampsOnly) {
  const Trajectory truth = {Pose(0.0, {0, 0, 0}), Pose(1.0, {1, 0, 0}), Pose(2.0, {2, 0, 0})};
  const Trajectory estimate = {Pose(0.5, {9, 9, 9}), Pose(1.0, {1, 0.2, 0}), Pose(2.0, {2, 0, 0.4})};
  const std::vector<Eigen::Matrix3d> covariance(3, 0.04 * Eigen::Matrix3d::Identity());
  const RunNees r = MatchedNees(estimate, covariance, truth);
  ASSERT_EQ(r.t.size(), 2u);
  EXPECT_EQ(r.t[0], At(1.0));
  EXPECT_NEAR(r.nees[0], 1.0, 1e-12);  // 0.2^2 / 0.04
  EXPECT_NEAR(r.nees[1], 4.0, 1e-12);  // 0.4^2 / 0.04
  EXPECT_NEAR(r.mean_nees, 2.5, 1e-12);
  EXPECT_NEAR(r.ate_m, std::sqrt((0.04 + 0.16) / 2.0), 1e-12);

  const Trajectory late = {Pose(5.0, {0, 0, 0})};
  EXPECT_TRUE(MatchedNees(late, {Eigen::Matrix3d::Identity()}, truth).t.empty());
}

// The runs are averaged on the stamps they share; a NaN NEES counts as +Inf (a diverged run).
TEST(AggregateRunNeesTest, AveragesOnTheCommonStamps) {
  RunNees a, b;
  a.t = {At(0.0), At(1.0), At(2.0)};
  a.nees = {1.0, 2.0, 3.0};
  b.t = {At(1.0), At(2.0), At(3.0)};
  b.nees = {4.0, std::numeric_limits<double>::quiet_NaN(), 6.0};
  const Result<MonteCarloNees> nees = AggregateRunNees({a, b}, 0.0);
  ASSERT_TRUE(nees.ok());
  EXPECT_EQ(nees.value().runs, 2);
  ASSERT_EQ(nees.value().t.size(), 2u);
  EXPECT_EQ(nees.value().t[0], At(1.0));
  EXPECT_DOUBLE_EQ(nees.value().mean_nees[0], 3.0);
  EXPECT_TRUE(std::isinf(nees.value().mean_nees[1]));

  RunNees c;
  c.t = {At(7.0)};
  c.nees = {1.0};
  EXPECT_FALSE(AggregateRunNees({a, c}, 0.0).ok());
}

}  // namespace
}  // namespace roamlab::eval
