#include "estimator/models/ackermann_velocity.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

constexpr double kL = 1.25;

Eigen::VectorXd Scalar(double x) { return Eigen::VectorXd::Constant(1, x); }
// The rows' coloured disturbance (w_v, w_lat, w_vert) [m/s].
Eigen::VectorXd Disturbance(double w_v = 0.0, double w_lat = 0.0, double w_vert = 0.0) {
  return Eigen::Vector3d(w_v, w_lat, w_vert);
}

// Pose after dt on a planar arc at forward speed v, side slip v_y and yaw rate omega, from pose0 (eq. 7 is exact for
// a constant twist only up to the chord; VelocitiesBetween inverts eq. 7 exactly, so build pose1 with PredictPose).
Eigen::VectorXd Step(const Eigen::VectorXd& pose0, double v, double omega, double dt, double v_y = 0.0) {
  const Pose<double> p1 =
      PredictPose<double>(PoseFromArray(pose0.data()), Eigen::Vector3d(v, v_y, 0), Eigen::Vector3d(0, 0, omega), dt);
  Eigen::VectorXd out(7);
  PoseToArray(p1, out.data());
  return out;
}

TEST(AckermannVelocityErrorTest, ZeroAtTruthForTableIAndSkewedGains) {
  std::mt19937 rng(11);
  for (const auto& [kv_over_l, k_theta, k_gamma] :
       std::vector<std::tuple<double, double, double>>{{0.8, 1.0, 0.0}, {0.8, 1.05, 0.02}}) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 10.0);
    const double v = 4.0, delta = 0.2, dt = 0.01;
    const double omega = v * std::tan(delta) / kL;
    const double z_v = v / (kv_over_l * kL);
    const double z_theta = (delta - k_gamma) / k_theta;
    const auto factor = MakeFactor(AckermannVelocityError(z_v, z_theta, kL, dt));
    const auto lin = testing::Evaluate(
        *factor, {pose0, Step(pose0, v, omega, dt), Scalar(kv_over_l), Scalar(k_theta), Scalar(k_gamma), Scalar(0.0),
                  Scalar(0.0), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()});
    EXPECT_LT(lin.error.norm(), 1e-10);
    EXPECT_TRUE(lin.noise_jacobian.isApprox(Eigen::MatrixXd::Identity(4, 4)));
  }
}

TEST(AckermannVelocityErrorTest, SpeedErrorScalesWithGain) {
  // 10% too large a gain predicts a reading 1/1.1 of the one taken.
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  const auto factor = MakeFactor(AckermannVelocityError(4.0 / kL / 0.8, 0.0, kL, 0.01));
  const auto lin =
      testing::Evaluate(*factor, {pose0, Step(pose0, 4.0, 0.0, 0.01), Scalar(0.88), Scalar(1.0), Scalar(0.0),
                                  Scalar(0.0), Scalar(0.0), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()});
  EXPECT_NEAR(lin.error[0], 4.0 / kL / 0.88 - 4.0 / kL / 0.8, 1e-12);
}

TEST(AckermannVelocityErrorTest, SteeringIgnoredAtStandstill) {
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  const auto factor = MakeFactor(AckermannVelocityError(0.0, 0.3, kL, 0.01));
  const auto lin = testing::Evaluate(*factor, {pose0, pose0, Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(0.0),
                                               Scalar(0.0), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()});
  EXPECT_LT(lin.error.norm(), 1e-12);
}

TEST(AckermannVelocityErrorTest, CorneringComplianceExplainsSideSlipAndUndersteer) {
  // A left turn at 4 m/s with a_y = 2 m/s^2: the rear axle drifts outwards (v_y = -c_rear a_y) and the front wheels
  // are steered c_front a_y further than the front axle's velocity direction, atan((L omega + v_y) / v).
  const double v = 4.0, omega = 0.5, dt = 0.01, c_front = 0.004, c_rear = 0.015;
  const double a_y = v * omega, v_y = -c_rear * a_y;
  const double delta = std::atan((kL * omega + v_y) / v) + c_front * a_y;
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  const Eigen::VectorXd pose1 = Step(pose0, v, omega, dt, v_y);
  const auto factor = MakeFactor(AckermannVelocityError(v / kL / 0.8, delta, kL, dt));
  const auto lin = testing::Evaluate(*factor, {pose0, pose1, Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(c_front),
                                               Scalar(c_rear), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()});
  EXPECT_LT(lin.error.norm(), 1e-10) << lin.error.transpose();
  // Without the compliances the same motion leaves the side slip and the understeer as errors.
  const auto rigid = testing::Evaluate(*factor, {pose0, pose1, Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(0.0),
                                                 Scalar(0.0), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()});
  EXPECT_NEAR(rigid.error[1], -c_front * a_y, 1e-9);
  EXPECT_NEAR(rigid.error[2], v_y, 1e-9);
}

TEST(AckermannVelocityErrorTest, FrontSlipVelocityExplainsUndersteerAtEverySpeed) {
  // Option front_slip_velocity: the front axle drifts outwards at c_front a_y [m/s], so the front wheels are steered
  // at atan((L omega + v_y + c_front a_y) / v): an understeer angle of about c_front omega, the same c_front at 2 and
  // 5 m/s. The angle form would need c_front / (v (1 + r^2)), a different coefficient per speed.
  const double a_y = 1.0, dt = 0.01, c_front = 0.02, c_rear = 0.015;
  const AckermannVelocityError::Options slip_velocity{0.0, 0.0, true};
  double angle_per_a_y[2];
  for (int i = 0; i < 2; ++i) {
    const double v = i == 0 ? 2.0 : 5.0, omega = a_y / v, v_y = -c_rear * a_y;
    const double delta = std::atan((kL * omega + v_y + c_front * a_y) / v);
    const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
    const Eigen::VectorXd pose1 = Step(pose0, v, omega, dt, v_y);
    const auto factor = MakeFactor(AckermannVelocityError(v / kL / 0.8, delta, kL, dt, slip_velocity));
    const auto lin = testing::Evaluate(*factor, {pose0, pose1, Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(c_front),
                                                 Scalar(c_rear), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()});
    EXPECT_LT(lin.error.norm(), 1e-10) << lin.error.transpose();
    // The angle form (default options) leaves delta - atan((L omega + v_y) / v) as the steering error without
    // c_front; that understeer angle per a_y falls with the speed.
    const auto angle = testing::Evaluate(*MakeFactor(AckermannVelocityError(v / kL / 0.8, delta, kL, dt)),
                                         {pose0, pose1, Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(0.0),
                                          Scalar(c_rear), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()});
    angle_per_a_y[i] = -angle.error[1] / a_y;
    const double r = (kL * omega + v_y) / v;
    EXPECT_NEAR(angle_per_a_y[i], c_front / (v * (1.0 + r * r)), 0.05 * c_front / v);
  }
  EXPECT_GT(angle_per_a_y[0], 2.0 * angle_per_a_y[1]);
}

TEST(AckermannVelocityErrorTest, ThrustAngleExplainsCrabAndTurnAtZeroHandlebar) {
  // A rear axle turned by alpha = 2 deg: with the handlebar at zero the vehicle turns at -v tan(alpha) / L and crabs,
  // v_y = v tan(alpha); the rear wheels read the rolling speed v / cos(alpha).
  const double v = 4.0, dt = 0.01, alpha = 2.0 * 3.14159265358979 / 180.0;
  const double omega = -v * std::tan(alpha) / kL, v_y = v * std::tan(alpha);
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  const Eigen::VectorXd pose1 = Step(pose0, v, omega, dt, v_y);
  const auto factor = MakeFactor(AckermannVelocityError(v / std::cos(alpha) / kL / 0.8, 0.0, kL, dt));
  const auto lin = testing::Evaluate(*factor, {pose0, pose1, Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(0.0),
                                               Scalar(0.0), Scalar(alpha), Scalar(0.0), Scalar(0.0), Disturbance()});
  EXPECT_LT(lin.error.norm(), 1e-10) << lin.error.transpose();
  // Without it the crab is a lateral error of v tan(alpha); the front axle still moves straight ahead, so the
  // steering row holds.
  const auto aligned = testing::Evaluate(*factor, {pose0, pose1, Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(0.0),
                                                   Scalar(0.0), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()});
  EXPECT_NEAR(aligned.error[2], v_y, 1e-9);
  EXPECT_LT(std::abs(aligned.error[1]), 1e-9);
  EXPECT_NEAR(aligned.error[0], v - v / std::cos(alpha), 1e-9);
}

TEST(AckermannVelocityErrorTest, ContactBelowOExplainsPitchAndRollRates) {
  // O at the wheel centres, h = 0.28 m above the contact, L / 2 = 0.625 m chord lever: a rigid vehicle that rolls
  // without slip at 4 m/s over a crest (pitch rate 0.3 rad/s) while rolling at 0.2 rad/s and turning at 0.4 rad/s.
  // O moves at the contact's velocity plus omega x (0, 0, h), and along its z by d omega_y.
  const double v = 4.0, dt = 0.01, h = 0.28, d = 0.625;
  const Eigen::Vector3d omega(0.2, 0.3, 0.4);
  const Eigen::Vector3d v_odom(v + h * omega.y(), -h * omega.x(), d * omega.y());
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  Eigen::VectorXd pose1(7);
  PoseToArray(PredictPose<double>(PoseFromArray(pose0.data()), v_odom, omega, dt), pose1.data());
  const double delta = std::atan(kL * omega.z() / v);
  const std::vector<Eigen::VectorXd> values = {pose0,       pose1,       Scalar(0.8),  Scalar(1.0),
                                               Scalar(0.0), Scalar(0.0), Scalar(0.0),  Scalar(0.0),
                                               Scalar(0.0), Scalar(0.0), Disturbance()};
  const auto contact = MakeFactor(AckermannVelocityError(v / kL / 0.8, delta, kL, dt, {h, d}));
  const auto lin = testing::Evaluate(*contact, values);
  EXPECT_LT(lin.error.norm(), 1e-9) << lin.error.transpose();
  // Eq. 15 at O (the default) reads the same motion as a speed error of h omega_y (in the reading's units), a side
  // slip of -h omega_x and a vertical velocity of d omega_y: what the non-holonomic noise terms would have to absorb.
  const auto at_o = testing::Evaluate(*MakeFactor(AckermannVelocityError(v / kL / 0.8, delta, kL, dt)), values);
  EXPECT_NEAR(at_o.error[0], h * omega.y() / (0.8 * kL), 1e-9);
  EXPECT_NEAR(at_o.error[2], -h * omega.x(), 1e-9);
  EXPECT_NEAR(at_o.error[3], d * omega.y(), 1e-9);
}

TEST(AckermannVelocityErrorTest, LongitudinalSlipFollowsTractionAndSlope) {
  // Climbing a 10 % grade (pitch atan(0.1), nose up) at 4 m/s while accelerating at 0.5 m/s^2: the forward specific
  // force is f_x = 0.5 + g sin(pitch); the rear wheel over-reads by 1 + s_f f_x + s_p g sin(pitch).
  const double v = 4.0, dt = 0.01, pitch = std::atan(0.1), s_f = 0.03, s_p = 0.05;
  const double g_sin = kStandardGravity * std::sin(pitch), f_x = 0.5 + g_sin;
  Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  const Eigen::Quaterniond q(Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()));  // about y: nose up is negative
  pose0.segment<4>(3) << q.w(), q.x(), q.y(), q.z();
  const Eigen::VectorXd pose1 = Step(pose0, v, 0.0, dt);
  const double z_v = v * (1.0 + s_f * f_x + s_p * g_sin) / kL / 0.8;
  const auto factor = MakeFactor(AckermannVelocityError(z_v, 0.0, kL, dt, {}, f_x));
  const auto lin = testing::Evaluate(*factor, {pose0, pose1, Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(0.0),
                                               Scalar(0.0), Scalar(0.0), Scalar(s_f), Scalar(s_p), Disturbance()});
  EXPECT_LT(lin.error.norm(), 1e-10) << lin.error.transpose();
  // Without the slip the reading is too high by v (s_f f_x + s_p g sin(pitch)); on the flat (the same step at zero
  // pitch) only the traction's part is left for s_f to explain.
  const auto rigid = testing::Evaluate(*factor, {pose0, pose1, Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(0.0),
                                                 Scalar(0.0), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()});
  EXPECT_NEAR(rigid.error[0], -v * (s_f * f_x + s_p * g_sin) / kL / 0.8, 1e-9);
  const Eigen::VectorXd flat0 = Manifold::Pose().Identity();
  const auto flat =
      testing::Evaluate(*factor, {flat0, Step(flat0, v, 0.0, dt), Scalar(0.8), Scalar(1.0), Scalar(0.0), Scalar(0.0),
                                  Scalar(0.0), Scalar(0.0), Scalar(s_f), Scalar(s_p), Disturbance()});
  EXPECT_NEAR(flat.error[0], -v * s_p * g_sin / kL / 0.8, 1e-9);
}

TEST(AckermannVelocityErrorTest, DisturbanceAddsToTheSpeedLateralAndVerticalRows) {
  // A straight run at 4 m/s whose wheel reads 0.05 m/s fast while O slides 0.02 m/s to the left and rises at 0.1 m/s:
  // a disturbance w = (0.05 / k_v, -0.02, -0.1) of the speed, lateral and vertical rows explains it; the steering row
  // (which sees the side slip at the front axle) does not see w.
  const double v = 4.0, dt = 0.01, w_v = 0.05, v_y = 0.02, v_z = 0.1;
  const Eigen::VectorXd pose0 = Manifold::Pose().Identity();
  Eigen::VectorXd pose1(7);
  PoseToArray(
      PredictPose<double>(PoseFromArray(pose0.data()), Eigen::Vector3d(v, v_y, v_z), Eigen::Vector3d::Zero(), dt),
      pose1.data());
  const auto factor = MakeFactor(AckermannVelocityError((v + w_v) / kL / 0.8, 0.0, kL, dt));
  std::vector<Eigen::VectorXd> values = {pose0,       pose1,       Scalar(0.8), Scalar(1.0), Scalar(0.0),  Scalar(0.0),
                                         Scalar(0.0), Scalar(0.0), Scalar(0.0), Scalar(0.0), Disturbance()};
  const auto rigid = testing::Evaluate(*factor, values);
  EXPECT_NEAR(rigid.error[0], -w_v / (0.8 * kL), 1e-9);
  EXPECT_NEAR(rigid.error[2], v_y, 1e-9);
  EXPECT_NEAR(rigid.error[3], v_z, 1e-9);
  values.back() = Disturbance(w_v / (0.8 * kL), -v_y, -v_z);
  const auto disturbed = testing::Evaluate(*factor, values);
  for (const int row : {0, 2, 3}) EXPECT_NEAR(disturbed.error[row], 0.0, 1e-9) << row;
  EXPECT_NEAR(disturbed.error[1], rigid.error[1], 1e-15);
}

TEST(AckermannVelocityErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd pose0 = testing::RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd pose1 = testing::Perturb(Manifold::Pose(), Step(pose0, 3.0 + trial, 0.2, 0.02), 0.002, &rng);
    // Eq. 15 at O, and with the rows at a contact below O (h, d nonzero: the rates enter every row); with slip.
    for (const AckermannVelocityError::Options contact :
         {AckermannVelocityError::Options{}, AckermannVelocityError::Options{0.28, 0.625}}) {
      const auto factor = MakeFactor(AckermannVelocityError(4.0, 0.1, kL, 0.02, contact, 0.7 - 0.4 * trial));
      testing::ExpectJacobiansMatchNumeric(
          *factor,
          {pose0, pose1, Scalar(0.78), Scalar(1.02), Scalar(0.01), Scalar(0.004), Scalar(-0.015), Scalar(0.02),
           Scalar(0.03), Scalar(0.05), Disturbance(0.01, -0.004, 0.02)},
          1e-5);
    }
  }
}

TEST(AckermannVelocityErrorTest, SmallSolveRecoversSpeedAndSteeringCalibration) {
  testing::SmallProblem problem = testing::AckermannProblem<AckermannVelocityError>(false, 17);
  testing::ExpectSolveRecoversTruth(&problem);
}

TEST(AckermannVelocityErrorTest, SmallNoisySolveIsWithinFourSigma) {
  testing::SmallProblem problem = testing::AckermannProblem<AckermannVelocityError>(true, 18);
  const Eigen::VectorXd sigma = testing::ExpectSolveWithinSigmas(&problem);
  // The data decide: every standard deviation is below a third of the smallest offset the solve started from (0.02 1/m,
  // 0.05, 0.02 rad).
  EXPECT_LT(sigma.maxCoeff(), 0.02 / 3.0) << sigma.transpose();
}

}  // namespace
}  // namespace roamlab::estimator
