// Prior on one variable of any kind: the initial pose that anchors the world frame, the default values of calibration
// parameters (seed 000, Section V starts them at S^(O) = 0, A = I, ...), or a previous calibration.
//
//   e = x [-] x0 + eta,          e, eta in R^d, d = tangent dimension of the block
//
// Box-minus as in geometry.h (x [-] x0 = d with x0 [+] d = x):
//   VectorBlock<N>:   x - x0
//   QuaternionBlock:  Log(q0^-1 q)                                  (rotation vector in the frame of q0 [rad])
//   PoseBlock:        [p - p0 (W, m);  Log(q0^-1 q) (body, rad)]
// Noise: eta ~ N(0, Sigma_prior) in the same tangent coordinates, so Sigma_prior is the covariance of the prior. The
// Jacobian with respect to the variable is the identity at x = x0.
// Variables: the variable itself (Block).
#pragma once

#include <cmath>
#include <tuple>

#include <Eigen/Core>

#include "common/check.h"
#include "estimator/geometry.h"
#include "estimator/manifold.h"

namespace roamlab::estimator {
namespace internal {

// delta = x [-] x0 for each block kind (x0 in doubles, x and delta in T).
template <typename T, int N>
void PriorBoxMinus(VectorBlock<N>, const T* x, const double* x0, T* delta) {
  for (int i = 0; i < N; ++i) delta[i] = x[i] - T(x0[i]);
}

template <typename T>
void PriorBoxMinus(QuaternionBlock, const T* x, const double* x0, T* delta) {
  const Quaternion<T> q0 = QuaternionFromArray(x0).template cast<T>();
  Eigen::Map<Vector3<T>> rotation(delta);
  rotation = QuaternionLog<T>(q0.conjugate() * QuaternionFromArray(x));
}

template <typename T>
void PriorBoxMinus(PoseBlock, const T* x, const double* x0, T* delta) {
  for (int i = 0; i < 3; ++i) delta[i] = x[i] - T(x0[i]);
  PriorBoxMinus<T>(QuaternionBlock(), x + 3, x0 + 3, delta + 3);
}

}  // namespace internal

template <typename Block>
class PriorError {
 public:
  using Blocks = std::tuple<Block>;
  static constexpr int kResidualDim = Block::kTangent;
  static constexpr int kNoiseDim = Block::kTangent;
  static constexpr bool kAdditiveNoise = true;  // e = f(x) + eta

  // x0: the prior value in the block's ambient representation (quaternions [w, x, y, z], unit norm).
  explicit PriorError(const Eigen::VectorXd& x0) : x0_(x0) {
    ROAMLAB_CHECK(x0.size() == Block::kAmbient,
                  "prior of size " << x0.size() << " for a block of ambient size " << Block::kAmbient);
    if (Block::manifold().kind() != ManifoldKind::kEuclidean) {
      ROAMLAB_CHECK(std::abs(x0.tail<4>().norm() - 1.0) < 1e-6,
                    "prior quaternion " << x0.tail<4>().transpose() << " is not unit-norm");
    }
  }

  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    internal::PriorBoxMinus<T>(Block(), x[0], x0_.data(), error);
    for (int i = 0; i < kResidualDim; ++i) error[i] += noise[i];
    return true;
  }

  const Eigen::VectorXd& x0() const { return x0_; }

 private:
  Eigen::VectorXd x0_;
};

}  // namespace roamlab::estimator
