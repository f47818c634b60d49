// Test helpers shared by the error-model tests: random points on manifolds, ambient vectors built with Eigen alone,
// central-difference Jacobians in tangent space (the oracle for the jet Jacobians) and checks that bundle them, and the
// pieces of the models' small end-to-end solves (a known trajectory, anchored poses, convergence and covariance
// checks).
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/factor.h"
#include "estimator/graph.h"
#include "estimator/manifold.h"
#include "estimator/solver.h"

namespace roamlab::estimator::testing {

// A random point: Gaussian entries (scale) for vectors, a uniformly random unit quaternion, or a pose with Gaussian
// position (scale) and random orientation.
Eigen::VectorXd RandomPoint(const Manifold& manifold, std::mt19937* rng, double scale = 1.0);

// A point near `x`: x [+] d with d Gaussian of standard deviation `sigma`.
Eigen::VectorXd Perturb(const Manifold& manifold, const Eigen::VectorXd& x, double sigma, std::mt19937* rng);

// Ambient vectors: a pose [x, y, z, qw, qx, qy, qz] and a quaternion [w, x, y, z].
Eigen::VectorXd PoseVector(const Eigen::Vector3d& p, const Eigen::Quaterniond& q);
Eigen::VectorXd QuaternionVector(const Eigen::Quaterniond& q);

// Rotation by the angle |w| [rad] about w (the identity for w = 0), built with Eigen's angle-axis rather than
// geometry.h, so that it can serve as an independent oracle for QuaternionExp.
Eigen::Quaterniond RotationAbout(const Eigen::Vector3d& w);

struct Linearization {
  Eigen::VectorXd error;
  std::vector<Eigen::MatrixXd> jacobians;  // one per variable: residual_dim x tangent_dim
  Eigen::MatrixXd noise_jacobian;          // residual_dim x noise_dim
};

// Error and Jacobians from Factor::Evaluate.
Linearization Evaluate(const Factor& factor, const std::vector<Eigen::VectorXd>& values);

// Central differences in tangent space (step h) for the variables; the noise Jacobian is not differenced (the factor
// interface takes no noise input) and is left empty.
std::vector<Eigen::MatrixXd> NumericJacobians(const Factor& factor, const std::vector<Eigen::VectorXd>& values,
                                              double h = 1e-6);

// Asserts that the factor evaluates and that its Jacobians match central differences within `tolerance`, relative to
// the largest Jacobian entry (at least 1).
void ExpectJacobiansMatchNumeric(const Factor& factor, const std::vector<Eigen::VectorXd>& values,
                                 double tolerance = 1e-6);

// Noise Jacobian by central differences of a model's operator() in the noise argument (for models, which do take
// noise). Uses the model directly.
template <typename Model>
Eigen::MatrixXd NumericNoiseJacobian(const Model& model, const std::vector<Eigen::VectorXd>& values, double h = 1e-6) {
  std::vector<const double*> ptrs;
  for (const auto& v : values) ptrs.push_back(v.data());
  Eigen::MatrixXd J(Model::kResidualDim, Model::kNoiseDim);
  for (int k = 0; k < Model::kNoiseDim; ++k) {
    Eigen::VectorXd np = Eigen::VectorXd::Zero(Model::kNoiseDim), nm = np;
    np[k] = h;
    nm[k] = -h;
    Eigen::VectorXd ep(Model::kResidualDim), em(Model::kResidualDim);
    EXPECT_TRUE(model(ptrs.data(), np.data(), ep.data()));
    EXPECT_TRUE(model(ptrs.data(), nm.data(), em.data()));
    J.col(k) = (ep - em) / (2 * h);
  }
  return J;
}

// Asserts that the jet noise Jacobian of a model matches NumericNoiseJacobian within `tolerance` (absolute).
template <typename Model>
void ExpectNoiseJacobianMatchesNumeric(const Model& model, const std::vector<Eigen::VectorXd>& values,
                                       double tolerance = 1e-8) {
  const Eigen::MatrixXd numeric = NumericNoiseJacobian(model, values);
  const Linearization lin = Evaluate(*MakeFactor(model), values);
  EXPECT_LT((lin.noise_jacobian - numeric).cwiseAbs().maxCoeff(), tolerance) << "jet\n"
                                                                             << lin.noise_jacobian << "\nnumeric\n"
                                                                             << numeric;
}

// Both Jacobian checks on one model: variables (ExpectJacobiansMatchNumeric, relative `tolerance`) and noise
// (ExpectNoiseJacobianMatchesNumeric, absolute 1e-8).
template <typename Model>
void ExpectModelJacobiansMatchNumeric(const Model& model, const std::vector<Eigen::VectorXd>& values,
                                      double tolerance = 1e-6) {
  ExpectJacobiansMatchNumeric(*MakeFactor(model), values, tolerance);
  ExpectNoiseJacobianMatchesNumeric(model, values);
}

// Small end-to-end solves (one tiny end-to-end solve per error model).

// Poses at t_k = k dt driven by a body twist (v, omega) held over each interval and composed as the seed's eq. 7
// describes the motion: turn half-way at omega, move v dt along the body axes of that orientation, turn the rest.
// Integrated with Eigen's angle-axis (RotationAbout), not with geometry.h, so that measurements derived from the twist
// are independent of the model code; the velocity models' interval estimators are exact on such a trajectory.
struct TwistTrajectory {
  double dt_s = 0.0;
  std::vector<Eigen::Vector3d> v_body;      // per interval [m/s], in O
  std::vector<Eigen::Vector3d> omega_body;  // per interval [rad/s], in O
  std::vector<Eigen::VectorXd> poses;       // ambient, one more than the intervals
};

// Body twist at time t [s]: linear velocity [m/s] and angular rate [rad/s], both in O.
using TwistFunction = std::function<void(double t, Eigen::Vector3d* v_body, Eigen::Vector3d* omega_body)>;

// Integrates `twist`, sampled at the middle of each interval, from pose0.
TwistTrajectory IntegrateTwists(const Eigen::VectorXd& pose0, int intervals, double dt_s, const TwistFunction& twist);

// A smooth 3-D motion (a drone-like flight): every component of v and omega is a sinusoid of its own frequency, so
// that over a few seconds the body turns through large angles about all three axes and its velocity varies along all
// three. |v| is about 3 m/s, |omega| about 1 rad/s.
TwistTrajectory SmoothMotion(int intervals = 30, double dt_s = 0.1);

// A car-like drive for the Ackermann models (seed eq. 15): the kinematic bicycle with rear-axle speed v(t) [m/s] and
// steering angle delta(t) [rad], body twist v = [v, 0, 0], omega = [0, 0, v tan(delta) / L], on a plane pitched and
// rolled by about 8 degrees (so the drive is 3-D), speed 3 to 5 m/s, steering both ways within 0.3 rad.
struct AckermannDrive {
  TwistTrajectory motion;
  std::vector<double> speed_mps;     // v per interval
  std::vector<double> steering_rad;  // delta per interval
};
AckermannDrive AckermannMotion(double wheelbase_m, int intervals = 40, double dt_s = 0.1);

// A model's small end-to-end solve: the graph, its free poses and calibration parameters, and their true values.
struct SmallProblem {
  Graph graph;
  std::vector<VariableId> poses;
  std::vector<Eigen::VectorXd> pose_truth;
  std::vector<VariableId> parameters;
  std::vector<Eigen::VectorXd> parameter_truth;
};

// Adds one free pose per true pose, started at truth [+] N(0, 0.05^2) (all six tangent components), each tied to the
// truth by a pose prior (PriorError<PoseBlock>) with standard deviations sigma_p_m [m] (position) and
// sigma_theta_rad [rad] (orientation). When `noisy`, each prior's centre is itself drawn from that distribution around
// the truth, so that the graph's statistics are right. Pose k of the problem is stamped k nanoseconds (the stamps only
// order the poses here). Returns the ids of the poses added, in order.
std::vector<VariableId> AddAnchoredPoses(const std::vector<Eigen::VectorXd>& truth, double sigma_p_m,
                                         double sigma_theta_rad, bool noisy, std::mt19937* rng, SmallProblem* problem);

// Adds a free calibration parameter that starts at `initial` and whose true value is `truth`; returns its id.
VariableId AddFreeParameter(const std::string& name, const Manifold& manifold, const Eigen::VectorXd& initial,
                            const Eigen::VectorXd& truth, SmallProblem* problem);

// A sensor mounting as two free parameters, the lever arm S^(O) [m] starting at zero and the misalignment q_S^O
// starting at the identity, with their true values; returns their ids (lever arm, misalignment).
std::pair<VariableId, VariableId> AddFreeMounting(const Eigen::Vector3d& p_body_sensor,
                                                  const Eigen::Quaterniond& q_body_sensor, SmallProblem* problem);

// N(0, sigma^2 I) in R^n; zero when sigma is 0.
Eigen::VectorXd GaussianNoise(int n, double sigma, std::mt19937* rng);

// The measurement noise of a small problem: `sigma` when `noisy`, none otherwise.
inline double NoiseSigma(bool noisy, double sigma) { return noisy ? sigma : 0.0; }

// value [-] truth in the variable's tangent coordinates.
Eigen::VectorXd TangentError(const Graph& graph, VariableId id, const Eigen::VectorXd& truth);

// Asserts that the solve ended on its function or step tolerance: not on a failure, the iteration cap or the time
// budget.
void ExpectEndedOnTolerance(const SolverSummary& summary);

// Solves a noise-free small problem (default options) and asserts what it must reach: it ended on a tolerance,
// lowered the cost from above 1 to below 1e-12 (exact measurements leave nothing to explain), and every parameter and
// every pose is within `tolerance` of its truth (norm of value [-] truth).
void ExpectSolveRecoversTruth(SmallProblem* problem, double tolerance = 1e-6);

// Solves a noisy small problem (default options) and asserts that it ended on a tolerance and that its parameters are
// within `k` marginal standard deviations of their truth (ExpectWithinSigmas, whose result it returns).
Eigen::VectorXd ExpectSolveWithinSigmas(SmallProblem* problem, double k = 4.0);

// Asserts that every tangent component of each listed variable is within `k` marginal standard deviations of its
// truth, the covariance being the inverse of the joint marginal information of the listed variables
// (ComputeMarginalInformation). Returns those standard deviations, concatenated in the order of `variables`.
Eigen::VectorXd ExpectWithinSigmas(const Graph& graph, const std::vector<VariableId>& variables,
                                   const std::vector<Eigen::VectorXd>& truth, double k = 4.0);

// The Ackermann models' small problem, for AckermannVelocityError and AckermannOdometerError (same readings, same
// variables): the AckermannMotion drive read by a rear-wheel speed sensor and a handlebar angle sensor calibrated as
// eq. 15 says (v = k_v z_v with k_v = kv_over_L L, delta = k_theta z_theta + k_gamma), one reading pair per interval,
// with pose priors holding the poses (the speed gain needs a length scale). kv_over_L, k_theta and k_gamma start at
// their nominal values (1 / L, 1, 0).
template <typename Model>
SmallProblem AckermannProblem(bool noisy, std::uint32_t seed) {
  constexpr double kWheelbaseM = 1.25;
  // Noise: speed [m/s], steering [rad], then the non-holonomic slack: lateral, vertical [m/s], roll and pitch rate
  // [rad/s], as far as the model has them.
  const Eigen::Matrix<double, 6, 1> sigma =
      (Eigen::Matrix<double, 6, 1>() << 0.02, 0.005, 0.02, 0.02, 0.05, 0.05).finished();
  const Eigen::MatrixXd covariance = sigma.head<Model::kNoiseDim>().cwiseAbs2().asDiagonal();
  const double kv_over_l = 0.78, k_theta = 1.05, k_gamma = 0.02;  // [1/m], [-], [rad]
  const AckermannDrive drive = AckermannMotion(kWheelbaseM);

  std::mt19937 rng(seed);
  SmallProblem problem;
  AddAnchoredPoses(drive.motion.poses, 0.005, 0.001, noisy, &rng, &problem);
  const auto scalar = [](double x) { return Eigen::VectorXd::Constant(1, x); };
  AddFreeParameter("kv_over_L", Manifold::Euclidean(1), scalar(1.0 / kWheelbaseM), scalar(kv_over_l), &problem);
  AddFreeParameter("k_theta", Manifold::Euclidean(1), scalar(1.0), scalar(k_theta), &problem);
  AddFreeParameter("k_gamma", Manifold::Euclidean(1), scalar(0.0), scalar(k_gamma), &problem);
  // The measurement form's cornering compliances, thrust angle, slips and disturbance, held at zero: the drive does not
  // slip, and at its constant speed the understeer c_front v^2 tan(delta) / L would be indistinguishable from k_theta.
  constexpr bool kCornering = std::tuple_size_v<typename Model::Blocks> == 11;
  std::vector<VariableId> compliances;
  if constexpr (kCornering) {
    for (const char* name :
         {"cornering_front", "cornering_rear", "thrust_angle", "slip_per_mps2", "slope_slip_per_mps2"})
      compliances.push_back(problem.graph.AddVariable({name, Manifold::Euclidean(1), scalar(0.0), true, std::nullopt}));
    compliances.push_back(problem.graph.AddVariable(
        {"disturbance", Manifold::Euclidean(3), Eigen::VectorXd::Zero(3), true, std::nullopt}));
  }
  for (std::size_t k = 0; k < drive.speed_mps.size(); ++k) {
    const Eigen::VectorXd noise = GaussianNoise(2, NoiseSigma(noisy, 1.0), &rng).cwiseProduct(sigma.head<2>());
    const double z_v = drive.speed_mps[k] / (kv_over_l * kWheelbaseM) + noise[0];
    const double z_theta = (drive.steering_rad[k] - k_gamma) / k_theta + noise[1];
    const std::vector<VariableId>& p = problem.parameters;
    std::vector<VariableId> variables = {problem.poses[k], problem.poses[k + 1], p[0], p[1], p[2]};
    variables.insert(variables.end(), compliances.begin(), compliances.end());
    problem.graph.AddFactor(MakeFactor(Model(z_v, z_theta, kWheelbaseM, drive.motion.dt_s)), variables, covariance,
                            Loss::Trivial(), "odometer", Time::FromNanoseconds(static_cast<std::int64_t>(k)));
  }
  return problem;
}

}  // namespace roamlab::estimator::testing
