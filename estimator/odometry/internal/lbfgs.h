// Limited-memory BFGS (Nocedal & Wright, Algorithm 7.4/7.5) with a backtracking Armijo line search, for the GP
// hyper-parameters. The cost may return +infinity for an infeasible point; the line search then shortens the step.
#pragma once

#include <functional>

#include <Eigen/Core>

namespace roamlab::estimator::odometry::internal {

// Cost at x; fills *gradient when it is not null.
using CostFunction = std::function<double(const Eigen::VectorXd& x, Eigen::VectorXd* gradient)>;

struct LbfgsOptions {
  int max_iterations = 200;
  int memory = 8;
  double gradient_tolerance = 1e-6;        // stop when |g|_inf <= tol (1 + |f|) ...
  double relative_cost_tolerance = 1e-10;  // ... or when the cost changes by less than this relative amount
  double armijo = 1e-4;
  int max_line_search_steps = 30;
};

struct LbfgsResult {
  Eigen::VectorXd x;
  double value = 0.0;
  int iterations = 0;
  int evaluations = 0;
};

// Minimizes cost from x0 (which must have a finite cost; otherwise x0 is returned).
LbfgsResult MinimizeLbfgs(const CostFunction& cost, const Eigen::VectorXd& x0, const LbfgsOptions& options);

}  // namespace roamlab::estimator::odometry::internal
