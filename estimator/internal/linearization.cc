#include "estimator/internal/linearization.h"

#include <Eigen/Cholesky>

namespace roamlab::estimator::internal {
namespace {

void GatherValues(const Graph& graph, const FactorEntry& entry, std::vector<const double*>* values) {
  values->clear();
  for (VariableId id : entry.variables) values->push_back(graph.variable(id).value.data());
}

}  // namespace

bool LinearizeFactor(const Graph& graph, const FactorEntry& entry, const std::vector<bool>& want_jacobian,
                     WhitenedFactor* out) {
  const Factor& factor = *entry.factor;
  const int m = factor.residual_dim();
  const std::size_t n = entry.variables.size();
  std::vector<const double*> values;
  GatherValues(graph, entry, &values);

  // Raw error, Jacobians in tangent space, and the noise Jacobian.
  Eigen::VectorXd error(m);
  out->jacobians.resize(n);
  std::vector<double*> jacobian_ptrs(n, nullptr);
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
    // Error covariance = noise covariance, whitened once when the factor was added.
    if (!factor.Evaluate(values.data(), error.data(), any_jacobian ? jacobian_ptrs.data() : nullptr, nullptr))
      return false;
    out->whitening = entry.noise_whitening;
  } else {
    // Error covariance of eq. 1 at the current estimate, and its whitening.
    Eigen::MatrixXd noise_jacobian(m, factor.noise_dim());
    if (!factor.Evaluate(values.data(), error.data(), jacobian_ptrs.data(), noise_jacobian.data())) return false;
    const Eigen::MatrixXd sigma_e = noise_jacobian * entry.noise_covariance * noise_jacobian.transpose();
    const Eigen::LLT<Eigen::MatrixXd> llt(sigma_e);
    if (llt.info() != Eigen::Success) return false;
    out->whitening = llt.matrixL().solve(Eigen::MatrixXd::Identity(m, m));
  }
  out->residual = out->whitening * error;
  for (std::size_t i = 0; i < n; ++i) {
    if (want_jacobian[i]) out->jacobians[i] = out->whitening * out->jacobians[i];
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

bool FactorCost(const Graph& graph, const FactorEntry& entry, const Eigen::MatrixXd& whitening, double* cost) {
  std::vector<const double*> values;
  GatherValues(graph, entry, &values);
  Eigen::VectorXd error(entry.factor->residual_dim());
  if (!entry.factor->Evaluate(values.data(), error.data(), nullptr, nullptr)) return false;
  double rho = 0.0, rho_prime = 1.0;
  entry.loss.Evaluate((whitening * error).squaredNorm(), &rho, &rho_prime);
  *cost = 0.5 * rho;
  return true;
}

}  // namespace roamlab::estimator::internal
