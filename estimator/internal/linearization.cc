#include "estimator/internal/linearization.h"

#include <Eigen/Cholesky>

#include "common/check.h"

namespace roamlab::estimator::internal {
namespace {

// Pointers to the connected variables' values, in a per-thread buffer (no allocation once it has grown).
const double* const* GatherValues(const Graph& graph, const FactorEntry& entry) {
  thread_local std::vector<const double*> values;
  values.clear();
  for (VariableId id : entry.variables) values.push_back(graph.variable(id).value.data());
  return values.data();
}

// Rows of Eigen's triangular vector solve's first panel (EIGEN_TUNE_TRIANGULAR_PANEL_WIDTH): up to this size its
// result is the plain substitution below.
constexpr Eigen::Index kTriangularPanel = EIGEN_TUNE_TRIANGULAR_PANEL_WIDTH;

// x <- L^-1 x for the error or a Jacobian: a division per row when L is diagonal (what the triangular solve does
// then), otherwise a triangular solve. A Jacobian of up to 4 rows (an error covariance of eq. 1 is 3 x 3) is solved
// by plain loops instead of Eigen's blocked matrix solve, whose set-up costs several times the arithmetic at this
// size; the loops do what that solve does on its first panel of rows (at least 4 wide), entry by entry: row i is
// multiplied by 1 / L(i, i), then x(r, j) -= x(i, j) L(r, i) for the rows below, so the result is the same.
template <typename Derived>
void Whiten(const Eigen::MatrixXd& L, bool diagonal, Eigen::MatrixBase<Derived>* x) {
  if (diagonal) {
    for (Eigen::Index r = 0; r < x->rows(); ++r) x->row(r) /= L(r, r);
  } else if (Derived::ColsAtCompileTime != 1 && x->rows() <= 4) {
    Eigen::MatrixBase<Derived>& m = *x;
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      const double a = 1.0 / L(i, i);
      for (Eigen::Index j = 0; j < m.cols(); ++j) {
        m(i, j) *= a;
        const double b = m(i, j);
        for (Eigen::Index r = i + 1; r < m.rows(); ++r) m(r, j) -= b * L(r, i);
      }
    }
  } else if (Derived::ColsAtCompileTime == 1 && x->rows() <= kTriangularPanel) {
    // An error vector: what Eigen's vector solve does within its first panel of rows, entry by entry (a nonzero
    // x(i) is divided by L(i, i), then x(r) -= x(i) L(r, i) for the rows below), without its call and set-up.
    Eigen::MatrixBase<Derived>& v = *x;
    for (Eigen::Index i = 0; i < v.rows(); ++i) {
      if (v(i) == 0.0) continue;
      v(i) /= L(i, i);
      const double b = v(i);
      for (Eigen::Index r = i + 1; r < v.rows(); ++r) v(r) -= b * L(r, i);
    }
  } else {
    L.triangularView<Eigen::Lower>().solveInPlace(*x);
  }
}

// rho(|L^-1 e|^2) / 2 for an un-whitened error e.
double WhitenedCost(const FactorEntry& entry, const Eigen::MatrixXd& sqrt_covariance, const Eigen::VectorXd& error) {
  thread_local Eigen::VectorXd whitened;
  whitened = error;
  Whiten(sqrt_covariance, &sqrt_covariance == &entry.noise->sqrt_covariance && entry.noise->sqrt_diagonal, &whitened);
  double rho = 0.0, rho_prime = 1.0;
  entry.loss.Evaluate(whitened.squaredNorm(), &rho, &rho_prime);
  return 0.5 * rho;
}

}  // namespace

bool LinearizeFactor(const Graph& graph, const FactorEntry& entry, const std::vector<bool>& want_jacobian,
                     WhitenedFactor* out) {
  ROAMLAB_CHECK(want_jacobian.size() <= 64, "factor from '" << entry.stream << "' has more than 64 variables");
  std::uint64_t mask = 0;
  for (std::size_t i = 0; i < want_jacobian.size(); ++i)
    if (want_jacobian[i]) mask |= std::uint64_t{1} << i;
  return LinearizeFactorAt(entry, GatherValues(graph, entry), mask, out);
}

bool LinearizeFactorAt(const FactorEntry& entry, const double* const* values, std::uint64_t want_mask,
                       WhitenedFactor* out, double* previous_cost) {
  const Factor& factor = *entry.factor;
  const int m = factor.residual_dim();
  const std::size_t n = entry.variables.size();
  const auto wanted = [want_mask](std::size_t i) { return ((want_mask >> i) & 1u) != 0; };

  // Raw error (into `residual`, whitened in place below), Jacobians in tangent space, and the noise Jacobian.
  out->residual.resize(m);
  out->jacobians.resize(n);
  thread_local std::vector<double*> jacobian_ptrs;
  jacobian_ptrs.assign(n, nullptr);
  for (std::size_t i = 0; i < n; ++i) {
    if (wanted(i)) {
      out->jacobians[i].resize(m, factor.manifolds()[i].tangent_dim());
      jacobian_ptrs[i] = out->jacobians[i].data();
    } else {
      out->jacobians[i].resize(0, 0);
    }
  }
  bool diagonal = false;
  if (factor.additive_noise()) {
    // Error covariance = noise covariance, factored once when the factor was added.
    if (!factor.Evaluate(values, out->residual.data(), want_mask != 0 ? jacobian_ptrs.data() : nullptr, nullptr))
      return false;
    diagonal = entry.noise->sqrt_diagonal;
  } else {
    // Error covariance of eq. 1 at the current estimate, and its Cholesky factor.
    thread_local Eigen::MatrixXd noise_jacobian;
    noise_jacobian.resize(m, factor.noise_dim());
    if (!factor.Evaluate(values, out->residual.data(), jacobian_ptrs.data(), noise_jacobian.data())) return false;
    // The earlier whitening is overwritten below: the cost with it first.
    if (previous_cost != nullptr) *previous_cost = WhitenedCost(entry, out->sqrt_covariance, out->residual);
    // The products and the factorization in per-thread buffers (no allocation once they have grown), as the
    // expression J Sigma J^T would evaluate them.
    thread_local Eigen::MatrixXd half, covariance;
    thread_local Eigen::LLT<Eigen::MatrixXd> llt;
    half.noalias() = noise_jacobian * entry.noise->covariance;
    covariance.noalias() = half * noise_jacobian.transpose();
    llt.compute(covariance);
    if (llt.info() != Eigen::Success) return false;
    out->sqrt_covariance = llt.matrixL();
  }
  // Whitening: L^-1 e and L^-1 J, in place.
  const Eigen::MatrixXd& L = SqrtCovariance(entry, *out);
  Whiten(L, diagonal, &out->residual);
  for (std::size_t i = 0; i < n; ++i) {
    if (wanted(i)) Whiten(L, diagonal, &out->jacobians[i]);
  }

  // Robust loss as a weight.
  out->squared_norm = out->residual.squaredNorm();
  double rho = 0.0, rho_prime = 1.0;
  entry.loss.Evaluate(out->squared_norm, &rho, &rho_prime);
  out->cost = 0.5 * rho;
  // An additive-noise factor's whitening does not change: the earlier one gives the same cost.
  if (previous_cost != nullptr && factor.additive_noise()) *previous_cost = out->cost;
  if (rho_prime != 1.0) {
    const double w = std::sqrt(rho_prime);
    out->residual *= w;
    for (std::size_t i = 0; i < n; ++i) {
      if (wanted(i)) out->jacobians[i] *= w;
    }
  }
  return true;
}

bool FactorCost(const Graph& graph, const FactorEntry& entry, const Eigen::MatrixXd& sqrt_covariance, double* cost) {
  return FactorCostAt(entry, GatherValues(graph, entry), sqrt_covariance, cost);
}

bool FactorCostAt(const FactorEntry& entry, const double* const* values, const Eigen::MatrixXd& sqrt_covariance,
                  double* cost) {
  thread_local Eigen::VectorXd error;
  error.resize(entry.factor->residual_dim());
  if (!entry.factor->Evaluate(values, error.data(), nullptr, nullptr)) return false;
  *cost = WhitenedCost(entry, sqrt_covariance, error);
  return true;
}

}  // namespace roamlab::estimator::internal
