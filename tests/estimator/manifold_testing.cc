#include "tests/estimator/manifold_testing.h"

#include <algorithm>
#include <vector>

namespace roamlab::estimator::testing {
namespace {

// Offset of the rotation part in the ambient and tangent vectors, or -1 for a Euclidean manifold.
int RotationAmbientOffset(const Manifold& manifold) {
  switch (manifold.kind()) {
    case ManifoldKind::kEuclidean:
      return -1;
    case ManifoldKind::kQuaternion:
      return 0;
    case ManifoldKind::kPose:
      return 3;
  }
  return -1;
}
int RotationTangentOffset(const Manifold& manifold) { return RotationAmbientOffset(manifold); }

}  // namespace

double AmbientDistance(const Manifold& manifold, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const int q = RotationAmbientOffset(manifold);
  if (q < 0) return (a - b).lpNorm<Eigen::Infinity>();
  Eigen::VectorXd flipped = b;
  flipped.segment<4>(q) = -b.segment<4>(q);
  return std::min((a - b).lpNorm<Eigen::Infinity>(), (a - flipped).lpNorm<Eigen::Infinity>());
}

Eigen::VectorXd RandomTangent(const Manifold& manifold, std::mt19937* rng, double scale, double max_angle) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd d = Eigen::VectorXd::NullaryExpr(manifold.tangent_dim(), [&] { return scale * normal(*rng); });
  const int r = RotationTangentOffset(manifold);
  if (r >= 0) {
    std::uniform_real_distribution<double> angle(0.0, max_angle);
    const Eigen::Vector3d axis = Eigen::Vector3d(normal(*rng), normal(*rng), normal(*rng)).normalized();
    d.segment<3>(r) = angle(*rng) * axis;
  }
  return d;
}

Eigen::VectorXd Plus(const Manifold& manifold, const Eigen::VectorXd& x, const Eigen::VectorXd& delta) {
  Eigen::VectorXd out(manifold.ambient_dim());
  manifold.Plus(x.data(), delta.data(), out.data());
  return out;
}

Eigen::VectorXd Minus(const Manifold& manifold, const Eigen::VectorXd& y, const Eigen::VectorXd& x) {
  Eigen::VectorXd d(manifold.tangent_dim());
  manifold.Minus(y.data(), x.data(), d.data());
  return d;
}

Eigen::MatrixXd NumericPlusJacobian(const Manifold& manifold, const Eigen::VectorXd& x, const Eigen::VectorXd& delta) {
  return CentralDifferenceJacobian([&](const Eigen::VectorXd& d) { return Plus(manifold, x, d); }, delta);
}

Eigen::MatrixXd NumericMinusPlusJacobian(const Manifold& manifold, const Eigen::VectorXd& x) {
  return CentralDifferenceJacobian([&](const Eigen::VectorXd& d) { return Minus(manifold, Plus(manifold, x, d), x); },
                                   Eigen::VectorXd::Zero(manifold.tangent_dim()));
}

Eigen::MatrixXd NumericAmbientMinusJacobian(const Manifold& manifold, const Eigen::VectorXd& x) {
  return CentralDifferenceJacobian([&](const Eigen::VectorXd& y) { return Minus(manifold, y, x); }, x);
}

void ExpectManifoldInvariantsHold(const Manifold& manifold, const Eigen::VectorXd& x, std::uint32_t seed, int trials,
                                  double scale) {
  ASSERT_EQ(x.size(), manifold.ambient_dim());
  const int n = manifold.tangent_dim();
  const double x_scale = 1.0 + x.lpNorm<Eigen::Infinity>();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  // x [+] 0 == x and x [-] x == 0.
  EXPECT_LE(AmbientDistance(manifold, Plus(manifold, x, zero), x), kRoundingUlps * kEpsilon * x_scale)
      << manifold.Name() << ": x [+] 0 != x";
  EXPECT_LE(Minus(manifold, x, x).lpNorm<Eigen::Infinity>(), kRoundingUlps * kEpsilon * x_scale)
      << manifold.Name() << ": x [-] x != 0";
  // d((x [+] delta) [-] x)/d(delta) at 0 is the identity.
  const double h = CentralDifferenceStep();
  EXPECT_LE((NumericMinusPlusJacobian(manifold, x) - Eigen::MatrixXd::Identity(n, n)).lpNorm<Eigen::Infinity>(),
            CentralDifferenceTolerance(h, x_scale))
      << manifold.Name() << ": Minus Jacobian of Plus\n"
      << NumericMinusPlusJacobian(manifold, x);

  std::mt19937 rng(seed);
  for (int trial = 0; trial < trials; ++trial) {
    SCOPED_TRACE(::testing::Message() << manifold.Name() << " trial " << trial);
    const Eigen::VectorXd d = RandomTangent(manifold, &rng, scale);
    const double d_scale = x_scale + d.lpNorm<Eigen::Infinity>();
    // (x [+] d) [-] x == d.
    const Eigen::VectorXd y = Plus(manifold, x, d);
    EXPECT_LE((Minus(manifold, y, x) - d).lpNorm<Eigen::Infinity>(), kRoundingUlps * kEpsilon * d_scale)
        << "d = " << d.transpose() << "\n(x [+] d) [-] x = " << Minus(manifold, y, x).transpose();
    // x [+] (z [-] x) == z for a random point z (near x when x is far from the origin: a pose's position).
    const Eigen::VectorXd z = Plus(manifold, x, RandomTangent(manifold, &rng, scale));
    const Eigen::VectorXd back = Plus(manifold, x, Minus(manifold, z, x));
    EXPECT_LE(AmbientDistance(manifold, back, z), kRoundingUlps * kEpsilon * (x_scale + z.lpNorm<Eigen::Infinity>()))
        << "z = " << z.transpose() << "\nx [+] (z [-] x) = " << back.transpose();
  }
}

}  // namespace roamlab::estimator::testing
