// The peer of roamlab's offline calibration: the same graph (same factors, error models, noise, free parameters and
// initial values) written as Ceres cost functions and solved by Ceres 2.1 (Levenberg-Marquardt, SPARSE_NORMAL_CHOLESKY
// on SuiteSparse, one thread). Benchmark code only: the roamlab libraries never depend on Ceres.
//
// Each factor becomes an AutoDiffCostFunction whose functor calls the roamlab model's templated error with Ceres jets
// (the models are written for any scalar type), with zero noise, and whitens it by L^-1 (L L^T = error covariance,
// seed eq. 1). For additive-noise models L is constant (NoiseModel::sqrt_covariance, graph.h). For the others (the
// gyroscope) roamlab re-evaluates L at every linearization and holds it while it judges a trial step; the peer does the
// same through an EvaluationCallback that recomputes L whenever Ceres asks for Jacobians. Poses and quaternions use
// roamlab's right perturbation x [+] d = x Exp(d) through AutoDiffManifold.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "estimator/graph.h"

namespace roamlab::bench {

struct CeresPeerResult {
  double seconds = 0.0;  // Ceres' total solve time
  int iterations = 0;
  double initial_cost = 0.0;  // Ceres' own cost (1/2 sum of squared whitened residuals)
  double final_cost = 0.0;
  std::string termination;  // Ceres' message
  bool usable = false;
  // Final values of the free variables, by id (ambient).
  std::vector<std::pair<estimator::VariableId, Eigen::VectorXd>> values;
};

struct CeresPeerOptions {
  int max_iterations = 100;
  double function_tolerance = 1e-10;
  double parameter_tolerance = 1e-10;
  double initial_lambda = 1e-4;  // the LM damping roamlab starts from; Ceres' initial radius is its inverse
};

// Solves the active factors of `graph` with Ceres from the graph's current values (the graph is not changed). Fixed
// variables stay constant. Every factor must have the trivial loss.
CeresPeerResult SolveWithCeres(const estimator::Graph& graph, const CeresPeerOptions& options);

}  // namespace roamlab::bench
