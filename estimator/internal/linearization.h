// Whitening and robust weighting of one factor (seed 000, eqs. 1-3): the error covariance Sigma_e = J_eta Sigma_eta
// J_eta^T is re-evaluated at the current estimate, factored as L L^T, and the error and its Jacobians are whitened by
// L^-1. A robust loss rho scales both by sqrt(rho'(s)) (iteratively reweighted least squares). Shared by the solver,
// the covariance recovery and the fixed-lag marginalization.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "estimator/graph.h"

namespace roamlab::estimator::internal {

struct WhitenedFactor {
  Eigen::VectorXd residual;               // whitened and loss-weighted
  std::vector<Eigen::MatrixXd> jacobians; // per connected variable (tangent columns); empty matrix when not asked
  Eigen::MatrixXd sqrt_covariance;        // L (lower) with L L^T = error covariance (kept to evaluate trial points)
  double squared_norm = 0.0;              // s = |L^-1 e|^2 before the loss
  double cost = 0.0;                      // rho(s) / 2
};

// Linearizes `entry` at the graph's current values. want_jacobian[i] says whether the Jacobian of variable i is
// needed. Returns false if the factor cannot be evaluated or its error covariance is not positive definite.
bool LinearizeFactor(const Graph& graph, const FactorEntry& entry, const std::vector<bool>& want_jacobian,
                     WhitenedFactor* out);

// Cost rho(|L^-1 e(x)|^2)/2 of `entry` at the graph's current values with the Cholesky factor L of an earlier
// linearization's error covariance. Returns false if the error cannot be evaluated.
bool FactorCost(const Graph& graph, const FactorEntry& entry, const Eigen::MatrixXd& sqrt_covariance, double* cost);

}  // namespace roamlab::estimator::internal
