#include "estimator/models/ackermann_odometer.h"

#include <cmath>
#include <ostream>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::PoseVector;
using testing::RandomPoint;

constexpr double kWheelbase = 1.25;  // [m]

struct Calibration {
  double kv_over_l;  // [1/m]
  double k_theta;    // [-]
  double k_gamma;    // [rad]
  const char* name = "";
};
constexpr Calibration kTableI{0.8, 1.0, 0.0, "TableI"};
constexpr Calibration kSkewed{0.8, 1.05, 0.02, "Skewed"};

void PrintTo(const Calibration& c, std::ostream* os) {
  *os << c.name << " {kv_over_L " << c.kv_over_l << ", k_theta " << c.k_theta << ", k_gamma " << c.k_gamma << "}";
}

Eigen::Quaterniond Yaw(double angle) { return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ())); }

// A vehicle on a slope (rolled, pitched and headed somewhere) driving at speed v [m/s] with steering angle delta [rad].
struct Drive {
  Eigen::Vector3d p0{12.0, -3.0, 4.5};
  Eigen::Quaterniond q0 = Eigen::Quaterniond(Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitZ()) *
                                             Eigen::AngleAxisd(0.12, Eigen::Vector3d::UnitY()) *
                                             Eigen::AngleAxisd(-0.08, Eigen::Vector3d::UnitX()));
  double v = 4.0;
  double delta = 0.25;
  double dt = 0.02;
  double yaw_rate() const { return v * std::tan(delta) / kWheelbase; }
};

// The readings a calibrated sensor produces: v = k_v z_v and delta = k_theta z_theta + k_gamma, inverted.
AckermannOdometerError ModelFor(const Drive& drive, const Calibration& c) {
  const double k_v = c.kv_over_l * kWheelbase;
  return AckermannOdometerError(drive.v / k_v, (drive.delta - c.k_gamma) / c.k_theta, kWheelbase, drive.dt);
}

std::vector<Eigen::VectorXd> Values(const Eigen::VectorXd& pose_k, const Eigen::VectorXd& pose_k1,
                                    const Calibration& c) {
  return {pose_k, pose_k1, Eigen::VectorXd::Constant(1, c.kv_over_l), Eigen::VectorXd::Constant(1, c.k_theta),
          Eigen::VectorXd::Constant(1, c.k_gamma)};
}

class AckermannCalibrationTest : public ::testing::TestWithParam<Calibration> {};

TEST_P(AckermannCalibrationTest, ZeroOnEq7StepOfPlanarArc) {
  // Eq. 7 in the vehicle's plane: turn half the heading change, drive v dt straight, turn the rest.
  const Drive drive;
  const double turn = drive.yaw_rate() * drive.dt;
  const Eigen::VectorXd pose_k = PoseVector(drive.p0, drive.q0);
  const Eigen::VectorXd pose_k1 = PoseVector(
      drive.p0 + drive.q0 * (Yaw(0.5 * turn) * Eigen::Vector3d(drive.v * drive.dt, 0.0, 0.0)), drive.q0 * Yaw(turn));
  const testing::Linearization lin =
      testing::Evaluate(*MakeFactor(ModelFor(drive, GetParam())), Values(pose_k, pose_k1, GetParam()));
  EXPECT_LT(lin.error.norm(), 1e-12) << lin.error.transpose();
}

TEST_P(AckermannCalibrationTest, ExactArcLeavesOnlyTheChordError) {
  // The true motion is a circular arc of radius v / yaw_rate. Eq. 7 gets the heading and the chord's direction right
  // and takes the arc length v dt for the chord's length 2 (v / w) sin(w dt / 2).
  const Drive drive;
  const double w = drive.yaw_rate();
  const double turn = w * drive.dt;
  const Eigen::Vector3d arc_body(drive.v / w * std::sin(turn), drive.v / w * (1.0 - std::cos(turn)), 0.0);
  const Eigen::VectorXd pose_k = PoseVector(drive.p0, drive.q0);
  const Eigen::VectorXd pose_k1 = PoseVector(drive.p0 + drive.q0 * arc_body, drive.q0 * Yaw(turn));
  const testing::Linearization lin =
      testing::Evaluate(*MakeFactor(ModelFor(drive, GetParam())), Values(pose_k, pose_k1, GetParam()));

  const double chord_error = drive.v * drive.dt - 2.0 * drive.v / w * std::sin(0.5 * turn);
  const Eigen::Vector3d expected = drive.q0 * (Yaw(0.5 * turn) * Eigen::Vector3d(chord_error, 0.0, 0.0));
  EXPECT_GT(chord_error, 0.0);
  EXPECT_LT(chord_error, 1e-5);
  EXPECT_LT((lin.error.head<3>() - expected).norm(), 1e-12) << lin.error.transpose();
  EXPECT_LT(lin.error.tail<3>().norm(), 1e-12) << lin.error.transpose();
}

TEST_P(AckermannCalibrationTest, LeftTurnIsPositiveYaw) {
  // With the vehicle standing still in the prediction's eyes (pose_k1 = pose_k), the orientation error is the
  // predicted turn: +yaw_rate dt about the vehicle's up axis for a positive steering angle.
  const Drive drive;
  const Eigen::VectorXd pose = PoseVector(drive.p0, drive.q0);
  const testing::Linearization lin =
      testing::Evaluate(*MakeFactor(ModelFor(drive, GetParam())), Values(pose, pose, GetParam()));
  const Eigen::Vector3d expected = drive.q0 * Eigen::Vector3d(0.0, 0.0, drive.yaw_rate() * drive.dt);
  EXPECT_GT(expected.norm(), 1e-2);
  EXPECT_LT((lin.error.tail<3>() - expected).norm(), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Calibrations, AckermannCalibrationTest, ::testing::Values(kTableI, kSkewed),
                         [](const ::testing::TestParamInfo<Calibration>& info) { return info.param.name; });

struct RandomCase {
  AckermannOdometerError model;
  std::vector<Eigen::VectorXd> values;
};

RandomCase RandomAckermannCase(std::mt19937* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> speed(1.0, 6.0), steering(-0.4, 0.4), dt(0.01, 0.05);
  const Calibration c{0.8 + 0.05 * normal(*rng), 1.0 + 0.05 * normal(*rng), 0.02 * normal(*rng)};
  const Eigen::VectorXd pose_k = RandomPoint(Manifold::Pose(), rng, 10.0);
  const Eigen::VectorXd pose_k1 = testing::Perturb(Manifold::Pose(), pose_k, 0.05, rng);
  const double z_v = speed(*rng);
  const double z_theta = steering(*rng);
  return {AckermannOdometerError(z_v, z_theta, kWheelbase, dt(*rng)), Values(pose_k, pose_k1, c)};
}

TEST(AckermannOdometerErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(21);
  for (int trial = 0; trial < 5; ++trial) {
    SCOPED_TRACE(trial);
    const RandomCase c = RandomAckermannCase(&rng);
    testing::ExpectModelJacobiansMatchNumeric(c.model, c.values);
  }
}

// Noise sigmas: the seed's sigma_v, sigma_theta, then lateral/vertical speed and roll/pitch rate slack.
const Eigen::Matrix<double, 6, 1> kSigmas =
    (Eigen::Matrix<double, 6, 1>() << 0.033, 0.014, 0.1, 0.1, 0.05, 0.05).finished();

TEST(AckermannOdometerErrorTest, ErrorCovarianceHasFullRank) {
  // To first order, each noise component drives its own direction of the error: eta_v, eta_vy, eta_vz the position
  // (times k_v dt, dt, dt), eta_wx, eta_wy, eta_theta the orientation (times dt, dt, kv_over_L z_v k_theta dt /
  // cos^2). The smallest eigenvalue of Sigma_e (eq. 1) must stay near the smallest of these variances; eta_v also
  // turns the vehicle (kv_over_L tan(steering) dt), a coupling that lowers it by well under half.
  std::mt19937 rng(22);
  for (int trial = 0; trial < 5; ++trial) {
    SCOPED_TRACE(trial);
    const RandomCase c = RandomAckermannCase(&rng);
    const testing::Linearization lin = testing::Evaluate(*MakeFactor(c.model), c.values);
    const Eigen::Matrix<double, 6, 6> sigma_eta = kSigmas.cwiseAbs2().asDiagonal();
    const Eigen::Matrix<double, 6, 6> sigma_e = lin.noise_jacobian * sigma_eta * lin.noise_jacobian.transpose();

    const double kv_over_l = c.values[2][0], k_theta = c.values[3][0], k_gamma = c.values[4][0];
    const double dt = c.model.dt_s();
    const double cos_steer = std::cos(k_theta * c.model.z_theta_rad() + k_gamma);
    const double yaw_gain = kv_over_l * c.model.z_v_mps() * k_theta / (cos_steer * cos_steer);
    const Eigen::Matrix<double, 6, 1> scale =
        (Eigen::Matrix<double, 6, 1>() << kv_over_l * kWheelbase, yaw_gain, 1.0, 1.0, 1.0, 1.0).finished();
    const double smallest_expected = (scale.cwiseProduct(kSigmas) * dt).cwiseAbs2().minCoeff();

    const Eigen::JacobiSVD<Eigen::Matrix<double, 6, 6>> svd(sigma_e);
    EXPECT_EQ(svd.rank(), 6);
    EXPECT_GT(svd.singularValues()[5], 0.5 * smallest_expected) << svd.singularValues().transpose();
  }
}

TEST(AckermannOdometerErrorTest, TwoReadingsAloneWouldGiveRankTwo) {
  // Eq. 15 as printed (only eta_v and eta_theta): the reason for the four extra noise components.
  std::mt19937 rng(23);
  const RandomCase c = RandomAckermannCase(&rng);
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(c.model), c.values);
  Eigen::Matrix<double, 6, 1> sigmas = kSigmas;
  sigmas.tail<4>().setZero();
  const Eigen::Matrix<double, 6, 6> sigma_e =
      lin.noise_jacobian * sigmas.cwiseAbs2().asDiagonal() * lin.noise_jacobian.transpose();
  const Eigen::JacobiSVD<Eigen::Matrix<double, 6, 6>> svd(sigma_e);
  EXPECT_GT(svd.singularValues()[1], 1e-3 * svd.singularValues()[0]);
  EXPECT_LT(svd.singularValues()[2], 1e-12 * svd.singularValues()[0]);
}

TEST(AckermannOdometerErrorTest, StandstillDropsYawUncertainty) {
  // Documented limitation: at z_v = 0 nothing but eta_v (through tan(steering)) moves the yaw, and eta_v also moves
  // the position, so Sigma_e has rank 5.
  std::mt19937 rng(24);
  const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 10.0);
  const AckermannOdometerError model(0.0, 0.2, kWheelbase, 0.02);
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(model), Values(pose, pose, kTableI));
  const Eigen::Matrix<double, 6, 6> sigma_e =
      lin.noise_jacobian * kSigmas.cwiseAbs2().asDiagonal() * lin.noise_jacobian.transpose();
  const Eigen::JacobiSVD<Eigen::Matrix<double, 6, 6>> svd(sigma_e);
  EXPECT_GT(svd.singularValues()[4], 1e-3 * svd.singularValues()[0]);
  EXPECT_LT(svd.singularValues()[5], 1e-12 * svd.singularValues()[0]);
}

TEST(AckermannOdometerErrorTest, SmallSolveRecoversSpeedAndSteeringCalibration) {
  testing::SmallProblem problem = testing::AckermannProblem<AckermannOdometerError>(false, 25);
  testing::ExpectSolveRecoversTruth(&problem);
}

// No noisy case here: this form's reading noise passes through the nonlinear model, which biases the speed gain
// (errors in variables, see ackermann_velocity.h); the calibration test
// SeedFormOfAckermannOdometerIsBiasedAndMeasurementFormIsNot measures that bias.

}  // namespace
}  // namespace roamlab::estimator
