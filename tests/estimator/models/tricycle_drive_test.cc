#include "estimator/models/tricycle_drive.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

constexpr double kRadius = 0.0331;
constexpr double kWheelToAxle = 0.162;
constexpr double kOffset = -0.021;

Eigen::VectorXd Scalar(double x) { return Eigen::VectorXd::Constant(1, x); }

Eigen::VectorXd Step(const Eigen::VectorXd& pose0, const Eigen::Vector3d& twist, double dt) {
  const Pose<double> p1 = PredictPose<double>(PoseFromArray(pose0.data()), Eigen::Vector3d(twist[0], twist[1], 0),
                                              Eigen::Vector3d(0, 0, twist[2]), dt);
  Eigen::VectorXd out(7);
  PoseToArray(p1, out.data());
  return out;
}

// The readings of a front wheel driven at rim speed v_w [m/s] and true steering angle delta [rad], from the geometry
// written out here (not the header's rows): the contact point L ahead of O moves at v_w (cos delta, sin delta), the
// rear axle's centre O only along x, so v_x = v_w cos delta and omega = v_w sin delta / L. The measured angle is
// delta - offset.
struct Drive {
  Eigen::Vector3d twist;
  double wheel_radps;
  double steering_rad;
};
Drive DriveAt(double v_w, double delta) {
  return {Eigen::Vector3d(v_w * std::cos(delta), 0.0, v_w * std::sin(delta) / kWheelToAxle), v_w / kRadius,
          delta - kOffset};
}

std::vector<Eigen::VectorXd> Values(const Eigen::VectorXd& pose0, const Eigen::VectorXd& pose1) {
  return {pose0, pose1, Scalar(kRadius), Scalar(kWheelToAxle), Scalar(kOffset)};
}

TEST(TricycleDriveErrorTest, ZeroAtTruthAndIdentityNoiseJacobian) {
  std::mt19937 rng(51);
  for (const auto& [v_w, delta] :
       {std::pair{0.3, 0.0}, std::pair{0.2, 0.4}, std::pair{-0.15, -0.6}, std::pair{0.1, 1.2}, std::pair{0.0, 0.3}}) {
    const Drive d = DriveAt(v_w, delta);
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const TricycleDriveError model(d.wheel_radps, d.steering_rad, 0.05);
    const auto values = Values(pose0, Step(pose0, d.twist, 0.05));
    const auto lin = testing::Evaluate(*MakeFactor(model), values);
    EXPECT_LT(lin.error.norm(), 1e-9) << v_w << " " << delta;
    EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::MatrixXd::Identity(6, 6)));
    EXPECT_LT((lin.noise_jacobian - testing::NumericNoiseJacobian(model, values)).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(TricycleDriveErrorTest, SteeringRowIsTheSteeringErrorInRadians) {
  // The robot turns as at delta, the sensor reads 0.01 rad less: the steering row is +0.01 rad to first order, the
  // wheel row sees only the cosine's second-order change.
  const Drive d = DriveAt(0.25, 0.3);
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  const auto lin = testing::Evaluate(*MakeFactor(TricycleDriveError(d.wheel_radps, d.steering_rad - 0.01, 0.05)),
                                     Values(pose0, Step(pose0, d.twist, 0.05)));
  EXPECT_NEAR(lin.error[1], 0.01, 1e-5);
  EXPECT_NEAR(lin.error[0], d.wheel_radps * (std::cos(0.01) - 1.0), 1e-6);
  EXPECT_LT(lin.error.tail<4>().norm(), 1e-9);
}

TEST(TricycleDriveErrorTest, ForwardKinematicsRoundTrip) {
  // Wheel rate and measured steering -> body twist (BodyVelocity) -> pose pair -> the error model's prediction: the
  // same readings back.
  std::mt19937 rng(52);
  std::uniform_real_distribution<double> rate(-8.0, 8.0), angle(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const double z_w = rate(rng), z_delta = angle(rng);
    Eigen::Vector3d v_body, omega_body;
    TricycleDriveError::BodyVelocity(z_w, z_delta, kRadius, kWheelToAxle, kOffset, &v_body, &omega_body);
    EXPECT_EQ(v_body.y(), 0.0);
    EXPECT_NEAR(v_body.x(), kRadius * z_w * std::cos(z_delta + kOffset), 1e-12);
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const Eigen::VectorXd pose1 = Step(pose0, Eigen::Vector3d(v_body.x(), v_body.y(), omega_body.z()), 0.05);
    const auto lin = testing::Evaluate(*MakeFactor(TricycleDriveError(z_w, z_delta, 0.05)), Values(pose0, pose1));
    EXPECT_LT(lin.error.norm(), 1e-9) << z_w << " " << z_delta;
  }
}

TEST(TricycleDriveErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(53);
  for (int trial = 0; trial < 6; ++trial) {
    const Drive d = DriveAt(0.3 - 0.1 * trial, 0.8 - 0.3 * trial);
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const Eigen::VectorXd pose1 = testing::Perturb(Manifold::Pose(), Step(pose0, d.twist, 0.05), 0.002, &rng);
    // Readings off the truth, so that every row has a non-zero error and slope.
    const auto factor = MakeFactor(TricycleDriveError(d.wheel_radps + 0.7, d.steering_rad - 0.05, 0.05));
    testing::ExpectJacobiansMatchNumeric(*factor, Values(pose0, pose1), 1e-5);
  }
}

// Small solve: a 20 s drive with varying speed and steering, poses held by priors; radius, L and the offset start at
// the nominal 0.0325 m, 0.15 m and 0.
testing::SmallProblem TricycleProblem(bool noisy, std::uint32_t seed) {
  const double dt = 0.05;
  std::vector<Drive> drives;
  const testing::TwistTrajectory motion = testing::IntegrateTwists(
      Manifold::Pose().Identity(), 400, dt, [&drives](double t, Eigen::Vector3d* v, Eigen::Vector3d* omega) {
        const Drive d = DriveAt(0.15 + 0.1 * std::sin(0.4 * t), 0.6 * std::sin(0.3 * t + 0.5));
        drives.push_back(d);
        *v = Eigen::Vector3d(d.twist[0], 0.0, 0.0);
        *omega = Eigen::Vector3d(0.0, 0.0, d.twist[2]);
      });
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << 0.1, 0.01, 0.005, 0.002, 0.02, 0.02;
  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.002, 0.001, noisy, &rng, &problem);
  testing::AddFreeParameter("radius", Manifold::Euclidean(1), Scalar(0.0325), Scalar(kRadius), &problem);
  testing::AddFreeParameter("wheel_to_axle", Manifold::Euclidean(1), Scalar(0.15), Scalar(kWheelToAxle), &problem);
  testing::AddFreeParameter("steering_offset", Manifold::Euclidean(1), Scalar(0.0), Scalar(kOffset), &problem);
  for (std::size_t k = 0; k + 1 < motion.poses.size(); ++k) {
    const Drive& d = drives[k];
    const double z_w = d.wheel_radps + testing::GaussianNoise(1, testing::NoiseSigma(noisy, sigma[0]), &rng)[0];
    const double z_delta = d.steering_rad + testing::GaussianNoise(1, testing::NoiseSigma(noisy, sigma[1]), &rng)[0];
    const std::vector<VariableId>& p = problem.parameters;
    problem.graph.AddFactor(MakeFactor(TricycleDriveError(z_w, z_delta, dt)),
                            {problem.poses[k], problem.poses[k + 1], p[0], p[1], p[2]},
                            Eigen::MatrixXd(sigma.cwiseAbs2().asDiagonal()), Loss::Trivial(), "wheel",
                            Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

TEST(TricycleDriveErrorTest, SmallSolveRecoversRadiusDistanceAndOffset) {
  testing::SmallProblem problem = TricycleProblem(false, 54);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(TricycleDriveErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = TricycleProblem(true, 55);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: each standard deviation is below a third of the offset the solve started from.
  EXPECT_LT(sigma[0], (kRadius - 0.0325) / 3.0);
  EXPECT_LT(sigma[1], (kWheelToAxle - 0.15) / 3.0);
  EXPECT_LT(sigma[2], std::abs(kOffset) / 3.0);
}

}  // namespace
}  // namespace roamlab::estimator
