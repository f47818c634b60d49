// NormalEquations' factorizations and solves (normal_equations.h): CHOLMOD's symbolic analysis and Cholesky, or the
// envelope factorization of a system in natural order with its band kernels; the step, the model decrease, marginal
// covariances and the border's information.
#include "estimator/internal/normal_equations.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "common/check.h"
#include "estimator/internal/normal_equations_shared.h"

namespace roamlab::estimator::internal {

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

bool NormalEquations::Solve(double lambda, Eigen::VectorXd* dx, Damping damping) {
  Cholmod& c = *cholmod_;
  undamped_step_ = false;
  damped_.assign(dimension_, 1);
  if (damping == Damping::kConstantsOnly)
    for (std::size_t b = 0; b < order_.size(); ++b)
      std::fill_n(damped_.begin() + block_offset_[b], dims_[b], static_cast<char>(full_column_[b]));
  const Eigen::SparseMatrix<double>* A = &H_;
  if (lambda > 0.0 && !natural_order_) {  // (the envelope takes H_ and adds the damping as it copies it)
    CompleteHessian();
    c.damped = H_;
    double* v = c.damped.valuePtr();
    for (int i = 0; i < dimension_; ++i)
      if (damped_[i]) v[diagonal_index_[i]] += lambda * std::max(v[diagonal_index_[i]], 1e-12);
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
    const int shift =
        static_cast<int>(std::find(kept_order_.begin(), kept_order_.end(), order_.front()) - kept_order_.begin());
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
    // Without border columns the border has no storage: a block of it would offset a null pointer.
    if (border_.cols() > 0) border_.topRows(reused_rows) = kept_border_.middleRows(row_shift, reused_rows);
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
      if (!undamped && damped_[j]) column[j] += lambda * std::max(column[j], 1e-12);
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
    if (!undamped && damped_[j]) diagonal += lambda * std::max(diagonal, 1e-12);
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

}  // namespace roamlab::estimator::internal
