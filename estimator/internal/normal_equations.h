// Sparse normal equations H dx = -g of the whitened, loss-weighted least-squares problem over an ordered list of free
// variables (seed 000, eqs. 2-3). The block-sparse pattern of H (upper triangle, compressed columns) is built per
// graph structure; each Linearize refills the values in place, and CHOLMOD's Cholesky (with its fill-reducing
// ordering) analyses the pattern once and refactors the values every iteration. Systems in their natural order (a
// band of poses with a dense border: a tracking window, or a whole recording whose factors tie poses to their
// neighbours in time only) are factored in their envelope instead (see Reset).
//
// An object can be Reset to a changed graph and keeps its buffers; when the new pattern is the same as the old one
// (a fixed-lag window that slid by one pose has the same band), the symbolic analysis is kept too, and a small
// system's last few patterns are kept so that one which comes back is not built again. A Reset after which
// the graph's factors and variables changed only by some leaving and new ones coming is incremental: the factors
// still in it keep their tables (their variables' values and blocks), only new ones are looked up; the result is the
// same as from scratch. Under a relinearization threshold the envelope factorization is incremental too: the leading
// block columns of the last factor whose rows of H did not change are taken over (FactorEnvelope).
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "estimator/graph.h"
#include "estimator/internal/linearization.h"

namespace roamlab::estimator::internal {

class NormalEquations {
 public:
  NormalEquations();
  // Reset(graph, order).
  NormalEquations(const Graph& graph, std::vector<VariableId> order);
  ~NormalEquations();

  // Binds to `graph` with the free variables `order`, in the order of their columns. Active factors that touch at
  // least one of them are included; the other variables they touch are held constant. The graph's structure (its
  // variables and factors) must not change until the next Reset; values may.
  void Reset(const Graph& graph, std::vector<VariableId> order);

  // Evaluates every included factor at the graph's current values; fills H, g and the per-factor whitening.
  // Returns false if some factor could not be linearized (its stream is named in *failed_stream). Under a
  // relinearization threshold, the blocks of H that the next undamped factorization takes over from the kept one
  // (FactorEnvelope) are left out: it does not read them. They are added from the factors' kept J^T J products when
  // something needs the whole of H (hessian_upper, a damped Solve), which must then come before a factor is evaluated
  // again (LinearizeForCost).
  bool Linearize(const Graph& graph, std::string* failed_stream = nullptr);

  // Cost at the graph's current values with the whitening of the last Linearize (so that a trial step is judged on
  // the same objective it was computed for).
  bool CostWithLastWhitening(const Graph& graph, double* cost) const;

  // The same cost, from a linearization of every factor at the current values, which is kept: the next Linearize at
  // these values (the next iteration once the step is taken, or the next solve of a window that slid) only adds it
  // up, and LinearizationAt hands it out. For a step that is always taken (Gauss-Newton), where the trial point is
  // the next linearization point.
  bool LinearizeForCost(double* cost);

  // The kept linearization of factor `id` when it was computed at the graph's current values with the Jacobians of
  // exactly the variables in want_mask (bit i: variable i), otherwise null. The factor must still be in the graph.
  // With a relinearization threshold its error may be carried to these values to first order (below).
  const WhitenedFactor* LinearizationAt(FactorId id, std::uint64_t want_mask) const;
  // The J_i^T J_j products of that linearization's Jacobians when they are kept (relinearization threshold, computed
  // by Linearize since the factor was last evaluated), otherwise null: per pair of its free positions i <= j in order
  // (i outer), each column-major.
  const std::vector<double>* KeptProductsAt(FactorId id, std::uint64_t want_mask) const;

  // Relinearization threshold (iSAM2's): when > 0, Linearize and LinearizeForCost do not evaluate again a factor with
  // a trivial loss whose free variables all moved by at most this much (every tangent component of x [-] x_lin) since
  // the point its Jacobians and whitening were computed at, x_lin; its whitened error is carried to the current values
  // to first order, r(x_lin) + sum_i J_i (x_i [-] x_lin_i), with the same Jacobians. 0 (the default): a factor is
  // evaluated again whenever one of its values changed.
  void set_relinearize_threshold(double threshold) { relinearize_threshold_ = threshold; }
  // Whether Linearize keeps every factor's linearization (its Jacobians, whitened error, point) for LinearizationAt
  // and KeptProductsAt (default true). Without a relinearization threshold and with keep false, each factor is
  // linearized into a buffer of its shape that the next one of that shape reuses, and only what the trial points'
  // costs need stays with the factor (its error covariance's factor when that depends on the estimate): the same H,
  // g and cost, without streaming a whole recording's
  // linearizations to memory that nothing reads again. LinearizationAt is then null after Linearize. (With a
  // threshold they are kept whatever this says: the carries need them; LinearizeForCost keeps its linearization of
  // a Gauss-Newton trial point, which the next Linearize takes.)
  void set_keep_linearizations(bool keep) { keep_linearizations_ = keep; }
  // Drops every factor's kept linearization: the next Linearize evaluates each factor exactly (none is carried to
  // first order or taken as current).
  void ForgetLinearizations();
  // Factor evaluations (with Jacobians) and first-order carries since construction.
  long evaluations() const { return evaluations_; }
  long carries() const { return carries_; }
  // Band block columns of the factor taken over from the last factorization since construction (incremental
  // factorization under a relinearization threshold: see FactorEnvelope).
  long reused_blocks() const { return reused_blocks_; }

  // Which variables Levenberg-Marquardt's damping lambda diag(H) reaches: every one, or the constant parameters only
  // (no time stamp), the states left undamped (Solve).
  enum class Damping { kAll, kConstantsOnly };

  // Solves (H + lambda D diag(H)) dx = -g, D selecting the damped variables. Returns false if the matrix is not
  // positive definite.
  bool Solve(double lambda, Eigen::VectorXd* dx, Damping damping = Damping::kAll);

  // The decrease of the quadratic model of the last Linearize along dx, -g.dx - dx.H.dx / 2. When H lacks the blocks
  // that the factorization took over (Linearize), dx must be the step of the last Solve, which was undamped: then
  // H dx = -g (to the solve's rounding) and the decrease is -g.dx / 2.
  double ModelDecrease(const Eigen::VectorXd& dx) const;

  // Marginal covariance of the listed free variables (their tangent blocks, in order; with leading_dims > 0 only
  // each one's first leading_dims tangent components) from H of the last Linearize: solves H X = E for their columns,
  // reusing the last factorization when it was undamped. Returns false when H is not positive definite.
  bool Covariance(const std::vector<VariableId>& variables, Eigen::MatrixXd* covariance, int leading_dims = 0);

  // The information of the border (the trailing constant parameters of a system factored in its envelope, when they
  // span exactly border_dimension) with every other free variable marginalized out: the Schur complement
  // C - B^T A^-1 B of H = [A B; B^T C], from the envelope factorization of A (Ua^T Ua = A, Ub = Ua^-T B, S = C - Ub^T
  // Ub). False when the system has no such border or A is not positive definite. The next Solve or Covariance factors
  // again.
  bool BorderInformation(int border_dimension, Eigen::MatrixXd* information);

  // Applies x [+] dx to the free variables, found in the graph by id, or given in the order of the blocks (a solve's
  // loop looks them up once instead of at every step).
  void Update(const Eigen::VectorXd& dx, Graph* graph) const;
  void Update(const Eigen::VectorXd& dx, const std::vector<Variable*>& free_variables) const;

  int dimension() const { return dimension_; }
  // Factored in the band's envelope (natural order), not by CHOLMOD (Reset).
  bool factored_in_envelope() const { return natural_order_; }
  double cost() const { return cost_; }
  const Eigen::VectorXd& gradient() const { return g_; }
  // Upper triangle of H (the blocks Linearize left out are added first).
  const Eigen::SparseMatrix<double>& hessian_upper();
  const std::vector<VariableId>& order() const { return order_; }
  // Column offset of a free variable, or -1.
  int OffsetOf(VariableId id) const;
  const std::vector<FactorId>& factor_ids() const { return factor_ids_; }
  // How many Reset calls had to analyse a new pattern (the others kept the symbolic factorization).
  int analyses() const { return analyses_; }
  // How many Reset calls built H's pattern anew (the others kept it, or took it from the few last ones).
  int patterns_built() const { return patterns_built_; }
  // How many Reset calls kept the tables of the factors still in the graph (incremental).
  int incremental_resets() const { return incremental_resets_; }

 private:
  // Block column of a free variable, or -1.
  int BlockOf(VariableId id) const;
  // Reset's steps: the last Reset's tables set aside for the factors still in the graph (KeepLastTables); the free
  // variables' blocks, returning whether every time-stamped variable comes before the constant ones (OrderBlocks);
  // every variable's value and block, by id (BuildVariableTable); whether the factors still in the graph keep their
  // tables, and their blocks' renumbering (PrepareIncremental); the included factors, their variables' blocks and
  // values, and the row blocks of each block column (CollectFactors).
  void KeepLastTables();
  bool OrderBlocks(const Graph& graph, std::vector<VariableId> order);
  void BuildVariableTable(const Graph& graph);
  bool PrepareIncremental();
  void CollectFactors(const Graph& graph, bool incremental, bool stamped_first);
  void BuildPattern();
  // pairs_ and pair_begin_ for the included factors (BuildPattern with a relinearization threshold; else at their first
  // use, EnsurePairs: a pass that sums each factor's products into H as it linearizes finds the blocks itself).
  void BuildPairs();
  void EnsurePairs() {
    if (!pairs_built_) BuildPairs();
  }
  // Index in H's value array of block (r, c), r <= c (BuildPattern's tables).
  std::ptrdiff_t ValueIndex(int r, int c) const {
    if (column_base_[c] >= 0) return column_base_[c] + block_offset_[r];
    const std::vector<int>& rows = rows_of_[c];
    const std::ptrdiff_t position = std::lower_bound(rows.begin(), rows.end(), r) - rows.begin();
    return static_cast<std::ptrdiff_t>(H_.outerIndexPtr()[block_offset_[c]]) + row_offset_[c][position];
  }
  bool EnvelopeIsNarrow() const;  // the envelopes hold little more than H's pattern (Reset)
  // The symbolic analysis of a new pattern: a natural-order system's band and border layout, or CHOLMOD's.
  void Analyze();

  std::vector<VariableId> order_;
  std::vector<std::pair<VariableId, int>> block_of_id_;  // sorted by id
  struct VariableSlot {
    VariableId id;
    const double* value;
    int block;  // -1: held constant
  };
  std::vector<VariableSlot> variable_table_;  // every variable of the graph, sorted by id
  std::vector<int> dims_;                     // per block
  std::vector<char> full_column_;             // per block: its column holds every row block before it
  std::vector<char> damped_;                  // per dimension: lambda diag(H) added there (Solve)
  std::vector<int> block_offset_;             // per block: first column
  int dimension_ = 0;

  // Included factors, and per factor k the range [var_begin_[k], var_begin_[k + 1]) of its variables in var_block_
  // (block column or -1 when held constant) and values_ (the variables' ambient values), and the range
  // [pair_begin_[k], pair_begin_[k + 1]) of its pairs of free positions i <= j (i outer) in pairs_: the block of H
  // that J_i^T J_j goes to, or its transpose when i's block comes after j's. (A block of H receives one product per
  // factor, so the order of a factor's pairs does not change the sums; a variable the factor takes twice, at i and
  // j, receives J_i^T J_j and then J_j^T J_i in its diagonal block, between J_i^T J_i and J_j^T J_j, as before.)
  std::vector<FactorId> factor_ids_;
  std::vector<const FactorEntry*> entries_;
  std::vector<std::uint64_t> want_;
  std::vector<int> var_begin_;
  std::vector<int> var_block_;
  std::vector<const double*> values_;
  std::vector<int> pair_begin_;
  struct PairSlot {
    std::ptrdiff_t value;  // index of the block in H's value array
    int row, column;       // its blocks, row <= column
    int a, b;              // the factor's variables (positions) whose J_a^T J_b the block receives
    int product;           // offset of the kept product J_i^T J_j, i <= j (FactorLinearization::products)
    bool transposed;       // the block receives that product's transpose
  };
  std::vector<PairSlot> pairs_;
  bool pairs_built_ = false;  // pairs_ are those of the last Reset
  // The last Reset's pairs and masks, and per factor its index there when it was kept with the same mask (else -1).
  std::vector<PairSlot> prev_pairs_;
  std::vector<int> prev_pair_begin_;
  std::vector<std::uint64_t> prev_want_;
  std::vector<int> kept_from_;
  // Per included factor, its last linearization and the point it was computed at: Linearize evaluates a factor again
  // only when its variables' values (bit for bit), its entry or its Jacobians' mask changed since.
  struct FactorLinearization {
    WhitenedFactor whitened;
    FactorId id = -1;  // the factor it belongs to, -1: none yet
    const FactorEntry* entry = nullptr;
    std::uint64_t mask = 0;
    std::vector<double> at;  // the factor's variables' ambient values, concatenated
    // The point the Jacobians and the whitening were computed at (ambient values, as `at`) and the whitened error
    // there; `at` and whitened.residual differ from them after a first-order carry (CarryToFirstOrder).
    std::vector<double> lin_at;
    Eigen::VectorXd lin_residual;
    // With a relinearization threshold: the J_i^T J_j of the Jacobians, per pair of free positions i <= j in order
    // (i outer), each column-major.
    std::vector<double> products;
    bool products_valid = false;
    // Member by member (MoveLinearizationsWithTheirFactors swaps one per factor and Reset): each buffer's pointers
    // change hands, where std::swap's three moves would also clear and re-fill them. A member added to this struct or
    // to WhitenedFactor goes here too.
    friend void swap(FactorLinearization& a, FactorLinearization& b) noexcept {
      a.whitened.residual.swap(b.whitened.residual);
      a.whitened.jacobians.swap(b.whitened.jacobians);
      a.whitened.sqrt_covariance.swap(b.whitened.sqrt_covariance);
      std::swap(a.whitened.squared_norm, b.whitened.squared_norm);
      std::swap(a.whitened.cost, b.whitened.cost);
      std::swap(a.id, b.id);
      std::swap(a.entry, b.entry);
      std::swap(a.mask, b.mask);
      a.at.swap(b.at);
      a.lin_at.swap(b.lin_at);
      a.lin_residual.swap(b.lin_residual);
      a.products.swap(b.products);
      std::swap(a.products_valid, b.products_valid);
    }
  };
  std::vector<FactorLinearization> linearized_;
  bool keep_linearizations_ = true;
  // Linearize without keeping: one buffer per factor shape (residual size and Jacobian columns, in that order), so
  // that a factor's Jacobians are written where the last factor of its kind left buffers of the right size.
  struct ShapedBuffer {
    std::vector<int> shape;
    WhitenedFactor whitened;
  };
  std::vector<ShapedBuffer> shaped_buffers_;
  std::vector<int> shape_scratch_;
  WhitenedFactor& BufferFor(std::size_t k);
  // Prefetches what linearizing or costing factor k + kPrefetchAhead will read (its entry further ahead, since the
  // others are found through it): a whole recording's factors, variables and noise matrices lie in separate heap
  // blocks far out of the cache, a chain of misses that the hardware's prefetcher cannot follow.
  void PrefetchAhead(std::size_t k) const;
  std::vector<FactorLinearization> prev_linearized_;
  std::vector<bool> taken_scratch_;         // Reset: which of prev_linearized_ found their factor
  std::vector<std::size_t> fresh_scratch_;  // Reset: factors new since the last Reset
  bool Current(std::size_t k) const;        // linearized_[k] holds factor k at the current values
  // Reset: linearized_ and prev_linearized_ (the last Reset's) rearranged so that each factor still in the system
  // finds its record at its new place; marks the variables of factors that left while theirs stayed dirty.
  void MoveLinearizationsWithTheirFactors();
  // Adds factor k's kept J_a^T J_b into the blocks of H that Linearize sums (`left_out` false) or into those it left
  // out (true); computes the products first when they are not kept yet.
  void AddKeptProducts(std::size_t k, bool left_out);
  // Adds the blocks Linearize left out (see left_out_blocks_).
  void CompleteHessian();
  bool LinearizeAndRecord(std::size_t k, double* previous_cost);
  // Carries factor k's kept linearization to the current values to first order when the relinearization threshold
  // allows it (see set_relinearize_threshold); false when it must be evaluated again.
  bool CarryToFirstOrder(std::size_t k);
  double relinearize_threshold_ = 0.0;
  std::vector<double> carry_delta_;  // CarryToFirstOrder: the tangent offsets
  // CarryToFirstOrder: per block, the last box-minus of a pose or rotation (x [-] from) and its two points.
  static constexpr int kMinusMemoAmbient = 7;
  struct MinusMemo {
    int ambient = 0;  // 0: none
    double value[kMinusMemoAmbient];
    double from[kMinusMemoAmbient];
    double delta[kMinusMemoAmbient];
  };
  std::vector<MinusMemo> minus_memo_;
  long evaluations_ = 0;
  long carries_ = 0;

  std::vector<VariableId> var_id_;  // per factor variable, as var_block_

  // The tables of the last Reset (swapped out at the next one), for an incremental Reset of a graph that changed at
  // its ends: old_to_new_ maps the last Reset's blocks to the current ones (-1 when no longer free).
  std::vector<VariableSlot> prev_variable_table_;
  std::vector<VariableId> prev_order_;
  std::vector<FactorId> prev_factor_ids_;
  std::vector<const FactorEntry*> prev_entries_;
  std::vector<int> prev_var_begin_;
  std::vector<VariableId> prev_var_id_;
  std::vector<int> prev_var_block_;
  std::vector<const double*> prev_values_;
  std::vector<int> old_to_new_;

  // Pattern scratch: row blocks per block column (sorted) with their row offsets in the column, the column lengths,
  // and the new compressed-column arrays.
  std::vector<std::vector<int>> rows_of_;
  std::vector<std::vector<int>> row_offset_;
  std::vector<int> column_length_;
  std::vector<std::ptrdiff_t> column_base_;     // BuildPattern: per block column, see ValueIndex
  std::vector<int> block_stamp_, block_count_;  // BuildPattern: per block, the factor that last took it and how often
  std::vector<int> outer_, inner_;
  // The block pattern (dims_ and rows_of_) that H's pattern was built for, and the last few other patterns of a small
  // system with their H (BuildPattern), oldest first.
  std::vector<int> pattern_dims_;
  std::vector<std::vector<int>> pattern_rows_of_;
  struct PatternCacheEntry {
    std::vector<int> dims;
    std::vector<std::vector<int>> rows_of;
    Eigen::SparseMatrix<double> H;
  };
  std::vector<PatternCacheEntry> pattern_cache_;
  int patterns_built_ = 0;

  Eigen::SparseMatrix<double> H_;
  // With a kept factorization whose leading left_out_blocks_ band columns the next one takes over, H lacks the
  // blocks (r, c), r <= c, with r < left_out_blocks_ and c either before it or in the border (until CompleteHessian);
  // those values are stale. left_out_evaluations_: evaluations_ when Linearize left them out (the products it would
  // add are those of the factors' current Jacobians only until one is evaluated again).
  int left_out_blocks_ = 0;
  long left_out_evaluations_ = 0;
  bool undamped_step_ = false;  // the last Solve since Linearize was undamped and succeeded
  std::vector<std::ptrdiff_t> diagonal_index_;
  Eigen::VectorXd g_;
  double cost_ = 0.0;
  int analyses_ = 0;
  int incremental_resets_ = 0;
  bool natural_order_ = false;  // factor in the order of the blocks, in the envelope (Reset)

  // Cholesky H + lambda diag(H) = U^T U (lambda 0: undamped) of a natural-order system (a band of poses with a dense
  // border of constant parameters), in blocks H = [A B; B^T C], U = [Ua Ub; 0 Uc]: Ua^T Ua = A in A's block envelope
  // (block column b of Ua holds the row blocks first_block_[b]..b as one dense column-major matrix from
  // envelope_start_[b] in envelope_; blocks between a column's first coupled block and the diagonal may fill in, blocks
  // above it cannot), Ub = Ua^-T B and Uc^T Uc = C - Ub^T Ub (dense). The border is the trailing block columns coupled
  // to the first block, at most kMaxBorder columns.
  //
  // Incremental (with a relinearization threshold, undamped): the leading block columns of U depend only on H's
  // leading principal block, so the columns of the last factorization whose rows of H did not change are taken over.
  // A window that slid drops its oldest pose, which takes its block row of U with it: the rest of U is the factor of
  // the Schur complement, which is what the marginalization prior that replaces the pose's factors adds to H again
  // (to rounding, and to the directions its rank floor drops, below 10 n eps of H's scale). So a column is taken
  // over while its variable is the same as the kept column's and no factor on it or a variable before it changed
  // its Jacobians or left since (dirty_), except the new marginalization prior. The border's rows Ub follow the
  // same rule (a row of Ua^-T B depends on B's rows above it); C - Ub^T Ub and Uc are always computed.
  // factor_corner false: Ua and Ub only, corner_ left holding C - Ub^T Ub (BorderInformation). rhs (dimension_
  // values, optional): its band rows are substituted forward, Ua^-T, in the factorization's sweep (a step's
  // right-hand side, solved then with band_forwarded).
  bool FactorEnvelope(const Eigen::SparseMatrix<double>& A, double lambda, bool factor_corner = true,
                      double* rhs = nullptr);
  int ReusableBlocks() const;  // leading band blocks of the kept factorization that hold for this one
  // x <- U^-T x and x <- H^-1 x with the last FactorEnvelope; band_forwarded: x's band rows hold Ua^-T x already.
  void ForwardEnvelope(Eigen::Ref<Eigen::MatrixXd> x, bool band_forwarded = false);
  void SolveEnvelope(Eigen::Ref<Eigen::MatrixXd> x, bool band_forwarded = false);
  // Calls f with the band (a Band<6> when every block of A is a pose, otherwise a Band<Dynamic>, whose kernels are
  // picked per block size).
  template <typename Function>
  void WithBand(Function f);
  int band_blocks_ = 0;            // block columns of A
  bool band_pose_blocks_ = false;  // every block column of A has 6 columns
  int band_dimension_ = 0;         // scalar columns of A
  std::vector<int> first_block_;
  std::vector<std::ptrdiff_t> envelope_start_;
  std::vector<double> envelope_;
  Eigen::MatrixXd border_;          // Ub
  std::vector<int> border_cursor_;  // FactorEnvelope's scatter: per border column, its next entry of A
  Eigen::MatrixXd corner_;          // C, then Uc in its upper triangle

  // The last undamped factorization with a relinearization threshold (its order and band layout; its Ua and Ub stay
  // in envelope_ and border_ until the next factorization swaps them here), and the free variables of factors whose
  // Jacobians changed or that left the system since (FactorEnvelope).
  bool factor_kept_ = false;
  std::vector<VariableId> kept_order_;
  int kept_band_blocks_ = 0;
  std::vector<int> kept_first_block_;
  std::vector<int> kept_block_offset_;
  std::vector<std::ptrdiff_t> kept_envelope_start_;
  std::vector<double> kept_envelope_;
  Eigen::MatrixXd kept_border_;
  std::vector<VariableId> dirty_;
  long reused_blocks_ = 0;

  struct Cholmod;
  std::unique_ptr<Cholmod> cholmod_;
};

}  // namespace roamlab::estimator::internal
