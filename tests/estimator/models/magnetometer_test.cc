#include "estimator/models/magnetometer.h"

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::Perturb;
using testing::PoseVector;
using testing::QuaternionVector;
using testing::RandomPoint;
using testing::RotationAbout;

constexpr double kPi = 3.14159265358979323846;

// A unit field pointing north and down, as in the northern hemisphere (ENU: +y north, +z up).
const Eigen::Vector3d kFieldWorld(0.0, 0.6, -0.8);

// The 9 stored entries of A, row by row.
Eigen::VectorXd RowMajor(const Eigen::Matrix3d& A) {
  Eigen::VectorXd x(9);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) x[3 * r + c] = A(r, c);
  return x;
}

TEST(MagnetometerErrorTest, ZeroAtTruth) {
  std::mt19937 rng(31);
  const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 10.0);
  const Eigen::Quaterniond q_body_sensor(Eigen::AngleAxisd(0.25, Eigen::Vector3d(1.0, -1.0, 0.5).normalized()));
  Eigen::Matrix3d A;  // deliberately not symmetric, so that a transposed read of the block fails
  A << 1.05, 0.08, -0.02, -0.03, 0.95, 0.06, 0.10, 0.01, 1.10;
  const Eigen::Vector3d b(0.12, -0.05, 0.3);
  // Motor interference: k per N m, the proxy tau_hat = c (R_S f^(S))_x with c = m r / n for 354 kg, 0.28 m, 2 wheels.
  const Eigen::Vector3d k(4e-4, -2e-4, 1e-4);
  const Eigen::Vector3d f_sensor(1.5, -0.7, 9.6);
  const double c = 354.0 * 0.28 / 2.0;
  const double tau_nm = c * (q_body_sensor * f_sensor).x();

  // z = A R^T h + b + k tau with R the rotation from the sensor frame to W.
  const Eigen::Matrix3d R_world_sensor =
      PoseFromArray(pose.data()).q_world_body.toRotationMatrix() * q_body_sensor.toRotationMatrix();
  const Eigen::Vector3d z = A * R_world_sensor.transpose() * kFieldWorld + b + k * tau_nm;

  const MagnetometerError model(z, kFieldWorld, f_sensor, c);
  const std::vector<Eigen::VectorXd> values = {pose, QuaternionVector(q_body_sensor), RowMajor(A), b, k};
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(model), values);
  EXPECT_LT(lin.error.norm(), 1e-12);
  EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::Matrix3d::Identity()));

  // The transposed matrix gives a different prediction.
  const testing::Linearization transposed =
      testing::Evaluate(*MakeFactor(model), {pose, QuaternionVector(q_body_sensor), RowMajor(A.transpose()), b, k});
  EXPECT_GT(transposed.error.norm(), 1e-3);
  // Without the interference slot the error is the interference itself, -k tau.
  const testing::Linearization without = testing::Evaluate(
      *MakeFactor(model), {pose, QuaternionVector(q_body_sensor), RowMajor(A), b, Eigen::Vector3d::Zero()});
  EXPECT_LT((without.error + k * tau_nm).norm(), 1e-12);
}

TEST(MagnetometerErrorTest, YawingNorthPutsTheNorthComponentOnX) {
  // An ideal sensor on a level body yawed +90 deg (body x pointing north, body y pointing west) reads the north
  // component 0.6 on x, nothing on y and the vertical -0.8 on z.
  const Eigen::Quaterniond yaw_90(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitZ()));
  const Eigen::VectorXd pose = PoseVector(Eigen::Vector3d(5.0, 1.0, 0.0), yaw_90);
  const std::vector<Eigen::VectorXd> values = {pose, QuaternionVector(Eigen::Quaterniond::Identity()),
                                               RowMajor(Eigen::Matrix3d::Identity()), Eigen::Vector3d::Zero(),
                                               Eigen::Vector3d::Zero()};
  const Eigen::Vector3d z(0.6, 0.0, -0.8);
  EXPECT_LT(testing::Evaluate(*MakeFactor(MagnetometerError(z, kFieldWorld)), values).error.norm(), 1e-12);
  // e = z_hat - z: a reading 0.1 too large on x gives e_x = -0.1.
  const testing::Linearization off =
      testing::Evaluate(*MakeFactor(MagnetometerError(z + Eigen::Vector3d(0.1, 0.0, 0.0), kFieldWorld)), values);
  EXPECT_LT((off.error - Eigen::Vector3d(-0.1, 0.0, 0.0)).norm(), 1e-12);
}

TEST(MagnetometerErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(32);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd q_body_sensor =
        Perturb(Manifold::UnitQuaternion(), Manifold::UnitQuaternion().Identity(), 0.3, &rng);
    const Eigen::VectorXd A = RowMajor(Eigen::Matrix3d::Identity()) + RandomPoint(Manifold::Euclidean(9), &rng, 0.1);
    const Eigen::VectorXd b = RandomPoint(Manifold::Euclidean(3), &rng, 0.2);
    const Eigen::VectorXd k = RandomPoint(Manifold::Euclidean(3), &rng, 1e-3);
    const Eigen::Vector3d f_sensor = RandomPoint(Manifold::Euclidean(3), &rng, 5.0);
    const Eigen::Vector3d z = RandomPoint(Manifold::Euclidean(3), &rng);
    const MagnetometerError model(z, kFieldWorld, f_sensor, 50.0);
    const std::vector<Eigen::VectorXd> values = {pose, q_body_sensor, A, b, k};
    testing::ExpectModelJacobiansMatchNumeric(model, values);
  }
}

// The magnetometer's small end-to-end problem: a distorted magnetometer on the smooth 3-D motion, one reading per pose
// from the motion's own orientation and a drive torque's proxy from a made-up specific force,
// z = A (R_S^W)^T h + b + k c (R_S f^(S))_x + eta, with pose priors holding the poses. A, b and k start at their
// nominal values (identity, 0, 0). The misalignment stays fixed at its true value: A and q_S^O are not jointly
// observable (seed Section III-D), so only one of them can be estimated.
testing::SmallProblem MagnetometerProblem(bool noisy, std::uint32_t seed) {
  const double sigma = 0.005;  // [units of the field]
  const Eigen::Quaterniond q_body_sensor = RotationAbout(Eigen::Vector3d(0.1, -0.05, 0.2));
  const Eigen::Matrix3d A = (Eigen::Matrix3d() << 0.87, -0.02, -0.02, 0.0, 0.88, 0.0, -0.02, -0.04, 0.85).finished();
  const Eigen::Vector3d b(-0.08, 0.07, -0.04);
  const Eigen::Vector3d k(3e-4, -5e-4, 2e-4);  // per N m
  const double c = 50.0;                       // N m per m/s^2
  const testing::TwistTrajectory motion = testing::SmoothMotion(80);

  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.01, 0.002, noisy, &rng, &problem);
  const VariableId misalignment = problem.graph.AddVariable(
      {"misalignment", Manifold::UnitQuaternion(), QuaternionVector(q_body_sensor), true, std::nullopt});
  const VariableId A_id = testing::AddFreeParameter("A", Manifold::Euclidean(9), RowMajor(Eigen::Matrix3d::Identity()),
                                                    RowMajor(A), &problem);
  const VariableId b_id = testing::AddFreeParameter("b", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), b, &problem);
  const VariableId k_id = testing::AddFreeParameter("k", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), k, &problem);
  std::normal_distribution<double> accel(0.0, 1.0);
  for (std::size_t i = 0; i < motion.poses.size(); ++i) {
    const Eigen::Matrix3d R_world_sensor =
        PoseFromArray(motion.poses[i].data()).q_world_body.toRotationMatrix() * q_body_sensor.toRotationMatrix();
    const Eigen::Vector3d f_sensor(accel(rng), accel(rng), 9.8 + accel(rng));
    const double tau_nm = c * (q_body_sensor * f_sensor).x();
    const Eigen::Vector3d z = A * R_world_sensor.transpose() * kFieldWorld + b + k * tau_nm +
                              testing::GaussianNoise(3, testing::NoiseSigma(noisy, sigma), &rng);
    problem.graph.AddFactor(MakeFactor(MagnetometerError(z, kFieldWorld, f_sensor, c)),
                            {problem.poses[i], misalignment, A_id, b_id, k_id},
                            Eigen::Matrix3d::Identity() * sigma * sigma, Loss::Trivial(), "magnetometer",
                            Time::FromNanoseconds(static_cast<std::int64_t>(i)));
  }
  return problem;
}

TEST(MagnetometerErrorTest, SmallSolveRecoversSoftAndHardIron) {
  testing::SmallProblem problem = MagnetometerProblem(false, 33);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(MagnetometerErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = MagnetometerProblem(true, 34);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: well below the distortion the solve started from (A up to 0.15 off the identity, b up to 0.08,
  // k tau up to 0.05).
  EXPECT_LT(sigma.maxCoeff(), 0.01) << sigma.transpose();
}

}  // namespace
}  // namespace roamlab::estimator
