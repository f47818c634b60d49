// Checks of a manifold's invariants (in the spirit of Ceres' manifold invariants), for the manifolds of
// estimator/manifold.h. At a point x and at several seeded random tangent vectors d and points y:
//   x [+] 0 == x,   (x [+] d) [-] x == d,   x [+] (y [-] x) == y,   x [-] x == 0,
// and the Jacobians the estimator uses:
//   - the Plus Jacobian d(x [+] delta)/d(delta) (ambient x tangent), which AutoDiffFactor takes from the compile-time
//     block's Plus with jets (factor.h), against central differences of Manifold::Plus, at delta = 0 and at delta = d;
//   - the Minus Jacobian d((x [+] delta) [-] x)/d(delta) at delta = 0, which must be the identity (box-minus undoes
//     box-plus to first order), by central differences;
//   - their product: the ambient Jacobian of y [-] x in y at y = x (central differences) times the Plus Jacobian is the
//     identity.
//
// Tolerances. An identity such as x [+] 0 == x is a handful of floating-point operations: its error is a small multiple
// of eps relative to the scale of the numbers (kRoundingUlps eps (1 + |x| + |d|)). A central difference with step h
// has a truncation error h^2/6 max|f'''| and a rounding error eps max|f| / h; with h = cbrt(eps) both are about
// eps^(2/3) ~ 4e-11 times the function's scale (CentralDifferenceTolerance).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include <Eigen/Core>

#include "estimator/jet.h"
#include "estimator/manifold.h"

namespace roamlab::estimator::testing {

inline constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
// Bound on the rounding of an identity built from a few products, an Exp and a Log, in units of eps.
inline constexpr double kRoundingUlps = 64.0;

// Step of a central difference for a function whose argument has scale `scale`: cbrt(eps) scale.
inline double CentralDifferenceStep(double scale = 1.0) { return std::cbrt(kEpsilon) * scale; }

// Bound on the error of a central difference with step h of a function of scale `scale` (its value and its third
// derivative bounded by it): h^2/6 scale + eps scale / h, with a margin of 10.
inline double CentralDifferenceTolerance(double h, double scale = 1.0) {
  return 10.0 * (h * h / 6.0 + kEpsilon / h) * scale;
}

// Central-difference Jacobian of a vector function f at `at` with step h, column by column.
template <typename Function>
Eigen::MatrixXd CentralDifferenceJacobian(const Function& f, const Eigen::VectorXd& at,
                                          double h = CentralDifferenceStep()) {
  Eigen::MatrixXd jacobian;
  for (int k = 0; k < at.size(); ++k) {
    const Eigen::VectorXd e = h * Eigen::VectorXd::Unit(at.size(), k);
    const Eigen::VectorXd column = (f(at + e) - f(at - e)) / (2.0 * h);
    if (k == 0) jacobian.resize(column.size(), at.size());
    jacobian.col(k) = column;
  }
  return jacobian;
}

// Distance between two ambient points that stand for the same element: the rotation parts of unit quaternions and
// poses are compared up to sign (q and -q are the same rotation).
double AmbientDistance(const Manifold& manifold, const Eigen::VectorXd& a, const Eigen::VectorXd& b);

// A random tangent vector: Gaussian of standard deviation `scale` in Euclidean components, and for a rotation part a
// uniformly random axis with an angle uniform in [0, max_angle] (below pi, so that Log inverts Exp).
Eigen::VectorXd RandomTangent(const Manifold& manifold, std::mt19937* rng, double scale = 1.0, double max_angle = 3.0);

// x [+] delta and y [-] x as vectors.
Eigen::VectorXd Plus(const Manifold& manifold, const Eigen::VectorXd& x, const Eigen::VectorXd& delta);
Eigen::VectorXd Minus(const Manifold& manifold, const Eigen::VectorXd& y, const Eigen::VectorXd& x);

// Central-difference Jacobians: d(x [+] delta)/d(delta) at `delta` (ambient x tangent), d((x [+] delta) [-] x)/d(delta)
// at 0 (tangent x tangent), and d(y [-] x)/dy at y = x in ambient coordinates (tangent x ambient).
Eigen::MatrixXd NumericPlusJacobian(const Manifold& manifold, const Eigen::VectorXd& x, const Eigen::VectorXd& delta);
Eigen::MatrixXd NumericMinusPlusJacobian(const Manifold& manifold, const Eigen::VectorXd& x);
Eigen::MatrixXd NumericAmbientMinusJacobian(const Manifold& manifold, const Eigen::VectorXd& x);

// The invariants that need only the runtime interface (Plus, Minus), at x, for `trials` random tangent vectors (of
// scale `scale`) and random points, seeded by `seed`.
void ExpectManifoldInvariantsHold(const Manifold& manifold, const Eigen::VectorXd& x, std::uint32_t seed,
                                  int trials = 8, double scale = 1.0);

// The Plus Jacobian of a compile-time block (PoseBlock, QuaternionBlock, VectorBlock<N>) from jets at delta.
template <typename Block>
Eigen::MatrixXd JetPlusJacobian(const Eigen::VectorXd& x, const Eigen::VectorXd& delta) {
  using J = Jet<Block::kTangent>;
  J d[Block::kTangent];
  for (int k = 0; k < Block::kTangent; ++k) d[k] = J(delta[k], k);
  J out[Block::kAmbient];
  Block::template Plus<J>(x.data(), d, out);
  Eigen::MatrixXd jacobian(Block::kAmbient, Block::kTangent);
  for (int i = 0; i < Block::kAmbient; ++i) jacobian.row(i) = out[i].v.transpose();
  return jacobian;
}

// Every invariant of a compile-time block: those of its runtime manifold (above), its Plus with doubles the same as
// the runtime one, and its jet Plus Jacobian against central differences and against the Minus Jacobian.
template <typename Block>
void ExpectBlockInvariantsHold(const Eigen::VectorXd& x, std::uint32_t seed, int trials = 8, double scale = 1.0) {
  const Manifold manifold = Block::manifold();
  ASSERT_EQ(manifold.ambient_dim(), Block::kAmbient);
  ASSERT_EQ(manifold.tangent_dim(), Block::kTangent);
  ExpectManifoldInvariantsHold(manifold, x, seed, trials, scale);
  std::mt19937 rng(seed);
  const double x_scale = 1.0 + x.lpNorm<Eigen::Infinity>();
  const Eigen::MatrixXd minus_jacobian = NumericAmbientMinusJacobian(manifold, x);
  for (int trial = 0; trial <= trials; ++trial) {
    SCOPED_TRACE(::testing::Message() << manifold.Name() << " trial " << trial);
    // Trial 0 at delta = 0 (what AutoDiffFactor evaluates), the others at random tangent vectors.
    const Eigen::VectorXd delta =
        trial == 0 ? Eigen::VectorXd::Zero(Block::kTangent) : RandomTangent(manifold, &rng, scale);
    Eigen::VectorXd plus_block(Block::kAmbient);
    Block::template Plus<double>(x.data(), delta.data(), plus_block.data());
    EXPECT_EQ(plus_block, Plus(manifold, x, delta));
    const Eigen::MatrixXd jet = JetPlusJacobian<Block>(x, delta);
    const double h = CentralDifferenceStep();
    const double tolerance = CentralDifferenceTolerance(h, x_scale + delta.norm());
    EXPECT_LE((jet - NumericPlusJacobian(manifold, x, delta)).lpNorm<Eigen::Infinity>(), tolerance)
        << "jet Plus Jacobian\n"
        << jet << "\nnumeric\n"
        << NumericPlusJacobian(manifold, x, delta);
    if (trial == 0) {
      const Eigen::MatrixXd product = minus_jacobian * jet;
      const Eigen::MatrixXd off_identity =
          product - Eigen::MatrixXd::Identity(manifold.tangent_dim(), manifold.tangent_dim());
      EXPECT_LE(off_identity.lpNorm<Eigen::Infinity>(), tolerance) << "Minus Jacobian times Plus Jacobian\n" << product;
    }
  }
}

}  // namespace roamlab::estimator::testing
