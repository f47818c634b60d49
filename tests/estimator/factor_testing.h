// Test helpers shared by the error-model tests: random points on manifolds, central-difference Jacobians in tangent
// space (the oracle for the jet Jacobians), and a check that bundles both.
#pragma once

#include <random>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "estimator/manifold.h"

namespace roamlab::estimator::testing {

// A random point: Gaussian entries (scale) for vectors, a uniformly random unit quaternion, or a pose with Gaussian
// position (scale) and random orientation.
Eigen::VectorXd RandomPoint(const Manifold& manifold, std::mt19937* rng, double scale = 1.0);

// A point near `x`: x [+] d with d Gaussian of standard deviation `sigma`.
Eigen::VectorXd Perturb(const Manifold& manifold, const Eigen::VectorXd& x, double sigma, std::mt19937* rng);

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

}  // namespace roamlab::estimator::testing
