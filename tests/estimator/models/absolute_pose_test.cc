#include "estimator/models/absolute_pose.h"

#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::Perturb;
using testing::RandomPoint;

Eigen::VectorXd QuaternionVector(const Eigen::Quaterniond& q) { return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()); }

Eigen::Quaterniond RotationAbout(const Eigen::Vector3d& w) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(w.norm(), w.normalized()));
}

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
    const auto factor = MakeFactor(model);
    testing::ExpectJacobiansMatchNumeric(*factor, values);
    const testing::Linearization lin = testing::Evaluate(*factor, values);
    EXPECT_LT((lin.noise_jacobian - testing::NumericNoiseJacobian(model, values)).cwiseAbs().maxCoeff(), 1e-8);
  }
}

}  // namespace
}  // namespace roamlab::estimator
