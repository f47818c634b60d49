#include "eval/alignment.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace roamlab::eval {
namespace {

// Seeded points spread in 3-D (a hilly drive is not planar; a planar one would leave roll/pitch undetermined).
std::vector<Eigen::Vector3d> RandomPoints(int count, unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) points.emplace_back(u(random), u(random), 0.2 * u(random));
  return points;
}

// The rotation angle between two quaternions [rad].
double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) { return a.angularDistance(b); }

TEST(AlignmentTest, Se3RecoversAKnownRigidTransform) {
  const std::vector<Eigen::Vector3d> p_ref = RandomPoints(50, 1);
  // The estimate is the reference seen from another frame: p_est = T_est_ref p_ref.
  const Eigen::Quaterniond q_ref_est(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()));
  const Eigen::Vector3d p_ref_est(4.0, -2.5, 1.25);
  std::vector<Eigen::Vector3d> p_est;
  for (const Eigen::Vector3d& p : p_ref) p_est.push_back(q_ref_est.conjugate() * (p - p_ref_est));

  const RigidTransform t = AlignPositions(p_est, p_ref, AlignmentKind::kSe3);
  EXPECT_LT(AngleBetween(t.q_ref_est, q_ref_est), 1e-12);
  EXPECT_LT((t.p_ref_est - p_ref_est).norm(), 1e-11);
  for (std::size_t i = 0; i < p_ref.size(); ++i) EXPECT_LT((t.Apply(p_est[i]) - p_ref[i]).norm(), 1e-11);
}

TEST(AlignmentTest, YawTranslationRecoversAKnownYawAndTranslation) {
  const std::vector<Eigen::Vector3d> p_ref = RandomPoints(30, 2);
  const Eigen::Quaterniond q_ref_est(Eigen::AngleAxisd(-2.4, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d p_ref_est(-10.0, 3.0, 0.5);
  std::vector<Eigen::Vector3d> p_est;
  for (const Eigen::Vector3d& p : p_ref) p_est.push_back(q_ref_est.conjugate() * (p - p_ref_est));

  const RigidTransform t = AlignPositions(p_est, p_ref, AlignmentKind::kYawTranslation);
  EXPECT_LT(AngleBetween(t.q_ref_est, q_ref_est), 1e-12);
  EXPECT_LT((t.p_ref_est - p_ref_est).norm(), 1e-11);
  // The rotation stays about z even when the data would prefer a tilt.
  const RigidTransform tilted = AlignPositions(RandomPoints(30, 3), p_ref, AlignmentKind::kYawTranslation);
  EXPECT_LT((tilted.q_ref_est * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
}

TEST(AlignmentTest, NoneIsTheIdentity) {
  const RigidTransform t = AlignPositions(RandomPoints(5, 4), RandomPoints(5, 5), AlignmentKind::kNone);
  EXPECT_EQ(t.p_ref_est, Eigen::Vector3d::Zero());
  EXPECT_EQ(t.q_ref_est.coeffs(), Eigen::Quaterniond::Identity().coeffs());
}

TEST(AlignmentTest, TransformTrajectoryMapsPositionsAndOrientations) {
  RigidTransform t;
  t.q_ref_est = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  t.p_ref_est = Eigen::Vector3d(1.0, 0.0, 0.0);
  Trajectory trajectory(1);
  trajectory[0].t = Time::FromNanoseconds(5);
  trajectory[0].p_world_body = Eigen::Vector3d(1.0, 0.0, 0.0);
  const Trajectory out = TransformTrajectory(t, trajectory);
  EXPECT_EQ(out[0].t, trajectory[0].t);
  EXPECT_LT((out[0].p_world_body - Eigen::Vector3d(1.0, 1.0, 0.0)).norm(), 1e-15);
  EXPECT_LT(AngleBetween(out[0].q_world_body, t.q_ref_est), 1e-15);
}

TEST(AlignmentTest, NamesRoundTrip) {
  for (AlignmentKind kind : {AlignmentKind::kNone, AlignmentKind::kSe3, AlignmentKind::kYawTranslation,
                             AlignmentKind::kSim3, AlignmentKind::kOrigin})
    EXPECT_EQ(ParseAlignmentKind(AlignmentKindName(kind)), kind);
  EXPECT_EQ(ParseAlignmentKind("yaw"), AlignmentKind::kYawTranslation);
  EXPECT_FALSE(ParseAlignmentKind("sim4").has_value());
}

TEST(AlignmentTest, Sim3RecoversAKnownSimilarity) {
  const std::vector<Eigen::Vector3d> p_ref = RandomPoints(40, 6);
  const Eigen::Quaterniond q_ref_est(Eigen::AngleAxisd(-1.1, Eigen::Vector3d(0.6, 0.2, -0.4).normalized()));
  const Eigen::Vector3d p_ref_est(-3.0, 7.5, 0.25);
  const double scale = 2.5;  // the estimate is 2.5 times too small (a monocular estimate, say)
  std::vector<Eigen::Vector3d> p_est;
  for (const Eigen::Vector3d& p : p_ref) p_est.push_back(q_ref_est.conjugate() * (p - p_ref_est) / scale);

  const RigidTransform t = AlignPositions(p_est, p_ref, AlignmentKind::kSim3);
  EXPECT_NEAR(t.scale, scale, 1e-12);
  EXPECT_LT(AngleBetween(t.q_ref_est, q_ref_est), 1e-12);
  EXPECT_LT((t.p_ref_est - p_ref_est).norm(), 1e-11);
  for (std::size_t i = 0; i < p_ref.size(); ++i) EXPECT_LT((t.Apply(p_est[i]) - p_ref[i]).norm(), 1e-11);
  // se3 keeps the scale at 1 and cannot fit these points.
  const RigidTransform rigid = AlignPositions(p_est, p_ref, AlignmentKind::kSe3);
  EXPECT_EQ(rigid.scale, 1.0);
  EXPECT_GT((rigid.Apply(p_est[0]) - p_ref[0]).norm(), 1.0);
}

TEST(AlignmentTest, OriginMakesTheFirstPosesEqual) {
  Trajectory estimate(3), reference(3);
  for (int i = 0; i < 3; ++i) {
    estimate[i].p_world_body = Eigen::Vector3d(i, 0.0, 0.0);
    reference[i].p_world_body = Eigen::Vector3d(5.0, 5.0 + 2.0 * i, 1.0);  // turned by 90 deg, longer steps
  }
  estimate[0].q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  reference[0].q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.3 + M_PI / 2, Eigen::Vector3d::UnitZ()));
  const RigidTransform t = AlignTrajectories(estimate, reference, AlignmentKind::kOrigin);
  const StampedPose first = t.Apply(estimate[0]);
  EXPECT_LT((first.p_world_body - reference[0].p_world_body).norm(), 1e-12);
  EXPECT_LT(AngleBetween(first.q_world_body, reference[0].q_world_body), 1e-12);
  // Only the first pose decides: the second lands 1 m along +y (the turned x axis), not where the reference is.
  EXPECT_LT((t.Apply(estimate[1].p_world_body) - Eigen::Vector3d(5.0, 6.0, 1.0)).norm(), 1e-12);
}

}  // namespace
}  // namespace roamlab::eval
