#include "estimator/internal/normal_equations.h"

#include <algorithm>
#include <string>

#include <Eigen/CholmodSupport>

#include "common/check.h"

namespace roamlab::estimator::internal {

// H holds the block upper triangle with full diagonal blocks; CHOLMOD (stype = upper) reads only entries on and above
// the diagonal, and so does selfadjointView<Upper>().
struct NormalEquations::Cholmod {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Upper> llt;
  Eigen::SparseMatrix<double> damped;
  bool analyzed = false;
  bool factored_undamped = false;  // the factorization is of H itself, at the last linearization
};

NormalEquations::NormalEquations(const Graph& graph, std::vector<VariableId> order)
    : order_(std::move(order)), cholmod_(std::make_unique<Cholmod>()) {
  for (VariableId id : order_) {
    const Variable& v = graph.variable(id);
    ROAMLAB_CHECK(!v.fixed, "variable '" << v.name << "' is fixed but was ordered as free");
    ROAMLAB_CHECK(offset_.emplace(id, dimension_).second, "variable '" << v.name << "' ordered twice");
    dims_.push_back(v.manifold.tangent_dim());
    dimension_ += v.manifold.tangent_dim();
  }
  BuildPattern(graph);
  cholmod_->llt.cholmod().print = 0;
}

NormalEquations::~NormalEquations() = default;

int NormalEquations::OffsetOf(VariableId id) const {
  const auto it = offset_.find(id);
  return it == offset_.end() ? -1 : it->second;
}

void NormalEquations::BuildPattern(const Graph& graph) {
  // Position of each ordered variable, to find its block column.
  std::unordered_map<int, int> block_of_offset;
  std::vector<int> block_offset;
  for (std::size_t b = 0; b < order_.size(); ++b) {
    block_of_offset[offset_.at(order_[b])] = static_cast<int>(b);
    block_offset.push_back(offset_.at(order_[b]));
  }

  // Which row blocks appear in each block column (upper triangle, diagonal always present).
  const int nb = static_cast<int>(order_.size());
  std::vector<std::vector<int>> rows_of(nb);
  for (int b = 0; b < nb; ++b) rows_of[b].push_back(b);
  std::vector<std::vector<int>> factor_blocks;
  for (const auto& [fid, entry] : graph.factors()) {
    if (!entry.active) continue;
    std::vector<int> blocks;
    FactorSlots slots;
    for (VariableId v : entry.variables) {
      const int off = OffsetOf(v);
      slots.var_offset.push_back(off);
      if (off >= 0) blocks.push_back(block_of_offset.at(off));
    }
    if (blocks.empty()) continue;
    for (int a : blocks)
      for (int b : blocks)
        if (a < b) rows_of[b].push_back(a);
    factor_ids_.push_back(fid);
    slots_.push_back(std::move(slots));
    factor_blocks.push_back(std::move(blocks));
  }

  // Compressed columns: every scalar column of block column b holds the same row blocks.
  std::vector<std::unordered_map<int, int>> row_offset_in_column(nb);
  std::vector<int> column_length(nb, 0);
  std::ptrdiff_t nnz = 0;
  for (int b = 0; b < nb; ++b) {
    auto& rows = rows_of[b];
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    for (int r : rows) {
      row_offset_in_column[b][r] = column_length[b];
      column_length[b] += dims_[r];
    }
    nnz += static_cast<std::ptrdiff_t>(column_length[b]) * dims_[b];
  }
  H_.resize(dimension_, dimension_);
  H_.resizeNonZeros(nnz);
  int* outer = H_.outerIndexPtr();
  int* inner = H_.innerIndexPtr();
  std::ptrdiff_t pos = 0;
  for (int b = 0; b < nb; ++b) {
    for (int j = 0; j < dims_[b]; ++j) {
      outer[block_offset[b] + j] = static_cast<int>(pos);
      for (int r : rows_of[b])
        for (int i = 0; i < dims_[r]; ++i) inner[pos++] = block_offset[r] + i;
    }
  }
  outer[dimension_] = static_cast<int>(pos);
  std::fill(H_.valuePtr(), H_.valuePtr() + nnz, 0.0);

  // Value index of block (r, b): start of column block_offset[b] plus the row offset; later columns of the block are
  // found by adding j * column_length[b].
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    const auto& blocks = factor_blocks[k];
    for (std::size_t p = 0; p < blocks.size(); ++p) {
      for (std::size_t q = 0; q < blocks.size(); ++q) {
        const int r = blocks[p], b = blocks[q];
        if (r > b) continue;
        slots_[k].block.push_back(outer[block_offset[b]] + row_offset_in_column[b].at(r));
      }
    }
  }
  diagonal_index_.resize(dimension_);
  for (int b = 0; b < nb; ++b)
    for (int j = 0; j < dims_[b]; ++j)
      diagonal_index_[block_offset[b] + j] = outer[block_offset[b] + j] + row_offset_in_column[b].at(b) + j;
  whitened_.resize(factor_ids_.size());
  g_ = Eigen::VectorXd::Zero(dimension_);
}

bool NormalEquations::Linearize(const Graph& graph, std::string* failed_stream) {
  double* values = H_.valuePtr();
  std::fill(values, values + H_.nonZeros(), 0.0);
  g_.setZero();
  cost_ = 0.0;
  const int* outer = H_.outerIndexPtr();
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) {
    const FactorEntry& entry = graph.factor(factor_ids_[k]);
    const FactorSlots& slots = slots_[k];
    std::vector<bool> want(slots.var_offset.size());
    for (std::size_t i = 0; i < want.size(); ++i) want[i] = slots.var_offset[i] >= 0;
    WhitenedFactor& wf = whitened_[k];
    if (!LinearizeFactor(graph, entry, want, &wf)) {
      if (failed_stream != nullptr) *failed_stream = entry.stream;
      return false;
    }
    cost_ += wf.cost;

    // Accumulate J_a^T J_b into the (a <= b) blocks and J_a^T r into g.
    std::vector<int> free_vars;
    for (std::size_t i = 0; i < want.size(); ++i)
      if (want[i]) free_vars.push_back(static_cast<int>(i));
    std::size_t pair = 0;
    for (int va : free_vars) {
      g_.segment(slots.var_offset[va], wf.jacobians[va].cols()) += wf.jacobians[va].transpose() * wf.residual;
    }
    for (int va : free_vars) {
      for (int vb : free_vars) {
        if (slots.var_offset[va] > slots.var_offset[vb]) continue;
        // The block sits in H's value array with the column length of its block column as outer stride.
        const std::ptrdiff_t start = slots.block[pair++];
        const int col0 = slots.var_offset[vb];
        const std::ptrdiff_t stride = outer[col0 + 1] - outer[col0];
        Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> block(values + start, wf.jacobians[va].cols(),
                                                                   wf.jacobians[vb].cols(), Eigen::OuterStride<>(stride));
        block.noalias() += wf.jacobians[va].transpose() * wf.jacobians[vb];
      }
    }
  }
  return true;
}

bool NormalEquations::CostWithLastWhitening(const Graph& graph, double* cost) const {
  *cost = 0.0;
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) {
    double c = 0.0;
    if (!FactorCost(graph, graph.factor(factor_ids_[k]), whitened_[k].sqrt_covariance, &c)) return false;
    *cost += c;
  }
  return true;
}

bool NormalEquations::Solve(double lambda, Eigen::VectorXd* dx) {
  Cholmod& c = *cholmod_;
  c.damped = H_;
  if (lambda > 0.0) {
    double* v = c.damped.valuePtr();
    for (int i = 0; i < dimension_; ++i) v[diagonal_index_[i]] += lambda * std::max(v[diagonal_index_[i]], 1e-12);
  }
  if (!c.analyzed) {
    c.llt.analyzePattern(c.damped);
    c.analyzed = true;
  }
  c.llt.factorize(c.damped);
  c.factored_undamped = lambda <= 0.0 && c.llt.info() == Eigen::Success;
  if (c.llt.info() != Eigen::Success) return false;
  *dx = c.llt.solve(-g_);
  return c.llt.info() == Eigen::Success && dx->allFinite();
}

bool NormalEquations::Covariance(const std::vector<VariableId>& variables, Eigen::MatrixXd* covariance) {
  Cholmod& c = *cholmod_;
  if (!c.factored_undamped) {
    Eigen::VectorXd unused;
    if (!Solve(0.0, &unused)) return false;
  }
  int cols = 0;
  for (VariableId id : variables) cols += dims_[std::find(order_.begin(), order_.end(), id) - order_.begin()];
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(dimension_, cols);
  std::vector<int> rows;
  int col = 0;
  for (VariableId id : variables) {
    const int off = OffsetOf(id);
    ROAMLAB_CHECK(off >= 0, "covariance of variable " << id << ", which is not free in this system");
    const int dim = dims_[std::find(order_.begin(), order_.end(), id) - order_.begin()];
    for (int k = 0; k < dim; ++k) {
      E(off + k, col++) = 1.0;
      rows.push_back(off + k);
    }
  }
  const Eigen::MatrixXd X = c.llt.solve(E);
  if (c.llt.info() != Eigen::Success || !X.allFinite()) return false;
  covariance->resize(cols, cols);
  for (int i = 0; i < cols; ++i) covariance->row(i) = X.row(rows[i]);
  return true;
}

void NormalEquations::Update(const Eigen::VectorXd& dx, Graph* graph) const {
  for (std::size_t b = 0; b < order_.size(); ++b) {
    Variable& v = graph->mutable_variable(order_[b]);
    const int off = offset_.at(order_[b]);
    v.manifold.Plus(v.value.data(), dx.data() + off, v.value.data());
  }
}

}  // namespace roamlab::estimator::internal
