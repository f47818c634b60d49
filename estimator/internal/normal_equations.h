// Sparse normal equations H dx = -g of the whitened, loss-weighted least-squares problem over an ordered list of free
// variables (seed 000, eqs. 2-3). The block-sparse pattern of H (upper triangle, compressed columns) is built once
// per graph structure; each Linearize refills the values in place, and CHOLMOD's supernodal Cholesky (with its
// fill-reducing ordering) analyses the pattern once and refactors the values every iteration.
#pragma once

#include <memory>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "estimator/graph.h"
#include "estimator/internal/linearization.h"

namespace roamlab::estimator::internal {

class NormalEquations {
 public:
  // `order`: the free variables, in the order of their columns. Active factors that touch at least one of them are
  // included; the other variables they touch are held constant.
  NormalEquations(const Graph& graph, std::vector<VariableId> order);
  ~NormalEquations();

  // Evaluates every included factor at the graph's current values; fills H, g and the per-factor whitening.
  // Returns false if some factor could not be linearized (its stream is named in *failed_stream).
  bool Linearize(const Graph& graph, std::string* failed_stream = nullptr);

  // Cost at the graph's current values with the whitening of the last Linearize (so that a trial step is judged on
  // the same objective it was computed for).
  bool CostWithLastWhitening(const Graph& graph, double* cost) const;

  // Solves (H + lambda diag(H)) dx = -g. Returns false if the matrix is not positive definite.
  bool Solve(double lambda, Eigen::VectorXd* dx);

  // Marginal covariance of the listed free variables (their tangent blocks, in order) from H of the last Linearize:
  // solves H X = E for their columns, reusing the last factorization when it was undamped. Returns false when H is
  // not positive definite.
  bool Covariance(const std::vector<VariableId>& variables, Eigen::MatrixXd* covariance);

  // Applies x [+] dx to the free variables.
  void Update(const Eigen::VectorXd& dx, Graph* graph) const;

  int dimension() const { return dimension_; }
  double cost() const { return cost_; }
  const Eigen::VectorXd& gradient() const { return g_; }
  // Upper triangle of H.
  const Eigen::SparseMatrix<double>& hessian_upper() const { return H_; }
  const std::vector<VariableId>& order() const { return order_; }
  // Column offset of a free variable, or -1.
  int OffsetOf(VariableId id) const;
  const std::vector<FactorId>& factor_ids() const { return factor_ids_; }
  // The whitened factor of the last Linearize, by position in factor_ids().
  const WhitenedFactor& whitened(std::size_t i) const { return whitened_[i]; }

 private:
  struct FactorSlots {
    std::vector<int> var_offset;        // per connected variable: column offset, or -1 when held constant
    std::vector<std::ptrdiff_t> block;  // per pair (a <= b by offset) of free variables: value index of the block
  };

  void BuildPattern(const Graph& graph);

  std::vector<VariableId> order_;
  std::unordered_map<VariableId, int> offset_;
  std::vector<int> dims_;
  int dimension_ = 0;
  std::vector<FactorId> factor_ids_;
  std::vector<FactorSlots> slots_;
  std::vector<WhitenedFactor> whitened_;
  Eigen::SparseMatrix<double> H_;
  std::vector<std::ptrdiff_t> diagonal_index_;
  Eigen::VectorXd g_;
  double cost_ = 0.0;

  struct Cholmod;
  std::unique_ptr<Cholmod> cholmod_;
};

}  // namespace roamlab::estimator::internal
