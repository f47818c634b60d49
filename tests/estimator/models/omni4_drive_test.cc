#include "estimator/models/omni4_drive.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

const Eigen::Vector4d kRadii(0.0296, 0.0304, 0.0301, 0.0293);
constexpr double kWheelbase = 0.21, kTrack = 0.19;

Eigen::VectorXd Scalar(double x) { return Eigen::VectorXd::Constant(1, x); }

Eigen::VectorXd Step(const Eigen::VectorXd& pose0, const Eigen::Vector3d& twist, double dt) {
  const Pose<double> p1 = PredictPose<double>(PoseFromArray(pose0.data()), Eigen::Vector3d(twist[0], twist[1], 0),
                                              Eigen::Vector3d(0, 0, twist[2]), dt);
  Eigen::VectorXd out(7);
  PoseToArray(p1, out.data());
  return out;
}

// Wheel rates from the rolling constraint itself (not the header's rows): wheel i at p_i = (+-l1/2, +-l2/2) turns at
// d_i . (v + omega e_z x p_i) / r_i, d_i the 45-degree rolling directions of the X layout.
Eigen::Vector4d Rates(const Eigen::Vector3d& twist) {
  const double x = 0.5 * kWheelbase, y = 0.5 * kTrack;
  const Eigen::Vector2d p[4] = {{x, y}, {x, -y}, {-x, y}, {-x, -y}};
  const Eigen::Vector2d d[4] = {{1, -1}, {-1, -1}, {1, 1}, {-1, 1}};
  Eigen::Vector4d z;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d v_point = twist.head<2>() + twist[2] * Eigen::Vector2d(-p[i].y(), p[i].x());
    z[i] = d[i].normalized().dot(v_point) / kRadii[i];
  }
  return z;
}

std::vector<Eigen::VectorXd> Values(const Eigen::VectorXd& pose0, const Eigen::VectorXd& pose1) {
  return {pose0,
          pose1,
          Scalar(kRadii[0]),
          Scalar(kRadii[1]),
          Scalar(kRadii[2]),
          Scalar(kRadii[3]),
          Scalar(kWheelbase + kTrack)};
}

TEST(Omni4DriveErrorTest, ZeroAtTruthAndIdentityNoiseJacobian) {
  std::mt19937 rng(61);
  for (const Eigen::Vector3d& twist : {Eigen::Vector3d(0.5, 0.0, 0.0), Eigen::Vector3d(0.0, 0.4, 0.0),
                                       Eigen::Vector3d(0.0, 0.0, -2.0), Eigen::Vector3d(-0.3, 0.2, 1.1)}) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const Omni4DriveError model(Rates(twist), 0.01);
    const auto values = Values(pose0, Step(pose0, twist, 0.01));
    const auto lin = testing::Evaluate(*MakeFactor(model), values);
    EXPECT_LT(lin.error.norm(), 1e-9) << twist.transpose();
    EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::MatrixXd::Identity(7, 7)));
    EXPECT_LT((lin.noise_jacobian - testing::NumericNoiseJacobian(model, values)).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(Omni4DriveErrorTest, ForwardKinematicsInvertsTheWheelRows) {
  const Eigen::Vector3d twist(0.35, -0.25, 0.9);
  Eigen::Vector3d v_body, omega_body;
  Omni4DriveError::BodyVelocity(Rates(twist), kRadii, kWheelbase + kTrack, &v_body, &omega_body);
  EXPECT_NEAR(v_body.x(), 0.35, 1e-12);
  EXPECT_NEAR(v_body.y(), -0.25, 1e-12);
  EXPECT_NEAR(omega_body.z(), 0.9, 1e-12);
  EXPECT_EQ(v_body.z() + omega_body.head<2>().norm(), 0.0);
}

TEST(Omni4DriveErrorTest, ClockwiseTurnDrivesEveryWheelForward) {
  // The layout read off the OptiOdom runs: turning clockwise in place turns all four wheels positive, alike.
  const Eigen::Vector4d z = Rates(Eigen::Vector3d(0, 0, -1.0));
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(z[i] * kRadii[i], (kWheelbase + kTrack) / (2.0 * std::sqrt(2.0)), 1e-12) << i;
  // Driving forward turns the left wheels (0, 2) forward and the right wheels (1, 3) backward.
  const Eigen::Vector4d forward = Rates(Eigen::Vector3d(0.2, 0, 0));
  EXPECT_GT(forward[0], 0.0);
  EXPECT_LT(forward[1], 0.0);
  EXPECT_GT(forward[2], 0.0);
  EXPECT_LT(forward[3], 0.0);
}

TEST(Omni4DriveErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(62);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const Eigen::Vector3d twist(0.3 - 0.2 * trial, 0.1 * trial, 1.0 - 0.4 * trial);
    const Eigen::VectorXd pose1 = testing::Perturb(Manifold::Pose(), Step(pose0, twist, 0.02), 0.002, &rng);
    const auto factor = MakeFactor(Omni4DriveError(Eigen::Vector4d(7.0, -3.0, 9.0, 2.0), 0.02));
    testing::ExpectJacobiansMatchNumeric(*factor, Values(pose0, pose1), 1e-5);
  }
}

// Small solve: a 10 s holonomic drive, poses held by priors; the radii and l1 + l2 start at the nominal 0.03 m and
// 0.4 m.
testing::SmallProblem Omni4Problem(bool noisy, std::uint32_t seed) {
  const double dt = 0.1;
  const testing::TwistTrajectory motion = testing::IntegrateTwists(
      Manifold::Pose().Identity(), 100, dt, [](double t, Eigen::Vector3d* v, Eigen::Vector3d* omega) {
        *v = Eigen::Vector3d(0.4 * std::sin(0.9 * t), 0.3 * std::cos(0.6 * t + 0.2), 0.0);
        *omega = Eigen::Vector3d(0.0, 0.0, 1.2 * std::sin(0.7 * t + 0.4));
      });
  Eigen::Matrix<double, 7, 1> sigma;
  sigma << 0.05, 0.05, 0.05, 0.05, 0.01, 0.01, 0.01;
  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.002, 0.001, noisy, &rng, &problem);
  for (int i = 0; i < 4; ++i)
    testing::AddFreeParameter("radius_" + std::to_string(i), Manifold::Euclidean(1), Scalar(0.03), Scalar(kRadii[i]),
                              &problem);
  testing::AddFreeParameter("wheelbase_plus_track", Manifold::Euclidean(1), Scalar(0.4), Scalar(kWheelbase + kTrack),
                            &problem);
  for (std::size_t k = 0; k + 1 < motion.poses.size(); ++k) {
    const Eigen::Vector3d twist(motion.v_body[k].x(), motion.v_body[k].y(), motion.omega_body[k].z());
    const Eigen::Vector4d z = Rates(twist) + testing::GaussianNoise(4, testing::NoiseSigma(noisy, sigma[0]), &rng);
    const std::vector<VariableId>& p = problem.parameters;
    problem.graph.AddFactor(MakeFactor(Omni4DriveError(z, dt)),
                            {problem.poses[k], problem.poses[k + 1], p[0], p[1], p[2], p[3], p[4]},
                            Eigen::MatrixXd(sigma.cwiseAbs2().asDiagonal()), Loss::Trivial(), "odometer",
                            Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

TEST(Omni4DriveErrorTest, SmallSolveRecoversRadiiAndLever) {
  testing::SmallProblem problem = Omni4Problem(false, 63);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(Omni4DriveErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = Omni4Problem(true, 64);
  testing::ExpectSolveWithinSigmas(&problem);
}

}  // namespace
}  // namespace roamlab::estimator
