#include "estimator/models/absolute_pose.h"

#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::Perturb;
using testing::QuaternionVector;
using testing::RandomPoint;
using testing::RotationAbout;

TEST(AbsolutePoseErrorTest, ZeroAtTruth) {
  std::mt19937 rng(41);
  const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 10.0);
  const Eigen::Vector3d p_body_sensor(0.4, -0.15, 0.7);
  const Eigen::Quaterniond q_body_sensor(Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, 1.0, -0.4).normalized()));

  // The sensor frame's origin and orientation in W, from the body pose and the mounting.
  const Pose<double> T = PoseFromArray(pose.data());
  const Eigen::Vector3d z_p = T.p_world_body + T.q_world_body.toRotationMatrix() * p_body_sensor;
  const Eigen::Quaterniond z_q(T.q_world_body.toRotationMatrix() * q_body_sensor.toRotationMatrix());

  const AbsolutePoseError model(z_p, z_q);
  const std::vector<Eigen::VectorXd> values = {pose, p_body_sensor, QuaternionVector(q_body_sensor)};
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(model), values);
  EXPECT_LT(lin.error.norm(), 1e-12);
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  EXPECT_LT((lin.noise_jacobian - Matrix6d::Identity()).norm(), 1e-12);
}

TEST(AbsolutePoseErrorTest, ErrorIsPredictionMinusMeasurementInSensorFrame) {
  // Measured position 0.1 m short along W's x and measured orientation q_hat Exp(-delta): e = [0.1, 0, 0, delta].
  const Eigen::Quaterniond q_world_body(Eigen::AngleAxisd(0.8, Eigen::Vector3d(1.0, 1.0, 0.0).normalized()));
  const Eigen::Vector3d p_world_body(3.0, -2.0, 1.0);
  const Eigen::Quaterniond q_body_sensor(Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d p_body_sensor(0.2, 0.0, 0.1);
  const Eigen::Vector3d delta(0.02, -0.01, 0.03);
  const Eigen::Vector3d z_p = p_world_body + q_world_body * p_body_sensor - Eigen::Vector3d(0.1, 0.0, 0.0);
  const Eigen::Quaterniond z_q = q_world_body * q_body_sensor * RotationAbout(delta).conjugate();
  Eigen::VectorXd pose(7);
  pose << p_world_body, q_world_body.w(), q_world_body.x(), q_world_body.y(), q_world_body.z();
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(AbsolutePoseError(z_p, z_q)),
                                                       {pose, p_body_sensor, QuaternionVector(q_body_sensor)});
  Eigen::Matrix<double, 6, 1> expected;
  expected << 0.1, 0.0, 0.0, delta;
  EXPECT_LT((lin.error - expected).norm(), 1e-12);
}

TEST(AbsolutePoseErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd p_body_sensor = RandomPoint(Manifold::Euclidean(3), &rng, 0.5);
    const Eigen::VectorXd q_body_sensor =
        Perturb(Manifold::UnitQuaternion(), Manifold::UnitQuaternion().Identity(), 0.3, &rng);
    // A measurement near the truth, so that the orientation error is small but not zero.
    const Pose<double> T = PoseFromArray(pose.data());
    const Eigen::Vector3d z_p = T.p_world_body + RandomPoint(Manifold::Euclidean(3), &rng);
    const Eigen::VectorXd q_hat = QuaternionVector(T.q_world_body * QuaternionFromArray(q_body_sensor.data()));
    const Eigen::VectorXd z_q = Perturb(Manifold::UnitQuaternion(), q_hat, 0.2, &rng);
    const AbsolutePoseError model(z_p, QuaternionFromArray(z_q.data()));
    const std::vector<Eigen::VectorXd> values = {pose, p_body_sensor, q_body_sensor};
    testing::ExpectModelJacobiansMatchNumeric(model, values);
  }
}

// The absolute pose sensor's small end-to-end problem: a sensor at a lever arm and misalignment on the smooth 3-D
// motion, one pose fix per pose from the motion's own pose, z_p = p + R S^(O) + eta_p and z_q = q q_S^O
// Exp(eta_theta), with pose priors as the other source. Lever arm and misalignment start at their nominal values.
testing::SmallProblem AbsolutePoseProblem(bool noisy, std::uint32_t seed) {
  const double sigma_m = 0.02;
  const double sigma_rad = 0.01;
  const Eigen::Vector3d p_body_sensor(0.4, -0.15, 0.7);
  const Eigen::Quaterniond q_body_sensor = RotationAbout(Eigen::Vector3d(0.3, -0.5, 0.2));
  const testing::TwistTrajectory motion = testing::SmoothMotion(40);

  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.02, 0.005, noisy, &rng, &problem);
  const auto [lever_id, misalignment] = testing::AddFreeMounting(p_body_sensor, q_body_sensor, &problem);
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << Eigen::Vector3d::Constant(sigma_m), Eigen::Vector3d::Constant(sigma_rad);
  for (std::size_t k = 0; k < motion.poses.size(); ++k) {
    const Pose<double> T = PoseFromArray(motion.poses[k].data());
    const Eigen::Vector3d z_p = T.p_world_body + T.q_world_body.toRotationMatrix() * p_body_sensor +
                                testing::GaussianNoise(3, testing::NoiseSigma(noisy, sigma_m), &rng);
    const Eigen::Quaterniond z_q =
        T.q_world_body * q_body_sensor *
        RotationAbout(testing::GaussianNoise(3, testing::NoiseSigma(noisy, sigma_rad), &rng));
    problem.graph.AddFactor(MakeFactor(AbsolutePoseError(z_p, z_q)), {problem.poses[k], lever_id, misalignment},
                            sigma.cwiseAbs2().asDiagonal(), Loss::Trivial(), "pose",
                            Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

TEST(AbsolutePoseErrorTest, SmallSolveRecoversLeverArmAndMisalignment) {
  testing::SmallProblem problem = AbsolutePoseProblem(false, 43);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(AbsolutePoseErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = AbsolutePoseProblem(true, 44);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: far below the mounting offsets (0.15 m and more, 0.6 rad).
  EXPECT_LT(sigma.maxCoeff(), 0.01) << sigma.transpose();
}

}  // namespace
}  // namespace roamlab::estimator
