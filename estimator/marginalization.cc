#include "estimator/marginalization.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "estimator/geometry.h"
#include "estimator/internal/linearization.h"
#include "estimator/so3_jacobians.h"
#include "estimator/solver.h"

namespace roamlab::estimator {
namespace {

// Margin of the rank decision over the Schur complement's rounding (n eps max|H|): the eigenvalues of rounding alone
// stay well below that bound.
constexpr double kRoundingFloor = 10.0;

// J (r x n) and r0 with J^T J = H and J^T r0 = g for a positive semi-definite H (g in its range), keeping the
// directions of the eigenvalues above `floor` (the others carry no information, or only rounding: see Marginalize).
// Reference: the eigen-decomposition H = V diag(lambda) V^T, J = diag(sqrt(lambda)) V^T, r0 = diag(1/sqrt(lambda))
// V^T g over those eigenvalues. Fast path, for a clear gap: a Cholesky factorization with diagonal pivoting,
// H = P L L^T P^T, the largest remaining diagonal entry eliminated first, stopped at rank r when the remaining Schur
// complement S has no diagonal entry above floor / n. Then J = L^T P^T (r rows) and r0 = L11^-1 (P^T g)_1..r give the
// same prior: |r0 + J dx|^2 depends on them only through J^T J and J^T r0 (up to a constant), the same as the
// reference when both keep the same directions. They do when
//  - the dropped eigenvalues are below the floor: lambda_{r+1..n}(H) <= |S|_2 <= n max diag(S) <= floor;
//  - the kept ones are above it: by interlacing they are at least lambda_min(L11 L11^T) = 1 / |L11^-1|_2^2, which is
//    checked against the floor through an upper bound of |L11^-1|_2^2: first |L11^-1|_1 |L11^-1|_inf <= |M^-T e|_inf
//    |M^-1 e|_inf, with M the comparison matrix of L11 (|l_ii| on the diagonal, -|l_ij| below: |L11^-1| <= M^-1
//    entrywise, Higham, Accuracy and Stability of Numerical Algorithms, Thm. 8.12), two substitutions; where that is
//    too loose, |L11^-1|_F^2 (each column of the inverse).
// Otherwise (an eigenvalue near the floor) the eigen-decomposition decides. Returns false when H carries no
// information above the floor.
bool SquareRootInformation(const Eigen::MatrixXd& H_in, const Eigen::VectorXd& g, double floor, Eigen::MatrixXd* J,
                           Eigen::VectorXd* r0) {
  const int n = static_cast<int>(H_in.rows());
  Eigen::MatrixXd H = H_in;
  std::vector<int> perm(n);
  for (int i = 0; i < n; ++i) perm[i] = i;
  Eigen::VectorXd gp = g;
  int rank = 0;
  // In place, on the lower triangle only: column k of L (rows k..n-1, permuted) in H's column k; the trailing block
  // holds the lower triangle of the Schur complement. (The same operations on those entries as on a full symmetric
  // copy: the symmetric swap moves the same values, and the update of entry (i, j) is H(i, j) - H(i, k) H(j, k).)
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i)
      if (H(i, i) > H(p, p)) p = i;
    if (!(H(p, p) > floor / n)) break;
    if (p != k) {
      for (int j = 0; j < k; ++j) std::swap(H(k, j), H(p, j));
      std::swap(H(k, k), H(p, p));
      for (int i = k + 1; i < p; ++i) std::swap(H(i, k), H(p, i));
      for (int i = p + 1; i < n; ++i) std::swap(H(i, k), H(i, p));
      std::swap(perm[k], perm[p]);
      std::swap(gp[k], gp[p]);
    }
    // Plain loops over the columns (column-major, n rows): the same operations as Eigen's segment expressions, whose
    // per-segment set-up cost more than the arithmetic on a blanket of a few dozen coordinates.
    double* column_k = H.data() + static_cast<std::ptrdiff_t>(k) * n;
    const double d = std::sqrt(column_k[k]);
    column_k[k] = d;
    for (int i = k + 1; i < n; ++i) column_k[i] /= d;
    for (int j = k + 1; j < n; ++j) {
      const double a = column_k[j];
      double* column_j = H.data() + static_cast<std::ptrdiff_t>(j) * n;
      for (int i = j; i < n; ++i) column_j[i] -= a * column_k[i];
    }
    rank = k + 1;
  }
  // The kept eigenvalues' bound from the comparison matrix: y = M^-1 e (forward) and z = M^-T e (backward).
  bool gap = rank > 0;
  bool certified = false;
  if (gap) {
    std::vector<double> y(rank), z(rank);
    double y_max = 0.0, z_max = 0.0;
    for (int i = 0; i < rank; ++i) {
      double sum = 1.0;
      for (int j = 0; j < i; ++j) sum += std::abs(H(i, j)) * y[j];
      y[i] = sum / H(i, i);
      y_max = std::max(y_max, y[i]);
    }
    for (int j = rank - 1; j >= 0; --j) {
      const double* column_j = H.data() + static_cast<std::ptrdiff_t>(j) * n;
      double sum = 1.0;
      for (int i = j + 1; i < rank; ++i) sum += std::abs(column_j[i]) * z[i];
      z[j] = sum / column_j[j];
      z_max = std::max(z_max, z[j]);
    }
    certified = 1.0 / (y_max * z_max) > floor;
  }
  // Otherwise 1 / |L11^-1|_F^2: each column of L11^-1 by a forward substitution from its diagonal on (the rows above
  // are zero).
  if (gap && !certified) {
    std::vector<double> x(rank);
    double squared_norm = 0.0;
    for (int c = 0; c < rank; ++c) {
      std::fill(x.begin() + c, x.end(), 0.0);
      x[c] = 1.0;
      for (int j = c; j < rank; ++j) {
        const double* column_j = H.data() + static_cast<std::ptrdiff_t>(j) * n;
        const double xj = x[j] / column_j[j];
        x[j] = xj;
        squared_norm += xj * xj;
        for (int i = j + 1; i < rank; ++i) x[i] -= xj * column_j[i];
      }
    }
    gap = 1.0 / squared_norm > floor;
  }
  if (gap) {
    J->setZero(rank, n);
    for (int i = 0; i < n; ++i) J->col(perm[i]).head(std::min(i + 1, rank)) = H.row(i).head(std::min(i + 1, rank));
    *r0 = H.topLeftCorner(rank, rank).triangularView<Eigen::Lower>().solve(gp.head(rank));
    return true;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(H_in);
  std::vector<int> keep;
  for (int k = 0; k < n; ++k)
    if (eig.eigenvalues()[k] > floor) keep.push_back(k);
  if (keep.empty()) return false;
  J->resize(static_cast<int>(keep.size()), n);
  r0->resize(static_cast<int>(keep.size()));
  for (std::size_t i = 0; i < keep.size(); ++i) {
    const double ev = eig.eigenvalues()[keep[i]];
    const Eigen::VectorXd u = eig.eigenvectors().col(keep[i]);
    J->row(static_cast<int>(i)) = std::sqrt(ev) * u.transpose();
    (*r0)[static_cast<int>(i)] = u.dot(g) / std::sqrt(ev);
  }
  return true;
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
  // Evaluated at every linearization and trial point of a window: no allocation once the per-thread buffer has grown.
  const int m = residual_dim();
  thread_local Eigen::VectorXd delta;
  delta.resize(J_.cols());
  for (std::size_t i = 0; i < manifolds_.size(); ++i)
    manifolds_[i].Minus(values[i], x0_[i].data(), delta.data() + offsets_[i]);
  Eigen::Map<Eigen::VectorXd> e(error, m);
  e.noalias() = J_ * delta;
  e += r0_;
  if (jacobians != nullptr) {
    // J times the block's d[-] / dx: the identity on Euclidean coordinates and a pose's translation, the inverse right
    // Jacobian of SO(3) on rotations.
    for (std::size_t i = 0; i < manifolds_.size(); ++i) {
      if (jacobians[i] == nullptr) continue;
      const int d = manifolds_[i].tangent_dim();
      Eigen::Map<Eigen::MatrixXd> J_i(jacobians[i], m, d);
      const int o = offsets_[i];
      if (manifolds_[i].kind() == ManifoldKind::kQuaternion) {
        J_i.noalias() = J_.middleCols<3>(o) * InverseRightJacobianSO3(delta.segment<3>(o));
      } else if (manifolds_[i].kind() == ManifoldKind::kPose) {
        J_i.leftCols<3>() = J_.middleCols<3>(o);
        J_i.rightCols<3>().noalias() = J_.middleCols<3>(o + 3) * InverseRightJacobianSO3(delta.segment<3>(o + 3));
      } else {
        J_i = J_.middleCols(o, d);
      }
    }
  }
  if (noise_jacobian != nullptr) Eigen::Map<Eigen::MatrixXd>(noise_jacobian, m, m).setIdentity();
  return error != nullptr && r0_.allFinite();
}

namespace {

// The variables of an elimination: the leaving ones (free) first, then the blanket (the other free variables that
// their active factors touch), each one's offset in [leaving, blanket] tangent coordinates, n coordinates in all of
// which nm leaving; and the factors on the leaving variables.
struct EliminationOrder {
  std::vector<FactorId> factors;  // sorted, once each
  std::vector<VariableId> order;
  std::size_t n_leaving = 0;
  std::vector<int> offset;
  int n = 0;
  int nm = 0;
};

EliminationOrder OrderForElimination(const std::vector<VariableId>& leaving, const Graph* graph) {
  // The factors on the leaving variables (sorted, once each), and the blanket: the other free variables they touch.
  // Small sets (a pose and its blanket of a few dozen coordinates): sorted or searched vectors, no node containers.
  std::vector<FactorId> factors;
  for (VariableId v : leaving)
    for (FactorId f : graph->FactorsOf(v)) factors.push_back(f);
  std::sort(factors.begin(), factors.end());
  factors.erase(std::unique(factors.begin(), factors.end()), factors.end());
  const auto leaves = [&](VariableId v) { return std::find(leaving.begin(), leaving.end(), v) != leaving.end(); };
  std::vector<VariableId> order;  // leaving first, then blanket
  for (VariableId v : leaving)
    if (!graph->variable(v).fixed) order.push_back(v);
  const std::size_t n_leaving = order.size();
  for (FactorId f : factors) {
    const FactorEntry& e = graph->factor(f);
    if (!e.active) continue;
    for (VariableId v : e.variables)
      if (!leaves(v) && !graph->variable(v).fixed && std::find(order.begin(), order.end(), v) == order.end())
        order.push_back(v);
  }
  std::vector<int> offset(order.size());
  int n = 0, nm = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    offset[i] = n;
    n += graph->variable(order[i]).manifold.tangent_dim();
    if (i + 1 == n_leaving) nm = n;
  }
  return {std::move(factors), std::move(order), n_leaving, std::move(offset), n, nm};
}

// Adds the active factors' J^T J and J^T r over [leaving, blanket] to H (the blocks on and above the diagonal) and g:
// the last solve's linearizations and kept products where they are current, else linearized here. False when a
// factor cannot be linearized.
bool AddFactorInformation(const EliminationOrder& elimination, const Graph* graph, const SolverWorkspace* last_solve,
                          Eigen::MatrixXd* H_out, Eigen::VectorXd* g_out) {
  Eigen::MatrixXd& H = *H_out;
  Eigen::VectorXd& g = *g_out;
  const std::vector<FactorId>& factors = elimination.factors;
  const std::vector<VariableId>& order = elimination.order;
  const std::vector<int>& offset = elimination.offset;
  std::vector<bool> want;
  std::vector<int> var_offset;
  internal::WhitenedFactor wf;  // reused: its buffers keep their size
  std::vector<int> product_offset;
  for (FactorId f : factors) {
    const FactorEntry& e = graph->factor(f);
    if (!e.active) continue;
    want.clear();
    var_offset.clear();
    std::uint64_t mask = 0;
    for (VariableId v : e.variables) {
      const auto it = std::find(order.begin(), order.end(), v);
      if (it != order.end()) mask |= std::uint64_t{1} << want.size();
      want.push_back(it != order.end());
      var_offset.push_back(it != order.end() ? offset[it - order.begin()] : -1);
    }
    const internal::WhitenedFactor* linearized = last_solve != nullptr ? last_solve->Linearization(f, mask) : nullptr;
    if (linearized == nullptr) {
      if (!internal::LinearizeFactor(*graph, e, want, &wf)) return false;
      linearized = &wf;
    }
    const internal::WhitenedFactor& lf = *linearized;
    // The solve's own products J_a^T J_b of these Jacobians when it kept them (relinearization threshold): the same
    // coefficient-wise sums as the products below, bit for bit, without computing them
    // again. Kept per pair of wanted positions i <= j (i outer); product_offset at i * nv + j.
    const std::vector<double>* products = linearized != &wf ? last_solve->Products(f, mask) : nullptr;
    const std::size_t nv = e.variables.size();
    if (products != nullptr) {
      product_offset.resize(nv * nv);
      for (std::size_t i = 0, size = 0; i < nv; ++i)
        for (std::size_t j = i; j < nv; ++j) {
          product_offset[i * nv + j] = static_cast<int>(size);
          if (want[i] && want[j]) size += lf.jacobians[i].cols() * lf.jacobians[j].cols();
        }
    }
    for (std::size_t a = 0; a < nv; ++a) {
      if (!want[a]) continue;
      const int oa = var_offset[a];
      // Coefficient-wise products, in this order: tracking under a calibration prior is sensitive to the rounding of
      // H here (a different summation order moves its positions by metres).
      g.segment(oa, lf.jacobians[a].cols()) += lf.jacobians[a].transpose().lazyProduct(lf.residual);
      for (std::size_t b = 0; b < nv; ++b) {
        if (!want[b] || var_offset[b] < oa) continue;  // the lower triangle is mirrored below
        const Eigen::Index ca = lf.jacobians[a].cols(), cb = lf.jacobians[b].cols();
        auto block = H.block(oa, var_offset[b], ca, cb);
        if (products == nullptr)
          block += lf.jacobians[a].transpose().lazyProduct(lf.jacobians[b]);
        else if (a <= b)
          block += Eigen::Map<const Eigen::MatrixXd>(products->data() + product_offset[a * nv + b], ca, cb);
        else
          block += Eigen::Map<const Eigen::MatrixXd>(products->data() + product_offset[b * nv + a], cb, ca).transpose();
      }
    }
  }
  return true;
}

// The Schur complement of H = [Hmm Hmb; Hbm Hbb] onto its trailing blanket coordinates (nm leaving ones first), and
// the matching gradient gb - Hbm Hmm^-1 gm.
void SchurComplementOntoBlanket(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, int nm, Eigen::MatrixXd* Hbb_out,
                                Eigen::VectorXd* gb_out) {
  const int n = static_cast<int>(H.rows());
  const int nb = n - nm;
  Eigen::MatrixXd Hbb = H.bottomRightCorner(nb, nb);
  Eigen::VectorXd gb = g.tail(nb);
  // Without a blanket (nb = 0) there is nothing to condition, and a solve on W's zero columns would offset a null
  // pointer.
  if (nm > 0 && nb > 0) {
    // Hmb^T Hmm^-1 Hmb = W^T W with W = L^-1 Hmb (Hmm + 1e-12 I = L L^T): half the arithmetic of solving for
    // Hmm^-1 Hmb and multiplying, in coefficient-wise products (a blanket of a few dozen coordinates, on which a
    // blocked product's packing costs more than the arithmetic). LDLT where the Cholesky factorization fails.
    const Eigen::MatrixXd Hmm = H.topLeftCorner(nm, nm) + 1e-12 * Eigen::MatrixXd::Identity(nm, nm);
    const Eigen::LLT<Eigen::MatrixXd> llt(Hmm);
    if (llt.info() == Eigen::Success) {
      Eigen::MatrixXd W = H.topRightCorner(nm, nb);
      llt.matrixL().solveInPlace(W);
      Eigen::VectorXd w = g.head(nm);
      llt.matrixL().solveInPlace(w);
      Hbb.noalias() -= W.transpose().lazyProduct(W);
      gb.noalias() -= W.transpose().lazyProduct(w);
    } else {
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(Hmm);
      const Eigen::MatrixXd Hmb = H.topRightCorner(nm, nb);
      Hbb -= Hmb.transpose() * ldlt.solve(Hmb);
      gb -= Hmb.transpose() * ldlt.solve(g.head(nm));
    }
  }
  *Hbb_out = std::move(Hbb);
  *gb_out = std::move(gb);
}

}  // namespace

bool Marginalize(const std::vector<VariableId>& leaving, Graph* graph, const SolverWorkspace* last_solve) {
  // The factors on the leaving variables and the blanket: the other free variables they touch.
  const EliminationOrder elimination = OrderForElimination(leaving, graph);
  const std::vector<FactorId>& factors = elimination.factors;
  const std::vector<VariableId>& order = elimination.order;
  const std::size_t n_leaving = elimination.n_leaving;
  const int n = elimination.n, nm = elimination.nm;

  // Dense H and g over [leaving, blanket].
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  if (!AddFactorInformation(elimination, graph, last_solve, &H, &g)) return false;
  H.triangularView<Eigen::StrictlyLower>() = H.transpose();

  // Schur complement onto the blanket, factored as J^T J (SquareRootInformation, dropping null directions).
  const int nb = n - nm;
  Eigen::MatrixXd Hbb;
  Eigen::VectorXd gb;
  SchurComplementOntoBlanket(H, g, nm, &Hbb, &gb);
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
  Eigen::MatrixXd J;
  Eigen::VectorXd r0;
  // The floor: the Schur complement is computed with an absolute error of about n eps max|H| (H over leaving and
  // blanket; the leaving pose's own information is often 1e2-1e3 times the blanket's), so its eigenvalues below that
  // are rounding, of either sign. Keeping such a direction (a floor of 1e-12 of the blanket's largest eigenvalue alone
  // lies within a few times that noise) turns rounding into information with a mean of noise / lambda, and which side
  // of the floor it falls on flips with the summation order. 1e-12 of the largest eigenvalue stays a lower bound.
  const Eigen::MatrixXd S = 0.5 * (Hbb + Hbb.transpose());
  const double floor =
      std::max(kRoundingFloor * n * std::numeric_limits<double>::epsilon() * std::max(H.diagonal().maxCoeff(), 0.0),
               1e-12 * std::max(S.diagonal().maxCoeff(), 0.0));
  if (!SquareRootInformation(S, gb, floor, &J, &r0)) return true;
  const int dim = static_cast<int>(J.rows());
  graph->AddFactor(std::make_unique<LinearPriorFactor>(manifolds, x0, J, r0), blanket,
                   Eigen::MatrixXd::Identity(dim, dim), Loss::Trivial(), "marginalization", Time());
  return true;
}

}  // namespace roamlab::estimator
