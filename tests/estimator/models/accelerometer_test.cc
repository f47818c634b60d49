#include "estimator/models/accelerometer.h"

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

// Values for the three poses with an ideal sensor: identity misalignment, lever arm S, zero bias, unit scale.
std::vector<Eigen::VectorXd> IdealSensorValues(const Eigen::VectorXd& pose0, const Eigen::VectorXd& pose1,
                                               const Eigen::VectorXd& pose2,
                                               const Eigen::Vector3d& p_body_sensor = Eigen::Vector3d::Zero()) {
  return {pose0,
          pose1,
          pose2,
          QuaternionVector(Eigen::Quaterniond::Identity()),
          p_body_sensor,
          Eigen::Vector3d::Zero(),
          Eigen::Vector3d::Ones()};
}

// The predicted reading: with z = 0, e = scale o a_hat^(S) + bias.
Eigen::Vector3d PredictedReading(double dt0, double dt1, const std::vector<Eigen::VectorXd>& values) {
  return testing::Evaluate(*MakeFactor(AccelerometerError(Eigen::Vector3d::Zero(), dt0, dt1)), values).error;
}

TEST(AccelerometerErrorTest, LevelAtRestReadsPlusGravityOnZ) {
  const Eigen::VectorXd pose = PoseVector(Eigen::Vector3d(1.0, 2.0, 3.0), Eigen::Quaterniond::Identity());
  const Eigen::Vector3d z(0.1, -0.2, 9.7);
  const testing::Linearization lin =
      testing::Evaluate(*MakeFactor(AccelerometerError(z, 0.02, 0.03)), IdealSensorValues(pose, pose, pose));
  // e = -z + [0, 0, 9.80665]: a level accelerometer at rest reads +9.80665 m/s^2 on its z (up) axis.
  EXPECT_LT((lin.error - (Eigen::Vector3d(0.0, 0.0, 9.80665) - z)).norm(), 1e-12);
  EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::Matrix3d::Identity()));
}

TEST(AccelerometerErrorTest, RollNinetyDegreesReadsGravityOnY) {
  // q_world_body = 90 deg about x: R = [1 0 0; 0 0 -1; 0 1 0] takes the body's y axis to [0, 0, 1], world up. The
  // reading R^T [0, 0, g] = [0, g, 0]: +9.80665 on the sensor's y axis, nothing on z.
  const Eigen::Quaterniond roll_90(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitX()));
  const Eigen::VectorXd pose = PoseVector(Eigen::Vector3d(-4.0, 0.5, 1.0), roll_90);
  const Eigen::Vector3d reading = PredictedReading(0.02, 0.02, IdealSensorValues(pose, pose, pose));
  EXPECT_LT((reading - Eigen::Vector3d(0.0, kStandardGravity, 0.0)).norm(), 1e-12);
}

TEST(AccelerometerErrorTest, ZeroAtTruthForConstantAccelerationAndSpin) {
  // O moves with constant world acceleration a and spins at a constant body rate omega; the sensor sits at S with
  // misalignment, bias and scale. Positions are quadratic in time and the rotation has a fixed axis, so the finite
  // differences are exact even with dt0 != dt1, and the true reading is
  //   z = scale o (q_body_sensor^-1 (R1^T (a + [0, 0, g]) + omega x (omega x S))) + bias.
  std::mt19937 rng(21);
  const Eigen::Vector3d p0 = RandomPoint(Manifold::Euclidean(3), &rng, 10.0);
  const Eigen::VectorXd q0_wxyz = RandomPoint(Manifold::UnitQuaternion(), &rng);
  const Eigen::Quaterniond q0 = QuaternionFromArray(q0_wxyz.data());
  const Eigen::Vector3d v0(1.5, -0.4, 0.2);
  const Eigen::Vector3d a_world(0.7, 1.3, -0.5);
  const Eigen::Vector3d omega_body(0.3, -0.5, 0.9);
  const double dt0 = 0.02;
  const double dt1 = 0.035;
  auto pose_at = [&](double t) {
    return PoseVector(p0 + v0 * t + 0.5 * a_world * t * t, q0 * RotationAbout(omega_body * t));
  };
  const Eigen::Quaterniond q_body_sensor(Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.3, -1.0, 0.5).normalized()));
  const Eigen::Vector3d p_body_sensor(0.25, -0.1, 0.4);
  const Eigen::Vector3d bias(0.05, -0.03, 0.08);
  const Eigen::Vector3d scale(1.01, 0.98, 1.03);

  const Eigen::Matrix3d R1 = (q0 * RotationAbout(omega_body * dt0)).toRotationMatrix();
  const Eigen::Vector3d f_body = R1.transpose() * (a_world + Eigen::Vector3d(0.0, 0.0, kStandardGravity)) +
                                 omega_body.cross(omega_body.cross(p_body_sensor));
  const Eigen::Vector3d z = scale.cwiseProduct(q_body_sensor.conjugate() * f_body) + bias;

  const AccelerometerError model(z, dt0, dt1);
  const std::vector<Eigen::VectorXd> values = {
      pose_at(0.0), pose_at(dt0), pose_at(dt0 + dt1), QuaternionVector(q_body_sensor), p_body_sensor, bias, scale};
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(model), values);
  EXPECT_LT(lin.error.norm(), 1e-8);
  EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::Matrix3d::Identity()));
}

// A body on a horizontal circle of radius r around the world origin, counter-clockwise at speed v, heading along the
// tangent: yaw = theta + pi/2, so the body's x axis is the direction of travel and its y axis points to the centre.
struct Circle {
  double radius = 5.0;                            // [m]
  double speed = 2.0;                             // [m/s]
  double rate() const { return speed / radius; }  // [rad/s]
  Eigen::VectorXd PoseAt(double theta) const {
    return PoseVector(Eigen::Vector3d(radius * std::cos(theta), radius * std::sin(theta), 1.5),
                      Eigen::Quaterniond(Eigen::AngleAxisd(theta + kPi / 2.0, Eigen::Vector3d::UnitZ())));
  }
};

TEST(AccelerometerErrorTest, CircleReadsCentripetalSpecificForce) {
  const Circle circle;
  const double omega = circle.rate();
  const double dt = 0.01 / omega;  // omega dt = 0.01
  const double theta1 = 0.7;
  const Eigen::Vector3d reading = PredictedReading(
      dt, dt,
      IdealSensorValues(circle.PoseAt(theta1 - omega * dt), circle.PoseAt(theta1), circle.PoseAt(theta1 + omega * dt)));
  // True specific force: v^2/r = 0.8 m/s^2 toward the centre (body +y) and +g up. The second difference of
  // r cos(omega t) underestimates omega^2 r by the factor 2 (1 - cos(omega dt)) / (omega dt)^2 = 1 - (omega dt)^2/12
  // + ..., so the bound is (v^2 / r) (omega dt)^2 / 12 (about 7e-6 m/s^2 here), with 1% slack.
  const double centripetal = circle.speed * circle.speed / circle.radius;
  const Eigen::Vector3d expected(0.0, centripetal, kStandardGravity);
  const double bound = 1.01 * centripetal * 0.01 * 0.01 / 12.0;
  EXPECT_LE((reading - expected).norm(), bound) << reading.transpose();
  EXPECT_LT(reading.y(), centripetal);  // the truncation error has the sign worked out above
}

TEST(AccelerometerErrorTest, DisplacedSensorOnTurningBodySeesOmegaCrossOmegaCrossS) {
  // The body turns rigidly about the world z axis, so every body-fixed point, the sensor's c = p + R S included, moves
  // on a horizontal circle about that axis with acceleration -omega^2 [c_x, c_y, 0]. The expected reading is that
  // acceleration minus gravity, in the body frame at t1.
  const Circle circle;
  const double omega = circle.rate();
  const double dt = 0.01 / omega;
  const double theta1 = -1.2;
  const Eigen::Vector3d p_body_sensor(0.3, -0.2, 0.5);
  const std::vector<Eigen::VectorXd> poses = {circle.PoseAt(theta1 - omega * dt), circle.PoseAt(theta1),
                                              circle.PoseAt(theta1 + omega * dt)};
  const Eigen::Vector3d displaced =
      PredictedReading(dt, dt, IdealSensorValues(poses[0], poses[1], poses[2], p_body_sensor));
  const Eigen::Vector3d centred = PredictedReading(dt, dt, IdealSensorValues(poses[0], poses[1], poses[2]));

  const Pose<double> pose1 = PoseFromArray(poses[1].data());
  const Eigen::Vector3d c_world = pose1.p_world_body + pose1.q_world_body * p_body_sensor;
  const Eigen::Vector3d a_sensor_world(-omega * omega * c_world.x(), -omega * omega * c_world.y(), 0.0);
  const Eigen::Vector3d expected =
      pose1.q_world_body.conjugate() * (a_sensor_world + Eigen::Vector3d(0.0, 0.0, kStandardGravity));
  const double bound = 1.01 * circle.speed * circle.speed / circle.radius * 0.01 * 0.01 / 12.0;
  EXPECT_LE((displaced - expected).norm(), bound) << displaced.transpose();

  // The lever arm adds omega x (omega x S) = -omega^2 [S_x, S_y, 0] (0.16 * [-0.3, 0.2, 0] here), exactly: the rate
  // estimate is exact for a fixed axis and the angular acceleration is zero.
  const Eigen::Vector3d lever_term = displaced - centred;
  EXPECT_LT((lever_term - Eigen::Vector3d(-omega * omega * 0.3, omega * omega * 0.2, 0.0)).norm(), 1e-9);
}

TEST(AccelerometerErrorTest, AngularAccelerationTermAppears) {
  // O stays at a fixed point and yaws with theta(t) = theta1 + w1 (t - t1) + alpha (t - t1)^2 / 2. The sensor at S
  // moves on a circle about O: in the body frame its acceleration is alpha x S + omega x (omega x S), so for
  // S = [s, 0, 0] the reading is [-w1^2 s, alpha s, g]. theta is quadratic in t with a fixed axis, so with equal steps
  // the rate at t1 and the angular acceleration are estimated exactly.
  const double w1 = 0.8;     // [rad/s]
  const double alpha = 2.0;  // [rad/s^2]
  const double s = 0.4;      // [m]
  const double dt = 0.02;
  auto pose_at = [&](double t) {
    const double theta = 0.3 + w1 * t + 0.5 * alpha * t * t;
    return PoseVector(Eigen::Vector3d(2.0, -1.0, 0.5),
                      Eigen::Quaterniond(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ())));
  };
  const Eigen::Vector3d reading = PredictedReading(
      dt, dt, IdealSensorValues(pose_at(-dt), pose_at(0.0), pose_at(dt), Eigen::Vector3d(s, 0.0, 0.0)));
  EXPECT_LT((reading - Eigen::Vector3d(-w1 * w1 * s, alpha * s, kStandardGravity)).norm(), 1e-9) << reading.transpose();
}

TEST(AccelerometerErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> dt_dist(0.01, 0.05);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose0 = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd pose1 = Perturb(Manifold::Pose(), pose0, 0.02, &rng);
    const Eigen::VectorXd pose2 = Perturb(Manifold::Pose(), pose1, 0.02, &rng);
    const Eigen::VectorXd q_body_sensor =
        Perturb(Manifold::UnitQuaternion(), Manifold::UnitQuaternion().Identity(), 0.3, &rng);
    const Eigen::VectorXd p_body_sensor = RandomPoint(Manifold::Euclidean(3), &rng, 0.5);
    const Eigen::VectorXd bias = RandomPoint(Manifold::Euclidean(3), &rng, 0.1);
    const Eigen::VectorXd scale = Eigen::Vector3d::Ones() + RandomPoint(Manifold::Euclidean(3), &rng, 0.05);
    const Eigen::Vector3d z = Eigen::Vector3d(0.0, 0.0, kStandardGravity) + RandomPoint(Manifold::Euclidean(3), &rng);
    const AccelerometerError model(z, dt_dist(rng), dt_dist(rng));
    const std::vector<Eigen::VectorXd> values = {pose0, pose1, pose2, q_body_sensor, p_body_sensor, bias, scale};
    testing::ExpectModelJacobiansMatchNumeric(model, values);
  }
}

// A stretch of motion on which the model's finite differences are exact at equal steps: O moves with constant jerk
// (positions cubic in t; the central second difference of a cubic is its second derivative) and turns about an axis
// fixed in O with constant angular acceleration (the angle is quadratic in t, so the rotation vectors' differences give
// the rate and the angular acceleration exactly).
struct FixedAxisStretch {
  Eigen::Vector3d p0, v0, a0, jerk;   // W, at t = 0 [m, m/s, m/s^2, m/s^3]
  Eigen::Quaterniond q0;              // q_world_body at t = 0
  Eigen::Vector3d axis;               // unit, in O
  double rate0 = 0.0;                 // [rad/s] at t = 0
  double angular_acceleration = 0.0;  // [rad/s^2]

  Eigen::Quaterniond OrientationAt(double t) const {
    return q0 * RotationAbout(axis * (rate0 * t + 0.5 * angular_acceleration * t * t));
  }
  Eigen::VectorXd PoseAt(double t) const {
    return PoseVector(p0 + v0 * t + 0.5 * a0 * t * t + jerk * t * t * t / 6.0, OrientationAt(t));
  }
  // Specific force at a point S^(O) of the body, in O: the point's acceleration a + R (alpha x S + omega x (omega x
  // S)) minus gravity, rotated into O.
  Eigen::Vector3d SpecificForceAt(double t, const Eigen::Vector3d& p_body_sensor) const {
    const Eigen::Vector3d omega = axis * (rate0 + angular_acceleration * t);
    const Eigen::Vector3d alpha = axis * angular_acceleration;
    const Eigen::Vector3d a_world = a0 + jerk * t;
    return OrientationAt(t).toRotationMatrix().transpose() * (a_world + Eigen::Vector3d(0.0, 0.0, kStandardGravity)) +
           alpha.cross(p_body_sensor) + omega.cross(omega.cross(p_body_sensor));
  }
};

// The accelerometer's small end-to-end problem: a misaligned, displaced, biased, scaled accelerometer on six
// stretches of fixed-axis motion (random axes, orientations and accelerations from the seed), 21 poses 0.05 s apart
// each, one reading at every inner pose, z = k_s o ((R_S^O)^T f) + b + eta. Pose priors hold the poses. A single fixed
// axis would leave the lever arm's component along it and part of the misalignment unobservable; six axes make all
// 12 parameters observable. They start at their nominal values (identity, 0, 0, 1).
testing::SmallProblem AccelerometerProblem(bool noisy, std::uint32_t seed) {
  const double sigma = 0.02;  // [m/s^2]
  const int stretches = 6;
  const int poses_per_stretch = 21;
  const double dt = 0.05;
  const Eigen::Quaterniond q_body_sensor = RotationAbout(Eigen::Vector3d(0.05, -0.1, 0.08));
  const Eigen::Vector3d p_body_sensor(0.3, -0.2, 0.5);
  const Eigen::Vector3d bias(0.1, -0.05, 0.08);
  const Eigen::Vector3d scale(1.02, 0.98, 1.03);

  std::mt19937 rng(seed);
  testing::SmallProblem problem;
  const std::vector<VariableId> parameters = {
      testing::AddFreeParameter("misalignment", Manifold::UnitQuaternion(),
                                QuaternionVector(Eigen::Quaterniond::Identity()), QuaternionVector(q_body_sensor),
                                &problem),
      testing::AddFreeParameter("lever_arm", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), p_body_sensor, &problem),
      testing::AddFreeParameter("bias", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), bias, &problem),
      testing::AddFreeParameter("scale", Manifold::Euclidean(3), Eigen::Vector3d::Ones(), scale, &problem)};
  std::uniform_real_distribution<double> rate(1.0, 2.0), angular_acceleration(-4.0, 4.0);
  for (int s = 0; s < stretches; ++s) {
    FixedAxisStretch stretch;
    stretch.p0 = RandomPoint(Manifold::Euclidean(3), &rng, 10.0);
    stretch.v0 = RandomPoint(Manifold::Euclidean(3), &rng, 2.0);
    stretch.a0 = RandomPoint(Manifold::Euclidean(3), &rng, 1.5);
    stretch.jerk = RandomPoint(Manifold::Euclidean(3), &rng, 2.0);
    stretch.q0 = QuaternionFromArray(RandomPoint(Manifold::UnitQuaternion(), &rng).data());
    stretch.axis = RandomPoint(Manifold::Euclidean(3), &rng).normalized();
    stretch.rate0 = (s % 2 == 0 ? 1.0 : -1.0) * rate(rng);
    stretch.angular_acceleration = angular_acceleration(rng);

    // Poses at t_j = (j - 10) dt, readings at the inner ones.
    std::vector<Eigen::VectorXd> truth;
    for (int j = 0; j < poses_per_stretch; ++j) truth.push_back(stretch.PoseAt((j - poses_per_stretch / 2) * dt));
    const std::vector<VariableId> ids = testing::AddAnchoredPoses(truth, 0.0005, 0.0005, noisy, &rng, &problem);
    for (int j = 1; j + 1 < poses_per_stretch; ++j) {
      const Eigen::Vector3d f_body = stretch.SpecificForceAt((j - poses_per_stretch / 2) * dt, p_body_sensor);
      const Eigen::Vector3d z = scale.cwiseProduct(q_body_sensor.toRotationMatrix().transpose() * f_body) + bias +
                                testing::GaussianNoise(3, testing::NoiseSigma(noisy, sigma), &rng);
      problem.graph.AddFactor(
          MakeFactor(AccelerometerError(z, dt, dt)),
          {ids[j - 1], ids[j], ids[j + 1], parameters[0], parameters[1], parameters[2], parameters[3]},
          Eigen::Matrix3d::Identity() * sigma * sigma, Loss::Trivial(), "accelerometer",
          Time::FromNanoseconds(s * poses_per_stretch + j));
    }
  }
  return problem;
}

TEST(AccelerometerErrorTest, SmallSolveRecoversMisalignmentLeverArmBiasAndScale) {
  testing::SmallProblem problem = AccelerometerProblem(false, 23);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(AccelerometerErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = AccelerometerProblem(true, 24);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: every standard deviation is below a third of the smallest offset the solve started from (0.02).
  EXPECT_LT(sigma.maxCoeff(), 0.02 / 3.0) << sigma.transpose();
}

}  // namespace
}  // namespace roamlab::estimator
