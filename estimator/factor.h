// Hyper-edges of the estimation graph.
//
// A Factor computes the un-whitened error e(x, eta) of one measurement and, when asked, its Jacobians with respect to
// the tangent-space perturbation of every connected variable (J_e_x[i], residual_dim x tangent_dim(i), column-major)
// and with respect to the noise eta (J_e_eta, residual_dim x noise_dim). The graph combines J_e_eta with the noise
// covariance into the error covariance of the seed's eq. 1 and whitens; robust losses are applied there too.
//
// Error models are small functors (see estimator/models/) wrapped by AutoDiffFactor, which differentiates them with
// jets: every block is perturbed as x [+] d with d = 0 carrying one derivative slot per tangent coordinate, and the
// noise carries one slot per component, so one evaluation yields both Jacobians exactly.
//
// A model looks like
//   struct GpsError {
//     using Blocks = std::tuple<PoseBlock, Vector3Block>;   // variables, in order
//     static constexpr int kResidualDim = 3;
//     static constexpr int kNoiseDim = 3;
//     template <typename T>
//     bool operator()(const T* const* x, const T* noise, T* error) const;  // x[i]: ambient values of block i
//   };
#pragma once

#include <array>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include "estimator/internal/jet.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {

class Factor {
 public:
  virtual ~Factor() = default;
  virtual int residual_dim() const = 0;
  virtual int noise_dim() const = 0;
  // One manifold per connected variable, in order.
  virtual const std::vector<Manifold>& manifolds() const = 0;
  // values[i]: ambient values of variable i. error: residual_dim entries. jacobians: null, or one pointer per variable
  // (each may be null) to a column-major residual_dim x tangent_dim block. noise_jacobian: null or column-major
  // residual_dim x noise_dim. Returns false when the error cannot be evaluated (for example a NaN).
  virtual bool Evaluate(const double* const* values, double* error, double* const* jacobians,
                        double* noise_jacobian) const = 0;
};

namespace internal {
template <typename Tuple> struct BlockSizes;
template <typename... B>
struct BlockSizes<std::tuple<B...>> {
  static constexpr int kCount = sizeof...(B);
  static constexpr int kTangentSum = (0 + ... + B::kTangent);
  static constexpr int kAmbientMax = std::max({0, B::kAmbient...});
};
}  // namespace internal

template <typename Model>
class AutoDiffFactor final : public Factor {
 public:
  using Blocks = typename Model::Blocks;
  static constexpr int kBlockCount = internal::BlockSizes<Blocks>::kCount;
  static constexpr int kSlots = internal::BlockSizes<Blocks>::kTangentSum + Model::kNoiseDim;
  using JetT = Jet<kSlots>;

  explicit AutoDiffFactor(Model model) : model_(std::move(model)) {
    FillManifolds(std::make_index_sequence<kBlockCount>());
  }

  const Model& model() const { return model_; }
  int residual_dim() const override { return Model::kResidualDim; }
  int noise_dim() const override { return Model::kNoiseDim; }
  const std::vector<Manifold>& manifolds() const override { return manifolds_; }

  bool Evaluate(const double* const* values, double* error, double* const* jacobians,
                double* noise_jacobian) const override {
    if (jacobians == nullptr && noise_jacobian == nullptr) {
      std::array<double, Model::kNoiseDim + 1> zero_noise{};
      return model_(values, zero_noise.data(), error) && AllFinite(error);
    }
    // Perturb every block by a jet-valued zero tangent vector, and the noise by jet-valued zeros.
    std::array<std::array<JetT, internal::BlockSizes<Blocks>::kAmbientMax>, kBlockCount> perturbed;
    std::array<const JetT*, kBlockCount> block_ptrs;
    PerturbBlocks(values, &perturbed, std::make_index_sequence<kBlockCount>());
    for (int i = 0; i < kBlockCount; ++i) block_ptrs[i] = perturbed[i].data();
    std::array<JetT, Model::kNoiseDim + 1> noise;
    for (int k = 0; k < Model::kNoiseDim; ++k) noise[k] = JetT(0.0, kSlots - Model::kNoiseDim + k);

    std::array<JetT, Model::kResidualDim> e;
    if (!model_(block_ptrs.data(), noise.data(), e.data())) return false;

    // Scatter values and derivative slots.
    for (int r = 0; r < Model::kResidualDim; ++r) {
      error[r] = e[r].a;
      if (!std::isfinite(e[r].a) || !e[r].v.allFinite()) return false;
    }
    if (jacobians != nullptr) {
      int slot = 0;
      for (int i = 0; i < kBlockCount; ++i) {
        const int dim = manifolds_[i].tangent_dim();
        if (jacobians[i] != nullptr) {
          for (int c = 0; c < dim; ++c)
            for (int r = 0; r < Model::kResidualDim; ++r) jacobians[i][c * Model::kResidualDim + r] = e[r].v[slot + c];
        }
        slot += dim;
      }
    }
    if (noise_jacobian != nullptr) {
      const int first = kSlots - Model::kNoiseDim;
      for (int c = 0; c < Model::kNoiseDim; ++c)
        for (int r = 0; r < Model::kResidualDim; ++r) noise_jacobian[c * Model::kResidualDim + r] = e[r].v[first + c];
    }
    return true;
  }

 private:
  static bool AllFinite(const double* e) {
    for (int r = 0; r < Model::kResidualDim; ++r)
      if (!std::isfinite(e[r])) return false;
    return true;
  }

  template <std::size_t... I>
  void FillManifolds(std::index_sequence<I...>) {
    (manifolds_.push_back(std::tuple_element_t<I, Blocks>::manifold()), ...);
  }

  template <std::size_t... I, typename Storage>
  static void PerturbBlocks(const double* const* values, Storage* out, std::index_sequence<I...>) {
    int slot = 0;
    (PerturbBlock<std::tuple_element_t<I, Blocks>>(values[I], &slot, (*out)[I].data()), ...);
  }

  template <typename Block>
  static void PerturbBlock(const double* x, int* slot, JetT* out) {
    std::array<JetT, Block::kTangent> delta;
    for (int k = 0; k < Block::kTangent; ++k) delta[k] = JetT(0.0, *slot + k);
    Block::template Plus<JetT>(x, delta.data(), out);
    *slot += Block::kTangent;
  }

  Model model_;
  std::vector<Manifold> manifolds_;
};

template <typename Model>
std::unique_ptr<Factor> MakeFactor(Model model) {
  return std::make_unique<AutoDiffFactor<Model>>(std::move(model));
}

}  // namespace roamlab::estimator
