#include "estimator/models/differential_drive.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

constexpr double kRadiusLeft = 0.074, kRadiusRight = 0.0765, kBaseline = 0.41;

Eigen::VectorXd Scalar(double x) { return Eigen::VectorXd::Constant(1, x); }
const Eigen::VectorXd kRound = Eigen::VectorXd::Zero(2);  // deformation (a, b) of a round tire

// Pose after dt at forward speed v and yaw rate omega (eq. 7, which VelocitiesBetween inverts exactly).
Eigen::VectorXd Step(const Eigen::VectorXd& pose0, double v, double omega, double dt) {
  const Pose<double> p1 =
      PredictPose<double>(PoseFromArray(pose0.data()), Eigen::Vector3d(v, 0, 0), Eigen::Vector3d(0, 0, omega), dt);
  Eigen::VectorXd out(7);
  PoseToArray(p1, out.data());
  return out;
}

// Wheel rates that the true geometry gives for (v, omega).
Eigen::Vector2d Rates(double v, double omega) {
  return Eigen::Vector2d((v - 0.5 * omega * kBaseline) / kRadiusLeft, (v + 0.5 * omega * kBaseline) / kRadiusRight);
}

TEST(DifferentialDriveErrorTest, ZeroAtTruthAndIdentityNoiseJacobian) {
  std::mt19937 rng(21);
  for (const auto& [v, omega] : std::vector<std::pair<double, double>>{{0.6, 0.0}, {-0.5, 1.2}, {0.0, -2.0}}) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const Eigen::Vector2d z = Rates(v, omega);
    const auto factor = MakeFactor(DifferentialDriveError(z[0], z[1], 0.01));
    const auto lin = testing::Evaluate(*factor, {pose0, Step(pose0, v, omega, 0.01), Scalar(kRadiusLeft),
                                                 Scalar(kRadiusRight), Scalar(kBaseline), Scalar(1.0), kRound, kRound});
    EXPECT_LT(lin.error.norm(), 1e-9) << v << " " << omega;
    EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::MatrixXd::Identity(6, 6)));
  }
}

// The interval's effective radius r + a C + b S is the mean of r(theta) = r + a cos 2 theta + b sin 2 theta over the
// wheel's turn (the rim's travel over the angle turned), here against a midpoint-rule integral.
TEST(DifferentialDriveErrorTest, DeformationHarmonicsAverageTheRadiusOverTheTurn) {
  const double a = 0.0012, b = -0.0007;
  for (const auto& [theta0, theta1] : std::vector<std::pair<double, double>>{{0.3, 0.45}, {2.0, 1.1}, {-7.0, 5.0}}) {
    const Eigen::Vector2d h = DifferentialDriveError::DeformationHarmonics(theta0, theta1);
    const int n = 20000;
    double travel = 0.0;
    for (int i = 0; i < n; ++i) {
      const double theta = theta0 + (theta1 - theta0) * (i + 0.5) / n;
      travel += (a * std::cos(2.0 * theta) + b * std::sin(2.0 * theta)) * (theta1 - theta0) / n;
    }
    EXPECT_NEAR(a * h[0] + b * h[1], travel / (theta1 - theta0), 1e-10) << theta0 << " " << theta1;
  }
  // No turn: the radius at the angle itself.
  const Eigen::Vector2d h = DifferentialDriveError::DeformationHarmonics(0.7, 0.7);
  EXPECT_NEAR(h[0], std::cos(1.4), 1e-15);
  EXPECT_NEAR(h[1], std::sin(1.4), 1e-15);
}

// A deformed left tire: the readings of the true motion through r(theta) give a zero error with the true (a, b) and
// a non-zero wheel row with a round tire.
TEST(DifferentialDriveErrorTest, ZeroAtTruthWithADeformedTire) {
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  const double v = 0.5, omega = 0.3, dt = 0.01;
  const Eigen::Vector2d deformation(0.0015, 0.0008);
  const double theta0 = 1.3, rim_left = (v - 0.5 * omega * kBaseline) * dt;
  // The left wheel's turn dtheta solves the rim travel (r + a C(dtheta) + b S(dtheta)) dtheta = rim_left.
  double dtheta = rim_left / kRadiusLeft;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector2d h = DifferentialDriveError::DeformationHarmonics(theta0, theta0 + dtheta);
    dtheta = rim_left / (kRadiusLeft + deformation.dot(h));
  }
  const Eigen::Vector2d h = DifferentialDriveError::DeformationHarmonics(theta0, theta0 + dtheta);
  const auto factor =
      MakeFactor(DifferentialDriveError(dtheta / dt, Rates(v, omega)[1], dt, h, Eigen::Vector2d(0.2, 0.1)));
  const std::vector<Eigen::VectorXd> at = {pose0,
                                           Step(pose0, v, omega, dt),
                                           Scalar(kRadiusLeft),
                                           Scalar(kRadiusRight),
                                           Scalar(kBaseline),
                                           Scalar(1.0),
                                           deformation,
                                           kRound};
  EXPECT_LT(testing::Evaluate(*factor, at).error.norm(), 1e-9);
  std::vector<Eigen::VectorXd> round = at;
  round[6] = kRound;
  EXPECT_GT(std::abs(testing::Evaluate(*factor, round).error[0]), 0.05);
}

TEST(DifferentialDriveErrorTest, ForwardKinematicsInvertsTheWheelRows) {
  const Eigen::Vector2d z = Rates(0.45, -0.8);
  Eigen::Vector3d v_body, omega_body;
  DifferentialDriveError::BodyVelocity(z[0], z[1], kRadiusLeft, kRadiusRight, kBaseline, &v_body, &omega_body);
  EXPECT_NEAR(v_body.x(), 0.45, 1e-12);
  EXPECT_NEAR(omega_body.z(), -0.8, 1e-12);
  EXPECT_EQ(v_body.tail<2>().norm() + omega_body.head<2>().norm(), 0.0);
}

TEST(DifferentialDriveErrorTest, SidewaysMotionShowsInTheLateralRow) {
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  Eigen::VectorXd pose1 = pose0;
  pose1[1] = 0.002;  // 2 mm to the left in 10 ms: 0.2 m/s of side slip
  const auto factor = MakeFactor(DifferentialDriveError(0.0, 0.0, 0.01));
  const auto lin = testing::Evaluate(*factor, {pose0, pose1, Scalar(kRadiusLeft), Scalar(kRadiusRight),
                                               Scalar(kBaseline), Scalar(1.0), kRound, kRound});
  EXPECT_NEAR(lin.error[2], 0.2, 1e-12);
  EXPECT_NEAR(lin.error.head<2>().norm() + lin.error.tail<3>().norm(), 0.0, 1e-12);
}

TEST(DifferentialDriveErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(22);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const Eigen::VectorXd pose1 =
        testing::Perturb(Manifold::Pose(), Step(pose0, 0.3 + 0.2 * trial, 1.0 - 0.4 * trial, 0.02), 0.002, &rng);
    const auto factor = MakeFactor(DifferentialDriveError(
        7.0, 9.0, 0.02, DifferentialDriveError::DeformationHarmonics(0.3 * trial, 0.3 * trial + 0.14),
        DifferentialDriveError::DeformationHarmonics(-0.5 * trial, -0.5 * trial + 0.18)));
    // The ratio slot away from 1 and deformed tires, so that every column and the ratio's effect on the right wheel's
    // row are exercised.
    testing::ExpectJacobiansMatchNumeric(
        *factor,
        {pose0, pose1, Scalar(kRadiusLeft), Scalar(kRadiusRight), Scalar(kBaseline), Scalar(0.97 + 0.02 * trial),
         Eigen::Vector2d(0.001, -0.0005), Eigen::Vector2d(-0.0007, 0.0012)},
        1e-5);
  }
}

// Small solve: a 10 s drive with both wheels' rates read at every interval, poses held by priors; the radii and the
// baseline start at the nominal 0.075 m and 0.40 m. `shared_radius`: one radius for both slots and the right/left
// ratio free (from 1), as the reality-gap diagnosis frees it; else two radii and the ratio fixed at 1.
testing::SmallProblem DiffDriveProblem(bool noisy, std::uint32_t seed, bool shared_radius = false) {
  const double dt = 0.1;
  const testing::TwistTrajectory motion = testing::IntegrateTwists(
      Manifold::Pose().Identity(), 100, dt, [](double t, Eigen::Vector3d* v, Eigen::Vector3d* omega) {
        *v = Eigen::Vector3d(0.5 + 0.3 * std::sin(0.9 * t), 0.0, 0.0);
        *omega = Eigen::Vector3d(0.0, 0.0, 1.2 * std::sin(0.7 * t + 0.4));
      });
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << 0.05, 0.05, 0.01, 0.01, 0.01, 0.01;
  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.002, 0.001, noisy, &rng, &problem);
  std::vector<VariableId> slots;  // r_L, r_R, B, rho
  if (shared_radius) {
    const VariableId r =
        testing::AddFreeParameter("radius", Manifold::Euclidean(1), Scalar(0.075), Scalar(kRadiusLeft), &problem);
    const VariableId b =
        testing::AddFreeParameter("baseline", Manifold::Euclidean(1), Scalar(0.40), Scalar(kBaseline), &problem);
    const VariableId rho = testing::AddFreeParameter("right_left_ratio", Manifold::Euclidean(1), Scalar(1.0),
                                                     Scalar(kRadiusRight / kRadiusLeft), &problem);
    slots = {r, r, b, rho};
  } else {
    slots.push_back(
        testing::AddFreeParameter("radius_left", Manifold::Euclidean(1), Scalar(0.075), Scalar(kRadiusLeft), &problem));
    slots.push_back(testing::AddFreeParameter("radius_right", Manifold::Euclidean(1), Scalar(0.075),
                                              Scalar(kRadiusRight), &problem));
    slots.push_back(
        testing::AddFreeParameter("baseline", Manifold::Euclidean(1), Scalar(0.40), Scalar(kBaseline), &problem));
    slots.push_back(problem.graph.AddVariable({"ratio", Manifold::Euclidean(1), Scalar(1.0), true, std::nullopt}));
  }
  const VariableId round =
      problem.graph.AddVariable({"deformation", Manifold::Euclidean(2), kRound, true, std::nullopt});
  for (std::size_t k = 0; k + 1 < motion.poses.size(); ++k) {
    const Eigen::Vector2d z = Rates(motion.v_body[k].x(), motion.omega_body[k].z()) +
                              testing::GaussianNoise(2, testing::NoiseSigma(noisy, sigma[0]), &rng);
    problem.graph.AddFactor(
        MakeFactor(DifferentialDriveError(z[0], z[1], dt)),
        {problem.poses[k], problem.poses[k + 1], slots[0], slots[1], slots[2], slots[3], round, round},
        Eigen::MatrixXd(sigma.cwiseAbs2().asDiagonal()), Loss::Trivial(), "odometer",
        Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

TEST(DifferentialDriveErrorTest, SmallSolveRecoversRadiiAndBaseline) {
  testing::SmallProblem problem = DiffDriveProblem(false, 23);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(DifferentialDriveErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = DiffDriveProblem(true, 24);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: each standard deviation is below a third of the offset the solve started from (1 mm, 1.5 mm,
  // 10 mm).
  EXPECT_LT(sigma[0], 0.001 / 3.0);
  EXPECT_LT(sigma[1], 0.0015 / 3.0);
  EXPECT_LT(sigma[2], 0.01 / 3.0);
}

TEST(DifferentialDriveErrorTest, SmallNoisySolveRecoversTheRatioWithOneRadius) {
  testing::SmallProblem problem = DiffDriveProblem(true, 25, true);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  EXPECT_LT(sigma[2], (kRadiusRight / kRadiusLeft - 1.0) / 3.0);  // the ratio's offset from 1 is resolved
}

}  // namespace
}  // namespace roamlab::estimator
