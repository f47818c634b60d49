// NormalEquations::Linearize and the kept linearizations (normal_equations.h): H, g and the cost from the factors'
// whitened Jacobians, with the fixed-size J^T J kernels in this translation unit so that Linearize inlines them.
#include "estimator/internal/normal_equations.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "common/check.h"
#include "common/interrupt.h"
#include "estimator/internal/normal_equations_shared.h"

namespace roamlab::estimator::internal {

namespace {

// dst (A x B block of H's value array, column stride `stride`) += Ja^T Jb, Ja M x A, Jb M x B.
template <int M, int A, int B>
void AddProductFixed(const double* ja, const double* jb, double* dst, std::ptrdiff_t stride) {
  Eigen::Map<Eigen::Matrix<double, A, B>, 0, Eigen::OuterStride<>> block(dst, A, B, Eigen::OuterStride<>(stride));
  block.noalias() +=
      Eigen::Map<const Eigen::Matrix<double, M, A>>(ja).transpose() * Eigen::Map<const Eigen::Matrix<double, M, B>>(jb);
}

// The same with the column counts as template arguments when they are among the block sizes of the error models
// (1: scalar, 3: vector or rotation, 6: pose, 9: 3x3 matrix); false for other sizes.
template <int M, int A>
bool AddProductColumns(const double* ja, const double* jb, int b, double* dst, std::ptrdiff_t stride) {
  switch (b) {
    case 1:
      AddProductFixed<M, A, 1>(ja, jb, dst, stride);
      return true;
    case 3:
      AddProductFixed<M, A, 3>(ja, jb, dst, stride);
      return true;
    case 6:
      AddProductFixed<M, A, 6>(ja, jb, dst, stride);
      return true;
    case 9:
      AddProductFixed<M, A, 9>(ja, jb, dst, stride);
      return true;
    default:
      return false;
  }
}
template <int M>
bool AddProductRows(const double* ja, int a, const double* jb, int b, double* dst, std::ptrdiff_t stride) {
  switch (a) {
    case 1:
      return AddProductColumns<M, 1>(ja, jb, b, dst, stride);
    case 3:
      return AddProductColumns<M, 3>(ja, jb, b, dst, stride);
    case 6:
      return AddProductColumns<M, 6>(ja, jb, b, dst, stride);
    case 9:
      return AddProductColumns<M, 9>(ja, jb, b, dst, stride);
    default:
      return false;
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
    case 1:
      AddBlockFixed<A, 1>(src, transposed, dst, stride);
      return true;
    case 3:
      AddBlockFixed<A, 3>(src, transposed, dst, stride);
      return true;
    case 6:
      AddBlockFixed<A, 6>(src, transposed, dst, stride);
      return true;
    case 9:
      AddBlockFixed<A, 9>(src, transposed, dst, stride);
      return true;
    default:
      return false;
  }
}
void AddBlock(const double* src, int rows, int cols, bool transposed, double* dst, std::ptrdiff_t stride) {
  bool done = false;
  switch (rows) {
    case 1:
      done = AddBlockColumns<1>(src, cols, transposed, dst, stride);
      break;
    case 3:
      done = AddBlockColumns<3>(src, cols, transposed, dst, stride);
      break;
    case 6:
      done = AddBlockColumns<6>(src, cols, transposed, dst, stride);
      break;
    case 9:
      done = AddBlockColumns<9>(src, cols, transposed, dst, stride);
      break;
    default:
      break;
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
    case 1:
      f(std::integral_constant<int, M>(), std::integral_constant<int, 1>());
      return true;
    case 3:
      f(std::integral_constant<int, M>(), std::integral_constant<int, 3>());
      return true;
    case 6:
      f(std::integral_constant<int, M>(), std::integral_constant<int, 6>());
      return true;
    case 9:
      f(std::integral_constant<int, M>(), std::integral_constant<int, 9>());
      return true;
    default:
      return false;
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

// Whether an interruption arrived, looked at every 4096th factor: a whole drive's linearization takes seconds on a
// loaded machine, and the solver stops when it notices one (estimator/solver.cc).
bool Interrupted(std::size_t k) { return k % 4096 == 4095 && InterruptRequested(); }

}  // namespace

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
    if (Interrupted(k)) {
      if (failed_stream != nullptr) failed_stream->clear();
      return false;
    }
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
    if (!FactorCostAt(entry, &values_[var_begin_[k]], SqrtCovariance(entry, linearized_[k].whitened), &c)) return false;
    *cost += c;
  }
  return true;
}

bool NormalEquations::LinearizeForCost(double* cost) {
  *cost = 0.0;
  for (std::size_t k = 0; k < factor_ids_.size(); ++k) {
    if (Interrupted(k)) return false;
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
  const FactorLinearization& l =
      linearized_[std::lower_bound(factor_ids_.begin(), factor_ids_.end(), id) - factor_ids_.begin()];
  return l.products_valid ? &l.products : nullptr;
}

const WhitenedFactor* NormalEquations::LinearizationAt(FactorId id, std::uint64_t want_mask) const {
  const auto it = std::lower_bound(factor_ids_.begin(), factor_ids_.end(), id);
  if (it == factor_ids_.end() || *it != id) return nullptr;
  const std::size_t k = static_cast<std::size_t>(it - factor_ids_.begin());
  if (want_[k] != want_mask || !Current(k)) return nullptr;
  return &linearized_[k].whitened;
}

}  // namespace roamlab::estimator::internal
