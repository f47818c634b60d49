#include "estimator/internal/linearization.h"

#include <Eigen/Cholesky>

namespace roamlab::estimator::internal {
namespace {

// Pointers to the connected variables' values, in a per-thread buffer (no allocation once it has grown).
const double* const* GatherValues(const Graph& graph, const FactorEntry& entry) {
  thread_local std::vector<const double*> values;
  values.clear();
  for (VariableId id : entry.variables) values.push_back(graph.variable(id).value.data());
  return values.data();
}

}  // namespace

bool LinearizeFactor(const Graph& graph, const FactorEntry& entry, const std::vector<bool>& want_jacobian,
                     WhitenedFactor* out) {
  const Factor& factor = *entry.factor;
  const int m = factor.residual_dim();
  const std::size_t n = entry.variables.size();
  const double* const* values = GatherValues(graph, entry);

  // Raw error (into `residual`, whitened in place below), Jacobians in tangent space, and the noise Jacobian.
  out->residual.resize(m);
  out->jacobians.resize(n);
  thread_local std::vector<double*> jacobian_ptrs;
  jacobian_ptrs.assign(n, nullptr);
  for (std::size_t i = 0; i < n; ++i) {
    if (want_jacobian[i]) {
      out->jacobians[i].resize(m, factor.manifolds()[i].tangent_dim());
      jacobian_ptrs[i] = out->jacobians[i].data();
    } else {
      out->jacobians[i].resize(0, 0);
    }
  }
  bool any_jacobian = false;
  for (std::size_t i = 0; i < n; ++i) any_jacobian |= want_jacobian[i];
  if (factor.additive_noise()) {
    // Error covariance = noise covariance, factored once when the factor was added.
    if (!factor.Evaluate(values, out->residual.data(), any_jacobian ? jacobian_ptrs.data() : nullptr, nullptr))
      return false;
    out->sqrt_covariance = entry.noise_sqrt_covariance;
  } else {
    // Error covariance of eq. 1 at the current estimate, and its Cholesky factor.
    Eigen::MatrixXd noise_jacobian(m, factor.noise_dim());
    if (!factor.Evaluate(values, out->residual.data(), jacobian_ptrs.data(), noise_jacobian.data())) return false;
    const Eigen::LLT<Eigen::MatrixXd> llt(noise_jacobian * entry.noise_covariance * noise_jacobian.transpose());
    if (llt.info() != Eigen::Success) return false;
    out->sqrt_covariance = llt.matrixL();
  }
  // Whitening: L^-1 e and L^-1 J, by triangular solves in place.
  const auto L = out->sqrt_covariance.triangularView<Eigen::Lower>();
  L.solveInPlace(out->residual);
  for (std::size_t i = 0; i < n; ++i) {
    if (want_jacobian[i]) L.solveInPlace(out->jacobians[i]);
  }

  // Robust loss as a weight.
  out->squared_norm = out->residual.squaredNorm();
  double rho = 0.0, rho_prime = 1.0;
  entry.loss.Evaluate(out->squared_norm, &rho, &rho_prime);
  out->cost = 0.5 * rho;
  if (rho_prime != 1.0) {
    const double w = std::sqrt(rho_prime);
    out->residual *= w;
    for (std::size_t i = 0; i < n; ++i) {
      if (want_jacobian[i]) out->jacobians[i] *= w;
    }
  }
  return true;
}

bool FactorCost(const Graph& graph, const FactorEntry& entry, const Eigen::MatrixXd& sqrt_covariance, double* cost) {
  thread_local Eigen::VectorXd error;
  error.resize(entry.factor->residual_dim());
  if (!entry.factor->Evaluate(GatherValues(graph, entry), error.data(), nullptr, nullptr)) return false;
  sqrt_covariance.triangularView<Eigen::Lower>().solveInPlace(error);
  double rho = 0.0, rho_prime = 1.0;
  entry.loss.Evaluate(error.squaredNorm(), &rho, &rho_prime);
  *cost = 0.5 * rho;
  return true;
}

}  // namespace roamlab::estimator::internal
