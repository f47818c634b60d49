#include "estimator/models/odometer.h"

#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::PoseVector;
using testing::QuaternionVector;
using testing::RandomPoint;

// A sensor mounted away from O and rotated.
const Eigen::Vector3d kDisplacement(0.30, -0.12, 0.55);
const Eigen::Quaterniond kMisalignment(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, -0.5).normalized()));

// What the mounted sensor reads when O moves at (v_body, omega_body): rigid-body kinematics written in O, the inverse
// of eq. 5 (v_S = v_O + omega x S^(O), both then rotated into S).
Eigen::Matrix<double, 6, 1> SensorReading(const Eigen::Vector3d& v_body, const Eigen::Vector3d& omega_body) {
  const Eigen::Matrix3d R_sensor_body = kMisalignment.toRotationMatrix().transpose();
  Eigen::Matrix<double, 6, 1> z;
  z << R_sensor_body * (v_body + omega_body.cross(kDisplacement)), R_sensor_body * omega_body;
  return z;
}

// Constant twist for dt, integrated exactly, for motions where the screw axis passes through O (v parallel to omega,
// including pure rotation and pure translation): then eq. 7 is exact too.
struct Case {
  const char* name;
  Eigen::Vector3d v_body;
  Eigen::Vector3d omega_body;
};

TEST(OdometerErrorTest, ZeroAtTruthForExactMotions) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 1.1).normalized();
  const Case cases[] = {
      {"pure translation", Eigen::Vector3d(1.2, -0.3, 0.4), Eigen::Vector3d::Zero()},
      {"pure rotation", Eigen::Vector3d::Zero(), 1.3 * axis},
      {"screw", 2.0 * axis, 1.3 * axis},
  };
  std::mt19937 rng(11);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const Eigen::VectorXd pose_k = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::Vector3d p0 = pose_k.head<3>();
    const Eigen::Quaterniond q0(pose_k[3], pose_k[4], pose_k[5], pose_k[6]);
    const double dt = 0.05;
    const double angle = c.omega_body.norm() * dt;
    const Eigen::Quaterniond turn = angle > 0.0
                                        ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, c.omega_body.normalized()))
                                        : Eigen::Quaterniond::Identity();
    // v is along the rotation axis (or there is no rotation), so its world direction stays q0 v throughout.
    const Eigen::VectorXd pose_k1 = PoseVector(p0 + q0 * (c.v_body * dt), q0 * turn);

    const OdometerError model(SensorReading(c.v_body, c.omega_body), dt);
    const testing::Linearization lin =
        testing::Evaluate(*MakeFactor(model), {pose_k, pose_k1, kDisplacement, QuaternionVector(kMisalignment)});
    EXPECT_LT(lin.error.norm(), 1e-12) << lin.error.transpose();
  }
}

TEST(OdometerErrorTest, ErrorDetectsWrongMounting) {
  // Pure rotation about O, sensor away from O: the sensor moves, O does not. A model that ignores the displacement
  // takes the sensor's velocity omega x S^(O) for O's, which eq. 7 applies at the half-way orientation.
  std::mt19937 rng(12);
  const Eigen::VectorXd pose_k = RandomPoint(Manifold::Pose(), &rng, 10.0);
  const Eigen::Quaterniond q0(pose_k[3], pose_k[4], pose_k[5], pose_k[6]);
  const Eigen::Vector3d omega_body(0.0, 0.0, 1.0);
  const double dt = 0.02;
  const Eigen::VectorXd pose_k1 =
      PoseVector(pose_k.head<3>(), q0 * Eigen::Quaterniond(Eigen::AngleAxisd(dt, Eigen::Vector3d::UnitZ())));
  const OdometerError model(SensorReading(Eigen::Vector3d::Zero(), omega_body), dt);
  const testing::Linearization lin = testing::Evaluate(
      *MakeFactor(model), {pose_k, pose_k1, Eigen::Vector3d::Zero().eval(), QuaternionVector(kMisalignment)});
  const Eigen::Quaterniond q_mid = q0 * Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * dt, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d expected = q_mid * omega_body.cross(kDisplacement) * dt;
  EXPECT_GT(expected.norm(), 5e-3);
  EXPECT_LT((lin.error.head<3>() - expected).norm(), 1e-12);
  EXPECT_LT(lin.error.tail<3>().norm(), 1e-12);
}

TEST(OdometerErrorTest, NoiseJacobianOfVelocityIsRotationTimesDt) {
  // Without rotation, e_position = p0 + q0 q_S^O (z_v + eta_v) dt - p1, so d e_position / d eta_v = R0 R_S^O dt.
  std::mt19937 rng(13);
  const Eigen::VectorXd pose_k = RandomPoint(Manifold::Pose(), &rng, 10.0);
  const Eigen::Quaterniond q0(pose_k[3], pose_k[4], pose_k[5], pose_k[6]);
  const Eigen::Vector3d v_body(1.0, 0.2, -0.1);
  const double dt = 0.04;
  const Eigen::VectorXd pose_k1 = PoseVector(pose_k.head<3>() + q0 * (v_body * dt), q0);
  const OdometerError model(SensorReading(v_body, Eigen::Vector3d::Zero()), dt);
  const testing::Linearization lin =
      testing::Evaluate(*MakeFactor(model), {pose_k, pose_k1, kDisplacement, QuaternionVector(kMisalignment)});
  const Eigen::Matrix3d expected = (q0 * kMisalignment).toRotationMatrix() * dt;
  const Eigen::MatrixXd J_position_v = lin.noise_jacobian.topLeftCorner(3, 3);
  const Eigen::MatrixXd J_orientation_v = lin.noise_jacobian.bottomLeftCorner(3, 3);
  EXPECT_LT((J_position_v - expected).cwiseAbs().maxCoeff(), 1e-12) << J_position_v;
  EXPECT_LT(J_orientation_v.cwiseAbs().maxCoeff(), 1e-12) << J_orientation_v;
}

TEST(OdometerErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> dt_distribution(0.01, 0.05);
  for (int trial = 0; trial < 5; ++trial) {
    SCOPED_TRACE(trial);
    const Eigen::VectorXd pose_k = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd pose_k1 = testing::Perturb(Manifold::Pose(), pose_k, 0.05, &rng);
    const Eigen::VectorXd displacement = RandomPoint(Manifold::Euclidean(3), &rng, 0.5);
    const Eigen::VectorXd misalignment = RandomPoint(Manifold::UnitQuaternion(), &rng);
    const Eigen::Matrix<double, 6, 1> z = RandomPoint(Manifold::Euclidean(6), &rng, 2.0);
    const OdometerError model(z, dt_distribution(rng));
    const std::vector<Eigen::VectorXd> values = {pose_k, pose_k1, displacement, misalignment};
    testing::ExpectModelJacobiansMatchNumeric(model, values);
  }
}

// The odometer's small end-to-end problem: a velocity sensor (eqs. 5-8) at kDisplacement with kMisalignment on the
// smooth 3-D motion, one reading per interval from the interval's twist (SensorReading), with pose priors holding the
// poses. Displacement and misalignment start at their nominal values (0, identity).
testing::SmallProblem OdometerProblem(bool noisy, std::uint32_t seed) {
  Eigen::Matrix<double, 6, 1> sigma;  // [m/s] and [rad/s]
  sigma << Eigen::Vector3d::Constant(0.02), Eigen::Vector3d::Constant(0.005);
  const testing::TwistTrajectory motion = testing::SmoothMotion(40);

  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  testing::AddAnchoredPoses(motion.poses, 0.002, 0.001, noisy, &rng, &problem);
  const auto [displacement, misalignment] = testing::AddFreeMounting(kDisplacement, kMisalignment, &problem);
  for (std::size_t k = 0; k < motion.v_body.size(); ++k) {
    const Eigen::Matrix<double, 6, 1> z =
        SensorReading(motion.v_body[k], motion.omega_body[k]) +
        testing::GaussianNoise(6, testing::NoiseSigma(noisy, 1.0), &rng).cwiseProduct(sigma);
    problem.graph.AddFactor(MakeFactor(OdometerError(z, motion.dt_s)),
                            {problem.poses[k], problem.poses[k + 1], displacement, misalignment},
                            sigma.cwiseAbs2().asDiagonal(), Loss::Trivial(), "odometer",
                            Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

TEST(OdometerErrorTest, SmallSolveRecoversDisplacementAndMisalignment) {
  testing::SmallProblem problem = OdometerProblem(false, 15);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(OdometerErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = OdometerProblem(true, 16);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: far below the mounting offsets (0.12 m and more, 0.7 rad).
  EXPECT_LT(sigma.maxCoeff(), 0.02) << sigma.transpose();
}

}  // namespace
}  // namespace roamlab::estimator
