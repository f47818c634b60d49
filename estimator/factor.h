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
// A model may also provide analytic Jacobians (where profiling asks for them; the jets stay their test oracle):
//   bool Linearize(const double* const* x, double* error, double* const* jacobians, double* noise_jacobian) const;
// with Factor::Evaluate's layout and zero noise. AutoDiffFactor then calls it whenever a Jacobian is requested; it
// must fill exactly the requested blocks (a null jacobians[i] is skipped) and the same error as operator(). Models
// with kAdditiveNoise may ignore noise_jacobian: AutoDiffFactor fills the identity. EvaluateWithAutoDiff keeps the
// jet path available to the tests.
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
#include <cmath>
#include <memory>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "estimator/jet.h"
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
  // True when e = f(x) + eta exactly: J_e_eta is the identity and the error covariance is the noise covariance, so
  // it can be whitened once (graph.h) instead of at every linearization.
  virtual bool additive_noise() const { return false; }
};

namespace internal {
// Model::kAdditiveNoise, false when the model does not declare it.
template <typename Model, typename = void>
struct AdditiveNoise : std::false_type {};
template <typename Model>
struct AdditiveNoise<Model, std::void_t<decltype(Model::kAdditiveNoise)>>
    : std::integral_constant<bool, Model::kAdditiveNoise> {};

// True when the model has the analytic hook `bool Linearize(x, error, jacobians, noise_jacobian) const`.
template <typename Model>
using LinearizeResult =
    decltype(std::declval<const Model&>().Linearize(std::declval<const double* const*>(), std::declval<double*>(),
                                                    std::declval<double* const*>(), std::declval<double*>()));
template <typename Model, typename = void>
struct HasLinearize : std::false_type {};
template <typename Model>
struct HasLinearize<Model, std::void_t<LinearizeResult<Model>>> : std::is_same<LinearizeResult<Model>, bool> {};

template <typename Tuple>
struct BlockSizes;
template <typename... B>
struct BlockSizes<std::tuple<B...>> {
  static constexpr int kCount = sizeof...(B);
  static constexpr int kTangentSum = (0 + ... + B::kTangent);
  static constexpr int kAmbientMax = std::max({0, B::kAmbient...});
  static constexpr int kPoseTangentSum = (0 + ... + (std::is_same_v<B, PoseBlock> ? B::kTangent : 0));
};
}  // namespace internal

template <typename Model>
class AutoDiffFactor final : public Factor {
 public:
  using Blocks = typename Model::Blocks;
  static constexpr int kBlockCount = internal::BlockSizes<Blocks>::kCount;
  static constexpr bool kAdditive = internal::AdditiveNoise<Model>::value;
  // Derivative slots for the noise; none when the noise is additive (its Jacobian is the identity).
  static constexpr int kNoiseSlots = kAdditive ? 0 : Model::kNoiseDim;
  static constexpr int kSlots = internal::BlockSizes<Blocks>::kTangentSum + kNoiseSlots;
  static constexpr bool kAnalytic = internal::HasLinearize<Model>::value;

  explicit AutoDiffFactor(Model model) : model_(std::move(model)) {
    FillManifolds(std::make_index_sequence<kBlockCount>());
  }

  const Model& model() const { return model_; }
  int residual_dim() const override { return Model::kResidualDim; }
  int noise_dim() const override { return Model::kNoiseDim; }
  const std::vector<Manifold>& manifolds() const override { return manifolds_; }
  bool additive_noise() const override { return kAdditive; }

  bool Evaluate(const double* const* values, double* error, double* const* jacobians,
                double* noise_jacobian) const override {
    if (jacobians == nullptr && noise_jacobian == nullptr) {
      std::array<double, Model::kNoiseDim + 1> zero_noise{};
      return model_(values, zero_noise.data(), error) && AllFinite(error);
    }
    if constexpr (kAnalytic) {
      return EvaluateAnalytic(values, error, jacobians, noise_jacobian);
    } else {
      return EvaluateWithAutoDiff(values, error, jacobians, noise_jacobian);
    }
  }

  // Evaluate through the jets, also for models with analytic Jacobians (their oracle in the tests).
  bool EvaluateWithAutoDiff(const double* const* values, double* error, double* const* jacobians,
                            double* noise_jacobian) const {
    // When no Jacobian of a non-pose block is asked for (parameters held fixed, as in tracking), smaller jets that
    // carry only the pose and noise slots do the same work.
    bool parameters_wanted = false;
    for (int i = 0; i < kBlockCount && jacobians != nullptr; ++i)
      parameters_wanted |= jacobians[i] != nullptr && manifolds_[i].kind() != ManifoldKind::kPose;
    if (parameters_wanted) return EvaluateWithJets<kSlots, true>(values, error, jacobians, noise_jacobian);
    return EvaluateWithJets<kPoseSlots, false>(values, error, jacobians, noise_jacobian);
  }

 private:
  static constexpr int kPoseSlots = internal::BlockSizes<Blocks>::kPoseTangentSum + kNoiseSlots;

  // The model's Linearize, the identity noise Jacobian of additive noise, and the finiteness check of the jet path
  // (on what was requested).
  bool EvaluateAnalytic(const double* const* values, double* error, double* const* jacobians,
                        double* noise_jacobian) const {
    if (!model_.Linearize(values, error, jacobians, noise_jacobian)) return false;
    if (kAdditive && noise_jacobian != nullptr) {
      for (int c = 0; c < Model::kNoiseDim; ++c)
        for (int r = 0; r < Model::kResidualDim; ++r) noise_jacobian[c * Model::kResidualDim + r] = r == c ? 1.0 : 0.0;
    }
    if (!AllFinite(error)) return false;
    for (int i = 0; i < kBlockCount && jacobians != nullptr; ++i) {
      if (jacobians[i] != nullptr && !AllFinite(jacobians[i], Model::kResidualDim * manifolds_[i].tangent_dim()))
        return false;
    }
    return noise_jacobian == nullptr || AllFinite(noise_jacobian, Model::kResidualDim * Model::kNoiseDim);
  }

  // Every block with a slot range (all blocks, or poses only) is perturbed by a jet-valued zero tangent vector; the
  // others enter as constants. The noise always has slots, after the blocks'.
  template <int N, bool kAllBlocks>
  bool EvaluateWithJets(const double* const* values, double* error, double* const* jacobians,
                        double* noise_jacobian) const {
    using J = Jet<N>;
    std::array<std::array<J, internal::BlockSizes<Blocks>::kAmbientMax>, kBlockCount> perturbed;
    std::array<const J*, kBlockCount> block_ptrs;
    std::array<int, kBlockCount> first_slot;
    PerturbBlocks<J, kAllBlocks>(values, &perturbed, &first_slot, std::make_index_sequence<kBlockCount>());
    for (int i = 0; i < kBlockCount; ++i) block_ptrs[i] = perturbed[i].data();
    std::array<J, Model::kNoiseDim + 1> noise;
    for (int k = 0; k < Model::kNoiseDim; ++k) noise[k] = kAdditive ? J(0.0) : J(0.0, N - Model::kNoiseDim + k);

    std::array<J, Model::kResidualDim> e;
    if (!model_(block_ptrs.data(), noise.data(), e.data())) return false;

    // Scatter values and derivative slots.
    for (int r = 0; r < Model::kResidualDim; ++r) {
      error[r] = e[r].a;
      if (!std::isfinite(e[r].a) || !e[r].v.allFinite()) return false;
    }
    if (jacobians != nullptr) {
      for (int i = 0; i < kBlockCount; ++i) {
        if (jacobians[i] == nullptr) continue;
        const int dim = manifolds_[i].tangent_dim();
        for (int c = 0; c < dim; ++c)
          for (int r = 0; r < Model::kResidualDim; ++r)
            jacobians[i][c * Model::kResidualDim + r] = first_slot[i] >= 0 ? e[r].v[first_slot[i] + c] : 0.0;
      }
    }
    if (noise_jacobian != nullptr) {
      const int first = N - Model::kNoiseDim;
      for (int c = 0; c < Model::kNoiseDim; ++c)
        for (int r = 0; r < Model::kResidualDim; ++r)
          noise_jacobian[c * Model::kResidualDim + r] = kAdditive ? (r == c ? 1.0 : 0.0) : e[r].v[first + c];
    }
    return true;
  }

  static bool AllFinite(const double* e, int n = Model::kResidualDim) {
    for (int r = 0; r < n; ++r)
      if (!std::isfinite(e[r])) return false;
    return true;
  }

  template <std::size_t... I>
  void FillManifolds(std::index_sequence<I...>) {
    (manifolds_.push_back(std::tuple_element_t<I, Blocks>::manifold()), ...);
  }

  template <typename J, bool kAllBlocks, std::size_t... I, typename Storage>
  static void PerturbBlocks(const double* const* values, Storage* out, std::array<int, kBlockCount>* first_slot,
                            std::index_sequence<I...>) {
    int slot = 0;
    (PerturbBlock<J, kAllBlocks, std::tuple_element_t<I, Blocks>>(values[I], &slot, (*out)[I].data(),
                                                                  &(*first_slot)[I]),
     ...);
  }

  template <typename J, bool kAllBlocks, typename Block>
  static void PerturbBlock(const double* x, int* slot, J* out, int* first_slot) {
    std::array<J, Block::kTangent> delta;
    if (kAllBlocks || std::is_same_v<Block, PoseBlock>) {
      *first_slot = *slot;
      for (int k = 0; k < Block::kTangent; ++k) delta[k] = J(0.0, *slot + k);
      *slot += Block::kTangent;
    } else {
      *first_slot = -1;
      for (int k = 0; k < Block::kTangent; ++k) delta[k] = J(0.0);
    }
    Block::template Plus<J>(x, delta.data(), out);
  }

  Model model_;
  std::vector<Manifold> manifolds_;
};

template <typename Model>
std::unique_ptr<Factor> MakeFactor(Model model) {
  return std::make_unique<AutoDiffFactor<Model>>(std::move(model));
}

}  // namespace roamlab::estimator
