#include "estimator/internal/normal_equations.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>

#include <Eigen/CholmodSupport>

#include "common/check.h"

namespace roamlab::estimator::internal {

namespace {

// Systems up to this dimension (a tracking window) are factored in their envelope when in natural order (Reset),
// otherwise by CHOLMOD's simplicial LLT; larger ones (whole recordings) in their envelope when it is narrow, otherwise
// by CHOLMOD's supernodal LLT, whose dense BLAS kernels pay off only on large supernodes.
constexpr int kMaxSimplicialDimension = 2000;

// A large system in natural order is factored in its envelope when the envelope has at most this many times the
// entries of H's upper triangle (NormalEquations::EnvelopeIsNarrow).
constexpr std::size_t kMaxEnvelopeOverPattern = 2;

// Widest dense border of a natural-order system (NormalEquations::FactorEnvelope); columns beyond it stay in the
// envelope.
constexpr int kMaxBorder = 128;

// Up to this many columns, a natural-order system's covariance is Y^T Y from the forward substitution alone (the
// product costs columns^2 x dimension, a back substitution columns x the factor's size).
constexpr int kMaxForwardCovarianceColumns = 16;

// Block patterns of H kept for a small system whose pattern comes back as it slides (NormalEquations::BuildPattern):
// a window's instances of a parameter per 0.1 s repeat every ten poses.
constexpr std::size_t kPatternCache = 16;

// How far a pass over a whole recording's factors or variables prefetches ahead: their data lie in heap blocks of their
// own, whose addresses the hardware's prefetcher cannot follow.
constexpr std::size_t kPrefetchAhead = 8;  // factors or variables

// dst (A x B block of H's value array, column stride `stride`) += Ja^T Jb, Ja M x A, Jb M x B.
template <int M, int A, int B>
void AddProductFixed(const double* ja, const double* jb, double* dst, std::ptrdiff_t stride) {
  Eigen::Map<Eigen::Matrix<double, A, B>, 0, Eigen::OuterStride<>> block(dst, A, B, Eigen::OuterStride<>(stride));
  block.noalias() += Eigen::Map<const Eigen::Matrix<double, M, A>>(ja).transpose() *
                     Eigen::Map<const Eigen::Matrix<double, M, B>>(jb);
}

// The same with the column counts as template arguments when they are among the block sizes of the error models
// (1: scalar, 3: vector or rotation, 6: pose, 9: 3x3 matrix); false for other sizes.
template <int M, int A>
bool AddProductColumns(const double* ja, const double* jb, int b, double* dst, std::ptrdiff_t stride) {
  switch (b) {
    case 1: AddProductFixed<M, A, 1>(ja, jb, dst, stride); return true;
    case 3: AddProductFixed<M, A, 3>(ja, jb, dst, stride); return true;
    case 6: AddProductFixed<M, A, 6>(ja, jb, dst, stride); return true;
    case 9: AddProductFixed<M, A, 9>(ja, jb, dst, stride); return true;
    default: return false;
  }
}
template <int M>
bool AddProductRows(const double* ja, int a, const double* jb, int b, double* dst, std::ptrdiff_t stride) {
  switch (a) {
    case 1: return AddProductColumns<M, 1>(ja, jb, b, dst, stride);
    case 3: return AddProductColumns<M, 3>(ja, jb, b, dst, stride);
    case 6: return AddProductColumns<M, 6>(ja, jb, b, dst, stride);
    case 9: return AddProductColumns<M, 9>(ja, jb, b, dst, stride);
    default: return false;
  }
}

void AddProduct(const Eigen::MatrixXd& ja, const Eigen::MatrixXd& jb, double* dst, std::ptrdiff_t stride) {
  const int a = static_cast<int>(ja.cols()), b = static_cast<int>(jb.cols());
  if (ja.rows() == 3 && AddProductRows<3>(ja.data(), a, jb.data(), b, dst, stride)) return;
  if (ja.rows() == 4 && AddProductRows<4>(ja.data(), a, jb.data(), b, dst, stride)) return;
  if (ja.rows() == 6 && AddProductRows<6>(ja.data(), a, jb.data(), b, dst, stride)) return;
  // Coefficient-wise: at these sizes (a few rows, up to a few dozen columns) cheaper than a blocked product.
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> block(dst, ja.cols(), jb.cols(), Eigen::OuterStride<>(stride));
  block.noalias() += ja.transpose().lazyProduct(jb);
}

// dst (rows x cols block of H's value array, column stride `stride`) += src (rows x cols, column-major), or += src^T
// (src cols x rows) when `transposed`.
template <int A, int B>
void AddBlockFixed(const double* src, bool transposed, double* dst, std::ptrdiff_t stride) {
  Eigen::Map<Eigen::Matrix<double, A, B>, 0, Eigen::OuterStride<>> block(dst, A, B, Eigen::OuterStride<>(stride));
  if (transposed)
    block += Eigen::Map<const Eigen::Matrix<double, B, A>>(src).transpose();
  else
    block += Eigen::Map<const Eigen::Matrix<double, A, B>>(src);
}
template <int A>
bool AddBlockColumns(const double* src, int cols, bool transposed, double* dst, std::ptrdiff_t stride) {
  switch (cols) {
    case 1: AddBlockFixed<A, 1>(src, transposed, dst, stride); return true;
    case 3: AddBlockFixed<A, 3>(src, transposed, dst, stride); return true;
    case 6: AddBlockFixed<A, 6>(src, transposed, dst, stride); return true;
    case 9: AddBlockFixed<A, 9>(src, transposed, dst, stride); return true;
    default: return false;
  }
}
void AddBlock(const double* src, int rows, int cols, bool transposed, double* dst, std::ptrdiff_t stride) {
  bool done = false;
  switch (rows) {
    case 1: done = AddBlockColumns<1>(src, cols, transposed, dst, stride); break;
    case 3: done = AddBlockColumns<3>(src, cols, transposed, dst, stride); break;
    case 6: done = AddBlockColumns<6>(src, cols, transposed, dst, stride); break;
    case 9: done = AddBlockColumns<9>(src, cols, transposed, dst, stride); break;
    default: break;
  }
  if (done) return;
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> block(dst, rows, cols, Eigen::OuterStride<>(stride));
  if (transposed)
    block += Eigen::Map<const Eigen::MatrixXd>(src, cols, rows).transpose();
  else
    block += Eigen::Map<const Eigen::MatrixXd>(src, rows, cols);
}

// Calls f(std::integral_constant<int, M>(), std::integral_constant<int, A>()) for a J of M = 3 or 4 rows (the IMU's,
// magnetometer's, GPS's and Ackermann velocity's errors) and A = 1, 3, 6 or 9 columns (the models' block sizes), whose
// fixed-size kernels cost less than a general product's set-up; false for other shapes.
template <int M, typename Function>
bool WithColumns(int a, Function f) {
  switch (a) {
    case 1: f(std::integral_constant<int, M>(), std::integral_constant<int, 1>()); return true;
    case 3: f(std::integral_constant<int, M>(), std::integral_constant<int, 3>()); return true;
    case 6: f(std::integral_constant<int, M>(), std::integral_constant<int, 6>()); return true;
    case 9: f(std::integral_constant<int, M>(), std::integral_constant<int, 9>()); return true;
    default: return false;
  }
}
template <typename Function>
bool WithFixedShape(const Eigen::MatrixXd& j, Function f) {
  const int a = static_cast<int>(j.cols());
  return (j.rows() == 3 && WithColumns<3>(a, f)) || (j.rows() == 4 && WithColumns<4>(a, f));
}

// r += J d (d: J.cols() entries).
void AddJacobianTimes(const Eigen::MatrixXd& j, const double* d, Eigen::VectorXd* r) {
  const bool fixed = WithFixedShape(j, [&](auto m, auto a) {
    constexpr int M = decltype(m)::value, A = decltype(a)::value;
    Eigen::Map<Eigen::Matrix<double, M, 1>>(r->data()).noalias() +=
        Eigen::Map<const Eigen::Matrix<double, M, A>>(j.data()) * Eigen::Map<const Eigen::Matrix<double, A, 1>>(d);
  });
  if (!fixed) r->noalias() += j * Eigen::Map<const Eigen::VectorXd>(d, j.cols());
}

// g_segment += J^T r.
void AddGradient(const Eigen::MatrixXd& j, const Eigen::VectorXd& r, double* g) {
  const bool fixed = WithFixedShape(j, [&](auto m, auto a) {
    constexpr int M = decltype(m)::value, A = decltype(a)::value;
    Eigen::Map<Eigen::Matrix<double, A, 1>>(g).noalias() +=
        Eigen::Map<const Eigen::Matrix<double, M, A>>(j.data()).transpose() *
        Eigen::Map<const Eigen::Matrix<double, M, 1>>(r.data());
  });
  if (!fixed) Eigen::Map<Eigen::VectorXd>(g, j.cols()).noalias() += j.transpose() * r;
}

// The positions i < n with block[i] >= 0 (a factor's free variables), in order, into free; returns their count. The
// normal equations visit a factor's (a, b) pairs of free variables in this order, a outer, b inner.
int FreePositions(const int* block, int n, int* free) {
  int count = 0;
  for (int i = 0; i < n; ++i)
    if (block[i] >= 0) free[count++] = i;
  return count;
}

}  // namespace

// H holds the block upper triangle with full diagonal blocks; CHOLMOD (stype = upper) reads only entries on and above
// the diagonal, and so does selfadjointView<Upper>().
struct NormalEquations::Cholmod {
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Upper> llt;
  Eigen::SparseMatrix<double> damped;
  bool analyzed = false;
  bool factored_undamped = false;  // the factorization is of H itself, at the last linearization
};

NormalEquations::NormalEquations() : cholmod_(std::make_unique<Cholmod>()) { cholmod_->llt.cholmod().print = 0; }

NormalEquations::NormalEquations(const Graph& graph, std::vector<VariableId> order) : NormalEquations() {
  Reset(graph, std::move(order));
}

NormalEquations::~NormalEquations() = default;

int NormalEquations::BlockOf(VariableId id) const {
  const auto it = std::lower_bound(block_of_id_.begin(), block_of_id_.end(), std::make_pair(id, -1));
  return it != block_of_id_.end() && it->first == id ? it->second : -1;
}

int NormalEquations::OffsetOf(VariableId id) const {
  const int b = BlockOf(id);
  return b < 0 ? -1 : block_offset_[b];
}

void NormalEquations::Reset(const Graph& graph, std::vector<VariableId> order) {
  // The tables of the last Reset, kept for the factors still in the graph (below).
  prev_order_.swap(order_);
  prev_factor_ids_.swap(factor_ids_);
  prev_entries_.swap(entries_);
  prev_var_begin_.swap(var_begin_);
  prev_want_.swap(want_);
  prev_var_id_.swap(var_id_);
  prev_var_block_.swap(var_block_);
  prev_values_.swap(values_);

  // Blocks of the free variables.
  order_ = std::move(order);
  const int nb = static_cast<int>(order_.size());
  block_of_id_.clear();
  dims_.clear();
  block_offset_.clear();
  full_column_.assign(nb, 0);
  dimension_ = 0;
  bool stamped_first = true;  // every time-stamped variable comes before the constant ones (natural order, below)
  bool constants_seen = false;
  for (int b = 0; b < nb; ++b) {
    const Variable& v = graph.variable(order_[b]);
    ROAMLAB_CHECK(!v.fixed, "variable '" << v.name << "' is fixed but was ordered as free");
    full_column_[b] = !v.stamp.has_value();
    if (v.stamp.has_value())
      stamped_first &= !constants_seen;
    else
      constants_seen = true;
    block_of_id_.emplace_back(order_[b], b);
    dims_.push_back(v.manifold.tangent_dim());
    block_offset_.push_back(dimension_);
    dimension_ += v.manifold.tangent_dim();
  }
  std::sort(block_of_id_.begin(), block_of_id_.end());
  for (std::size_t i = 1; i < block_of_id_.size(); ++i)
    ROAMLAB_CHECK(block_of_id_[i].first != block_of_id_[i - 1].first, "variable " << block_of_id_[i].first
                                                                                  << " ordered twice");

  // Every variable's value and block (-1 when held constant), by id: one pass over the graph's variables instead of
  // a graph look-up per factor and variable below.
  prev_variable_table_.swap(variable_table_);
  variable_table_.clear();
  auto free_it = block_of_id_.begin();
  for (const auto& [id, v] : graph.variables()) {
    while (free_it != block_of_id_.end() && free_it->first < id) ++free_it;
    const int block = free_it != block_of_id_.end() && free_it->first == id ? free_it->second : -1;
    variable_table_.push_back({id, v.value.data(), block});
  }
  // (The graph numbers its variables in order: without removals in between, id - the first id is the place.)
  const VariableId first_id = variable_table_.empty() ? 0 : variable_table_.front().id;
  const auto lookup = [this, first_id](VariableId id) -> const VariableSlot& {
    const VariableId place = id - first_id;
    if (place >= 0 && place < static_cast<VariableId>(variable_table_.size()) && variable_table_[place].id == id)
      return variable_table_[place];
    const auto it = std::lower_bound(variable_table_.begin(), variable_table_.end(), id,
                                     [](const VariableSlot& slot, VariableId key) { return slot.id < key; });
    ROAMLAB_CHECK(it != variable_table_.end() && it->id == id, "no variable " << id);
    return *it;
  };

  // Incremental (a window that slid: factors and variables left at the front, new ones came at the back): every
  // variable that was in the graph at the last Reset and still is keeps its value buffer, and none that was held
  // constant then is free now. A factor of the last Reset with the same id, entry and variables then keeps its
  // variables' values and its blocks, renumbered by old_to_new_; only the other factors (new ones, or ones gating
  // switched on again) look their variables up. The result is the same as from scratch.
  bool incremental = !prev_factor_ids_.empty();
  for (std::size_t i = 0, j = 0; incremental && i < prev_variable_table_.size() && j < variable_table_.size();) {
    const VariableSlot& before = prev_variable_table_[i];
    const VariableSlot& now = variable_table_[j];
    if (before.id < now.id) {
      ++i;
    } else if (now.id < before.id) {
      ++j;
    } else {
      incremental = before.value == now.value && (before.block >= 0 || now.block < 0);
      ++i;
      ++j;
    }
  }
  if (!incremental || relinearize_threshold_ <= 0.0) {
    factor_kept_ = false;
    dirty_.clear();
  }
  if (incremental) {
    ++incremental_resets_;
    old_to_new_.resize(prev_order_.size());
    for (std::size_t b = 0; b < prev_order_.size(); ++b) old_to_new_[b] = BlockOf(prev_order_[b]);
  }

  // The included factors, their variables' blocks and values, and which row blocks appear in each block column
  // (upper triangle, diagonal always present).
  factor_ids_.clear();
  entries_.clear();
  want_.clear();
  kept_from_.clear();
  var_begin_.assign(1, 0);
  var_id_.clear();
  var_block_.clear();
  values_.clear();
  // In a system in natural order the block column of a constant parameter holds every row block (below); only the
  // others collect their rows from the factors.
  if (!stamped_first) std::fill(full_column_.begin(), full_column_.end(), 0);
  rows_of_.resize(nb);
  for (int b = 0; b < nb; ++b) rows_of_[b].assign(1, b);
  std::size_t prev = 0;  // next factor of the last Reset to compare with (both lists in id order)
  // (Each factor's variable list is a heap block of its own: prefetched kPrefetchAhead factors ahead.)
  auto ahead = graph.factors().begin();
  for (std::size_t i = 0; i < kPrefetchAhead && ahead != graph.factors().end(); ++i) ++ahead;
  for (const auto& [fid, entry] : graph.factors()) {
    if (ahead != graph.factors().end()) {
      __builtin_prefetch(ahead->second.variables.data());
      ++ahead;
    }
    if (!entry.active) continue;
    ROAMLAB_CHECK(entry.variables.size() <= 64, "factor from '" << entry.stream << "' has over 64 variables");
    const std::size_t begin = var_block_.size();
    std::uint64_t mask = 0;
    while (incremental && prev < prev_factor_ids_.size() && prev_factor_ids_[prev] < fid) ++prev;
    const bool kept = incremental && prev < prev_factor_ids_.size() && prev_factor_ids_[prev] == fid &&
                      prev_entries_[prev] == &entry &&
                      prev_var_begin_[prev + 1] - prev_var_begin_[prev] == static_cast<int>(entry.variables.size()) &&
                      std::equal(entry.variables.begin(), entry.variables.end(),
                                 prev_var_id_.begin() + prev_var_begin_[prev]);
    for (std::size_t i = 0; i < entry.variables.size(); ++i) {
      int b = -1;
      if (kept) {
        const int p = prev_var_begin_[prev] + static_cast<int>(i);
        b = prev_var_block_[p] >= 0 ? old_to_new_[prev_var_block_[p]] : -1;
        values_.push_back(prev_values_[p]);
      } else {
        const VariableSlot& slot = lookup(entry.variables[i]);
        b = slot.block;
        values_.push_back(slot.value);
      }
      var_id_.push_back(entry.variables[i]);
      var_block_.push_back(b);
      if (b >= 0) mask |= std::uint64_t{1} << i;
    }
    if (mask == 0) {
      var_id_.resize(begin);
      var_block_.resize(begin);
      values_.resize(begin);
      continue;
    }
    // (A row block that its column received last, as from the factors before on the same pair, is not repeated.)
    for (std::size_t j = begin; j < var_block_.size(); ++j) {
      const int column = var_block_[j];
      if (column < 0 || full_column_[column]) continue;
      std::vector<int>& rows = rows_of_[column];
      for (std::size_t i = begin; i < var_block_.size(); ++i) {
        if (var_block_[i] < 0 || var_block_[i] >= column) continue;
        if (rows.back() != var_block_[i]) rows.push_back(var_block_[i]);
      }
    }
    factor_ids_.push_back(fid);
    entries_.push_back(&entry);
    want_.push_back(mask);
    // (BuildPattern copies the pairs of a factor kept with the same free variables.)
    kept_from_.push_back(kept && prev_want_[prev] == mask ? static_cast<int>(prev) : -1);
    var_begin_.push_back(static_cast<int>(var_block_.size()));
  }
  // In a small system (a tracking window), the block column of a free constant parameter (no time stamp) holds every
  // row block before it, coupled or not: its rows of the Cholesky factor fill in anyway once the band before it is
  // eliminated, and the pattern no longer depends on which poses happen to carry, say, a GPS fix, so it repeats when
  // the window slides and the symbolic analysis is kept.
  //
  // Such a window (poses in time order, then constant parameters) is a band with a dense border: eliminated in its
  // own order it has no fill outside each column's envelope (its rows from the first coupled one to the diagonal), so
  // it is factored there directly, densely per column (FactorEnvelope), which spares CHOLMOD's row-by-row sparse
  // triangular solves on so small a system. Time-varying parameters' instances sit in that order after the last pose
  // they serve (FreeVariableOrder) and only widen the band: an instance shared by the poses of an interval
  // (process.interval_s) has a tall column (those poses), the poses' columns stay short.
  //
  // A large system (a whole recording) in that order is factored in its envelope too when the envelope holds little
  // more than H's own pattern (poses coupled to their neighbours in time only): its cost is then linear in the drive's
  // length, where CHOLMOD's supernodal factorization spends much of its time permuting and transposing H's pattern.
  // Factors that tie poses far apart in time (an envelope many times the pattern) leave it to CHOLMOD.
  const bool natural_before = natural_order_;
  for (int b = 0; b < nb; ++b) {
    if (!full_column_[b]) continue;
    rows_of_[b].resize(b + 1);
    for (int r = 0; r <= b; ++r) rows_of_[b][r] = r;
  }
  BuildPattern();
  natural_order_ = stamped_first && (dimension_ <= kMaxSimplicialDimension || EnvelopeIsNarrow());
  if (natural_order_ != natural_before) cholmod_->analyzed = false;

  // The per-factor linearizations follow their factors (by id). Without keeping them (and without a threshold) they
  // stay where they are: Linearize writes every factor's anew, and a record left at another factor's place is not
  // current for it (Current compares the factor's id).
  if (keep_linearizations_ || relinearize_threshold_ > 0.0) {
    MoveLinearizationsWithTheirFactors();
  } else {
    linearized_.resize(factor_ids_.size());
  }
  g_.setZero(dimension_);
  minus_memo_.assign(nb, MinusMemo());
  cholmod_->factored_undamped = false;
  left_out_blocks_ = 0;
  undamped_step_ = false;
}

void NormalEquations::ForgetLinearizations() {
  for (FactorLinearization& l : linearized_) l.id = -1;
}

void NormalEquations::MoveLinearizationsWithTheirFactors() {
  // A new factor takes the buffers of one that left, in order: a window that slid drops its oldest factors and gains
  // new ones of the same kinds, so a factor's buffers mostly have its own sizes already (no reallocation).
  prev_linearized_.swap(linearized_);
  prev_linearized_.resize(prev_factor_ids_.size());
  linearized_.resize(factor_ids_.size());
  std::vector<bool>& taken = taken_scratch_;
  taken.assign(prev_linearized_.size(), false);
  std::vector<std::size_t>& fresh = fresh_scratch_;
  fresh.clear();
  for (std::size_t k = 0, p = 0; k < factor_ids_.size(); ++k) {
    while (p < prev_factor_ids_.size() && prev_factor_ids_[p] < factor_ids_[k]) ++p;
    if (p < prev_factor_ids_.size() && prev_factor_ids_[p] == factor_ids_[k]) {
      swap(linearized_[k], prev_linearized_[p]);
      taken[p] = true;
    } else {
      fresh.push_back(k);
    }
  }
  // A factor that left while all its variables stayed (gated off) changed H where they are free.
  if (factor_kept_) {
    for (std::size_t p = 0; p < prev_factor_ids_.size(); ++p) {
      if (taken[p]) continue;
      bool stayed = true;
      for (int v = prev_var_begin_[p]; v < prev_var_begin_[p + 1] && stayed; ++v) {
        const auto it = std::lower_bound(variable_table_.begin(), variable_table_.end(), prev_var_id_[v],
                                         [](const VariableSlot& slot, VariableId key) { return slot.id < key; });
        stayed = it != variable_table_.end() && it->id == prev_var_id_[v];
      }
      for (int v = prev_var_begin_[p]; v < prev_var_begin_[p + 1] && stayed; ++v)
        if (prev_var_block_[v] >= 0) dirty_.push_back(prev_var_id_[v]);
    }
  }
  for (std::size_t p = 0, i = 0; p < prev_linearized_.size() && i < fresh.size(); ++p)
    if (!taken[p]) swap(linearized_[fresh[i++]], prev_linearized_[p]);
  for (std::size_t k : fresh) linearized_[k].id = -1;
}

bool NormalEquations::EnvelopeIsNarrow() const {
  // Entries of the blocks' envelopes (rows_of_ sorted by BuildPattern) against those of H's upper triangle.
  std::size_t pattern = 0, envelope = 0;
  for (std::size_t b = 0; b < order_.size(); ++b) {
    pattern += static_cast<std::size_t>(column_length_[b]) * dims_[b];
    envelope += static_cast<std::size_t>(block_offset_[b] + dims_[b] - block_offset_[rows_of_[b].front()]) * dims_[b];
  }
  return envelope <= kMaxEnvelopeOverPattern * pattern;
}

void NormalEquations::BuildPattern() {
  // Compressed columns: every scalar column of block column b holds the same row blocks.
  const int nb = static_cast<int>(order_.size());
  column_length_.assign(nb, 0);
  row_offset_.resize(nb);
  for (int b = 0; b < nb; ++b) {
    auto& rows = rows_of_[b];
    if (!std::is_sorted(rows.begin(), rows.end())) std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    row_offset_[b].clear();
    for (int r : rows) {
      row_offset_[b].push_back(column_length_[b]);
      column_length_[b] += dims_[r];
    }
  }
  // The same block pattern as at the last call (a window that slid by one pose) keeps H's pattern. A window's
  // pattern also changes as it slides (where a time-varying parameter's instance sits in the band) and comes back
  // with that period: the last few patterns of a small system are kept with their H, and one that comes back is
  // swapped in instead of built again (the same arrays as a new build).
  const bool same_blocks = H_.rows() == dimension_ && pattern_dims_ == dims_ && pattern_rows_of_ == rows_of_;
  const auto cached = same_blocks ? pattern_cache_.end()
                                  : std::find_if(pattern_cache_.begin(), pattern_cache_.end(), [&](const auto& c) {
                                      return c.dims == dims_ && c.rows_of == rows_of_;
                                    });
  if (cached != pattern_cache_.end()) {
    // The cache entry takes the current pattern in exchange.
    H_.swap(cached->H);
    pattern_dims_.swap(cached->dims);
    pattern_rows_of_.swap(cached->rows_of);
    cholmod_->analyzed = false;
  } else if (!same_blocks) {
    // Sized once, each block column's first scalar column written and copied to the others.
    std::size_t nonzeros = 0;
    for (int b = 0; b < nb; ++b) nonzeros += static_cast<std::size_t>(column_length_[b]) * dims_[b];
    outer_.resize(dimension_ + 1);
    inner_.resize(nonzeros);
    int* out = inner_.data();
    for (int b = 0; b < nb; ++b) {
      const int* first = out;
      for (int r : rows_of_[b])
        for (int i = 0; i < dims_[r]; ++i) *out++ = block_offset_[r] + i;
      outer_[block_offset_[b]] = static_cast<int>(first - inner_.data());
      for (int j = 1; j < dims_[b]; ++j) {
        outer_[block_offset_[b] + j] = static_cast<int>(out - inner_.data());
        out = std::copy(first, first + column_length_[b], out);
      }
    }
    outer_[dimension_] = static_cast<int>(out - inner_.data());

    // A new pattern needs a new symbolic analysis; the same one keeps it.
    const bool same = H_.rows() == dimension_ && H_.nonZeros() == static_cast<Eigen::Index>(inner_.size()) &&
                      std::equal(outer_.begin(), outer_.end(), H_.outerIndexPtr()) &&
                      std::equal(inner_.begin(), inner_.end(), H_.innerIndexPtr());
    if (!same) {
      if (dimension_ <= kMaxSimplicialDimension && H_.rows() > 0) {
        // The current pattern goes to the cache (in the place of the oldest entry once it is full).
        if (pattern_cache_.size() < kPatternCache) {
          pattern_cache_.push_back({});
        } else {
          std::rotate(pattern_cache_.begin(), pattern_cache_.begin() + 1, pattern_cache_.end());
        }
        PatternCacheEntry& entry = pattern_cache_.back();
        entry.H.swap(H_);
        entry.dims.swap(pattern_dims_);
        entry.rows_of.swap(pattern_rows_of_);
      }
      H_.resize(dimension_, dimension_);
      H_.resizeNonZeros(static_cast<Eigen::Index>(inner_.size()));
      std::copy(outer_.begin(), outer_.end(), H_.outerIndexPtr());
      std::copy(inner_.begin(), inner_.end(), H_.innerIndexPtr());
      cholmod_->analyzed = false;
      ++patterns_built_;
    }
    pattern_dims_ = dims_;
    pattern_rows_of_ = rows_of_;
  }

  // Value index of block (r, b): start of column block_offset[b] plus the row offset of r in that column; later
  // columns of the block are found by adding j * column_length[b].
  // A column whose row blocks are consecutive (a constant parameter's in natural order: all up to the diagonal; most
  // of a band's) has block r at the scalar row offset block_offset[r] - block_offset[rows.front()] within it: per
  // column one flat base, read without chasing rows_of_'s vectors; -1 marks the others, which search their rows. (A
  // base is never negative: the entries before column block_offset[b] number at least block_offset[b].)
  const int* outer = H_.outerIndexPtr();
  column_base_.resize(nb);
  for (int b = 0; b < nb; ++b) {
    const auto& rows = rows_of_[b];
    column_base_[b] = rows.back() - rows.front() + 1 == static_cast<int>(rows.size())
                          ? static_cast<std::ptrdiff_t>(outer[block_offset_[b]]) - block_offset_[rows.front()]
                          : -1;
  }
  diagonal_index_.resize(dimension_);
  for (int b = 0; b < nb; ++b) {
    const std::ptrdiff_t diagonal = ValueIndex(b, b);
    for (int j = 0; j < dims_[b]; ++j)
      diagonal_index_[block_offset_[b] + j] = diagonal + static_cast<std::ptrdiff_t>(j) * column_length_[b] + j;
  }
  // Each factor's pairs of H blocks (BuildPairs) serve the kept products of a relinearization threshold. Without
  // one, Linearize finds each block as it sums the factor's products into H, and a whole recording's pairs (250 MB
  // for 30 min) are neither built nor streamed through at every linearization. A small system (a window that slides)
  // keeps its pairs for the next Reset to copy; a large one builds them in place.
  if (!pairs_built_) {  // (the last Reset's were not built: none to take over)
    pairs_.clear();
    pair_begin_.clear();
  }
  if (dimension_ <= kMaxSimplicialDimension) {
    prev_pairs_.swap(pairs_);
    prev_pair_begin_.swap(pair_begin_);
  } else {
    std::vector<PairSlot>().swap(prev_pairs_);
    prev_pair_begin_.clear();
  }
  pairs_built_ = false;
  if (relinearize_threshold_ > 0.0) {
    BuildPairs();
  } else if (dimension_ > kMaxSimplicialDimension) {
    std::vector<PairSlot>().swap(pairs_);
    pair_begin_.clear();
  }
}

void NormalEquations::BuildPairs() {
  // Counted first (a pair of free positions i <= j gives one slot, two when i < j take the same variable), then
  // written in place: a PairSlot assembled on the stack and copied in stalls on the store forwarding of its
  // mixed-width fields. (The pairs i < j on one block, counted by the block's earlier occurrences in the factor: a
  // stamp per block. A factor kept from the last Reset has as many as then.)
  const int nb = static_cast<int>(order_.size());
  // The last Reset's factor whose pairs factor k takes, or -1.
  const auto from = [&](std::size_t k) {
    return kept_from_[k] >= 0 && kept_from_[k] + 1 < static_cast<int>(prev_pair_begin_.size()) ? kept_from_[k] : -1;
  };
  int free[64];
  std::size_t pair_count = 0;
  block_stamp_.assign(nb, -1);
  block_count_.resize(nb);
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) {
    if (from(k) >= 0) {
      pair_count += prev_pair_begin_[from(k) + 1] - prev_pair_begin_[from(k)];
      continue;
    }
    const int* block = &var_block_[var_begin_[k]];
    const int nf = FreePositions(block, var_begin_[k + 1] - var_begin_[k], free);
    pair_count += static_cast<std::size_t>(nf) * (nf + 1) / 2;
    for (int i = 0; i < nf; ++i) {
      const int b = block[free[i]];
      if (block_stamp_[b] == static_cast<int>(k)) {
        pair_count += block_count_[b]++;
      } else {
        block_stamp_[b] = static_cast<int>(k);
        block_count_[b] = 1;
      }
    }
  }
  pairs_.resize(pair_count);
  pair_begin_.assign(1, 0);
  PairSlot* pair = pairs_.data();
  const auto add_pair = [&pair](std::ptrdiff_t value, int row, int column, int a, int b, int product,
                                bool transposed) {
    pair->value = value;
    pair->row = row;
    pair->column = column;
    pair->a = a;
    pair->b = b;
    pair->product = product;
    pair->transposed = transposed;
    ++pair;
  };
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) {
    // A factor kept from the last Reset with the same free variables: its pairs are the last ones with their blocks
    // renumbered (the same positions, products and transposition while the renumbering keeps its blocks' order, as a
    // window's slide does; otherwise they are built anew) and their places in this H.
    const int p = from(k);
    if (p >= 0) {
      PairSlot* const first = pair;
      for (int q = prev_pair_begin_[p]; q < prev_pair_begin_[p + 1]; ++q) {
        const PairSlot& old = prev_pairs_[q];
        const int row = old_to_new_[old.row], column = old_to_new_[old.column];
        if (row < 0 || row > column) {
          pair = first;
          break;
        }
        *pair = old;
        pair->row = row;
        pair->column = column;
        pair->value = ValueIndex(row, column);
        ++pair;
      }
      if (pair != first || prev_pair_begin_[p] == prev_pair_begin_[p + 1]) {
        pair_begin_.push_back(static_cast<int>(pair - pairs_.data()));
        continue;
      }
    }
    const int* block = &var_block_[var_begin_[k]];
    const int nf = FreePositions(block, var_begin_[k + 1] - var_begin_[k], free);
    for (int i = 0, product = 0; i < nf; ++i) {
      for (int j = i; j < nf; ++j) {
        const int a = block[free[i]], b = block[free[j]];
        const std::ptrdiff_t value = ValueIndex(std::min(a, b), std::max(a, b));
        if (a <= b) add_pair(value, a, b, free[i], free[j], product, false);
        // (A variable the factor takes twice gets both products in its diagonal block.)
        if (a > b || (a == b && i != j)) add_pair(value, b, a, free[j], free[i], product, true);
        product += dims_[a] * dims_[b];
      }
    }
    pair_begin_.push_back(static_cast<int>(pair - pairs_.data()));
  }
  ROAMLAB_CHECK(pair == pairs_.data() + pairs_.size(), "pair count " << pairs_.size() << ", written "
                                                                     << pair - pairs_.data());
  pairs_built_ = true;
}

void NormalEquations::PrefetchAhead(std::size_t k) const {
  const std::size_t n = factor_ids_.size();
  if (k + 2 * kPrefetchAhead < n) {
    const char* entry = reinterpret_cast<const char*>(entries_[k + 2 * kPrefetchAhead]);
    for (std::size_t line = 0; line < sizeof(FactorEntry); line += 64) __builtin_prefetch(entry + line);
  }
  if (k + kPrefetchAhead >= n) return;
  const std::size_t j = k + kPrefetchAhead;
  const FactorEntry& entry = *entries_[j];
  const char* factor = reinterpret_cast<const char*>(entry.factor.get());
  __builtin_prefetch(factor);
  __builtin_prefetch(factor + 64);
  __builtin_prefetch(linearized_[j].whitened.sqrt_covariance.data());
  for (int v = var_begin_[j]; v < var_begin_[j + 1]; ++v) __builtin_prefetch(values_[v]);
}

WhitenedFactor& NormalEquations::BufferFor(std::size_t k) {
  const FactorEntry& entry = *entries_[k];
  const std::vector<Manifold>& manifolds = entry.factor->manifolds();
  std::vector<int>& shape = shape_scratch_;
  shape.assign(1, entry.factor->residual_dim());
  for (std::size_t i = 0; i < manifolds.size(); ++i)
    shape.push_back(((want_[k] >> i) & 1u) != 0 ? manifolds[i].tangent_dim() : 0);
  for (ShapedBuffer& buffer : shaped_buffers_)
    if (buffer.shape == shape) return buffer.whitened;
  shaped_buffers_.push_back({shape, {}});
  return shaped_buffers_.back().whitened;
}

// flatten: the small fixed-size J^T J kernels are inlined here whatever the compiler's size heuristics decide (once
// left out of line, they cost a third more).
__attribute__((flatten)) bool NormalEquations::Linearize(const Graph& /*graph*/, std::string* failed_stream) {
  g_.setZero();
  cost_ = 0.0;
  undamped_step_ = false;
  double* values = H_.valuePtr();
  left_out_blocks_ = 0;
  // Without a relinearization threshold every block of H is summed, and each factor's J_a^T J_b go into it right after
  // its gradient, while its Jacobians are still in the cache: a whole recording's linearizations do not fit there,
  // and a second pass would stream them from memory again.
  const bool summed_in_pass = relinearize_threshold_ <= 0.0;
  if (summed_in_pass) std::fill(values, values + H_.nonZeros(), 0.0);
  // Every factor at the current values (kept, carried or evaluated), its cost and J_a^T r into g.
  int free[64];  // positions of a factor's free variables
  const bool keep = keep_linearizations_ || !summed_in_pass;
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) {
    PrefetchAhead(k);
    const WhitenedFactor* linearized = &linearized_[k].whitened;
    if (!keep && !Current(k)) {
      // Into the buffer of the factor's shape; the factor keeps what CostWithLastWhitening reads. (A Gauss-Newton
      // trial point's linearization, which LinearizeForCost keeps, is current.)
      WhitenedFactor& buffer = BufferFor(k);
      if (!LinearizeFactorAt(*entries_[k], &values_[var_begin_[k]], want_[k], &buffer)) {
        if (failed_stream != nullptr) *failed_stream = entries_[k]->stream;
        return false;
      }
      ++evaluations_;
      FactorLinearization& l = linearized_[k];
      l.id = -1;  // not a kept linearization
      if (!entries_[k]->factor->additive_noise()) l.whitened.sqrt_covariance = buffer.sqrt_covariance;
      linearized = &buffer;
    } else if (!Current(k) && !CarryToFirstOrder(k) && !LinearizeAndRecord(k, nullptr)) {
      if (failed_stream != nullptr) *failed_stream = entries_[k]->stream;
      return false;
    }
    const WhitenedFactor& wf = *linearized;
    cost_ += wf.cost;
    const int* block = &var_block_[var_begin_[k]];
    const int nf = FreePositions(block, var_begin_[k + 1] - var_begin_[k], free);
    for (int i = 0; i < nf; ++i)
      AddGradient(wf.jacobians[free[i]], wf.residual, g_.data() + block_offset_[block[free[i]]]);
    if (!summed_in_pass) continue;
    // J_a^T J_b into the blocks of the upper triangle, which sit in H's value array with the column length of their
    // block column as outer stride; where i's block comes after j's, J_j^T J_i into the block (j's, i's) instead
    // (BuildPairs' order: the same sums).
    for (int i = 0; i < nf; ++i) {
      const Eigen::MatrixXd& ji = wf.jacobians[free[i]];
      const int a = block[free[i]];
      for (int j = i; j < nf; ++j) {
        const Eigen::MatrixXd& jj = wf.jacobians[free[j]];
        const int b = block[free[j]];
        double* destination = values + ValueIndex(std::min(a, b), std::max(a, b));
        if (a <= b) AddProduct(ji, jj, destination, column_length_[b]);
        // (A variable the factor takes twice gets both products in its diagonal block.)
        if (a > b || (a == b && i != j)) AddProduct(jj, ji, destination, column_length_[a]);
      }
    }
  }
  if (summed_in_pass) return true;
  EnsurePairs();

  // H from the kept products. The blocks the next factorization takes over from the kept one (every factor evaluated
  // since is known now: ReusableBlocks) are left out; their band columns come first in H's values and stay as they are.
  if (natural_order_ && factor_kept_) {
    Analyze();
    left_out_blocks_ = ReusableBlocks();
    left_out_evaluations_ = evaluations_;
  }
  const std::ptrdiff_t summed_from = left_out_blocks_ > 0 ? H_.outerIndexPtr()[block_offset_[left_out_blocks_]] : 0;
  std::fill(values + summed_from, values + H_.nonZeros(), 0.0);
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) AddKeptProducts(k, false);
  return true;
}

__attribute__((flatten)) void NormalEquations::AddKeptProducts(std::size_t k, bool left_out) {
  // The products J_a^T J_b of a linearization whose Jacobians are kept (relinearization threshold) are kept with it:
  // a carried factor only adds them again. Kept per pair of free positions i <= j (the block order of two variables
  // may change between Resets: then the transpose is added; BuildPattern's pairs_ say where each goes).
  FactorLinearization& l = linearized_[k];
  if (!l.products_valid) {
    const WhitenedFactor& wf = l.whitened;
    const int* block = &var_block_[var_begin_[k]];
    int free[64];
    const int nf = FreePositions(block, var_begin_[k + 1] - var_begin_[k], free);
    std::ptrdiff_t size = 0;
    for (int i = 0; i < nf; ++i)
      for (int j = i; j < nf; ++j) size += wf.jacobians[free[i]].cols() * wf.jacobians[free[j]].cols();
    l.products.resize(size);
    double* product = l.products.data();
    for (int i = 0; i < nf; ++i)
      for (int j = i; j < nf; ++j) {
        const Eigen::MatrixXd& ja = wf.jacobians[free[i]];
        const Eigen::MatrixXd& jb = wf.jacobians[free[j]];
        std::fill_n(product, ja.cols() * jb.cols(), 0.0);
        AddProduct(ja, jb, product, ja.cols());
        product += ja.cols() * jb.cols();
      }
    l.products_valid = true;
  }
  double* values = H_.valuePtr();
  const int first_summed = left_out_blocks_;
  for (int p = pair_begin_[k]; p < pair_begin_[k + 1]; ++p) {
    const PairSlot& pair = pairs_[p];
    if ((pair.row < first_summed && (pair.column < first_summed || pair.column >= band_blocks_)) != left_out) continue;
    AddBlock(l.products.data() + pair.product, dims_[pair.row], dims_[pair.column], pair.transposed,
             values + pair.value, column_length_[pair.column]);
  }
}

void NormalEquations::CompleteHessian() {
  if (left_out_blocks_ == 0) return;
  ROAMLAB_CHECK(evaluations_ == left_out_evaluations_,
                "the normal equations' H is incomplete and a factor was evaluated again since Linearize");
  // The left-out band columns (the first values) were not zeroed; the border's left-out rows were.
  double* values = H_.valuePtr();
  std::fill(values, values + H_.outerIndexPtr()[block_offset_[left_out_blocks_]], 0.0);
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) AddKeptProducts(k, true);
  left_out_blocks_ = 0;
}

const Eigen::SparseMatrix<double>& NormalEquations::hessian_upper() {
  CompleteHessian();
  return H_;
}

bool NormalEquations::CostWithLastWhitening(const Graph& /*graph*/, double* cost) const {
  *cost = 0.0;
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) {
    PrefetchAhead(k);
    double c = 0.0;
    const FactorEntry& entry = *entries_[k];
    if (!FactorCostAt(entry, &values_[var_begin_[k]], SqrtCovariance(entry, linearized_[k].whitened), &c))
      return false;
    *cost += c;
  }
  return true;
}

bool NormalEquations::LinearizeForCost(double* cost) {
  *cost = 0.0;
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) {
    double c = 0.0;
    if (CarryToFirstOrder(k))
      c = linearized_[k].whitened.cost;
    else if (!LinearizeAndRecord(k, &c))
      return false;
    *cost += c;
  }
  return true;
}

bool NormalEquations::Current(std::size_t k) const {
  const FactorLinearization& l = linearized_[k];
  if (l.id != factor_ids_[k] || l.entry != entries_[k] || l.mask != want_[k]) return false;
  const std::vector<Manifold>& manifolds = entries_[k]->factor->manifolds();
  const double* at = l.at.data();
  for (int v = var_begin_[k]; v < var_begin_[k + 1]; ++v) {
    const int n = manifolds[v - var_begin_[k]].ambient_dim();
    if (std::memcmp(at, values_[v], n * sizeof(double)) != 0) return false;
    at += n;
  }
  return true;
}

bool NormalEquations::LinearizeAndRecord(std::size_t k, double* previous_cost) {
  FactorLinearization& l = linearized_[k];
  const int v0 = var_begin_[k];
  // A new marginalization prior stands for the Schur complement that the kept factorization already holds (see
  // FactorEnvelope); any other evaluation changes H where the factor's variables are free.
  const bool new_prior = l.id != factor_ids_[k] && entries_[k]->stream == "marginalization";
  if (factor_kept_ && !new_prior)
    for (int v = v0; v < var_begin_[k + 1]; ++v)
      if (var_block_[v] >= 0) dirty_.push_back(var_id_[v]);
  if (!LinearizeFactorAt(*entries_[k], &values_[v0], want_[k], &l.whitened, previous_cost)) {
    l.id = -1;
    return false;
  }
  l.id = factor_ids_[k];
  l.entry = entries_[k];
  l.mask = want_[k];
  l.products_valid = false;
  l.at.clear();
  const std::vector<Manifold>& manifolds = entries_[k]->factor->manifolds();
  for (int v = v0; v < var_begin_[k + 1]; ++v)
    l.at.insert(l.at.end(), values_[v], values_[v] + manifolds[v - v0].ambient_dim());
  ++evaluations_;
  if (relinearize_threshold_ > 0.0) {
    l.lin_at = l.at;
    l.lin_residual = l.whitened.residual;
  } else {
    l.lin_at.clear();  // not a point to carry from, should a later solve of this object set a threshold
  }
  return true;
}

bool NormalEquations::CarryToFirstOrder(std::size_t k) {
  FactorLinearization& l = linearized_[k];
  const FactorEntry& entry = *entries_[k];
  if (relinearize_threshold_ <= 0.0 || l.id != factor_ids_[k] || l.entry != &entry || l.mask != want_[k] ||
      entry.loss.type != Loss::Type::kTrivial || l.lin_at.size() != l.at.size())
    return false;
  // The tangent offsets x [-] x_lin of the free variables (a held-constant one must not have moved at all).
  const std::vector<Manifold>& manifolds = entry.factor->manifolds();
  const int v0 = var_begin_[k];
  const int n = var_begin_[k + 1] - v0;
  std::vector<double>& delta_values = carry_delta_;
  int total = 0;
  for (int i = 0; i < n; ++i) total += manifolds[i].tangent_dim();
  delta_values.resize(total);
  double* delta = delta_values.data();
  int offset = 0, tangent = 0;
  for (int i = 0; i < n; ++i) {
    const Manifold& manifold = manifolds[i];
    const int ambient = manifold.ambient_dim();
    if (((want_[k] >> i) & 1u) == 0) {
      if (std::memcmp(&l.lin_at[offset], values_[v0 + i], ambient * sizeof(double)) != 0) return false;
    } else {
      double* d = delta + tangent;
      const int block = var_block_[v0 + i];
      if (manifold.kind() == ManifoldKind::kEuclidean || ambient > kMinusMemoAmbient) {
        manifold.Minus(values_[v0 + i], &l.lin_at[offset], d);
      } else {
        // A pose's offset from the point its factors were linearized at recurs in each of them (a box-minus with a
        // logarithm): the last one per block is kept, by the bytes of both points.
        MinusMemo& memo = minus_memo_[block];
        const std::size_t bytes = ambient * sizeof(double);
        if (memo.ambient == ambient && std::memcmp(memo.value, values_[v0 + i], bytes) == 0 &&
            std::memcmp(memo.from, &l.lin_at[offset], bytes) == 0) {
          std::copy_n(memo.delta, manifold.tangent_dim(), d);
        } else {
          manifold.Minus(values_[v0 + i], &l.lin_at[offset], d);
          memo.ambient = ambient;
          std::memcpy(memo.value, values_[v0 + i], bytes);
          std::memcpy(memo.from, &l.lin_at[offset], bytes);
          std::copy_n(d, manifold.tangent_dim(), memo.delta);
        }
      }
      for (int j = 0; j < manifold.tangent_dim(); ++j)
        if (!(std::abs(d[j]) <= relinearize_threshold_)) return false;
      tangent += manifold.tangent_dim();
    }
    offset += ambient;
  }
  WhitenedFactor& wf = l.whitened;
  wf.residual = l.lin_residual;
  tangent = 0;
  for (int i = 0; i < n; ++i) {
    if (((want_[k] >> i) & 1u) == 0) continue;
    const Eigen::MatrixXd& J = wf.jacobians[i];
    AddJacobianTimes(J, delta + tangent, &wf.residual);
    tangent += static_cast<int>(J.cols());
  }
  wf.squared_norm = wf.residual.squaredNorm();
  wf.cost = 0.5 * wf.squared_norm;
  offset = 0;
  for (int i = 0; i < n; ++i) {
    const int ambient = manifolds[i].ambient_dim();
    std::copy(values_[v0 + i], values_[v0 + i] + ambient, l.at.begin() + offset);
    offset += ambient;
  }
  ++carries_;
  return true;
}

const std::vector<double>* NormalEquations::KeptProductsAt(FactorId id, std::uint64_t want_mask) const {
  if (LinearizationAt(id, want_mask) == nullptr) return nullptr;
  const FactorLinearization& l = linearized_[std::lower_bound(factor_ids_.begin(), factor_ids_.end(), id) -
                                             factor_ids_.begin()];
  return l.products_valid ? &l.products : nullptr;
}

const WhitenedFactor* NormalEquations::LinearizationAt(FactorId id, std::uint64_t want_mask) const {
  const auto it = std::lower_bound(factor_ids_.begin(), factor_ids_.end(), id);
  if (it == factor_ids_.end() || *it != id) return nullptr;
  const std::size_t k = static_cast<std::size_t>(it - factor_ids_.begin());
  if (want_[k] != want_mask || !Current(k)) return nullptr;
  return &linearized_[k].whitened;
}

void NormalEquations::Analyze() {
  Cholmod& c = *cholmod_;
  if (c.analyzed) return;
  if (natural_order_) {
    // The border: trailing block columns whose first row block is the first; the envelope of each other block column
    // reaches from its first row block to the diagonal. (The buffers are sized by FactorEnvelope: until then they
    // hold the last factorization, which it may take over.)
    band_blocks_ = static_cast<int>(order_.size());
    while (band_blocks_ > 0 && rows_of_[band_blocks_ - 1].front() == 0 &&
           dimension_ - block_offset_[band_blocks_ - 1] <= kMaxBorder)
      --band_blocks_;
    band_dimension_ = band_blocks_ < static_cast<int>(order_.size()) ? block_offset_[band_blocks_] : dimension_;
    first_block_.resize(band_blocks_);
    envelope_start_.resize(band_blocks_ + 1);
    envelope_start_[0] = 0;
    for (int b = 0; b < band_blocks_; ++b) {
      first_block_[b] = rows_of_[b].front();
      const int height = block_offset_[b] + dims_[b] - block_offset_[first_block_[b]];
      envelope_start_[b + 1] = envelope_start_[b] + static_cast<std::ptrdiff_t>(height) * dims_[b];
    }
    band_pose_blocks_ = std::all_of(dims_.begin(), dims_.begin() + band_blocks_, [](int d) { return d == 6; });
  } else {
    c.llt.setMode(dimension_ <= kMaxSimplicialDimension ? Eigen::CholmodSimplicialLLt : Eigen::CholmodSupernodalLLt);
    c.llt.analyzePattern(H_);
  }
  c.analyzed = true;
  ++analyses_;
}

bool NormalEquations::Solve(double lambda, Eigen::VectorXd* dx) {
  Cholmod& c = *cholmod_;
  undamped_step_ = false;
  const Eigen::SparseMatrix<double>* A = &H_;
  if (lambda > 0.0 && !natural_order_) {  // (the envelope takes H_ and adds the damping as it copies it)
    CompleteHessian();
    c.damped = H_;
    double* v = c.damped.valuePtr();
    for (int i = 0; i < dimension_; ++i) v[diagonal_index_[i]] += lambda * std::max(v[diagonal_index_[i]], 1e-12);
    A = &c.damped;
  }
  if (natural_order_ && factor_kept_) {
    // The last factorization (still in envelope_ and border_, for the solves after it) becomes the kept one
    // (FactorEnvelope); the buffers of the one before take the new factor.
    kept_envelope_.swap(envelope_);
    kept_border_.swap(border_);
  }
  Analyze();
  bool factored = false;
  if (natural_order_) {
    *dx = -g_;  // (its band rows substituted forward in the factorization's sweep)
    factored = FactorEnvelope(*A, lambda, /*factor_corner=*/true, dx->data());
  } else {
    c.llt.factorize(*A);
    factored = c.llt.info() == Eigen::Success;
  }
  c.factored_undamped = lambda <= 0.0 && factored;
  if (!factored) return false;
  undamped_step_ = c.factored_undamped;
  if (natural_order_) {
    SolveEnvelope(*dx, /*band_forwarded=*/true);
    return dx->allFinite();
  }
  *dx = c.llt.solve(-g_);
  return c.llt.info() == Eigen::Success && dx->allFinite();
}

double NormalEquations::ModelDecrease(const Eigen::VectorXd& dx) const {
  if (left_out_blocks_ > 0) {
    ROAMLAB_CHECK(undamped_step_, "model decrease with an incomplete H but no undamped step since Linearize");
    return -0.5 * g_.dot(dx);
  }
  const Eigen::VectorXd Hdx = H_.selfadjointView<Eigen::Upper>() * dx;
  return -g_.dot(dx) - 0.5 * dx.dot(Hdx);
}

namespace {

// a <- U with U^T U = a (upper triangles; the strict lower triangle is left alone), column by column:
// U(i, j) = (a(i, j) - sum_{k<i} U(k, i) U(k, j)) / U(i, i), U(j, j) = sqrt(a(j, j) - sum_{k<j} U(k, j)^2).
// Returns false when a is not positive definite.
template <typename Matrix>
bool UpperCholeskyInPlace(Matrix& a) {
  for (Eigen::Index j = 0; j < a.cols(); ++j) {
    for (Eigen::Index i = 0; i < j; ++i) {
      double s = a(i, j);
      for (Eigen::Index k = 0; k < i; ++k) s -= a(k, i) * a(k, j);
      a(i, j) = s / a(i, i);
    }
    double d = a(j, j);
    for (Eigen::Index k = 0; k < j; ++k) d -= a(k, j) * a(k, j);
    if (!(d > 0.0)) return false;
    a(j, j) = std::sqrt(d);
  }
  return true;
}

// x <- U^-T x (forward substitution) and x <- U^-1 x (back substitution) for a small upper triangular U: plain loops,
// cheaper than a general triangular solve at the size of a pose block. The columns of x are independent: looping over
// them innermost lets their chains of multiply-subtract and division overlap (each entry sees the same operations in
// the same order as a column at a time).
template <typename Upper, typename Rhs>
void SolveUpperTransposed(const Upper& u, Rhs& x) {
  for (Eigen::Index i = 0; i < u.rows(); ++i) {
    for (Eigen::Index c = 0; c < x.cols(); ++c) {
      double s = x(i, c);
      for (Eigen::Index k = 0; k < i; ++k) s -= u(k, i) * x(k, c);
      x(i, c) = s / u(i, i);
    }
  }
}
template <typename Upper, typename Rhs>
void SolveUpper(const Upper& u, Rhs& x) {
  for (Eigen::Index i = u.rows() - 1; i >= 0; --i) {
    for (Eigen::Index c = 0; c < x.cols(); ++c) {
      double s = x(i, c);
      for (Eigen::Index k = i + 1; k < u.rows(); ++k) s -= u(i, k) * x(k, c);
      x(i, c) = s / u(i, i);
    }
  }
}

// Calls f(std::integral_constant<int, N>{}) with N = d for the block sizes of the band's variables that have
// fixed-size kernels (6: a pose, 3: a vector such as a time-varying parameter's instance), else N = Eigen::Dynamic.
template <typename Function>
void WithBlockSize(int d, Function&& f) {
  if (d == 6) {
    f(std::integral_constant<int, 6>{});
  } else if (d == 3) {
    f(std::integral_constant<int, 3>{});
  } else {
    f(std::integral_constant<int, Eigen::Dynamic>{});
  }
}

// The band part Ua of an envelope factorization (NormalEquations::FactorEnvelope): block column b holds the row blocks
// first_block[b]..b as one column-major matrix from u + start[b]. Block dimension D: 6 when every block is a pose,
// otherwise Eigen::Dynamic, and then each block's kernels are picked by its size (WithBlockSize).
template <int D>
struct Band {
  template <int R, int C>
  using Block = Eigen::Map<Eigen::Matrix<double, R, C>, 0, Eigen::OuterStride<>>;
  template <int R, int M = Eigen::Dynamic>
  using Rows = Eigen::Map<Eigen::Matrix<double, R, M>, 0, Eigen::OuterStride<>>;
  int blocks;
  const int* first_block;
  const int* offset;  // first scalar row of each block
  const int* dims;
  const std::ptrdiff_t* start;
  double* u;

  // f(std::integral_constant<int, N>{}) with N the compile-time size of block k (D, or by WithBlockSize).
  template <typename Function>
  void Sized(int k, Function&& f) const {
    if constexpr (D == Eigen::Dynamic) {
      WithBlockSize(dims[k], f);
    } else {
      f(std::integral_constant<int, D>{});
    }
  }
  int height(int b) const { return static_cast<int>((start[b + 1] - start[b]) / dims[b]); }
  // U(r, b), first_block[b] <= r <= b, as an R x C map (R, C: dims[r], dims[b] or Dynamic).
  template <int R, int C>
  Block<R, C> block(int r, int b) const {
    return Block<R, C>(u + start[b] + (offset[r] - offset[first_block[b]]), dims[r], dims[b],
                       Eigen::OuterStride<>(height(b)));
  }
  // Rows of block k of x (column stride ldx, m columns; M: m at compile time, or Dynamic).
  template <int R, int M = Eigen::Dynamic>
  Rows<R, M> rows(double* x, Eigen::Index ldx, Eigen::Index m, int k) const {
    return Rows<R, M>(x + offset[k], dims[k], m, Eigen::OuterStride<>(ldx));
  }

  // Block Crout, block column b: U(r, b) = U(r, r)^-T (A(r, b) - sum_k U(k, r)^T U(k, b)) for r < b, over the row
  // blocks k both columns hold, and U(b, b)^T U(b, b) = A(b, b) - sum_k U(k, b)^T U(k, b). u holds A's column b
  // (upper triangle) on entry, and U in the columns before it. False when A is not positive definite.
  bool FactorColumn(int b) const {
    bool ok = true;
    Sized(b, [&](auto nb) {
      constexpr int B = decltype(nb)::value;
      for (int r = first_block[b]; r < b; ++r) {
        Sized(r, [&](auto nr) {
          constexpr int R = decltype(nr)::value;
          Block<R, B> x = block<R, B>(r, b);
          for (int k = std::max(first_block[r], first_block[b]); k < r; ++k) {
            Sized(k, [&](auto nk) {
              constexpr int K = decltype(nk)::value;
              x.noalias() -= block<K, R>(k, r).transpose() * block<K, B>(k, b);
            });
          }
          SolveUpperTransposed(block<R, R>(r, r), x);
        });
      }
      Block<B, B> d = block<B, B>(b, b);
      for (int k = first_block[b]; k < b; ++k) {
        Sized(k, [&](auto nk) {
          constexpr int K = decltype(nk)::value;
          d.noalias() -= block<K, B>(k, b).transpose() * block<K, B>(k, b);
        });
      }
      ok = UpperCholeskyInPlace(d);
    });
    return ok;
  }
  // x <- Ua^-T x over the band's rows of x, block by block (coefficient-wise products: a block is small, and x has
  // one column for a step, a few for a covariance, the border's for Ub).
  // Rows of blocks from..blocks-1; the ones before hold their result already. M: the column count m at compile time
  // (a pose's covariance: 6), or Dynamic.
  template <int M = Eigen::Dynamic>
  void Forward(double* x, Eigen::Index ldx, Eigen::Index m, int from = 0) const {
    for (int b = from; b < blocks; ++b) ForwardRows<M>(b, x, ldx, m);
  }
  // Row block b of that substitution (the row blocks before it hold their result).
  template <int M = Eigen::Dynamic>
  void ForwardRows(int b, double* x, Eigen::Index ldx, Eigen::Index m) const {
    Sized(b, [&](auto nb) {
      constexpr int B = decltype(nb)::value;
      Rows<B, M> xb = rows<B, M>(x, ldx, m, b);
      for (int k = first_block[b]; k < b; ++k) {
        Sized(k, [&](auto nk) {
          constexpr int K = decltype(nk)::value;
          xb.noalias() -= block<K, B>(k, b).transpose().lazyProduct(rows<K, M>(x, ldx, m, k));
        });
      }
      SolveUpperTransposed(block<B, B>(b, b), xb);
    });
  }
  // x <- Ua^-1 x, block by block from the last.
  void Backward(double* x, Eigen::Index ldx, Eigen::Index m) const {
    for (int b = blocks - 1; b >= 0; --b) {
      Sized(b, [&](auto nb) {
        constexpr int B = decltype(nb)::value;
        Rows<B> xb = rows<B>(x, ldx, m, b);
        SolveUpper(block<B, B>(b, b), xb);
        for (int k = first_block[b]; k < b; ++k) {
          Sized(k, [&](auto nk) {
            constexpr int K = decltype(nk)::value;
            rows<K>(x, ldx, m, k).noalias() -= block<K, B>(k, b).lazyProduct(xb);
          });
        }
      });
    }
  }
};

}  // namespace

template <typename Function>
void NormalEquations::WithBand(Function f) {
  if (band_pose_blocks_) {
    f(Band<6>{band_blocks_, first_block_.data(), block_offset_.data(), dims_.data(), envelope_start_.data(),
              envelope_.data()});
  } else {
    f(Band<Eigen::Dynamic>{band_blocks_, first_block_.data(), block_offset_.data(), dims_.data(),
                           envelope_start_.data(), envelope_.data()});
  }
}

int NormalEquations::ReusableBlocks() const {
  if (!factor_kept_ || order_.empty() || kept_band_blocks_ == 0) return 0;
  // The kept order without the blocks that left at its front (shift), and the same border.
  const auto first = std::find(kept_order_.begin(), kept_order_.begin() + kept_band_blocks_, order_.front());
  if (first == kept_order_.begin() + kept_band_blocks_) return 0;
  const int shift = static_cast<int>(first - kept_order_.begin());
  const int border_blocks = static_cast<int>(order_.size()) - band_blocks_;
  if (static_cast<int>(kept_order_.size()) - kept_band_blocks_ != border_blocks ||
      !std::equal(order_.begin() + band_blocks_, order_.end(), kept_order_.begin() + kept_band_blocks_))
    return 0;
  int reusable = 0;
  while (reusable < band_blocks_ && reusable + shift < kept_band_blocks_ &&
         order_[reusable] == kept_order_[reusable + shift] &&
         first_block_[reusable] == std::max(kept_first_block_[reusable + shift] - shift, 0))
    ++reusable;
  for (VariableId id : dirty_) {
    const int b = BlockOf(id);
    if (b >= 0) {
      if (b < band_blocks_) reusable = std::min(reusable, b);
    } else if (std::find(kept_order_.begin(), kept_order_.end(), id) != kept_order_.end()) {
      return 0;  // a factor on a variable that left (or is no longer free) changed: the Schur complement did too
    }
  }
  return reusable;
}

bool NormalEquations::FactorEnvelope(const Eigen::SparseMatrix<double>& A, double lambda, bool factor_corner,
                                     double* rhs) {
  const bool undamped = lambda <= 0.0;
  const int na = band_dimension_;
  const int reused = undamped && relinearize_threshold_ > 0.0 ? ReusableBlocks() : 0;
  if (reused < left_out_blocks_) CompleteHessian();  // (A is H_, the damping added below)
  const int reused_rows = reused > 0 ? block_offset_[reused] : 0;
  envelope_.resize(envelope_start_[band_blocks_]);
  border_.resize(na, dimension_ - na);
  if (reused > 0) {
    // Columns 0..reused-1 of Ua from the kept ones shifted by the blocks that left (their rows above the first
    // block now are dropped), and the rows of Ub before row block `reused`.
    const int shift = static_cast<int>(std::find(kept_order_.begin(), kept_order_.end(), order_.front()) -
                                       kept_order_.begin());
    const int row_shift = kept_block_offset_[shift];
    for (int b = 0; b < reused; ++b) {
      const int kb = b + shift;
      const std::ptrdiff_t kept_height = (kept_envelope_start_[kb + 1] - kept_envelope_start_[kb]) / dims_[b];
      const std::ptrdiff_t height = (envelope_start_[b + 1] - envelope_start_[b]) / dims_[b];
      const std::ptrdiff_t skip =
          kept_block_offset_[first_block_[b] + shift] - kept_block_offset_[kept_first_block_[kb]];
      for (int t = 0; t < dims_[b]; ++t)
        std::copy_n(kept_envelope_.data() + kept_envelope_start_[kb] + t * kept_height + skip, height,
                    envelope_.data() + envelope_start_[b] + t * height);
    }
    border_.topRows(reused_rows) = kept_border_.middleRows(row_shift, reused_rows);
  }
  reused_blocks_ += reused;

  // Scatter the upper triangle of A: the band's column j of block b into its column of the block's envelope, rows
  // from the first of block first_block_[b] (the columns not taken over), with the damping on the diagonal:
  // A(j, j) + lambda max(A(j, j), 1e-12); the border's columns into B's rows (Ub's place) and C (corner_).
  // Ua and Ub = Ua^-T B (forward substitution on B's columns) are computed block by block in the same sweep, each
  // block column scattered just before it is factored and its rows of B substituted just after: a whole recording's
  // envelope and border (hundreds of MB) are then streamed from memory once, not once per pass over them, and the
  // arithmetic is that of the passes one after the other.
  corner_.setZero(dimension_ - na, dimension_ - na);
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* value = A.valuePtr();
  const int border_columns = dimension_ - na;
  // Per border column, its next entry (rows sorted: the ones taken over are skipped at once).
  std::vector<int>& next = border_cursor_;
  next.resize(border_columns);
  for (int c = 0; c < border_columns; ++c)
    next[c] = static_cast<int>(std::lower_bound(inner + outer[na + c], inner + outer[na + c + 1], reused_rows) - inner);
  const auto scatter = [&](int b) {
    const int row0 = block_offset_[first_block_[b]];
    const std::ptrdiff_t height = (envelope_start_[b + 1] - envelope_start_[b]) / dims_[b];
    std::fill(envelope_.begin() + envelope_start_[b], envelope_.begin() + envelope_start_[b + 1], 0.0);
    for (int t = 0; t < dims_[b]; ++t) {
      const int j = block_offset_[b] + t;
      double* column = envelope_.data() + envelope_start_[b] + t * height - row0;
      for (int p = outer[j]; p < outer[j + 1]; ++p)
        if (inner[p] <= j) column[inner[p]] = value[p];
      if (!undamped) column[j] += lambda * std::max(column[j], 1e-12);
    }
    const int end_row = block_offset_[b] + dims_[b];
    for (int c = 0; c < border_columns; ++c) {
      double* column = border_.data() + static_cast<std::ptrdiff_t>(c) * na;
      std::fill(column + block_offset_[b], column + end_row, 0.0);
      int p = next[c];
      for (; p < outer[na + c + 1] && inner[p] < end_row; ++p) column[inner[p]] = value[p];
      next[c] = p;
    }
  };
  bool factored = true;
  WithBand([&](const auto& band) {
    if (rhs != nullptr)
      for (int b = 0; b < reused; ++b) band.ForwardRows(b, rhs, dimension_, 1);
    for (int b = reused; b < band_blocks_ && factored; ++b) {
      scatter(b);
      factored = band.FactorColumn(b);
      if (factored && border_columns > 0) band.ForwardRows(b, border_.data(), border_.rows(), border_.cols());
      if (factored && rhs != nullptr) band.ForwardRows(b, rhs, dimension_, 1);
    }
  });
  // (The cursors are past the band's rows once every block column is factored.)
  for (int c = 0; c < border_columns && factored; ++c) {
    const int j = na + c;
    for (int p = next[c]; p < outer[j + 1]; ++p)
      if (inner[p] <= j) corner_(inner[p] - na, c) = value[p];
    double& diagonal = corner_(c, c);
    if (!undamped) diagonal += lambda * std::max(diagonal, 1e-12);
  }
  if (factored && dimension_ > na) {
    corner_.selfadjointView<Eigen::Upper>().rankUpdate(border_.transpose(), -1.0);
    if (factor_corner) factored = UpperCholeskyInPlace(corner_);
  }
  // Kept for the next factorization (with a relinearization threshold, undamped).
  factor_kept_ = factored && factor_corner && undamped && relinearize_threshold_ > 0.0;
  dirty_.clear();
  if (factor_kept_) {
    kept_order_ = order_;
    kept_band_blocks_ = band_blocks_;
    kept_first_block_ = first_block_;
    kept_block_offset_ = block_offset_;
    kept_envelope_start_ = envelope_start_;
  }
  return factored;
}

bool NormalEquations::BorderInformation(int border_dimension, Eigen::MatrixXd* information) {
  if (!natural_order_ || border_dimension <= 0) return false;
  Analyze();
  if (dimension_ - band_dimension_ != border_dimension) return false;
  // The factorization without Uc, from scratch (no kept columns): corner_ keeps C - Ub^T Ub (upper triangle), which
  // need not be positive definite.
  cholmod_->factored_undamped = false;
  factor_kept_ = false;
  const bool factored = FactorEnvelope(hessian_upper(), 0.0, /*factor_corner=*/false);
  if (!factored) return false;
  *information = corner_.selfadjointView<Eigen::Upper>();
  return true;
}

void NormalEquations::ForwardEnvelope(Eigen::Ref<Eigen::MatrixXd> x, bool band_forwarded) {
  // U^T y = x: Ua^T ya = xa, then Uc^T yc = xc - Ub^T ya.
  if (!band_forwarded) WithBand([&](const auto& band) { band.Forward(x.data(), x.outerStride(), x.cols()); });
  const int na = band_dimension_;
  if (dimension_ > na) {
    auto xc = x.bottomRows(dimension_ - na);
    xc.noalias() -= border_.transpose() * x.topRows(na);
    corner_.triangularView<Eigen::Upper>().transpose().solveInPlace(xc);
  }
}

void NormalEquations::SolveEnvelope(Eigen::Ref<Eigen::MatrixXd> x, bool band_forwarded) {
  // U^T y = x, then U x = y: Uc xc = yc, then Ua xa = ya - Ub xc.
  ForwardEnvelope(x, band_forwarded);
  const int na = band_dimension_;
  if (dimension_ > na) {
    auto xc = x.bottomRows(dimension_ - na);
    corner_.triangularView<Eigen::Upper>().solveInPlace(xc);
    x.topRows(na).noalias() -= border_ * xc;
  }
  WithBand([&](const auto& band) { band.Backward(x.data(), x.outerStride(), x.cols()); });
}

bool NormalEquations::Covariance(const std::vector<VariableId>& variables, Eigen::MatrixXd* covariance,
                                 int leading_dims) {
  Cholmod& c = *cholmod_;
  if (!c.factored_undamped) {
    Eigen::VectorXd unused;
    if (!Solve(0.0, &unused)) return false;
  }
  const auto used = [&](int b) { return leading_dims > 0 ? std::min(leading_dims, dims_[b]) : dims_[b]; };
  int cols = 0;
  for (VariableId id : variables) {
    const int b = BlockOf(id);
    ROAMLAB_CHECK(b >= 0, "covariance of variable " << id << ", which is not free in this system");
    cols += used(b);
  }
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(dimension_, cols);
  std::vector<int> rows;
  int col = 0;
  for (VariableId id : variables) {
    const int b = BlockOf(id);
    for (int k = 0; k < used(b); ++k) {
      E(block_offset_[b] + k, col++) = 1.0;
      rows.push_back(block_offset_[b] + k);
    }
  }
  Eigen::MatrixXd X;
  if (natural_order_ && cols <= kMaxForwardCovarianceColumns) {
    // H^-1 = U^-1 U^-T, so the covariance is Y^T Y with U^T Y = E: the forward substitution only. As
    // ForwardEnvelope, with kernels for so few columns: a pose's six (or its position's three) at compile time in the
    // band, and the border's and the Gram matrix's products coefficient-wise (a blocked product packs the whole of Ub
    // for six columns). Y's rows above the first requested block stay zero: the substitution and the products start
    // there (a window's leaving pose is its first block; an initial batch's poses leave from the front one by one).
    const int na = band_dimension_;
    int first = static_cast<int>(order_.size());
    for (VariableId id : variables) first = std::min(first, BlockOf(id));
    const int from = std::min(first, band_blocks_);
    const int row0 = from < band_blocks_ ? block_offset_[from] : na;
    WithBand([&](const auto& band) {
      if (cols == 6)
        band.template Forward<6>(E.data(), E.outerStride(), cols, from);
      else if (cols == 3)
        band.template Forward<3>(E.data(), E.outerStride(), cols, from);
      else
        band.Forward(E.data(), E.outerStride(), cols, from);
    });
    if (dimension_ > na) {
      auto yc = E.bottomRows(dimension_ - na);
      yc.noalias() -= border_.bottomRows(na - row0).transpose().lazyProduct(E.middleRows(row0, na - row0));
      SolveUpperTransposed(corner_, yc);
    }
    const auto y = E.bottomRows(dimension_ - row0);
    if (!y.allFinite()) return false;
    *covariance = y.transpose().lazyProduct(y);
    return true;
  }
  if (natural_order_) {
    X = std::move(E);
    SolveEnvelope(X);
  } else {
    X = c.llt.solve(E);
    if (c.llt.info() != Eigen::Success) return false;
  }
  if (!X.allFinite()) return false;
  covariance->resize(cols, cols);
  for (int i = 0; i < cols; ++i) covariance->row(i) = X.row(rows[i]);
  return true;
}

void NormalEquations::Update(const Eigen::VectorXd& dx, Graph* graph) const {
  std::vector<Variable*> free_variables;
  free_variables.reserve(order_.size());
  for (VariableId id : order_) free_variables.push_back(&graph->mutable_variable(id));
  Update(dx, free_variables);
}

void NormalEquations::Update(const Eigen::VectorXd& dx, const std::vector<Variable*>& free_variables) const {
  ROAMLAB_CHECK(free_variables.size() == order_.size(), "Update with " << free_variables.size() << " variables for "
                                                                        << order_.size() << " blocks");
  // (The variables lie in separate heap blocks, their values in others: both prefetched ahead.)
  const std::size_t n = order_.size();
  for (std::size_t b = 0; b < n; ++b) {
    if (b + 2 * kPrefetchAhead < n) __builtin_prefetch(free_variables[b + 2 * kPrefetchAhead]);
    if (b + kPrefetchAhead < n) __builtin_prefetch(free_variables[b + kPrefetchAhead]->value.data());
    Variable& v = *free_variables[b];
    v.manifold.Plus(v.value.data(), dx.data() + block_offset_[b], v.value.data());
  }
}

}  // namespace roamlab::estimator::internal
