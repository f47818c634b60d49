// Whitening and robust weighting of one factor (seed 000, eqs. 1-3): the error covariance Sigma_e = J_eta Sigma_eta
// J_eta^T is re-evaluated at the current estimate, factored as L L^T, and the error and its Jacobians are whitened by
// L^-1. A robust loss rho scales both by sqrt(rho'(s)) (iteratively reweighted least squares). Shared by the solver,
// the covariance recovery and the fixed-lag marginalization.
//
// Additive-noise factors (Factor::additive_noise) have a constant error covariance, factored once when the factor was
// added (NoiseModel::sqrt_covariance, graph.h); when that factor is diagonal the whitening is a division per row.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "estimator/graph.h"

namespace roamlab::estimator::internal {

struct WhitenedFactor {
  Eigen::VectorXd residual;                // whitened and loss-weighted
  std::vector<Eigen::MatrixXd> jacobians;  // per connected variable (tangent columns); empty matrix when not asked
  // L (lower) with L L^T = error covariance, kept to evaluate trial points; only for factors whose error covariance
  // depends on the estimate (SqrtCovariance gives it for every factor).
  Eigen::MatrixXd sqrt_covariance;
  double squared_norm = 0.0;  // s = |L^-1 e|^2 before the loss
  double cost = 0.0;          // rho(s) / 2
};

// The L of `out`'s linearization of `entry`.
inline const Eigen::MatrixXd& SqrtCovariance(const FactorEntry& entry, const WhitenedFactor& out) {
  return entry.factor->additive_noise() ? entry.noise->sqrt_covariance : out.sqrt_covariance;
}

// Linearizes `entry` at the graph's current values. want_jacobian[i] says whether the Jacobian of variable i is
// needed. Returns false if the factor cannot be evaluated or its error covariance is not positive definite.
bool LinearizeFactor(const Graph& graph, const FactorEntry& entry, const std::vector<bool>& want_jacobian,
                     WhitenedFactor* out);

// The same at given variable values (values[i]: ambient values of variable i), with bit i of want_mask asking for the
// Jacobian of variable i (factors with up to 64 variables). When previous_cost is given, `out` must hold an earlier
// linearization of the same factor: it also receives the cost at these values with that linearization's whitening
// (what FactorCostAt gives with its L), computed from the same error before `out` is overwritten.
bool LinearizeFactorAt(const FactorEntry& entry, const double* const* values, std::uint64_t want_mask,
                       WhitenedFactor* out, double* previous_cost = nullptr);

// Cost rho(|L^-1 e(x)|^2)/2 of `entry` at the graph's current values with the Cholesky factor L of an earlier
// linearization's error covariance. Returns false if the error cannot be evaluated.
bool FactorCost(const Graph& graph, const FactorEntry& entry, const Eigen::MatrixXd& sqrt_covariance, double* cost);

// The same at given variable values.
bool FactorCostAt(const FactorEntry& entry, const double* const* values, const Eigen::MatrixXd& sqrt_covariance,
                  double* cost);

}  // namespace roamlab::estimator::internal
