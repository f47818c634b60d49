#include "estimator/models/gps.h"

#include <cstdint>
#include <optional>
#include <random>
#include <vector>

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
  const Eigen::Vector3d bias(0.8, -1.1, 2.3);
  const Eigen::Vector3d z = T.p_world_body + T.q_world_body * lever + bias;
  const auto factor = MakeFactor(GpsError(z));
  const testing::Linearization lin = testing::Evaluate(*factor, {pose, lever, bias});
  EXPECT_LT(lin.error.norm(), 1e-12);
  EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::Matrix3d::Identity()));
}

TEST(GpsErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd lever = RandomPoint(Manifold::Euclidean(3), &rng);
    const Eigen::VectorXd bias = RandomPoint(Manifold::Euclidean(3), &rng);
    const Eigen::Vector3d z = RandomPoint(Manifold::Euclidean(3), &rng, 10.0);
    testing::ExpectJacobiansMatchNumeric(*MakeFactor(GpsError(z)), {pose, lever, bias});
  }
}

// The GPS's small end-to-end problem: an antenna at a lever arm on the smooth 3-D motion, one fix per pose from the
// motion's own pose, z = p + R S^(O) + eta, with pose priors as the other source of position and orientation. The
// lever arm starts at zero; the bias is 0 and fixed.
testing::SmallProblem GpsProblem(bool noisy, std::uint32_t seed) {
  const double sigma = 0.02;  // [m]
  const Eigen::Vector3d lever_arm(0.57, -0.46, 0.32);
  const testing::TwistTrajectory motion = testing::SmoothMotion(40);

  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.02, 0.002, noisy, &rng, &problem);
  const VariableId lever_id =
      testing::AddFreeParameter("lever_arm", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), lever_arm, &problem);
  const VariableId bias_id =
      problem.graph.AddVariable({"bias", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), true, std::nullopt});
  for (std::size_t k = 0; k < motion.poses.size(); ++k) {
    const Pose<double> T = PoseFromArray(motion.poses[k].data());
    const Eigen::Vector3d z = T.p_world_body + T.q_world_body.toRotationMatrix() * lever_arm +
                              testing::GaussianNoise(3, testing::NoiseSigma(noisy, sigma), &rng);
    problem.graph.AddFactor(MakeFactor(GpsError(z)), {problem.poses[k], lever_id, bias_id},
                            Eigen::Matrix3d::Identity() * sigma * sigma, Loss::Trivial(), "gps",
                            Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

TEST(GpsErrorTest, SmallSolveRecoversLeverArm) {
  testing::SmallProblem problem = GpsProblem(false, 3);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(GpsErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = GpsProblem(true, 4);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: far below the lever arm's components (0.3 m and more).
  EXPECT_LT(sigma.maxCoeff(), 0.01) << sigma.transpose();
}

}  // namespace
}  // namespace roamlab::estimator
