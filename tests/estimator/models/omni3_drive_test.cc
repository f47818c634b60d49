#include "estimator/models/omni3_drive.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

const Eigen::Vector3d kRadii(0.049, 0.0505, 0.0512);
constexpr double kDistance = 0.205;

Eigen::VectorXd Scalar(double x) { return Eigen::VectorXd::Constant(1, x); }

// Pose after dt at body velocity (v_x, v_y) and yaw rate omega (eq. 7, which VelocitiesBetween inverts exactly).
Eigen::VectorXd Step(const Eigen::VectorXd& pose0, const Eigen::Vector3d& twist, double dt) {
  const Pose<double> p1 = PredictPose<double>(PoseFromArray(pose0.data()), Eigen::Vector3d(twist[0], twist[1], 0),
                                              Eigen::Vector3d(0, 0, twist[2]), dt);
  Eigen::VectorXd out(7);
  PoseToArray(p1, out.data());
  return out;
}

// Wheel rates of the true geometry for twist (v_x, v_y, omega_z), written out from the header's rows.
Eigen::Vector3d Rates(const Eigen::Vector3d& twist) {
  Eigen::Vector3d z;
  for (int i = 0; i < 3; ++i) {
    const double alpha = (60.0 + 120.0 * i) * M_PI / 180.0;
    z[i] = (-std::sin(alpha) * twist[0] + std::cos(alpha) * twist[1] + kDistance * twist[2]) / kRadii[i];
  }
  return z;
}

std::vector<Eigen::VectorXd> Values(const Eigen::VectorXd& pose0, const Eigen::VectorXd& pose1) {
  return {pose0, pose1, Scalar(kRadii[0]), Scalar(kRadii[1]), Scalar(kRadii[2]), Scalar(kDistance)};
}

TEST(Omni3DriveErrorTest, ZeroAtTruthAndIdentityNoiseJacobian) {
  std::mt19937 rng(31);
  for (const Eigen::Vector3d& twist : {Eigen::Vector3d(0.5, 0.0, 0.0), Eigen::Vector3d(-0.2, 0.4, 1.5),
                                       Eigen::Vector3d(0.0, 0.0, -2.0), Eigen::Vector3d(0.0, -0.5, 0.0)}) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const Omni3DriveError model(Rates(twist), 0.01);
    const auto values = Values(pose0, Step(pose0, twist, 0.01));
    const auto lin = testing::Evaluate(*MakeFactor(model), values);
    EXPECT_LT(lin.error.norm(), 1e-9) << twist.transpose();
    EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::MatrixXd::Identity(6, 6)));
    EXPECT_LT((lin.noise_jacobian - testing::NumericNoiseJacobian(model, values)).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(Omni3DriveErrorTest, ForwardKinematicsInvertsTheWheelRows) {
  const Eigen::Vector3d twist(0.35, -0.25, 0.9);
  Eigen::Vector3d v_body, omega_body;
  Omni3DriveError::BodyVelocity(Rates(twist), kRadii, kDistance, &v_body, &omega_body);
  EXPECT_NEAR(v_body.x(), 0.35, 1e-12);
  EXPECT_NEAR(v_body.y(), -0.25, 1e-12);
  EXPECT_NEAR(omega_body.z(), 0.9, 1e-12);
  EXPECT_EQ(v_body.z() + omega_body.head<2>().norm(), 0.0);
}

TEST(Omni3DriveErrorTest, PureRotationTurnsAllWheelsAlikeAndSidewaysMotionIsNotAnError) {
  // Rotation in place: every wheel at L omega / r_i.
  const Eigen::Vector3d z = Rates(Eigen::Vector3d(0, 0, 1.0));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(z[i] * kRadii[i], kDistance, 1e-12);
  // Sideways motion read by the wheels leaves no residual (unlike differential_drive's lateral row).
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  Eigen::VectorXd pose1 = pose0;
  pose1[1] = 0.004;  // 0.4 m/s to the left for 10 ms
  const auto lin =
      testing::Evaluate(*MakeFactor(Omni3DriveError(Rates(Eigen::Vector3d(0, 0.4, 0)), 0.01)), Values(pose0, pose1));
  EXPECT_LT(lin.error.norm(), 1e-9);
  // Motion off the floor shows in the vertical row only.
  pose1[2] = 0.0002;
  const auto up =
      testing::Evaluate(*MakeFactor(Omni3DriveError(Rates(Eigen::Vector3d(0, 0.4, 0)), 0.01)), Values(pose0, pose1));
  EXPECT_NEAR(up.error[3], 0.02, 1e-12);
  EXPECT_LT(up.error.head<3>().norm(), 1e-9);
}

TEST(Omni3DriveErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(32);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const Eigen::Vector3d twist(0.3 - 0.2 * trial, 0.1 * trial, 1.0 - 0.4 * trial);
    const Eigen::VectorXd pose1 = testing::Perturb(Manifold::Pose(), Step(pose0, twist, 0.02), 0.002, &rng);
    const auto factor = MakeFactor(Omni3DriveError(Eigen::Vector3d(7.0, -3.0, 9.0), 0.02));
    testing::ExpectJacobiansMatchNumeric(*factor, Values(pose0, pose1), 1e-5);
  }
}

// Small solve: a 10 s holonomic drive with the three wheels' rates read at every interval, poses held by priors; the
// radii and L start at the nominal 0.05 m and 0.20 m.
testing::SmallProblem OmniProblem(bool noisy, std::uint32_t seed) {
  const double dt = 0.1;
  const testing::TwistTrajectory motion = testing::IntegrateTwists(
      Manifold::Pose().Identity(), 100, dt, [](double t, Eigen::Vector3d* v, Eigen::Vector3d* omega) {
        *v = Eigen::Vector3d(0.4 * std::sin(0.9 * t), 0.3 * std::cos(0.6 * t + 0.2), 0.0);
        *omega = Eigen::Vector3d(0.0, 0.0, 1.2 * std::sin(0.7 * t + 0.4));
      });
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << 0.05, 0.05, 0.05, 0.01, 0.01, 0.01;
  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.002, 0.001, noisy, &rng, &problem);
  for (int i = 0; i < 3; ++i)
    testing::AddFreeParameter("radius_" + std::to_string(i), Manifold::Euclidean(1), Scalar(0.05), Scalar(kRadii[i]),
                              &problem);
  testing::AddFreeParameter("distance", Manifold::Euclidean(1), Scalar(0.20), Scalar(kDistance), &problem);
  for (std::size_t k = 0; k + 1 < motion.poses.size(); ++k) {
    const Eigen::Vector3d twist(motion.v_body[k].x(), motion.v_body[k].y(), motion.omega_body[k].z());
    const Eigen::Vector3d z = Rates(twist) + testing::GaussianNoise(3, testing::NoiseSigma(noisy, sigma[0]), &rng);
    const std::vector<VariableId>& p = problem.parameters;
    problem.graph.AddFactor(MakeFactor(Omni3DriveError(z, dt)),
                            {problem.poses[k], problem.poses[k + 1], p[0], p[1], p[2], p[3]},
                            Eigen::MatrixXd(sigma.cwiseAbs2().asDiagonal()), Loss::Trivial(), "odometer",
                            Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

TEST(Omni3DriveErrorTest, SmallSolveRecoversRadiiAndDistance) {
  testing::SmallProblem problem = OmniProblem(false, 33);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(Omni3DriveErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = OmniProblem(true, 34);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: each standard deviation is below a third of the offset the solve started from.
  EXPECT_LT(sigma[0], 0.001 / 3.0);
  EXPECT_LT(sigma[1], 0.0005 / 3.0);
  EXPECT_LT(sigma[2], 0.0012 / 3.0);
  EXPECT_LT(sigma[3], 0.005 / 3.0);
}

}  // namespace
}  // namespace roamlab::estimator
