#include "estimator/models/imu_time_offset.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "estimator/models/accelerometer.h"
#include "estimator/models/gyroscope.h"
#include "estimator/models/magnetometer.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::Perturb;
using testing::PoseVector;
using testing::QuaternionVector;
using testing::RandomPoint;
using testing::RotationAbout;

const Eigen::Vector3d kFieldWorld(0.0, 0.6, -0.8);
const Eigen::Quaterniond kQBodySensor(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 2.0, -1.0).normalized()));

Eigen::VectorXd Scalar(double x) { return Eigen::VectorXd::Constant(1, x); }

// Seven poses at uneven steps around a random start, turning and moving by a few centimetres and degrees per step.
std::vector<Eigen::VectorXd> PoseChain(std::mt19937* rng) {
  std::vector<Eigen::VectorXd> poses = {RandomPoint(Manifold::Pose(), rng, 5.0)};
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 6; ++i) {
    const Pose<double> p = PoseFromArray(poses.back().data());
    const Eigen::Vector3d step(0.05 + 0.01 * n(*rng), 0.01 * n(*rng), 0.01 * n(*rng));
    const Eigen::Vector3d turn(0.02 * n(*rng), 0.02 * n(*rng), 0.05 + 0.02 * n(*rng));
    poses.push_back(PoseVector(p.p_world_body + p.q_world_body * step, p.q_world_body * RotationAbout(turn)));
  }
  return poses;
}

const Eigen::Vector4d kDt(0.011, 0.009, 0.010, 0.012);
const Eigen::Vector4d kSpanDt(0.021, 0.019, 0.020, 0.022);

TEST(ImuTimeOffsetTest, AtZeroOffsetEachModelIsThePlainOne) {
  std::mt19937 rng(3);
  const std::vector<Eigen::VectorXd> p = PoseChain(&rng);
  const Eigen::VectorXd q = QuaternionVector(kQBodySensor);
  const Eigen::Vector3d bias(0.01, -0.02, 0.03), scale(1.02, 0.97, 1.01), lever(0.3, -0.2, 0.5);
  const Eigen::Vector3d z(0.3, -0.4, 9.5);

  const auto error = [](const Factor& f, const std::vector<Eigen::VectorXd>& values) {
    return testing::Evaluate(f, values).error;
  };
  // Gyroscope over the interval [p1, p2], with p0 and p3 around it.
  EXPECT_LT((error(*MakeFactor(GyroscopeTimeOffsetError(z, kDt[0], kDt[1], kDt[2])),
                   {p[0], p[1], p[2], p[3], q, bias, scale, Scalar(0.0)}) -
             error(*MakeFactor(GyroscopeError(z, kDt[1])), {p[1], p[2], q, bias, scale}))
                .norm(),
            1e-10);
  // Accelerometer at p3.
  EXPECT_LT((error(*MakeFactor(AccelerometerTimeOffsetError(z, kDt[1], kDt[2], kSpanDt)),
                   {p[0], p[1], p[2], p[3], p[4], p[5], p[6], q, lever, bias, scale, Scalar(0.0)}) -
             error(*MakeFactor(AccelerometerError(z, kDt[1], kDt[2])), {p[2], p[3], p[4], q, lever, bias, scale}))
                .norm(),
            1e-10);
  // Magnetometer at p1, with the motor-interference proxy.
  const Eigen::VectorXd A = (Eigen::VectorXd(9) << 1.05, 0.08, -0.02, -0.03, 0.95, 0.06, 0.1, 0.01, 1.1).finished();
  const Eigen::Vector3d k(4e-4, -2e-4, 1e-4), f(1.5, -0.7, 9.6);
  EXPECT_LT((error(*MakeFactor(MagnetometerTimeOffsetError(z, kFieldWorld, f, 49.6, kDt[0], kDt[1])),
                   {p[0], p[1], p[2], q, A, bias, k, Scalar(0.0)}) -
             error(*MakeFactor(MagnetometerError(z, kFieldWorld, f, 49.6)), {p[1], q, A, bias, k}))
                .norm(),
            1e-10);
}

// The jets' Jacobians, the offset's column among them, against central differences at a non-zero offset.
TEST(ImuTimeOffsetTest, JacobiansMatchCentralDifferences) {
  for (std::uint32_t seed : {5u, 6u, 7u}) {
    std::mt19937 rng(seed);
    const std::vector<Eigen::VectorXd> p = PoseChain(&rng);
    const Eigen::VectorXd q = Perturb(Manifold::UnitQuaternion(), QuaternionVector(kQBodySensor), 0.1, &rng);
    const Eigen::Vector3d bias(0.01, -0.02, 0.03), scale(1.02, 0.97, 1.01), lever(0.3, -0.2, 0.5);
    const Eigen::Vector3d z(0.3, -0.4, 9.5);
    const Eigen::VectorXd delta = Scalar(0.03 * (seed - 6.0) + 0.017);
    const GyroscopeTimeOffsetError gyro(Eigen::Vector3d(0.2, -0.1, 4.0), kDt[0], kDt[1], kDt[2]);
    testing::ExpectModelJacobiansMatchNumeric(gyro, {p[0], p[1], p[2], p[3], q, bias, scale, delta});
    testing::ExpectJacobiansMatchNumeric(*MakeFactor(AccelerometerTimeOffsetError(z, kDt[1], kDt[2], kSpanDt)),
                                         {p[0], p[1], p[2], p[3], p[4], p[5], p[6], q, lever, bias, scale, delta});
    const Eigen::VectorXd A = (Eigen::VectorXd(9) << 1.05, 0.08, -0.02, -0.03, 0.95, 0.06, 0.1, 0.01, 1.1).finished();
    testing::ExpectJacobiansMatchNumeric(
        *MakeFactor(MagnetometerTimeOffsetError(z, kFieldWorld, Eigen::Vector3d(1.5, -0.7, 9.6), 49.6, kDt[0], kDt[1])),
        {p[0], p[1], p[2], q, A, bias, Eigen::Vector3d(4e-4, -2e-4, 1e-4), delta});
  }
}

// A turn about a fixed axis at a uniformly growing rate omega(t) = w0 + a t: the mean rates over the spans before and
// after the reading's interval are the rates at the spans' middles, so their difference gives a exactly, and the
// reading of [t(k), t(k+1)], the mean rate over [t(k) - delta, t(k+1) - delta], is matched exactly; the offset's sign
// is the simulator's (sim/scenario.h).
TEST(ImuTimeOffsetTest, GyroscopeIsExactOnAUniformlyAcceleratingTurn) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  const double w0 = 0.4, a = 2.5, dt = 0.01, delta = 0.027;
  const auto angle = [&](double t) { return w0 * t + 0.5 * a * t * t; };
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.0, 0.6, 0.8)));
  std::vector<Eigen::VectorXd> p;
  for (double t : {-3 * dt, 0.0, dt, 4 * dt})   // m = 3
    p.push_back(PoseVector(Eigen::Vector3d::Zero(), q0 * RotationAbout(axis * angle(t))));
  const double mean_rate = (angle(dt - delta) - angle(-delta)) / dt;
  const Eigen::Vector3d z = kQBodySensor.conjugate() * (axis * mean_rate);
  const auto factor = MakeFactor(GyroscopeTimeOffsetError(z, 3 * dt, dt, 3 * dt));
  const Eigen::VectorXd q = QuaternionVector(kQBodySensor);
  const std::vector<Eigen::VectorXd> base = {p[0], p[1], p[2], p[3], q, Eigen::Vector3d::Zero(),
                                             Eigen::Vector3d::Ones()};
  std::vector<Eigen::VectorXd> values = base;
  values.push_back(Scalar(delta));
  EXPECT_LT(testing::Evaluate(*factor, values).error.norm(), 1e-12);
  values.back() = Scalar(-delta);   // the other sign is off by 2 delta a dt
  EXPECT_NEAR(testing::Evaluate(*factor, values).error.norm(), 2.0 * delta * a * dt, 1e-9);
}

// A level straight run with a constant jerk j: the positions are cubic in time, so the second differences give the
// acceleration exactly and their central difference its rate; the reading stamped t(k) = 0 is the specific force at
// -delta.
TEST(ImuTimeOffsetTest, AccelerometerIsExactOnAConstantJerkRun) {
  const double j = 1.7, dt = 0.01, delta = -0.034;
  std::vector<Eigen::VectorXd> p;
  for (double t : {-6 * dt, -3 * dt, -dt, 0.0, dt, 3 * dt, 6 * dt})   // m = 3
    p.push_back(PoseVector(Eigen::Vector3d(j * t * t * t / 6.0 + 0.8 * t * t, 0.0, 0.0), Eigen::Quaterniond::Identity()));
  const Eigen::Vector3d f_body(j * (0.0 - delta) + 1.6, 0.0, kStandardGravity);
  const Eigen::Vector3d z = kQBodySensor.conjugate() * f_body;
  const auto factor = MakeFactor(AccelerometerTimeOffsetError(z, dt, dt, Eigen::Vector4d::Constant(3 * dt)));
  const std::vector<Eigen::VectorXd> values = {p[0], p[1], p[2], p[3], p[4], p[5], p[6],
                                               QuaternionVector(kQBodySensor),
                                               Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                               Eigen::Vector3d::Ones(), Scalar(delta)};
  EXPECT_LT(testing::Evaluate(*factor, values).error.norm(), 1e-9);
}

// A constant turn: the field in S turns back by delta omega; the first-order model leaves (delta |omega|)^2 / 2.
TEST(ImuTimeOffsetTest, MagnetometerFollowsTheTurnToFirstOrder) {
  const Eigen::Vector3d omega(0.1, -0.2, 0.8);
  const double dt = 0.01, delta = 0.04;
  std::vector<Eigen::VectorXd> p;
  for (int i = -1; i <= 1; ++i) p.push_back(PoseVector(Eigen::Vector3d::Zero(), RotationAbout(omega * (i * dt))));
  const Eigen::Quaterniond q_then = RotationAbout(-omega * delta);
  const Eigen::Vector3d z = (q_then * kQBodySensor).conjugate() * kFieldWorld;
  const auto factor = MakeFactor(MagnetometerTimeOffsetError(z, kFieldWorld, Eigen::Vector3d::Zero(), 0.0, dt, dt));
  std::vector<Eigen::VectorXd> values = {p[0], p[1], p[2], QuaternionVector(kQBodySensor),
                                         (Eigen::VectorXd(9) << 1, 0, 0, 0, 1, 0, 0, 0, 1).finished(),
                                         Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Scalar(delta)};
  const double with_offset = testing::Evaluate(*factor, values).error.norm();
  EXPECT_LT(with_offset, 0.5 * std::pow(delta * omega.norm(), 2));
  values.back() = Scalar(0.0);
  EXPECT_GT(testing::Evaluate(*factor, values).error.norm(), 10.0 * with_offset);
}

}  // namespace
}  // namespace roamlab::estimator
