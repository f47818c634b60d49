#include "eval/metrics.h"

#include <cmath>

#include <gtest/gtest.h>

namespace roamlab::eval {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = 180.0 / kPi;

// A reference drive: speed 2 m/s along a circle of radius 10 m (yaw rate 0.2 rad/s), climbing 0.1 m/s, sampled every
// dt seconds; the body x axis follows the path.
Trajectory CircleDrive(int poses, double dt) {
  Trajectory trajectory(poses);
  for (int i = 0; i < poses; ++i) {
    const double t = i * dt;
    const double yaw = 0.2 * t;
    trajectory[i].t = Time::FromSeconds(t);
    trajectory[i].p_world_body = Eigen::Vector3d(10.0 * std::sin(yaw), 10.0 - 10.0 * std::cos(yaw), 0.1 * t);
    trajectory[i].q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  }
  return trajectory;
}

TEST(MetricsTest, SummarizeComputesRmseMeanMedianMax) {
  const ErrorStatistics even = Summarize({4.0, 3.0});
  EXPECT_EQ(even.count, 2u);
  EXPECT_DOUBLE_EQ(even.rmse, std::sqrt(12.5));
  EXPECT_DOUBLE_EQ(even.mean, 3.5);
  EXPECT_DOUBLE_EQ(even.median, 3.5);
  EXPECT_DOUBLE_EQ(even.max, 4.0);
  EXPECT_DOUBLE_EQ(Summarize({5.0, 1.0, 2.0}).median, 2.0);
  EXPECT_DOUBLE_EQ(even.std, 0.5);
  EXPECT_DOUBLE_EQ(even.min, 3.0);
  const ErrorStatistics none = Summarize({});
  EXPECT_EQ(none.count, 0u);
  EXPECT_TRUE(std::isnan(none.rmse));
}

TEST(MetricsTest, AteOfATransformedCopyIsZeroAfterAlignment) {
  const Trajectory reference = CircleDrive(200, 0.1);
  RigidTransform t_est_ref;  // the estimate seen from a rotated and shifted world frame
  t_est_ref.q_ref_est = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.1, 0.2, 1.0).normalized()));
  t_est_ref.p_ref_est = Eigen::Vector3d(3.0, -1.0, 0.5);
  const Trajectory estimate = TransformTrajectory(t_est_ref, reference);

  const AbsoluteTrajectoryError se3 = ComputeAte(estimate, reference, AlignmentKind::kSe3);
  EXPECT_LT(se3.statistics.rmse, 1e-10);
  EXPECT_LT(se3.statistics.max, 1e-10);
  // Aligned orientations agree too.
  EXPECT_LT(se3.aligned_estimate[57].q_world_body.angularDistance(reference[57].q_world_body), 1e-10);
}

TEST(MetricsTest, AteWithoutAlignmentEqualsTheOffset) {
  const Trajectory reference = CircleDrive(100, 0.1);
  RigidTransform shift;
  shift.p_ref_est = Eigen::Vector3d(0.3, -0.4, 0.0);  // 0.5 m
  const Trajectory estimate = TransformTrajectory(shift, reference);
  const AbsoluteTrajectoryError none = ComputeAte(estimate, reference, AlignmentKind::kNone);
  EXPECT_NEAR(none.statistics.rmse, 0.5, 1e-12);
  EXPECT_NEAR(none.statistics.mean, 0.5, 1e-12);
  EXPECT_NEAR(none.statistics.max, 0.5, 1e-12);
  EXPECT_LT((none.error_world[10] - shift.p_ref_est).norm(), 1e-12);
  // Yaw + translation alignment removes a pure shift as well.
  EXPECT_LT(ComputeAte(estimate, reference, AlignmentKind::kYawTranslation).statistics.rmse, 1e-10);
}

TEST(MetricsTest, AteRotationAndAxesOfAKnownError) {
  const Trajectory reference = CircleDrive(100, 0.1);
  Trajectory estimate = reference;
  // Every pose 2 deg too far about z, and off by (0.3, -0.4, +-1.2) m: the sign of z alternates.
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    estimate[i].q_world_body =
        estimate[i].q_world_body * Eigen::Quaterniond(Eigen::AngleAxisd(2.0 / kDeg, Eigen::Vector3d::UnitZ()));
    estimate[i].p_world_body += Eigen::Vector3d(0.3, -0.4, i % 2 == 0 ? 1.2 : -1.2);
  }
  const AbsoluteTrajectoryError ate = ComputeAte(estimate, reference, AlignmentKind::kNone);
  EXPECT_NEAR(ate.rotation.rmse, 2.0, 1e-9);
  EXPECT_NEAR(ate.rotation.max, 2.0, 1e-9);
  EXPECT_NEAR(ate.axis[0].mean, 0.3, 1e-12);
  EXPECT_NEAR(ate.axis[1].rmse, 0.4, 1e-12);
  EXPECT_NEAR(ate.axis[2].rmse, 1.2, 1e-12);
  EXPECT_NEAR(ate.axis[2].mean, 0.0, 1e-12);
  EXPECT_NEAR(ate.axis[2].std, 1.2, 1e-12);
  EXPECT_NEAR(ate.axis[2].min, -1.2, 1e-12);
  EXPECT_NEAR(ate.horizontal.rmse, 0.5, 1e-12);
  EXPECT_NEAR(ate.vertical.mean, 1.2, 1e-12);
  EXPECT_NEAR(ate.statistics.rmse, std::sqrt(0.25 + 1.44), 1e-12);
}

TEST(MetricsTest, ConstantDriftGivesItsPerStepRpe) {
  // Estimate = reference + drift * t in the world frame (same orientations): every pair k poses apart is off by
  // |drift| k dt, whatever the heading, and has no rotation error.
  const double dt = 0.1;
  const Trajectory reference = CircleDrive(150, dt);
  const Eigen::Vector3d drift(0.03, -0.04, 0.0);  // 0.05 m/s
  Trajectory estimate = reference;
  for (StampedPose& pose : estimate) pose.p_world_body += drift * pose.t.seconds();
  for (std::size_t k : {1, 10}) {
    const RelativePoseError rpe = RpeByStep(estimate, reference, k);
    ASSERT_EQ(rpe.translation_m.size(), 150 - k);
    for (double e : rpe.translation_m) EXPECT_NEAR(e, 0.05 * k * dt, 1e-12);
    EXPECT_NEAR(rpe.translation.rmse, 0.05 * k * dt, 1e-12);
    EXPECT_LT(rpe.rotation.max, 1e-6);
  }
}

TEST(MetricsTest, ConstantYawRateErrorGivesItsRotationRpe) {
  // The estimated heading runs 0.01 rad/s fast: pairs k poses apart are rotated by 0.01 k dt about z.
  const double dt = 0.05;
  const double yaw_rate_error = 0.01;
  const Trajectory reference = CircleDrive(120, dt);
  Trajectory estimate = reference;
  for (StampedPose& pose : estimate)
    pose.q_world_body =
        pose.q_world_body * Eigen::AngleAxisd(yaw_rate_error * pose.t.seconds(), Eigen::Vector3d::UnitZ());
  const std::size_t k = 20;
  const RelativePoseError rpe = RpeByStep(estimate, reference, k);
  ASSERT_EQ(rpe.rotation_deg.size(), 100u);
  for (double e : rpe.rotation_deg) EXPECT_NEAR(e, yaw_rate_error * k * dt * kDeg, 1e-9);
  EXPECT_NEAR(rpe.rotation.rmse, yaw_rate_error * k * dt * kDeg, 1e-9);

  // Spinning in place: the heading error gives no translation error.
  Trajectory spin_ref = reference;
  Trajectory spin_est = estimate;
  for (std::size_t i = 0; i < spin_ref.size(); ++i)
    spin_ref[i].p_world_body = spin_est[i].p_world_body = Eigen::Vector3d(1.0, 2.0, 3.0);
  EXPECT_LT(RpeByStep(spin_est, spin_ref, k).translation.max, 1e-12);
}

TEST(MetricsTest, RpeIgnoresARigidTransformOfTheWholeEstimate) {
  const Trajectory reference = CircleDrive(80, 0.1);
  RigidTransform t;
  t.q_ref_est = Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d(1.0, 1.0, 0.0).normalized()));
  t.p_ref_est = Eigen::Vector3d(-5.0, 2.0, 1.0);
  const RelativePoseError rpe = RpeByStep(TransformTrajectory(t, reference), reference, 7);
  EXPECT_LT(rpe.translation.max, 1e-10);
  EXPECT_LT(rpe.rotation.max, 1e-6);
}

TEST(MetricsTest, RpeByDistanceUsesSegmentsAlongTheReference) {
  // Straight line, 0.5 m between poses (exact in binary), estimate stretched by 10 %: a 2 m segment spans exactly four
  // steps and is 0.2 m too long in the estimate.
  Trajectory reference(21);
  for (int i = 0; i < 21; ++i) {
    reference[i].t = Time::FromSeconds(0.1 * i);
    reference[i].p_world_body = Eigen::Vector3d(0.5 * i, 0.0, 0.0);
  }
  Trajectory estimate = reference;
  for (StampedPose& pose : estimate) pose.p_world_body *= 1.1;
  const RelativePoseError rpe = RpeByDistance(estimate, reference, 2.0);
  ASSERT_EQ(rpe.first.size(), 17u);
  for (std::size_t n = 0; n < rpe.first.size(); ++n) EXPECT_EQ(rpe.second[n], rpe.first[n] + 4);
  for (double e : rpe.translation_m) EXPECT_NEAR(e, 0.2, 1e-12);
  EXPECT_EQ(RpeByDistance(estimate, reference, 100.0).translation.count, 0u);
}

TEST(MetricsTest, StepForDurationUsesTheMedianPeriod) {
  EXPECT_EQ(StepForDuration(CircleDrive(500, 0.01), 1.0), 100u);
  EXPECT_EQ(StepForDuration(CircleDrive(500, 0.01), 0.001), 1u);
  EXPECT_EQ(StepForDuration(CircleDrive(1, 0.01), 1.0), 1u);
}

TEST(MetricsTest, RotationAngleOfAKnownRotation) {
  EXPECT_NEAR(RotationAngleDeg(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()))), 0.3 * kDeg,
              1e-12);
  // -q is the same rotation.
  Eigen::Quaterniond q(Eigen::AngleAxisd(2.0, Eigen::Vector3d::UnitX()));
  q.coeffs() = -q.coeffs();
  EXPECT_NEAR(RotationAngleDeg(q), 2.0 * kDeg, 1e-10);
}

}  // namespace
}  // namespace roamlab::eval
