#include "tests/estimator/factor_testing.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "estimator/covariance.h"
#include "estimator/geometry.h"
#include "estimator/models/prior.h"

namespace roamlab::estimator::testing {

Eigen::VectorXd RandomPoint(const Manifold& manifold, std::mt19937* rng, double scale) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd x(manifold.ambient_dim());
  for (int i = 0; i < x.size(); ++i) x[i] = normal(*rng);
  switch (manifold.kind()) {
    case ManifoldKind::kEuclidean:
      x *= scale;
      break;
    case ManifoldKind::kQuaternion:
      x.normalize();
      break;
    case ManifoldKind::kPose:
      x.head<3>() *= scale;
      x.tail<4>().normalize();
      break;
  }
  return x;
}

Eigen::VectorXd Perturb(const Manifold& manifold, const Eigen::VectorXd& x, double sigma, std::mt19937* rng) {
  std::normal_distribution<double> normal(0.0, sigma);
  Eigen::VectorXd d(manifold.tangent_dim());
  for (int i = 0; i < d.size(); ++i) d[i] = normal(*rng);
  Eigen::VectorXd out(x.size());
  manifold.Plus(x.data(), d.data(), out.data());
  return out;
}

Eigen::VectorXd PoseVector(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  Eigen::VectorXd x(7);
  x << p, q.w(), q.x(), q.y(), q.z();
  return x;
}

Eigen::VectorXd QuaternionVector(const Eigen::Quaterniond& q) { return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()); }

Eigen::Quaterniond RotationAbout(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle == 0.0) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle));
}

Linearization Evaluate(const Factor& factor, const std::vector<Eigen::VectorXd>& values) {
  const int m = factor.residual_dim();
  Linearization lin;
  lin.error.resize(m);
  std::vector<const double*> ptrs;
  std::vector<double*> jac_ptrs;
  for (std::size_t i = 0; i < values.size(); ++i) {
    ptrs.push_back(values[i].data());
    lin.jacobians.emplace_back(m, factor.manifolds()[i].tangent_dim());
  }
  for (auto& J : lin.jacobians) jac_ptrs.push_back(J.data());
  lin.noise_jacobian.resize(m, factor.noise_dim());
  EXPECT_TRUE(factor.Evaluate(ptrs.data(), lin.error.data(), jac_ptrs.data(), lin.noise_jacobian.data()));
  return lin;
}

std::vector<Eigen::MatrixXd> NumericJacobians(const Factor& factor, const std::vector<Eigen::VectorXd>& values,
                                              double h) {
  const int m = factor.residual_dim();
  std::vector<Eigen::MatrixXd> jacobians;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const Manifold& manifold = factor.manifolds()[i];
    Eigen::MatrixXd J(m, manifold.tangent_dim());
    for (int k = 0; k < manifold.tangent_dim(); ++k) {
      std::vector<Eigen::VectorXd> plus = values, minus = values;
      Eigen::VectorXd d = Eigen::VectorXd::Zero(manifold.tangent_dim());
      d[k] = h;
      manifold.Plus(values[i].data(), d.data(), plus[i].data());
      d[k] = -h;
      manifold.Plus(values[i].data(), d.data(), minus[i].data());
      std::vector<const double*> pp, pm;
      for (std::size_t j = 0; j < values.size(); ++j) {
        pp.push_back(plus[j].data());
        pm.push_back(minus[j].data());
      }
      Eigen::VectorXd ep(m), em(m);
      EXPECT_TRUE(factor.Evaluate(pp.data(), ep.data(), nullptr, nullptr));
      EXPECT_TRUE(factor.Evaluate(pm.data(), em.data(), nullptr, nullptr));
      J.col(k) = (ep - em) / (2 * h);
    }
    jacobians.push_back(J);
  }
  return jacobians;
}

void ExpectJacobiansMatchNumeric(const Factor& factor, const std::vector<Eigen::VectorXd>& values, double tolerance) {
  const Linearization lin = Evaluate(factor, values);
  const std::vector<Eigen::MatrixXd> numeric = NumericJacobians(factor, values);
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double scale = std::max(1.0, numeric[i].cwiseAbs().maxCoeff());
    EXPECT_LE((lin.jacobians[i] - numeric[i]).cwiseAbs().maxCoeff(), tolerance * scale)
        << "variable " << i << "\nanalytic\n"
        << lin.jacobians[i] << "\nnumeric\n"
        << numeric[i];
  }
}

TwistTrajectory IntegrateTwists(const Eigen::VectorXd& pose0, int intervals, double dt_s, const TwistFunction& twist) {
  TwistTrajectory out;
  out.dt_s = dt_s;
  Eigen::Vector3d p = pose0.head<3>();
  Eigen::Quaterniond q = Eigen::Quaterniond(pose0[3], pose0[4], pose0[5], pose0[6]).normalized();
  out.poses.push_back(PoseVector(p, q));
  for (int k = 0; k < intervals; ++k) {
    Eigen::Vector3d v, omega;
    twist((k + 0.5) * dt_s, &v, &omega);
    // Turn half-way, move along the body axes of that orientation, turn the rest.
    const Eigen::Quaterniond q_mid = q * RotationAbout(0.5 * dt_s * omega);
    p += q_mid * (v * dt_s);
    q = (q * RotationAbout(dt_s * omega)).normalized();
    out.v_body.push_back(v);
    out.omega_body.push_back(omega);
    out.poses.push_back(PoseVector(p, q));
  }
  return out;
}

TwistTrajectory SmoothMotion(int intervals, double dt_s) {
  const Eigen::VectorXd pose0 =
      PoseVector(Eigen::Vector3d(4.0, -2.0, 1.5), RotationAbout(Eigen::Vector3d(0.2, -0.3, 0.8)));
  return IntegrateTwists(pose0, intervals, dt_s, [](double t, Eigen::Vector3d* v, Eigen::Vector3d* omega) {
    *v = Eigen::Vector3d(3.0 + 0.8 * std::sin(1.1 * t), 1.2 * std::sin(1.7 * t + 0.4), 0.9 * std::cos(1.3 * t));
    *omega =
        Eigen::Vector3d(1.0 * std::sin(1.9 * t + 0.3), 0.8 * std::cos(1.4 * t), 0.3 + 0.9 * std::sin(0.9 * t + 1.0));
  });
}

AckermannDrive AckermannMotion(double wheelbase_m, int intervals, double dt_s) {
  // Headed north-east, pitched and rolled by the slope.
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(0.12, Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(-0.08, Eigen::Vector3d::UnitX()));
  const Eigen::VectorXd pose0 = PoseVector(Eigen::Vector3d(12.0, -3.0, 4.5), q0);
  const auto speed = [](double t) { return 4.0 + 1.0 * std::sin(0.9 * t); };
  const auto steering = [](double t) { return 0.25 * std::sin(1.3 * t + 0.2) + 0.05; };
  AckermannDrive drive;
  drive.motion = IntegrateTwists(pose0, intervals, dt_s, [&](double t, Eigen::Vector3d* v, Eigen::Vector3d* omega) {
    *v = Eigen::Vector3d(speed(t), 0.0, 0.0);
    *omega = Eigen::Vector3d(0.0, 0.0, speed(t) * std::tan(steering(t)) / wheelbase_m);
  });
  for (int k = 0; k < intervals; ++k) {
    drive.speed_mps.push_back(speed((k + 0.5) * dt_s));
    drive.steering_rad.push_back(steering((k + 0.5) * dt_s));
  }
  return drive;
}

std::vector<VariableId> AddAnchoredPoses(const std::vector<Eigen::VectorXd>& truth, double sigma_p_m,
                                         double sigma_theta_rad, bool noisy, std::mt19937* rng, SmallProblem* problem) {
  const Manifold pose = Manifold::Pose();
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << Eigen::Vector3d::Constant(sigma_p_m), Eigen::Vector3d::Constant(sigma_theta_rad);
  std::vector<VariableId> ids;
  for (const Eigen::VectorXd& x : truth) {
    const Time t = Time::FromNanoseconds(static_cast<std::int64_t>(problem->poses.size()));
    ids.push_back(problem->graph.AddVariable({"pose", pose, Perturb(pose, x, 0.05, rng), false, t}));
    Eigen::VectorXd centre = x;
    if (noisy) {
      const Eigen::VectorXd d = GaussianNoise(6, 1.0, rng).cwiseProduct(sigma);
      pose.Plus(x.data(), d.data(), centre.data());
    }
    problem->graph.AddFactor(MakeFactor(PriorError<PoseBlock>(centre)), {ids.back()}, sigma.cwiseAbs2().asDiagonal(),
                             Loss::Trivial(), "prior", t);
    problem->poses.push_back(ids.back());
    problem->pose_truth.push_back(x);
  }
  return ids;
}

VariableId AddFreeParameter(const std::string& name, const Manifold& manifold, const Eigen::VectorXd& initial,
                            const Eigen::VectorXd& truth, SmallProblem* problem) {
  problem->parameters.push_back(problem->graph.AddVariable({name, manifold, initial, false, std::nullopt}));
  problem->parameter_truth.push_back(truth);
  return problem->parameters.back();
}

std::pair<VariableId, VariableId> AddFreeMounting(const Eigen::Vector3d& p_body_sensor,
                                                  const Eigen::Quaterniond& q_body_sensor, SmallProblem* problem) {
  const VariableId lever_arm =
      AddFreeParameter("lever_arm", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), p_body_sensor, problem);
  const VariableId misalignment =
      AddFreeParameter("misalignment", Manifold::UnitQuaternion(), QuaternionVector(Eigen::Quaterniond::Identity()),
                       QuaternionVector(q_body_sensor), problem);
  return {lever_arm, misalignment};
}

Eigen::VectorXd GaussianNoise(int n, double sigma, std::mt19937* rng) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  if (sigma == 0.0) return x;
  std::normal_distribution<double> normal(0.0, sigma);
  for (int i = 0; i < n; ++i) x[i] = normal(*rng);
  return x;
}

Eigen::VectorXd TangentError(const Graph& graph, VariableId id, const Eigen::VectorXd& truth) {
  const Variable& v = graph.variable(id);
  Eigen::VectorXd d(v.manifold.tangent_dim());
  v.manifold.Minus(v.value.data(), truth.data(), d.data());
  return d;
}

void ExpectEndedOnTolerance(const SolverSummary& summary) {
  EXPECT_TRUE(summary.termination == Termination::kFunctionTolerance ||
              summary.termination == Termination::kStepTolerance)
      << TerminationName(summary.termination) << " after " << summary.iterations << " iterations: " << summary.message;
}

void ExpectSolveRecoversTruth(SmallProblem* problem, double tolerance) {
  const SolverSummary summary = Solve(SolverOptions{}, &problem->graph);
  ExpectEndedOnTolerance(summary);
  EXPECT_GT(summary.initial_cost, 1.0);
  EXPECT_LT(summary.final_cost, 1e-12);
  for (std::size_t i = 0; i < problem->parameters.size(); ++i) {
    const Eigen::VectorXd error = TangentError(problem->graph, problem->parameters[i], problem->parameter_truth[i]);
    EXPECT_LT(error.norm(), tolerance) << problem->graph.variable(problem->parameters[i]).name << ": error "
                                       << error.transpose();
  }
  double worst = 0.0;
  for (std::size_t k = 0; k < problem->poses.size(); ++k) {
    worst = std::max(worst, TangentError(problem->graph, problem->poses[k], problem->pose_truth[k]).norm());
  }
  EXPECT_LT(worst, tolerance);
}

Eigen::VectorXd ExpectSolveWithinSigmas(SmallProblem* problem, double k) {
  ExpectEndedOnTolerance(Solve(SolverOptions{}, &problem->graph));
  return ExpectWithinSigmas(problem->graph, problem->parameters, problem->parameter_truth, k);
}

Eigen::VectorXd ExpectWithinSigmas(const Graph& graph, const std::vector<VariableId>& variables,
                                   const std::vector<Eigen::VectorXd>& truth, double k) {
  const auto info = ComputeMarginalInformation(graph, variables);
  EXPECT_TRUE(info.ok()) << info.status().message();
  if (!info.ok()) return {};
  const Eigen::MatrixXd covariance = info.value().information.inverse();
  const Eigen::VectorXd sigma = covariance.diagonal().cwiseSqrt();
  for (std::size_t i = 0; i < variables.size(); ++i) {
    const Eigen::VectorXd error = TangentError(graph, variables[i], truth[i]);
    const Eigen::VectorXd s = sigma.segment(info.value().offsets[i], error.size());
    for (int c = 0; c < error.size(); ++c) {
      EXPECT_LT(std::abs(error[c]), k * s[c]) << graph.variable(variables[i]).name << " component " << c << ": error "
                                              << error.transpose() << ", sigma " << s.transpose();
    }
  }
  return sigma;
}

}  // namespace roamlab::estimator::testing
