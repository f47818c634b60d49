// The spaces estimator variables live in, and their box-plus / box-minus (conventions in geometry.h).
//
// Runtime side: Manifold describes a variable (Euclidean vector, unit quaternion or pose) for the graph and solver.
// Compile-time side: PoseBlock, QuaternionBlock and VectorBlock<N> name the blocks an error model reads, so that
// AutoDiffFactor (factor.h) can size its jets and apply box-plus with jet perturbations.
#pragma once

#include <string>

#include <Eigen/Core>

#include "estimator/geometry.h"

namespace roamlab::estimator {

enum class ManifoldKind { kEuclidean, kQuaternion, kPose };

class Manifold {
 public:
  static Manifold Euclidean(int dim) { return Manifold(ManifoldKind::kEuclidean, dim, dim); }
  static Manifold UnitQuaternion() { return Manifold(ManifoldKind::kQuaternion, 4, 3); }
  static Manifold Pose() { return Manifold(ManifoldKind::kPose, 7, 6); }

  ManifoldKind kind() const { return kind_; }
  int ambient_dim() const { return ambient_dim_; }
  int tangent_dim() const { return tangent_dim_; }
  std::string Name() const;

  // out = x [+] delta. x and out have ambient_dim entries, delta tangent_dim. out may alias x.
  void Plus(const double* x, const double* delta, double* out) const;
  // delta = x [-] y, so that y [+] delta = x.
  void Minus(const double* x, const double* y, double* delta) const;
  // The identity element: zeros, [1, 0, 0, 0], or the origin pose.
  Eigen::VectorXd Identity() const;

  friend bool operator==(const Manifold& a, const Manifold& b) {
    return a.kind_ == b.kind_ && a.ambient_dim_ == b.ambient_dim_;
  }

 private:
  Manifold(ManifoldKind kind, int ambient, int tangent) : kind_(kind), ambient_dim_(ambient), tangent_dim_(tangent) {}
  ManifoldKind kind_;
  int ambient_dim_;
  int tangent_dim_;
};

struct PoseBlock {
  static constexpr int kAmbient = 7;
  static constexpr int kTangent = 6;
  static Manifold manifold() { return Manifold::Pose(); }
  template <typename T>
  static void Plus(const double* x, const T* delta, T* out) {
    for (int i = 0; i < 3; ++i) out[i] = T(x[i]) + delta[i];
    const Quaternion<T> q{T(x[3]), T(x[4]), T(x[5]), T(x[6])};
    QuaternionToArray<T>(q * QuaternionExp<T>(Vector3<T>(delta[3], delta[4], delta[5])), out + 3);
  }
};

struct QuaternionBlock {
  static constexpr int kAmbient = 4;
  static constexpr int kTangent = 3;
  static Manifold manifold() { return Manifold::UnitQuaternion(); }
  template <typename T>
  static void Plus(const double* x, const T* delta, T* out) {
    const Quaternion<T> q{T(x[0]), T(x[1]), T(x[2]), T(x[3])};
    QuaternionToArray<T>(q * QuaternionExp<T>(Vector3<T>(delta[0], delta[1], delta[2])), out);
  }
};

template <int N>
struct VectorBlock {
  static constexpr int kAmbient = N;
  static constexpr int kTangent = N;
  static Manifold manifold() { return Manifold::Euclidean(N); }
  template <typename T>
  static void Plus(const double* x, const T* delta, T* out) {
    for (int i = 0; i < N; ++i) out[i] = T(x[i]) + delta[i];
  }
};

using ScalarBlock = VectorBlock<1>;
using Vector3Block = VectorBlock<3>;
using Matrix3Block = VectorBlock<9>;  // 3x3 matrix, row-major

}  // namespace roamlab::estimator
