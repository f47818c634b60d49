// The analytic Jacobians of the error models (their Linearize) against the jets, which stay the oracle:
// every block and the noise Jacobian to 1e-9 relative at seeded random points (plausible motions at dt = 0.01 s and a
// few large rotations), the same error as operator(), and the same blocks when only some are requested. Also the
// dispatch in AutoDiffFactor: a model with the hook is linearized by it, through Factor::Evaluate.
#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "estimator/factor.h"
#include "estimator/geometry.h"
#include "estimator/models/accelerometer.h"
#include "estimator/models/ackermann_velocity.h"
#include "estimator/models/gps.h"
#include "estimator/models/gyroscope.h"
#include "estimator/models/imu_time_offset.h"
#include "estimator/models/magnetometer.h"
#include "estimator/models/odometer.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::Perturb;
using testing::RandomPoint;

constexpr int kPoints = 24;            // seeded random points per model
constexpr double kDt = 0.01;           // [s]
constexpr double kJacobianTol = 1e-9;  // relative to the largest entry of the jet block
constexpr double kErrorTol = 1e-12;    // relative to the largest error entry (at least 1)

// Every fourth point is a large-rotation point.
bool LargeRotation(int point) { return point % 4 == 3; }

// One evaluation: error, the requested Jacobian blocks (empty when not requested) and the noise Jacobian.
struct Evaluation {
  bool ok = false;
  Eigen::VectorXd error;
  std::vector<Eigen::MatrixXd> jacobians;
  Eigen::MatrixXd noise_jacobian;
};

// Evaluates `factor` analytically (Evaluate) or with jets (EvaluateWithAutoDiff), asking for the blocks flagged in
// `wanted` (null pointers for the others; a null array when none is wanted) and for the noise Jacobian when
// `want_noise`. Outputs start as NaN, so that a requested entry left unwritten cannot pass.
template <typename Model>
Evaluation EvaluateBlocks(const AutoDiffFactor<Model>& factor, const std::vector<Eigen::VectorXd>& values,
                          const std::vector<bool>& wanted, bool want_noise, bool autodiff) {
  const double nan = std::nan("");
  const int m = Model::kResidualDim;
  Evaluation out;
  out.error = Eigen::VectorXd::Constant(m, nan);
  std::vector<const double*> value_ptrs;
  for (const Eigen::VectorXd& v : values) value_ptrs.push_back(v.data());
  std::vector<double*> jacobian_ptrs(values.size(), nullptr);
  out.jacobians.resize(values.size());
  bool any = false;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!wanted[i]) continue;
    out.jacobians[i] = Eigen::MatrixXd::Constant(m, factor.manifolds()[i].tangent_dim(), nan);
    jacobian_ptrs[i] = out.jacobians[i].data();
    any = true;
  }
  if (want_noise) out.noise_jacobian = Eigen::MatrixXd::Constant(m, Model::kNoiseDim, nan);
  double* const* jacobians = any ? jacobian_ptrs.data() : nullptr;
  double* noise = want_noise ? out.noise_jacobian.data() : nullptr;
  out.ok = autodiff ? factor.EvaluateWithAutoDiff(value_ptrs.data(), out.error.data(), jacobians, noise)
                    : factor.Evaluate(value_ptrs.data(), out.error.data(), jacobians, noise);
  return out;
}

// |analytic - jet| <= tol * max|jet| entry-wise (exact equality for an all-zero block).
void ExpectRelativelyNear(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& jet, double tol,
                          const std::string& what) {
  ASSERT_EQ(analytic.rows(), jet.rows()) << what;
  ASSERT_EQ(analytic.cols(), jet.cols()) << what;
  const double scale = jet.cwiseAbs().maxCoeff();
  EXPECT_LE((analytic - jet).cwiseAbs().maxCoeff(), tol * scale) << what << "\nanalytic\n"
                                                                 << analytic << "\njet\n"
                                                                 << jet;
}

// The block subsets a solver asks for: each block alone, the poses only (tracking with parameters fixed), all but
// one, and none; each with and without the noise Jacobian.
template <typename Model>
std::vector<std::vector<bool>> Subsets(const AutoDiffFactor<Model>& factor) {
  const std::size_t n = factor.manifolds().size();
  std::vector<std::vector<bool>> subsets;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<bool> only(n, false), all_but(n, true);
    only[i] = true;
    all_but[i] = false;
    subsets.push_back(only);
    subsets.push_back(all_but);
  }
  std::vector<bool> poses(n, false);
  for (std::size_t i = 0; i < n; ++i) poses[i] = factor.manifolds()[i].kind() == ManifoldKind::kPose;
  subsets.push_back(poses);
  subsets.push_back(std::vector<bool>(n, false));
  return subsets;
}

// The whole check at one point.
template <typename Model>
void ExpectAnalyticMatchesJets(const Model& model, const std::vector<Eigen::VectorXd>& values,
                               const std::string& label) {
  static_assert(internal::HasLinearize<Model>::value);
  SCOPED_TRACE(label);
  const AutoDiffFactor<Model> factor(model);
  const std::size_t n = values.size();
  const std::vector<bool> all(n, true);

  // Everything requested.
  const Evaluation analytic = EvaluateBlocks(factor, values, all, true, false);
  const Evaluation jets = EvaluateBlocks(factor, values, all, true, true);
  ASSERT_TRUE(analytic.ok);
  ASSERT_TRUE(jets.ok);

  // The error is operator()'s at zero noise.
  std::vector<const double*> value_ptrs;
  for (const Eigen::VectorXd& v : values) value_ptrs.push_back(v.data());
  const Eigen::VectorXd zero_noise = Eigen::VectorXd::Zero(Model::kNoiseDim);
  Eigen::VectorXd direct(Model::kResidualDim);
  ASSERT_TRUE(model(value_ptrs.data(), zero_noise.data(), direct.data()));
  const double error_tol = kErrorTol * std::max(1.0, direct.cwiseAbs().maxCoeff());
  EXPECT_LE((analytic.error - direct).cwiseAbs().maxCoeff(), error_tol) << analytic.error.transpose() << "\n"
                                                                        << direct.transpose();
  EXPECT_LE((jets.error - direct).cwiseAbs().maxCoeff(), error_tol);

  // Every block and the noise Jacobian against the jets.
  for (std::size_t i = 0; i < n; ++i)
    ExpectRelativelyNear(analytic.jacobians[i], jets.jacobians[i], kJacobianTol, "block " + std::to_string(i));
  ExpectRelativelyNear(analytic.noise_jacobian, jets.noise_jacobian, kJacobianTol, "noise");

  // Subsets: the requested blocks are the full evaluation's, bit for bit, and the error is unchanged; the jets' own
  // subset paths (pose-only jets) agree too.
  for (const std::vector<bool>& wanted : Subsets(factor)) {
    for (const bool want_noise : {true, false}) {
      std::ostringstream name;
      for (const bool w : wanted) name << (w ? '1' : '0');
      name << (want_noise ? " +noise" : "");
      SCOPED_TRACE(name.str());
      const Evaluation partial = EvaluateBlocks(factor, values, wanted, want_noise, false);
      const Evaluation partial_jets = EvaluateBlocks(factor, values, wanted, want_noise, true);
      ASSERT_TRUE(partial.ok);
      ASSERT_TRUE(partial_jets.ok);
      EXPECT_EQ(partial.error, analytic.error);
      for (std::size_t i = 0; i < n; ++i) {
        if (!wanted[i]) continue;
        EXPECT_EQ(partial.jacobians[i], analytic.jacobians[i]) << "block " << i;
        ExpectRelativelyNear(partial.jacobians[i], partial_jets.jacobians[i], kJacobianTol,
                             "subset block " + std::to_string(i));
      }
      if (want_noise) {
        EXPECT_EQ(partial.noise_jacobian, analytic.noise_jacobian);
      }
    }
  }
}

Eigen::Vector3d Gaussian3(double sigma, std::mt19937* rng) {
  std::normal_distribution<double> normal(0.0, sigma);
  return Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng));
}

// A rotation vector in a random direction with angle uniform in [min_angle, max_angle] [rad].
Eigen::Vector3d RandomRotationVector(double min_angle, double max_angle, std::mt19937* rng) {
  std::uniform_real_distribution<double> angle(min_angle, max_angle);
  return Gaussian3(1.0, rng).normalized() * angle(*rng);
}

// pose [+] (dp, dtheta).
Eigen::VectorXd PlusPose(const Eigen::VectorXd& pose, const Eigen::Vector3d& dp, const Eigen::Vector3d& dtheta) {
  Eigen::Matrix<double, 6, 1> d;
  d << dp, dtheta;
  Eigen::VectorXd out(7);
  Manifold::Pose().Plus(pose.data(), d.data(), out.data());
  return out;
}

Eigen::VectorXd Scalar(double x) { return Eigen::VectorXd::Constant(1, x); }

// A misalignment: near the identity, or anywhere for large-rotation points.
Eigen::VectorXd Misalignment(bool large, std::mt19937* rng) {
  const Manifold s3 = Manifold::UnitQuaternion();
  return large ? RandomPoint(s3, rng) : Perturb(s3, s3.Identity(), 0.05, rng);
}

TEST(AnalyticJacobiansTest, Gyroscope) {
  std::mt19937 rng(11);
  for (int point = 0; point < kPoints; ++point) {
    const bool large = LargeRotation(point);
    const Eigen::VectorXd q_body_sensor = Misalignment(large, &rng);
    const Eigen::Vector3d bias = Gaussian3(large ? 0.5 : 0.01, &rng);
    const Eigen::Vector3d scale = Eigen::Vector3d::Ones() + Gaussian3(large ? 0.1 : 0.02, &rng);
    // Body rate about 1 rad/s (large: 100-250 rad/s, i.e. 1-2.5 rad over dt), read through the sensor model.
    const Eigen::Vector3d omega_body = large ? RandomRotationVector(1.0, 2.5, &rng) / kDt : Gaussian3(1.0, &rng);
    const Eigen::Vector3d omega_sensor =
        QuaternionFromArray(q_body_sensor.data()).conjugate() * omega_body + Gaussian3(0.03, &rng);
    const Eigen::Vector3d z = scale.cwiseProduct(omega_sensor) + bias;
    // The next pose turned by about omega dt (large: also an orientation error up to 1.2 rad).
    const Eigen::VectorXd pose_k = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::Vector3d dtheta =
        omega_body * kDt + (large ? RandomRotationVector(0.0, 1.2, &rng) : Gaussian3(0.003, &rng));
    const Eigen::VectorXd pose_k1 = PlusPose(pose_k, Gaussian3(0.05, &rng), dtheta);
    ExpectAnalyticMatchesJets(GyroscopeError(z, kDt), {pose_k, pose_k1, q_body_sensor, bias, scale},
                              "point " + std::to_string(point));
  }
}

TEST(AnalyticJacobiansTest, Accelerometer) {
  std::mt19937 rng(12);
  for (int point = 0; point < kPoints; ++point) {
    const bool large = LargeRotation(point);
    const double dt0 = kDt, dt1 = point % 2 == 0 ? kDt : 1.2 * kDt;
    // Three poses about 3 m/s and 1 rad/s apart (large: 0.8-1.4 rad per interval, so that the span stays below pi).
    const Eigen::VectorXd pose0 = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::Vector3d v_world = Gaussian3(3.0, &rng);
    const auto turn = [&](double dt) {
      return large ? RandomRotationVector(0.8, 1.4, &rng) : Eigen::Vector3d(Gaussian3(1.0, &rng) * dt);
    };
    const Eigen::VectorXd pose1 = PlusPose(pose0, v_world * dt0, turn(dt0));
    const Eigen::VectorXd pose2 = PlusPose(pose1, (v_world + Gaussian3(0.05, &rng)) * dt1, turn(dt1));
    const Eigen::VectorXd q_body_sensor = Misalignment(large, &rng);
    const Eigen::Vector3d p_body_sensor = Gaussian3(0.5, &rng);
    const Eigen::Vector3d bias = Gaussian3(0.05, &rng);
    const Eigen::Vector3d scale = Eigen::Vector3d::Ones() + Gaussian3(0.02, &rng);
    const Eigen::Vector3d z = kSpecificForceAtRest_world + Gaussian3(1.0, &rng);
    ExpectAnalyticMatchesJets(AccelerometerError(z, dt0, dt1),
                              {pose0, pose1, pose2, q_body_sensor, p_body_sensor, bias, scale},
                              "point " + std::to_string(point));
  }
}

// The IMU's time-offset models (imu_time_offset.h): the plain models' points, a reading rate of a few units per
// second and an offset of a few master periods either sign.
TEST(AnalyticJacobiansTest, ImuTimeOffset) {
  const Eigen::Vector3d h_world(0.0, 0.5, -0.8660254037844386);
  std::mt19937 rng(21);
  for (int point = 0; point < kPoints; ++point) {
    const std::string where = "point " + std::to_string(point);
    const Eigen::VectorXd delta =
        Eigen::VectorXd::Constant(1, 0.05 * (2.0 * (point % 2) - 1.0) + 0.01 * point / kPoints);
    const Eigen::Vector3d rate = Gaussian3(3.0, &rng);
    const Eigen::VectorXd q_body_sensor = Misalignment(false, &rng);
    const Eigen::Vector3d bias = Gaussian3(0.01, &rng), scale = Eigen::Vector3d::Ones() + Gaussian3(0.02, &rng);
    const Eigen::Vector3d omega_body = Gaussian3(1.0, &rng);
    const Eigen::VectorXd pose0 = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::Vector3d v_world = Gaussian3(3.0, &rng);
    const Eigen::VectorXd pose1 = PlusPose(pose0, v_world * kDt, omega_body * kDt + Gaussian3(0.003, &rng));
    const Eigen::VectorXd pose2 = PlusPose(pose1, v_world * kDt, omega_body * kDt + Gaussian3(0.003, &rng));

    const Eigen::Vector3d gyro_z =
        scale.cwiseProduct(QuaternionFromArray(q_body_sensor.data()).conjugate() * omega_body) + bias;
    ExpectAnalyticMatchesJets(GyroscopeTimeOffsetError(GyroscopeError(gyro_z, kDt), rate),
                              {pose0, pose1, q_body_sensor, bias, scale, delta}, "gyroscope " + where);
    const Eigen::Vector3d lever = Gaussian3(0.5, &rng);
    ExpectAnalyticMatchesJets(
        AccelerometerTimeOffsetError(AccelerometerError(kSpecificForceAtRest_world + Gaussian3(1.0, &rng), kDt, kDt),
                                     rate),
        {pose0, pose1, pose2, q_body_sensor, lever, bias, scale, delta}, "accelerometer " + where);
    Eigen::VectorXd A(9);
    A << 1, 0, 0, 0, 1, 0, 0, 0, 1;
    A += RandomPoint(Manifold::Euclidean(9), &rng, 0.05);
    const Eigen::Vector3d mag_z = Gaussian3(1.0, &rng).normalized();
    ExpectAnalyticMatchesJets(
        MagnetometerTimeOffsetError(MagnetometerError(mag_z, h_world, Gaussian3(3.0, &rng), 49.6), rate),
        {pose1, q_body_sensor, A, bias, Gaussian3(5e-4, &rng), delta}, "magnetometer " + where);
  }
}

TEST(AnalyticJacobiansTest, AckermannVelocity) {
  constexpr double kWheelbase = 1.25;  // [m]
  std::mt19937 rng(13);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int point = 0; point < kPoints; ++point) {
    const bool large = LargeRotation(point);
    // Every fifth point below kMinSteeringSpeed, where the steering row is zero.
    const bool slow = point % 5 == 4;
    // Every third with the understeer as the front axle's slip velocity (option front_slip_velocity, c_front in s).
    const bool slip_velocity = point % 3 == 1;
    const Eigen::Vector3d v_body(slow ? 0.05 * normal(rng) : 3.0 + 1.5 * normal(rng), 0.05 * normal(rng),
                                 0.05 * normal(rng));
    const Eigen::Vector3d omega_body = large ? RandomRotationVector(1.0, 2.5, &rng) / kDt
                                             : Eigen::Vector3d(0.1 * normal(rng), 0.1 * normal(rng), 0.5 * normal(rng));
    // Eq. 7: turn half-way, move, turn the rest.
    const Eigen::VectorXd pose_k = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Quaternion<double> q_mid =
        QuaternionFromArray(pose_k.data() + 3) * QuaternionExp<double>(omega_body * (0.5 * kDt));
    const Eigen::VectorXd pose_k1 = PlusPose(pose_k, q_mid * (v_body * kDt), omega_body * kDt);
    const double kv_over_l = 0.8 + 0.02 * normal(rng), k_theta = 1.0 + 0.05 * normal(rng);
    const double k_gamma = 0.02 * normal(rng);
    const double c_front = (slip_velocity ? 0.02 : 0.003) * normal(rng);  // [s] or [rad s^2/m]
    const double c_rear = 0.015 * normal(rng);                            // [s]
    const double alpha = 0.03 * normal(rng);                              // [rad]
    const double s_f = 0.03 * normal(rng), s_p = 0.03 * normal(rng);      // [s^2/m]
    const double f_x = normal(rng);                                       // [m/s^2]
    const Eigen::VectorXd w = Eigen::Vector3d(0.01 * normal(rng), 0.005 * normal(rng), 0.03 * normal(rng));  // [m/s]
    const double z_v = v_body.x() / (kv_over_l * kWheelbase) + 0.03 * normal(rng);
    const double z_theta = 0.2 * normal(rng);
    // Every other point with the rows at a ground contact below O (options contact_height_m, pitch_lever_m).
    const AckermannVelocityError::Options contact{point % 2 ? 0.28 : 0.0, point % 2 ? 0.625 : 0.0, slip_velocity};
    ExpectAnalyticMatchesJets(AckermannVelocityError(z_v, z_theta, kWheelbase, kDt, contact, f_x),
                              {pose_k, pose_k1, Scalar(kv_over_l), Scalar(k_theta), Scalar(k_gamma), Scalar(c_front),
                               Scalar(c_rear), Scalar(alpha), Scalar(s_f), Scalar(s_p), w},
                              "point " + std::to_string(point));
  }
}

TEST(AnalyticJacobiansTest, Magnetometer) {
  const Eigen::Vector3d h_world(0.0, 0.5, -0.8660254037844386);
  std::mt19937 rng(14);
  for (int point = 0; point < kPoints; ++point) {
    const bool large = LargeRotation(point);
    const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 10.0);
    const Eigen::VectorXd q_body_sensor = Misalignment(large, &rng);
    Eigen::VectorXd A(9);
    A << 1, 0, 0, 0, 1, 0, 0, 0, 1;
    A += RandomPoint(Manifold::Euclidean(9), &rng, large ? 0.5 : 0.05);
    const Eigen::Vector3d b = Gaussian3(0.05, &rng);
    const Eigen::Vector3d k = Gaussian3(5e-4, &rng);
    const Eigen::Vector3d f_sensor = Gaussian3(3.0, &rng);
    const Eigen::Vector3d z = Gaussian3(1.0, &rng).normalized() + Gaussian3(0.067, &rng);
    ExpectAnalyticMatchesJets(MagnetometerError(z, h_world, f_sensor, 49.6), {pose, q_body_sensor, A, b, k},
                              "point " + std::to_string(point));
  }
}

TEST(AnalyticJacobiansTest, Gps) {
  std::mt19937 rng(15);
  for (int point = 0; point < kPoints; ++point) {
    const bool large = LargeRotation(point);
    const Eigen::VectorXd pose = RandomPoint(Manifold::Pose(), &rng, 100.0);
    const Eigen::Vector3d lever = Gaussian3(large ? 10.0 : 0.5, &rng);
    const Pose<double> T = PoseFromArray(pose.data());
    const Eigen::Vector3d bias = Gaussian3(1.5, &rng);
    const Eigen::Vector3d z = T.p_world_body + T.q_world_body * lever + bias + Gaussian3(0.33, &rng);
    ExpectAnalyticMatchesJets(GpsError(z), {pose, lever, bias}, "point " + std::to_string(point));
  }
}

// A model whose two linearizations can be told apart: operator() is e = x + eta (the jets give J = I and, without
// additive noise, J_eta = I), Linearize gives J = 2 I and J_eta = 3 I, counts its calls and can return a NaN.
template <bool kAdditive>
struct ProbeModel {
  using Blocks = std::tuple<Vector3Block>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;
  static constexpr bool kAdditiveNoise = kAdditive;

  int* calls = nullptr;
  bool nan_jacobian = false;

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    for (int i = 0; i < 3; ++i) error[i] = x[0][i] + noise[i];
    return true;
  }
  bool Linearize(const double* const* x, double* error, double* const* jacobians, double* noise_jacobian) const {
    ++*calls;
    for (int i = 0; i < 3; ++i) error[i] = x[0][i];
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix3d>{jacobians[0]} = 2.0 * Eigen::Matrix3d::Identity();
      if (nan_jacobian) jacobians[0][4] = std::nan("");
    }
    if (!kAdditive && noise_jacobian != nullptr)
      Eigen::Map<Eigen::Matrix3d>{noise_jacobian} = 3.0 * Eigen::Matrix3d::Identity();
    return true;
  }
};

// The same without the hook.
struct NoHookModel {
  using Blocks = std::tuple<Vector3Block>;
  static constexpr int kResidualDim = 3;
  static constexpr int kNoiseDim = 3;
  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    for (int i = 0; i < 3; ++i) error[i] = x[0][i] + noise[i];
    return true;
  }
};

static_assert(internal::HasLinearize<GyroscopeError>::value);
static_assert(internal::HasLinearize<AccelerometerError>::value);
static_assert(internal::HasLinearize<AckermannVelocityError>::value);
static_assert(internal::HasLinearize<MagnetometerError>::value);
static_assert(internal::HasLinearize<GpsError>::value);
static_assert(internal::HasLinearize<ProbeModel<true>>::value);
static_assert(!internal::HasLinearize<NoHookModel>::value);
static_assert(!internal::HasLinearize<OdometerError>::value);

template <bool kAdditive>
void ExpectDispatch() {
  int calls = 0;
  ProbeModel<kAdditive> model;
  model.calls = &calls;
  const AutoDiffFactor<ProbeModel<kAdditive>> autodiff_factor(model);
  const Factor& factor = autodiff_factor;
  const Eigen::Vector3d x(1.0, -2.0, 3.0);
  const double* values[] = {x.data()};
  Eigen::Vector3d error;
  Eigen::Matrix3d J, J_eta;
  double* jacobians[] = {J.data()};

  // Only the error: operator(), not the hook.
  ASSERT_TRUE(factor.Evaluate(values, error.data(), nullptr, nullptr));
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(error, x);

  // Jacobians through Factor::Evaluate: the hook.
  ASSERT_TRUE(factor.Evaluate(values, error.data(), jacobians, J_eta.data()));
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(error, x);
  EXPECT_EQ(J, 2.0 * Eigen::Matrix3d::Identity());
  EXPECT_EQ(J_eta, (kAdditive ? 1.0 : 3.0) * Eigen::Matrix3d::Identity());

  // Only the noise Jacobian: the hook too.
  J_eta.setZero();
  ASSERT_TRUE(factor.Evaluate(values, error.data(), nullptr, J_eta.data()));
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(J_eta, (kAdditive ? 1.0 : 3.0) * Eigen::Matrix3d::Identity());

  // The jets, on request.
  ASSERT_TRUE(autodiff_factor.EvaluateWithAutoDiff(values, error.data(), jacobians, J_eta.data()));
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(J, Eigen::Matrix3d::Identity());
  EXPECT_EQ(J_eta, Eigen::Matrix3d::Identity());

  // A non-finite requested Jacobian fails the evaluation, as on the jet path.
  ProbeModel<kAdditive> nan_model = model;
  nan_model.nan_jacobian = true;
  EXPECT_FALSE(AutoDiffFactor<ProbeModel<kAdditive>>(nan_model).Evaluate(values, error.data(), jacobians, nullptr));
}

TEST(AnalyticJacobiansTest, FactorEvaluateCallsTheHook) { ExpectDispatch<false>(); }
TEST(AnalyticJacobiansTest, FactorEvaluateCallsTheHookAdditiveNoise) { ExpectDispatch<true>(); }

TEST(AnalyticJacobiansTest, ModelsWithoutTheHookUseTheJets) {
  const AutoDiffFactor<NoHookModel> factor{NoHookModel{}};
  const Eigen::Vector3d x(1.0, -2.0, 3.0);
  const double* values[] = {x.data()};
  Eigen::Vector3d error;
  Eigen::Matrix3d J, J_eta;
  double* jacobians[] = {J.data()};
  ASSERT_TRUE(factor.Evaluate(values, error.data(), jacobians, J_eta.data()));
  EXPECT_EQ(error, x);
  EXPECT_EQ(J, Eigen::Matrix3d::Identity());
  EXPECT_EQ(J_eta, Eigen::Matrix3d::Identity());
}

}  // namespace
}  // namespace roamlab::estimator
