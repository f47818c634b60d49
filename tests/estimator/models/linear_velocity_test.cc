#include "estimator/models/linear_velocity.h"

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

Eigen::Matrix3d SkewOf(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return m;
}

TEST(LinearVelocityErrorTest, ZeroForStepComposedAsInEq7) {
  // Pose at t+dt composed as eq. 7 describes it: turn half-way at omega, move v dt along the body axes of that
  // orientation, turn the rest. With S at the origin of O and no misalignment the sensor reads v exactly.
  std::mt19937 rng(51);
  const Eigen::VectorXd pose0 = RandomPoint(Manifold::Pose(), &rng, 10.0);
  const Pose<double> T0 = PoseFromArray(pose0.data());
  const Eigen::Vector3d v_body(3.0, 0.4, -0.2);
  const Eigen::Vector3d omega_body(0.1, -0.3, 0.8);
  const double dt = 0.04;
  const Eigen::Quaterniond q_mid = T0.q_world_body * RotationAbout(omega_body * dt / 2.0);
  const Eigen::VectorXd pose1 =
      PoseVector(T0.p_world_body + q_mid * (v_body * dt), T0.q_world_body * RotationAbout(omega_body * dt));

  const LinearVelocityError model(v_body, dt);
  const std::vector<Eigen::VectorXd> values = {pose0, pose1, Eigen::Vector3d::Zero(),
                                               QuaternionVector(Eigen::Quaterniond::Identity())};
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(model), values);
  EXPECT_LT(lin.error.norm(), 1e-12);
  EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::Matrix3d::Identity()));
}

TEST(LinearVelocityErrorTest, DisplacedMisalignedSensorOnScrewMotion) {
  // O moves with constant body twist (v, omega): q(t) = q0 Exp(omega t), p(t) = p0 + R0 V(t) v with
  // V(t) = int_0^t Exp(omega s) ds = t I + (1 - cos(w t)) / w^2 [omega]x + (w t - sin(w t)) / w^3 [omega]x^2 with
  // w = |omega|.
  // The sensor's origin c(t) = p(t) + R(t) S; its velocity at the middle of the interval, by a central difference of
  // c with a small step, expressed in S, is the reading. The model's chord velocity shrinks the part of v normal to
  // omega by sin(w dt / 2) / (w dt / 2) = 1 - (w dt)^2 / 24 + ..., which bounds the error.
  std::mt19937 rng(52);
  const Eigen::VectorXd pose0 = RandomPoint(Manifold::Pose(), &rng, 10.0);
  const Pose<double> T0 = PoseFromArray(pose0.data());
  const Eigen::Vector3d v_body(4.0, 0.5, -0.3);
  const Eigen::Vector3d omega_body(0.2, -0.1, 0.6);
  const Eigen::Vector3d p_body_sensor(1.2, -0.4, 0.3);
  const Eigen::Quaterniond q_body_sensor(Eigen::AngleAxisd(0.6, Eigen::Vector3d(0.5, 0.5, -1.0).normalized()));
  const double dt = 0.05;
  const double w = omega_body.norm();
  const Eigen::Matrix3d W = SkewOf(omega_body);
  auto pose_at = [&](double t) {
    const Eigen::Matrix3d V = t * Eigen::Matrix3d::Identity() + (1.0 - std::cos(w * t)) / (w * w) * W +
                              (w * t - std::sin(w * t)) / (w * w * w) * W * W;
    return Pose<double>{T0.p_world_body + T0.q_world_body * (V * v_body),
                        T0.q_world_body * RotationAbout(omega_body * t)};
  };
  auto sensor_origin_at = [&](double t) {
    const Pose<double> T = pose_at(t);
    return Eigen::Vector3d(T.p_world_body + T.q_world_body * p_body_sensor);
  };
  const double h = 1e-4;
  const Eigen::Vector3d c_dot_world = (sensor_origin_at(dt / 2 + h) - sensor_origin_at(dt / 2 - h)) / (2 * h);
  const Eigen::Vector3d z = (pose_at(dt / 2).q_world_body * q_body_sensor).conjugate() * c_dot_world;

  const std::vector<Eigen::VectorXd> values = {PoseVector(pose_at(0.0).p_world_body, pose_at(0.0).q_world_body),
                                               PoseVector(pose_at(dt).p_world_body, pose_at(dt).q_world_body),
                                               p_body_sensor, QuaternionVector(q_body_sensor)};
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(LinearVelocityError(z, dt)), values);
  const Eigen::Vector3d v_normal = v_body - omega_body * omega_body.dot(v_body) / (w * w);
  const double bound = 1.01 * v_normal.norm() * (w * dt) * (w * dt) / 24.0 + 1e-8;
  EXPECT_LE(lin.error.norm(), bound) << lin.error.transpose();
  // The lever arm matters: ignoring it (S = 0) misses omega x S, which is much larger than the bound.
  const testing::Linearization no_lever = testing::Evaluate(*MakeFactor(LinearVelocityError(z, dt)),
                                                            {values[0], values[1], Eigen::Vector3d::Zero(), values[3]});
  EXPECT_NEAR(no_lever.error.norm(), omega_body.cross(p_body_sensor).norm(), 10 * bound);
}

TEST(LinearVelocityErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> dt_dist(0.01, 0.05);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose0 = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd pose1 = Perturb(Manifold::Pose(), pose0, 0.05, &rng);
    const Eigen::VectorXd p_body_sensor = RandomPoint(Manifold::Euclidean(3), &rng, 0.5);
    const Eigen::VectorXd q_body_sensor =
        Perturb(Manifold::UnitQuaternion(), Manifold::UnitQuaternion().Identity(), 0.3, &rng);
    const Eigen::Vector3d z = RandomPoint(Manifold::Euclidean(3), &rng);
    const LinearVelocityError model(z, dt_dist(rng));
    const std::vector<Eigen::VectorXd> values = {pose0, pose1, p_body_sensor, q_body_sensor};
    testing::ExpectModelJacobiansMatchNumeric(model, values);
  }
}

// The linear velocity sensor's small end-to-end problem: a sensor at a lever arm and misalignment on the smooth 3-D
// motion, one reading per interval from the interval's body twist by rigid-body kinematics, z = (R_S^O)^T (v +
// omega x S^(O)) + eta, with pose priors holding the poses. Lever arm and misalignment start at their nominal values.
testing::SmallProblem LinearVelocityProblem(bool noisy, std::uint32_t seed) {
  const double sigma = 0.02;  // [m/s]
  const Eigen::Vector3d p_body_sensor(1.2, -0.4, 0.3);
  const Eigen::Quaterniond q_body_sensor = RotationAbout(Eigen::Vector3d(-0.2, 0.3, 0.4));
  const testing::TwistTrajectory motion = testing::SmoothMotion(40);

  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.002, 0.001, noisy, &rng, &problem);
  const auto [lever_id, misalignment] = testing::AddFreeMounting(p_body_sensor, q_body_sensor, &problem);
  for (std::size_t k = 0; k < motion.v_body.size(); ++k) {
    const Eigen::Vector3d v_sensor_in_body = motion.v_body[k] + motion.omega_body[k].cross(p_body_sensor);
    const Eigen::Vector3d z = q_body_sensor.toRotationMatrix().transpose() * v_sensor_in_body +
                              testing::GaussianNoise(3, testing::NoiseSigma(noisy, sigma), &rng);
    problem.graph.AddFactor(MakeFactor(LinearVelocityError(z, motion.dt_s)),
                            {problem.poses[k], problem.poses[k + 1], lever_id, misalignment},
                            Eigen::Matrix3d::Identity() * sigma * sigma, Loss::Trivial(), "velocity",
                            Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

TEST(LinearVelocityErrorTest, SmallSolveRecoversLeverArmAndMisalignment) {
  testing::SmallProblem problem = LinearVelocityProblem(false, 55);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(LinearVelocityErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = LinearVelocityProblem(true, 56);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: far below the mounting offsets (0.3 m and more, 0.5 rad).
  EXPECT_LT(sigma.maxCoeff(), 0.02) << sigma.transpose();
}

}  // namespace
}  // namespace roamlab::estimator
