#include "estimator/marginalization.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "estimator/geometry.h"
#include "estimator/internal/linearization.h"

namespace roamlab::estimator {
namespace {

// Inverse right Jacobian of SO(3): d Log(Exp(phi) Exp(d)) / dd at d = 0.
Eigen::Matrix3d InverseRightJacobian(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d K = Skew<double>(phi);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * K + K * K / 12.0;
  const double c = 1.0 / (theta * theta) - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() + 0.5 * K + c * K * K;
}

}  // namespace

LinearPriorFactor::LinearPriorFactor(std::vector<Manifold> manifolds, std::vector<Eigen::VectorXd> linearization_point,
                                     Eigen::MatrixXd J, Eigen::VectorXd r0)
    : manifolds_(std::move(manifolds)), x0_(std::move(linearization_point)), J_(std::move(J)), r0_(std::move(r0)) {
  int offset = 0;
  for (const Manifold& m : manifolds_) {
    offsets_.push_back(offset);
    offset += m.tangent_dim();
  }
}

bool LinearPriorFactor::Evaluate(const double* const* values, double* error, double* const* jacobians,
                                 double* noise_jacobian) const {
  const int m = residual_dim();
  Eigen::VectorXd delta(J_.cols());
  for (std::size_t i = 0; i < manifolds_.size(); ++i)
    manifolds_[i].Minus(values[i], x0_[i].data(), delta.data() + offsets_[i]);
  Eigen::Map<Eigen::VectorXd>(error, m) = r0_ + J_ * delta;
  if (jacobians != nullptr) {
    for (std::size_t i = 0; i < manifolds_.size(); ++i) {
      if (jacobians[i] == nullptr) continue;
      const int d = manifolds_[i].tangent_dim();
      Eigen::MatrixXd D = Eigen::MatrixXd::Identity(d, d);
      if (manifolds_[i].kind() == ManifoldKind::kQuaternion) {
        D = InverseRightJacobian(delta.segment<3>(offsets_[i]));
      } else if (manifolds_[i].kind() == ManifoldKind::kPose) {
        D.bottomRightCorner<3, 3>() = InverseRightJacobian(delta.segment<3>(offsets_[i] + 3));
      }
      Eigen::Map<Eigen::MatrixXd>(jacobians[i], m, d) = J_.middleCols(offsets_[i], d) * D;
    }
  }
  if (noise_jacobian != nullptr) Eigen::Map<Eigen::MatrixXd>(noise_jacobian, m, m).setIdentity();
  return error != nullptr && r0_.allFinite();
}

bool Marginalize(const std::vector<VariableId>& leaving, Graph* graph) {
  // The factors on the leaving variables, and the blanket: the other free variables they touch.
  const std::set<VariableId> leaving_set(leaving.begin(), leaving.end());
  std::set<FactorId> factors;
  for (VariableId v : leaving)
    for (FactorId f : graph->FactorsOf(v)) factors.insert(f);
  std::vector<VariableId> order;  // leaving first, then blanket
  std::set<VariableId> blanket_set;
  for (VariableId v : leaving)
    if (!graph->variable(v).fixed) order.push_back(v);
  const std::size_t n_leaving = order.size();
  for (FactorId f : factors) {
    const FactorEntry& e = graph->factor(f);
    if (!e.active) continue;
    for (VariableId v : e.variables)
      if (!leaving_set.count(v) && !graph->variable(v).fixed && blanket_set.insert(v).second) order.push_back(v);
  }
  std::map<VariableId, int> offset;
  int n = 0, nm = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    offset[order[i]] = n;
    n += graph->variable(order[i]).manifold.tangent_dim();
    if (i + 1 == n_leaving) nm = n;
  }

  // Dense H and g over [leaving, blanket].
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  std::vector<bool> want;
  std::vector<int> var_offset;
  internal::WhitenedFactor wf;  // reused: its buffers keep their size
  for (FactorId f : factors) {
    const FactorEntry& e = graph->factor(f);
    if (!e.active) continue;
    want.clear();
    var_offset.clear();
    for (VariableId v : e.variables) {
      const auto it = offset.find(v);
      want.push_back(it != offset.end());
      var_offset.push_back(it != offset.end() ? it->second : -1);
    }
    if (!internal::LinearizeFactor(*graph, e, want, &wf)) return false;
    // Coefficient-wise products: the blocks are a few rows by at most a few dozen columns.
    for (std::size_t a = 0; a < e.variables.size(); ++a) {
      if (!want[a]) continue;
      const int oa = var_offset[a];
      g.segment(oa, wf.jacobians[a].cols()) += wf.jacobians[a].transpose().lazyProduct(wf.residual);
      for (std::size_t b = 0; b < e.variables.size(); ++b) {
        if (!want[b]) continue;
        H.block(oa, var_offset[b], wf.jacobians[a].cols(), wf.jacobians[b].cols()) +=
            wf.jacobians[a].transpose().lazyProduct(wf.jacobians[b]);
      }
    }
  }

  // Schur complement onto the blanket, factored as J^T J by eigen-decomposition (dropping null directions).
  const int nb = n - nm;
  Eigen::MatrixXd Hbb = H.bottomRightCorner(nb, nb);
  Eigen::VectorXd gb = g.tail(nb);
  if (nm > 0) {
    const Eigen::MatrixXd Hmm = H.topLeftCorner(nm, nm);
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(Hmm + 1e-12 * Eigen::MatrixXd::Identity(nm, nm));
    const Eigen::MatrixXd Hmb = H.topRightCorner(nm, nb);
    Hbb -= Hmb.transpose() * ldlt.solve(Hmb);
    gb -= Hmb.transpose() * ldlt.solve(g.head(nm));
  }
  std::vector<Manifold> manifolds;
  std::vector<Eigen::VectorXd> x0;
  std::vector<VariableId> blanket(order.begin() + static_cast<std::ptrdiff_t>(n_leaving), order.end());
  for (VariableId v : blanket) {
    manifolds.push_back(graph->variable(v).manifold);
    x0.push_back(graph->variable(v).value);
  }

  // Replace the factors and variables by the prior.
  for (FactorId f : factors) graph->RemoveFactor(f);
  for (VariableId v : leaving) graph->RemoveVariable(v);
  if (nb == 0) return true;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (Hbb + Hbb.transpose()));
  const double max_ev = std::max(eig.eigenvalues().maxCoeff(), 0.0);
  std::vector<int> keep;
  for (int k = 0; k < nb; ++k)
    if (eig.eigenvalues()[k] > 1e-12 * max_ev && eig.eigenvalues()[k] > 0.0) keep.push_back(k);
  if (keep.empty()) return true;
  Eigen::MatrixXd J(keep.size(), nb);
  Eigen::VectorXd r0(keep.size());
  for (std::size_t i = 0; i < keep.size(); ++i) {
    const double ev = eig.eigenvalues()[keep[i]];
    const Eigen::VectorXd u = eig.eigenvectors().col(keep[i]);
    J.row(static_cast<int>(i)) = std::sqrt(ev) * u.transpose();
    r0[static_cast<int>(i)] = u.dot(gb) / std::sqrt(ev);
  }
  const int dim = static_cast<int>(keep.size());
  graph->AddFactor(std::make_unique<LinearPriorFactor>(manifolds, x0, J, r0), blanket,
                   Eigen::MatrixXd::Identity(dim, dim), Loss::Trivial(), "marginalization", Time());
  return true;
}

}  // namespace roamlab::estimator
