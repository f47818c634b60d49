#include "estimator/tracking.h"

#include <cmath>

#include <gtest/gtest.h>

#include "common/chi_square.h"
#include "tests/estimator/estimation_testing.h"
#include "tests/support/synthetic.h"

namespace roamlab::estimator {
namespace {

// Position error of each tracked pose against the ground truth at the same time stamp.
std::vector<Eigen::Vector3d> PositionErrors(const TrackingResult& r, const Trajectory& truth) {
  std::vector<Eigen::Vector3d> errors;
  std::size_t j = 0;
  for (const StampedPose& p : r.trajectory) {
    while (j < truth.size() && truth[j].t < p.t) ++j;
    EXPECT_LT(j, truth.size());
    EXPECT_EQ(truth[j].t, p.t);
    errors.push_back(p.p_world_body - truth[j].p_world_body);
  }
  return errors;
}

TEST(TrackingTest, NoiseFreeTrackingFollowsTheTruth) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 4.0;
  options.noise = false;
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  auto result = Track(testing::AtvConfig({}, 20), synthetic.recording, {});
  ASSERT_TRUE(result.ok()) << result.status().message();
  // One pose per master sample.
  EXPECT_EQ(result.value().trajectory.size(), synthetic.recording.Find("rear_wheel")->t.size());
  double worst = 0.0;
  for (const Eigen::Vector3d& e : PositionErrors(result.value(), *synthetic.recording.ground_truth))
    worst = std::max(worst, e.norm());
  EXPECT_LT(worst, 0.02);
  EXPECT_GT(result.value().updates, 0);
}

TEST(TrackingTest, NoisyPositionErrorsAreConsistentWithReportedCovariance) {
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 10.0;
  options.seed = 3;
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  auto result = Track(testing::AtvConfig({}, 30), synthetic.recording, {});
  ASSERT_TRUE(result.ok()) << result.status().message();
  const auto errors = PositionErrors(result.value(), *synthetic.recording.ground_truth);
  // Errors are strongly correlated in time, so this is a gross check, not the Monte-Carlo NEES test: at least 90% of
  // the poses within the 99.7% chi-square(3) ellipsoid of their own covariance.
  const double gate = ChiSquareQuantile(0.997, 3);
  int inside = 0;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const double nees = errors[i].dot(result.value().position_covariance[i].ldlt().solve(errors[i]));
    inside += nees <= gate;
  }
  EXPECT_GE(inside, static_cast<int>(0.9 * errors.size()));
}

TEST(TrackingTest, MarginalizationKeepsTheInformationOfTheWindow) {
  // A short window with marginalization must end where a window holding everything ends: the prior carries what
  // the removed poses knew (exact for a linear problem, to within a small fraction of a standard deviation here).
  roamlab::testing::SyntheticOptions options;
  options.duration_s = 3.0;
  options.seed = 5;
  const auto synthetic = roamlab::testing::MakeAtvRecording(options);
  auto sliding = Track(testing::AtvConfig({}, 10), synthetic.recording, {});
  auto whole = Track(testing::AtvConfig({}, 100000), synthetic.recording, {});
  ASSERT_TRUE(sliding.ok() && whole.ok());
  const StampedPose& a = sliding.value().trajectory.back();
  const StampedPose& b = whole.value().trajectory.back();
  ASSERT_EQ(a.t, b.t);
  const Eigen::Matrix3d& cov = whole.value().position_covariance.back();
  const Eigen::Vector3d d = a.p_world_body - b.p_world_body;
  EXPECT_LT(std::sqrt(d.dot(cov.ldlt().solve(d))), 0.2);
  EXPECT_NEAR(std::sqrt(sliding.value().position_covariance.back().trace()), std::sqrt(cov.trace()),
              0.1 * std::sqrt(cov.trace()));
}

}  // namespace
}  // namespace roamlab::estimator
