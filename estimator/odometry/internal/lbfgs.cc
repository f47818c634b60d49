#include "estimator/odometry/internal/lbfgs.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

namespace roamlab::estimator::odometry::internal {

LbfgsResult MinimizeLbfgs(const CostFunction& cost, const Eigen::VectorXd& x0, const LbfgsOptions& options) {
  LbfgsResult result;
  result.x = x0;
  Eigen::VectorXd g;
  result.value = cost(x0, &g);
  result.evaluations = 1;
  if (!std::isfinite(result.value)) return result;
  std::deque<Eigen::VectorXd> s_history;
  std::deque<Eigen::VectorXd> y_history;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    if (g.lpNorm<Eigen::Infinity>() <= options.gradient_tolerance * (1.0 + std::abs(result.value))) break;
    // Two-loop recursion: d = -H g with H the L-BFGS inverse-Hessian approximation.
    Eigen::VectorXd q = g;
    const std::size_t k = s_history.size();
    std::vector<double> alpha(k);
    for (std::size_t j = k; j-- > 0;) {
      alpha[j] = s_history[j].dot(q) / y_history[j].dot(s_history[j]);
      q -= alpha[j] * y_history[j];
    }
    if (k > 0)
      q *= s_history.back().dot(y_history.back()) / y_history.back().squaredNorm();
    else
      q /= std::max(1.0, g.norm());  // first step: at most unit length
    for (std::size_t j = 0; j < k; ++j) {
      const double beta = y_history[j].dot(q) / y_history[j].dot(s_history[j]);
      q += s_history[j] * (alpha[j] - beta);
    }
    Eigen::VectorXd d = -q;
    double slope = g.dot(d);
    if (!(slope < 0.0)) {  // not a descent direction: restart along the gradient
      s_history.clear();
      y_history.clear();
      d = -g / std::max(1.0, g.norm());
      slope = g.dot(d);
    }
    // Backtracking line search with the Armijo condition.
    double step = 1.0;
    Eigen::VectorXd x_new;
    Eigen::VectorXd g_new;
    double f_new = 0.0;
    bool accepted = false;
    for (int ls = 0; ls < options.max_line_search_steps; ++ls) {
      x_new = result.x + step * d;
      f_new = cost(x_new, &g_new);
      ++result.evaluations;
      if (std::isfinite(f_new) && f_new <= result.value + options.armijo * step * slope) {
        accepted = true;
        break;
      }
      step *= 0.5;
    }
    if (!accepted) break;
    result.iterations = iteration + 1;
    const Eigen::VectorXd s = x_new - result.x;
    const Eigen::VectorXd y = g_new - g;
    const double change = result.value - f_new;
    result.x = x_new;
    g = g_new;
    const double previous = result.value;
    result.value = f_new;
    // Keep the curvature pair only when it is positive (keeps H positive definite).
    if (s.dot(y) > 1e-12 * s.norm() * y.norm()) {
      s_history.push_back(s);
      y_history.push_back(y);
      if (static_cast<int>(s_history.size()) > options.memory) {
        s_history.pop_front();
        y_history.pop_front();
      }
    }
    if (change <= options.relative_cost_tolerance * std::max(1.0, std::abs(previous))) break;
  }
  return result;
}

}  // namespace roamlab::estimator::odometry::internal
