#include "estimator/geometry.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/manifold.h"
#include "estimator/so3_jacobians.h"
#include "tests/estimator/factor_testing.h"
#include "tests/estimator/manifold_testing.h"

namespace roamlab::estimator {
namespace {

using testing::CentralDifferenceJacobian;
using testing::CentralDifferenceStep;
using testing::CentralDifferenceTolerance;
using testing::kEpsilon;
using testing::kRoundingUlps;

// Rotation angles [rad] at which Exp, Log and their Jacobians are checked: near zero (both sides of Exp's and Log's
// series branch at 1e-8 rad, and of the Jacobians' at 1e-3 rad), in general position, and near a half turn.
const std::vector<double> kAngles = {1e-9, 1e-6, 1e-4, 0.1, 1.0, 2.5, M_PI - 1e-3, M_PI - 1e-6, M_PI - 1e-9};

Eigen::Vector3d RandomAxis(std::mt19937* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng)).normalized();
}

Eigen::Quaterniond Exp(const Eigen::Vector3d& w) { return QuaternionExp<double>(w); }
Eigen::Vector3d Log(const Eigen::Quaterniond& q) { return QuaternionLog<double>(q); }

// |a - b| over the four coefficients, up to the sign of the quaternion (q and -q are the same rotation).
double QuaternionDistance(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return std::min((a.coeffs() - b.coeffs()).norm(), (a.coeffs() + b.coeffs()).norm());
}

// Conventions at the top of geometry.h.

TEST(GeometryConventionsTest, QuaternionsAreStoredWFirst) {
  const double wxyz[] = {0.5, -0.5, 0.5, 0.5};
  const Eigen::Quaterniond q = QuaternionFromArray(wxyz);
  EXPECT_EQ(q.w(), 0.5);
  EXPECT_EQ(q.x(), -0.5);
  EXPECT_EQ(q.y(), 0.5);
  EXPECT_EQ(q.z(), 0.5);
  double back[4];
  QuaternionToArray(q, back);
  EXPECT_TRUE(std::equal(back, back + 4, wxyz));
}

TEST(GeometryConventionsTest, QuaternionsAreHamiltonAndRotateFromTheRightFrameIntoTheLeft) {
  // Hamilton: i j = k (JPL would give i j = -k).
  const Eigen::Quaterniond k = Eigen::Quaterniond(0, 1, 0, 0) * Eigen::Quaterniond(0, 0, 1, 0);
  EXPECT_EQ(k.coeffs(), Eigen::Quaterniond(0, 0, 0, 1).coeffs());
  // v_a = q_a_b * v_b: body b turned a quarter turn left (about up) from a; its x axis points along a's y axis.
  const Eigen::Quaterniond q_a_b = Exp(Eigen::Vector3d(0, 0, M_PI / 2));
  EXPECT_LE((q_a_b * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), kRoundingUlps * kEpsilon);
  // Exp(d) = [cos(|d|/2), sin(|d|/2) d/|d|].
  const Eigen::Vector3d d(0.3, -0.4, 1.2);
  const double half = d.norm() / 2;
  const Eigen::Vector3d axis = d / d.norm();
  const Eigen::Quaterniond expected(std::cos(half), std::sin(half) * axis.x(), std::sin(half) * axis.y(),
                                    std::sin(half) * axis.z());
  EXPECT_LE((Exp(d).coeffs() - expected.coeffs()).norm(), kRoundingUlps * kEpsilon);
}

TEST(GeometryConventionsTest, BoxPlusIsARightPerturbationInTheBodyFrame) {
  std::mt19937 rng(3);
  const Eigen::VectorXd q = testing::RandomPoint(Manifold::UnitQuaternion(), &rng);
  const Eigen::Vector3d d(0.2, -0.1, 0.3);
  const Eigen::VectorXd plus = testing::Plus(Manifold::UnitQuaternion(), q, d);
  const Eigen::Quaterniond right = QuaternionFromArray(q.data()) * Exp(d);
  const Eigen::Quaterniond left = Exp(d) * QuaternionFromArray(q.data());
  EXPECT_LE(QuaternionDistance(QuaternionFromArray(plus.data()), right), kRoundingUlps * kEpsilon);
  EXPECT_GT(QuaternionDistance(QuaternionFromArray(plus.data()), left), 1e-3);

  // Pose tangent [dp (world frame), dtheta (body frame)]: (p, q) [+] (dp, dtheta) = (p + dp, q Exp(dtheta)).
  const Eigen::VectorXd pose = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
  Eigen::VectorXd delta(6);
  delta << 1.0, -2.0, 0.5, d;
  const Eigen::VectorXd pose_plus = testing::Plus(Manifold::Pose(), pose, delta);
  EXPECT_LE((pose_plus.head<3>() - (pose.head<3>() + delta.head<3>())).norm(), kRoundingUlps * kEpsilon * 5.0);
  EXPECT_LE(
      QuaternionDistance(QuaternionFromArray(pose_plus.data() + 3), QuaternionFromArray(pose.data() + 3) * Exp(d)),
      kRoundingUlps * kEpsilon);

  // Box-minus: x [-] y = (p_x - p_y, Log(q_y^-1 q_x)).
  const Eigen::VectorXd other = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
  const Eigen::VectorXd minus = testing::Minus(Manifold::Pose(), other, pose);
  EXPECT_EQ(minus.head<3>(), other.head<3>() - pose.head<3>());
  EXPECT_EQ(minus.tail<3>(),
            Log(QuaternionFromArray(pose.data() + 3).conjugate() * QuaternionFromArray(other.data() + 3)));
}

TEST(GeometryConventionsTest, AnAccelerometerAtRestReadsGravityUpwards) {
  EXPECT_EQ(kSpecificForceAtRest_world, Eigen::Vector3d(0.0, 0.0, kStandardGravity));
  EXPECT_EQ(kStandardGravity, 9.80665);
}

// Exp and Log.

TEST(GeometryTest, ExpMatchesTheAngleAxisRotation) {
  std::mt19937 rng(5);
  for (const double angle : kAngles) {
    const Eigen::Vector3d w = angle * RandomAxis(&rng);
    EXPECT_LE(QuaternionDistance(Exp(w), testing::RotationAbout(w)), kRoundingUlps * kEpsilon) << "angle " << angle;
    EXPECT_NEAR(Exp(w).norm(), 1.0, kRoundingUlps * kEpsilon) << "angle " << angle;
  }
  EXPECT_EQ(Exp(Eigen::Vector3d::Zero()).coeffs(), Eigen::Quaterniond::Identity().coeffs());
}

TEST(GeometryTest, LogInvertsExpNearZeroInGeneralPositionAndNearAHalfTurn) {
  std::mt19937 rng(7);
  for (const double angle : kAngles) {
    for (int trial = 0; trial < 4; ++trial) {
      const Eigen::Vector3d w = angle * RandomAxis(&rng);
      // Relative to |w|: near zero both use series whose truncation is below eps relative.
      EXPECT_LE((Log(Exp(w)) - w).norm(), kRoundingUlps * kEpsilon * angle)
          << "w = " << w.transpose() << ", Log(Exp(w)) = " << Log(Exp(w)).transpose();
    }
  }
  EXPECT_EQ(Log(Eigen::Quaterniond::Identity()), Eigen::Vector3d::Zero());
}

TEST(GeometryTest, LogOfAHalfTurnIsEitherOfItsTwoRotationVectors) {
  // Exactly pi: w and -w are the same rotation; Log returns one of them (angle pi), and Exp of it is the rotation.
  std::mt19937 rng(9);
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::Vector3d w = M_PI * RandomAxis(&rng);
    const Eigen::Vector3d log = Log(Exp(w));
    EXPECT_LE(std::min((log - w).norm(), (log + w).norm()), kRoundingUlps * kEpsilon * M_PI) << log.transpose();
    const Eigen::Quaterniond half_turn(0.0, w.x() / M_PI, w.y() / M_PI, w.z() / M_PI);  // w = 0 exactly
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Quaterniond q(sign * half_turn.coeffs());
      EXPECT_NEAR(Log(q).norm(), M_PI, kRoundingUlps * kEpsilon * M_PI);
      EXPECT_LE(QuaternionDistance(Exp(Log(q)), q), kRoundingUlps * kEpsilon);
    }
  }
}

TEST(GeometryTest, ExpInvertsLogAndLogTakesTheShortWay) {
  std::mt19937 rng(13);
  for (const double angle : kAngles) {
    const Eigen::Quaterniond q = testing::RotationAbout(angle * RandomAxis(&rng));
    EXPECT_LE(QuaternionDistance(Exp(Log(q)), q), kRoundingUlps * kEpsilon) << "angle " << angle;
    // q and -q: the same rotation vector, of angle at most pi.
    const Eigen::Quaterniond minus_q(-q.coeffs());
    EXPECT_LE((Log(minus_q) - Log(q)).norm(), kRoundingUlps * kEpsilon * angle) << "angle " << angle;
    EXPECT_LE(Log(minus_q).norm(), M_PI);
  }
}

// Jet derivatives of Exp and Log (what AutoDiffFactor differentiates) against central differences, and at zero
// exactly: d Exp(w)/dw = [0; I/2] and d Log(q)/dq = [0, 2 I] at the identity (q = [w, x, y, z]).
TEST(GeometryTest, JetDerivativesOfExpAndLogMatchCentralDifferences) {
  const auto exp_jacobian = [](const Eigen::Vector3d& w) {
    using J = Jet<3>;
    const Quaternion<J> q = QuaternionExp<J>(Vector3<J>(J(w.x(), 0), J(w.y(), 1), J(w.z(), 2)));
    Eigen::Matrix<double, 4, 3> jacobian;
    jacobian << q.w().v.transpose(), q.x().v.transpose(), q.y().v.transpose(), q.z().v.transpose();
    return jacobian;
  };
  const auto exp_coeffs = [](const Eigen::VectorXd& w) {
    const Eigen::Quaterniond q = Exp(w);
    return Eigen::VectorXd(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
  };
  // Log as a function of the four coefficients [w, x, y, z].
  const auto log_jacobian = [](const Eigen::Vector4d& q) {
    using J = Jet<4>;
    const Vector3<J> log = QuaternionLog<J>(Quaternion<J>(J(q[0], 0), J(q[1], 1), J(q[2], 2), J(q[3], 3)));
    Eigen::Matrix<double, 3, 4> jacobian;
    jacobian << log.x().v.transpose(), log.y().v.transpose(), log.z().v.transpose();
    return jacobian;
  };
  const auto log_of_coeffs = [](const Eigen::VectorXd& q) {
    return Eigen::VectorXd(Log(Eigen::Quaterniond(q[0], q[1], q[2], q[3])));
  };

  Eigen::Matrix<double, 4, 3> exp_at_zero = Eigen::Matrix<double, 4, 3>::Zero();
  exp_at_zero.bottomRows<3>() = 0.5 * Eigen::Matrix3d::Identity();
  EXPECT_EQ(exp_jacobian(Eigen::Vector3d::Zero()), exp_at_zero);
  Eigen::Matrix<double, 3, 4> log_at_identity = Eigen::Matrix<double, 3, 4>::Zero();
  log_at_identity.rightCols<3>() = 2.0 * Eigen::Matrix3d::Identity();
  EXPECT_EQ(log_jacobian(Eigen::Vector4d(1, 0, 0, 0)), log_at_identity);

  std::mt19937 rng(17);
  for (const double angle : kAngles) {
    SCOPED_TRACE(::testing::Message() << "angle " << angle);
    const Eigen::Vector3d w = angle * RandomAxis(&rng);
    const double h = CentralDifferenceStep();
    const Eigen::MatrixXd exp_numeric = CentralDifferenceJacobian(exp_coeffs, w, h);
    EXPECT_LE((exp_jacobian(w) - exp_numeric).lpNorm<Eigen::Infinity>(), CentralDifferenceTolerance(h));
    // Log flips q to -q where its w turns negative (a jump): near a half turn, where w = cos(angle / 2), the step
    // stays within w. Its derivatives are bounded there (atan2 away from the origin); their scale is the angle's.
    const Eigen::Quaterniond q = Exp(w);
    const Eigen::Vector4d coeffs(q.w(), q.x(), q.y(), q.z());
    const double h_log = std::min(h, q.w() / 8);
    const Eigen::MatrixXd log_numeric = CentralDifferenceJacobian(log_of_coeffs, coeffs, h_log);
    EXPECT_LE((log_jacobian(coeffs) - log_numeric).lpNorm<Eigen::Infinity>(),
              CentralDifferenceTolerance(h_log, 1.0 + angle));
  }
}

// The SO(3) Jacobians of so3_jacobians.h against central differences of their defining relations:
//   Log(Exp(phi)^-1 Exp(phi + d)) = Jr(phi) d,  Log(Exp(phi) Exp(d)) - phi = Jr^-1(phi) d,
//   Log(Exp(phi + d) Exp(phi)^-1) = Jl(phi) d,  Log(Exp(d) Exp(phi)) - phi = Jl^-1(phi) d,
// and the identities Jl = Jr(-phi) = Jr^T = R(phi) Jr, Jr Jr^-1 = I.
TEST(GeometryTest, So3JacobiansMatchCentralDifferences) {
  std::mt19937 rng(19);
  for (const double angle : kAngles) {
    SCOPED_TRACE(::testing::Message() << "angle " << angle);
    const Eigen::Vector3d phi = angle * RandomAxis(&rng);
    const Eigen::Quaterniond R = Exp(phi);
    const Eigen::Matrix3d Jr = RightJacobianSO3(phi);
    const Eigen::Matrix3d Jr_inv = InverseRightJacobianSO3(phi);
    const double h = CentralDifferenceStep();
    const auto right = [&](const Eigen::Vector3d& p) { return Eigen::VectorXd(Log(R.conjugate() * Exp(p))); };
    const auto left = [&](const Eigen::Vector3d& p) { return Eigen::VectorXd(Log(Exp(p) * R.conjugate())); };
    const Eigen::MatrixXd Jr_numeric = CentralDifferenceJacobian(right, phi, h);
    const Eigen::MatrixXd Jl_numeric = CentralDifferenceJacobian(left, phi, h);
    EXPECT_LE((Jr - Jr_numeric).lpNorm<Eigen::Infinity>(), CentralDifferenceTolerance(h));
    EXPECT_LE((Jr.transpose() - Jl_numeric).lpNorm<Eigen::Infinity>(), CentralDifferenceTolerance(h));
    // Log jumps at a half turn (from pi u to -pi u): the steps stay within the distance to it. Its derivatives are
    // bounded up to there; their scale is the angle's.
    const double h_log = std::min(h, (M_PI - angle) / 8);
    const double scale = 1.0 + angle;
    const auto log_right = [&](const Eigen::Vector3d& d) { return Eigen::VectorXd(Log(R * Exp(d))); };
    const auto log_left = [&](const Eigen::Vector3d& d) { return Eigen::VectorXd(Log(Exp(d) * R)); };
    const Eigen::MatrixXd Jr_inv_numeric = CentralDifferenceJacobian(log_right, Eigen::Vector3d::Zero(), h_log);
    const Eigen::MatrixXd Jl_inv_numeric = CentralDifferenceJacobian(log_left, Eigen::Vector3d::Zero(), h_log);
    EXPECT_LE((Jr_inv - Jr_inv_numeric).lpNorm<Eigen::Infinity>(), CentralDifferenceTolerance(h_log, scale));
    EXPECT_LE((Jr_inv.transpose() - Jl_inv_numeric).lpNorm<Eigen::Infinity>(),
              CentralDifferenceTolerance(h_log, scale));
    // Identities, to rounding: the entries of Jr and Jr^-1 are at most about 1 + angle^2.
    const double rounding = kRoundingUlps * kEpsilon * (1.0 + angle * angle);
    EXPECT_LE((RightJacobianSO3(-phi) - Jr.transpose()).lpNorm<Eigen::Infinity>(), rounding);
    EXPECT_LE((R.toRotationMatrix() * Jr - Jr.transpose()).lpNorm<Eigen::Infinity>(), rounding);
    EXPECT_LE((Jr * Jr_inv - Eigen::Matrix3d::Identity()).lpNorm<Eigen::Infinity>(), rounding);
  }
}

// Poses and velocities.

TEST(GeometryTest, PoseArraysRoundTrip) {
  const double x[] = {1.0, -2.0, 3.0, 0.5, 0.5, -0.5, 0.5};
  const Pose<double> pose = PoseFromArray(x);
  EXPECT_EQ(pose.p_world_body, Eigen::Vector3d(1.0, -2.0, 3.0));
  EXPECT_EQ(pose.q_world_body.coeffs(), Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5).coeffs());
  double back[7];
  PoseToArray(pose, back);
  EXPECT_TRUE(std::equal(back, back + 7, x));
}

// Phi is q Exp(omega dt); PredictPose turns half-way, moves v dt along the body axes there and turns the rest;
// VelocitiesBetween recovers (v, omega) from the two poses.
TEST(GeometryTest, VelocitiesBetweenInvertsPredictPose) {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 8; ++trial) {
    const Eigen::VectorXd x = testing::RandomPoint(Manifold::Pose(), &rng, 5.0);
    const Pose<double> pose0 = PoseFromArray(x.data());
    const Eigen::Vector3d v = testing::GaussianNoise(3, 3.0, &rng);
    const Eigen::Vector3d omega = testing::GaussianNoise(3, 1.0, &rng);
    const double dt = 0.1;
    EXPECT_EQ(Phi<double>(pose0.q_world_body, omega, dt).coeffs(), (pose0.q_world_body * Exp(omega * dt)).coeffs());
    const Pose<double> pose1 = PredictPose<double>(pose0, v, omega, dt);
    const Eigen::Quaterniond q_mid = pose0.q_world_body * Exp(omega * dt / 2);
    EXPECT_LE((pose1.p_world_body - (pose0.p_world_body + q_mid * (v * dt))).norm(),
              kRoundingUlps * kEpsilon * (1.0 + x.head<3>().norm()));
    Eigen::Vector3d v_back, omega_back;
    VelocitiesBetween<double>(pose0, pose1, dt, &v_back, &omega_back);
    // Rounding of positions of scale |p| divided by dt.
    EXPECT_LE((v_back - v).norm(), kRoundingUlps * kEpsilon * (1.0 + x.head<3>().norm()) / dt);
    EXPECT_LE((omega_back - omega).norm(), kRoundingUlps * kEpsilon / dt);
  }
}

// The velocity of O from that of a sensor S rigidly mounted at p_body_sensor: v_O = v_S - omega x p_body_sensor (both
// in O's axes), omega_O = R_body_sensor omega_S.
TEST(GeometryTest, SensorToBodyVelocityIsTheRigidBodyRelation) {
  std::mt19937 rng(29);
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::Quaterniond q_body_sensor =
        QuaternionFromArray(testing::RandomPoint(Manifold::UnitQuaternion(), &rng).data());
    const Eigen::Vector3d p_body_sensor = testing::GaussianNoise(3, 1.0, &rng);
    const Eigen::Vector3d v_sensor = testing::GaussianNoise(3, 3.0, &rng);
    const Eigen::Vector3d omega_sensor = testing::GaussianNoise(3, 1.0, &rng);
    Eigen::Vector3d v_body, omega_body;
    SensorToBodyVelocity<double>(v_sensor, omega_sensor, q_body_sensor, p_body_sensor, &v_body, &omega_body);
    const Eigen::Vector3d omega_expected = q_body_sensor * omega_sensor;
    const Eigen::Vector3d v_expected = q_body_sensor * v_sensor - omega_expected.cross(p_body_sensor);
    EXPECT_LE((omega_body - omega_expected).norm(), kRoundingUlps * kEpsilon * omega_sensor.norm());
    EXPECT_LE((v_body - v_expected).norm(),
              kRoundingUlps * kEpsilon * (v_sensor.norm() + omega_sensor.norm() * (1.0 + p_body_sensor.norm())));
  }
}

TEST(GeometryTest, SkewIsTheCrossProductMatrix) {
  const Eigen::Vector3d a(0.3, -1.2, 2.0), b(-0.7, 0.4, 1.1);
  EXPECT_EQ(Skew<double>(a) * b, a.cross(b));
  EXPECT_EQ(Skew<double>(a).transpose(), -Skew<double>(a));
}

}  // namespace
}  // namespace roamlab::estimator
