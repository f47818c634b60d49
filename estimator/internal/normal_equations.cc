#include "estimator/internal/normal_equations.h"

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "common/check.h"
#include "estimator/internal/normal_equations_shared.h"

namespace roamlab::estimator::internal {

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
  KeepLastTables();
  const bool stamped_first = OrderBlocks(graph, std::move(order));
  BuildVariableTable(graph);
  const bool incremental = PrepareIncremental();
  CollectFactors(graph, incremental, stamped_first);
  const int nb = static_cast<int>(order_.size());

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

void NormalEquations::KeepLastTables() {
  // The tables of the last Reset, kept for the factors still in the graph (below).
  prev_order_.swap(order_);
  prev_factor_ids_.swap(factor_ids_);
  prev_entries_.swap(entries_);
  prev_var_begin_.swap(var_begin_);
  prev_want_.swap(want_);
  prev_var_id_.swap(var_id_);
  prev_var_block_.swap(var_block_);
  prev_values_.swap(values_);
}

bool NormalEquations::OrderBlocks(const Graph& graph, std::vector<VariableId> order) {
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
    ROAMLAB_CHECK(block_of_id_[i].first != block_of_id_[i - 1].first,
                  "variable " << block_of_id_[i].first << " ordered twice");
  return stamped_first;
}

void NormalEquations::BuildVariableTable(const Graph& graph) {
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
}

bool NormalEquations::PrepareIncremental() {
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
  return incremental;
}

void NormalEquations::CollectFactors(const Graph& graph, bool incremental, bool stamped_first) {
  const int nb = static_cast<int>(order_.size());
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
    const bool kept =
        incremental && prev < prev_factor_ids_.size() && prev_factor_ids_[prev] == fid &&
        prev_entries_[prev] == &entry &&
        prev_var_begin_[prev + 1] - prev_var_begin_[prev] == static_cast<int>(entry.variables.size()) &&
        std::equal(entry.variables.begin(), entry.variables.end(), prev_var_id_.begin() + prev_var_begin_[prev]);
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
  // one, Linearize finds each block as it sums the factor's products into H, and a whole recording's pairs (hundreds
  // of MB) are neither built nor streamed through at every linearization. A small system (a window that slides)
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
  const auto add_pair = [&pair](std::ptrdiff_t value, int row, int column, int a, int b, int product, bool transposed) {
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
  ROAMLAB_CHECK(pair == pairs_.data() + pairs_.size(),
                "pair count " << pairs_.size() << ", written " << pair - pairs_.data());
  pairs_built_ = true;
}

void NormalEquations::Update(const Eigen::VectorXd& dx, Graph* graph) const {
  std::vector<Variable*> free_variables;
  free_variables.reserve(order_.size());
  for (VariableId id : order_) free_variables.push_back(&graph->mutable_variable(id));
  Update(dx, free_variables);
}

void NormalEquations::Update(const Eigen::VectorXd& dx, const std::vector<Variable*>& free_variables) const {
  ROAMLAB_CHECK(free_variables.size() == order_.size(),
                "Update with " << free_variables.size() << " variables for " << order_.size() << " blocks");
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
