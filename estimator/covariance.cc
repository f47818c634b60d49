#include "estimator/covariance.h"

#include <cmath>
#include <limits>
#include <unordered_set>

#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>

#include "estimator/internal/normal_equations.h"
#include "estimator/solver.h"

namespace roamlab::estimator {

const char* ObservabilityName(Observability observability) {
  switch (observability) {
    case Observability::kObservable:
      return "observable";
    case Observability::kWeak:
      return "weak";
    case Observability::kUnobservable:
      return "unobservable";
  }
  return "unknown";
}

Result<MarginalInformation> ComputeMarginalInformation(const Graph& graph, const std::vector<VariableId>& variables,
                                                       SolverWorkspace* workspace) {
  // Order every other free variable first, the requested ones last.
  const std::unordered_set<VariableId> requested(variables.begin(), variables.end());
  std::vector<VariableId> order;
  for (VariableId id : FreeVariableOrder(graph))
    if (requested.count(id) == 0) order.push_back(id);
  MarginalInformation result;
  result.variables = variables;
  int np = 0;
  for (VariableId id : variables) {
    const Variable& v = graph.variable(id);
    if (v.fixed) return Status::Error("variable '" + v.name + "' is fixed: it has no marginal covariance");
    result.offsets.push_back(np);
    np += v.manifold.tangent_dim();
    order.push_back(id);
  }

  internal::NormalEquations local;
  internal::NormalEquations& system = workspace != nullptr ? *workspace->system_ : local;
  system.set_relinearize_threshold(0.0);
  system.set_keep_linearizations(false);  // (one linearization, H alone read)
  system.Reset(graph, std::move(order));
  system.ForgetLinearizations();  // (a workspace's may have been carried to first order)
  std::string failed;
  if (!system.Linearize(graph, &failed)) return Status::Error("a factor from '" + failed + "' cannot be evaluated");
  const int n = system.dimension();
  const int nx = n - np;
  {
    const Eigen::SparseMatrix<double>& upper = system.hessian_upper();
    result.conditional.resize(np);
    for (int i = 0; i < np; ++i) result.conditional[i] = upper.coeff(nx + i, nx + i);
  }
  // Schur complement S = Hpp - Hxp^T Hxx^-1 Hxp: from the envelope factorization when the other variables are a band
  // of poses with the requested ones as its border (a calibration), else with CHOLMOD on the (large, sparse) Hxx.
  if (nx > 0 && system.BorderInformation(np, &result.information)) return result;
  const Eigen::SparseMatrix<double> H = system.hessian_upper().selfadjointView<Eigen::Upper>();
  const Eigen::MatrixXd Hpp = Eigen::MatrixXd(H.bottomRightCorner(np, np));
  if (nx == 0) {
    result.information = Hpp;
    return result;
  }

  Eigen::SparseMatrix<double> Hxx = H.topLeftCorner(nx, nx);
  const Eigen::MatrixXd Hxp = Eigen::MatrixXd(H.topRightCorner(nx, np));
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  llt.cholmod().print = 0;
  llt.compute(Hxx);
  if (llt.info() != Eigen::Success) {
    // Gauge freedom in the other variables: regularize them very slightly.
    for (int i = 0; i < nx; ++i) Hxx.coeffRef(i, i) += 1e-10 * std::max(1.0, Hxx.coeff(i, i));
    llt.compute(Hxx);
    if (llt.info() != Eigen::Success)
      return Status::Error("the Hessian of the variables being marginalized is singular");
  }
  const Eigen::MatrixXd Y = llt.solve(Hxp);
  result.information = Hpp - Hxp.transpose() * Y;
  result.information = 0.5 * (result.information + result.information.transpose()).eval();
  return result;
}

ObservabilityAnalysis AnalyzeObservability(const Eigen::MatrixXd& information, const Eigen::VectorXd& conditional,
                                           const ObservabilityOptions& options) {
  const int n = static_cast<int>(information.rows());
  ObservabilityAnalysis out;
  out.std = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  out.inflation = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  out.observability.assign(n, Observability::kUnobservable);
  out.covariance = Eigen::MatrixXd::Zero(n, n);
  out.correlation = Eigen::MatrixXd::Identity(n, n);
  if (n == 0) return out;

  // Normalize to unit diagonal; a zero diagonal means no information at all.
  Eigen::VectorXd scale(n);
  for (int i = 0; i < n; ++i) scale[i] = information(i, i) > 0.0 ? 1.0 / std::sqrt(information(i, i)) : 0.0;
  const Eigen::MatrixXd normalized = scale.asDiagonal() * information * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(normalized);
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const Eigen::MatrixXd& V = eig.eigenvectors();

  // Null loading, pseudo-inverse and regularized inverse in normalized coordinates.
  Eigen::VectorXd null_loading = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd pseudo = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd regularized = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k < n; ++k) {
    const Eigen::VectorXd v = V.col(k);
    if (lambda[k] < options.null_eigenvalue) {
      null_loading += v.cwiseAbs2();
    } else {
      pseudo += v * v.transpose() / lambda[k];
    }
    regularized += v * v.transpose() / (std::max(lambda[k], 0.0) + 1e-6);
  }
  out.covariance = scale.asDiagonal() * pseudo * scale.asDiagonal();
  for (int i = 0; i < n; ++i) {
    if (scale[i] == 0.0 || null_loading[i] > options.null_loading) continue;
    out.inflation[i] = out.covariance(i, i) * conditional[i];
    if (out.inflation[i] > options.unobservable_inflation) continue;
    out.std[i] = std::sqrt(out.covariance(i, i));
    out.observability[i] =
        out.inflation[i] > options.weak_inflation ? Observability::kWeak : Observability::kObservable;
  }
  const Eigen::VectorXd d = regularized.diagonal().cwiseSqrt().cwiseInverse();
  out.correlation = d.asDiagonal() * regularized * d.asDiagonal();
  return out;
}

}  // namespace roamlab::estimator
