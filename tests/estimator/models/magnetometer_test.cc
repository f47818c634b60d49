#include "estimator/models/magnetometer.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::Perturb;
using testing::RandomPoint;

constexpr double kPi = 3.14159265358979323846;

// A unit field pointing north and down, as in the northern hemisphere (ENU: +y north, +z up).
const Eigen::Vector3d kFieldWorld(0.0, 0.6, -0.8);

Eigen::VectorXd PoseVector(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  Eigen::VectorXd x(7);
  x << p, q.w(), q.x(), q.y(), q.z();
  return x;
}

Eigen::VectorXd QuaternionVector(const Eigen::Quaterniond& q) { return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()); }

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
  A << 1.05, 0.08, -0.02,
       -0.03, 0.95, 0.06,
       0.10, 0.01, 1.10;
  const Eigen::Vector3d b(0.12, -0.05, 0.3);

  // z = A R^T h + b with R the rotation from the sensor frame to W.
  const Eigen::Matrix3d R_world_sensor =
      PoseFromArray(pose.data()).q_world_body.toRotationMatrix() * q_body_sensor.toRotationMatrix();
  const Eigen::Vector3d z = A * R_world_sensor.transpose() * kFieldWorld + b;

  const MagnetometerError model(z, kFieldWorld);
  const std::vector<Eigen::VectorXd> values = {pose, QuaternionVector(q_body_sensor), RowMajor(A), b};
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(model), values);
  EXPECT_LT(lin.error.norm(), 1e-12);
  EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::Matrix3d::Identity()));

  // The transposed matrix gives a different prediction.
  const testing::Linearization transposed =
      testing::Evaluate(*MakeFactor(model), {pose, QuaternionVector(q_body_sensor), RowMajor(A.transpose()), b});
  EXPECT_GT(transposed.error.norm(), 1e-3);
}

TEST(MagnetometerErrorTest, YawingNorthPutsTheNorthComponentOnX) {
  // An ideal sensor on a level body yawed +90 deg (body x pointing north, body y pointing west) reads the north
  // component 0.6 on x, nothing on y and the vertical -0.8 on z.
  const Eigen::Quaterniond yaw_90(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitZ()));
  const Eigen::VectorXd pose = PoseVector(Eigen::Vector3d(5.0, 1.0, 0.0), yaw_90);
  const std::vector<Eigen::VectorXd> values = {pose, QuaternionVector(Eigen::Quaterniond::Identity()),
                                               RowMajor(Eigen::Matrix3d::Identity()), Eigen::Vector3d::Zero()};
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
    const Eigen::Vector3d z = RandomPoint(Manifold::Euclidean(3), &rng);
    const MagnetometerError model(z, kFieldWorld);
    const std::vector<Eigen::VectorXd> values = {pose, q_body_sensor, A, b};
    const auto factor = MakeFactor(model);
    testing::ExpectJacobiansMatchNumeric(*factor, values);
    const testing::Linearization lin = testing::Evaluate(*factor, values);
    EXPECT_LT((lin.noise_jacobian - testing::NumericNoiseJacobian(model, values)).cwiseAbs().maxCoeff(), 1e-8);
  }
}

}  // namespace
}  // namespace roamlab::estimator
