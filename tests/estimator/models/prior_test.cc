#include "estimator/models/prior.h"

#include <random>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "tests/estimator/factor_testing.h"

namespace roamlab::estimator {
namespace {

using testing::RandomPoint;

// The same checks for every block kind.
template <typename Block>
class PriorErrorTest : public ::testing::Test {};
using BlockKinds = ::testing::Types<PoseBlock, QuaternionBlock, Vector3Block>;
TYPED_TEST_SUITE(PriorErrorTest, BlockKinds);

TYPED_TEST(PriorErrorTest, ZeroAtPriorWithIdentityJacobian) {
  constexpr int kDim = TypeParam::kTangent;
  std::mt19937 rng(41);
  const Manifold manifold = TypeParam::manifold();
  const Eigen::VectorXd x0 = RandomPoint(manifold, &rng, 10.0);
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(PriorError<TypeParam>(x0)), {x0});
  EXPECT_LT(lin.error.norm(), 1e-12);
  EXPECT_LT((lin.jacobians[0] - Eigen::MatrixXd::Identity(kDim, kDim)).cwiseAbs().maxCoeff(), 1e-12)
      << lin.jacobians[0];
  EXPECT_LT((lin.noise_jacobian - Eigen::MatrixXd::Identity(kDim, kDim)).cwiseAbs().maxCoeff(), 1e-15);
}

TYPED_TEST(PriorErrorTest, ErrorIsTheTangentStepFromThePrior) {
  // x = x0 [+] d (the manifold's own box-plus) must give e = d.
  std::mt19937 rng(42);
  const Manifold manifold = TypeParam::manifold();
  const auto normal = [&rng] { return std::normal_distribution<double>(0.0, 0.7)(rng); };
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::VectorXd x0 = RandomPoint(manifold, &rng, 10.0);
    Eigen::VectorXd d(manifold.tangent_dim());
    for (int i = 0; i < d.size(); ++i) d[i] = normal();
    Eigen::VectorXd x(manifold.ambient_dim());
    manifold.Plus(x0.data(), d.data(), x.data());
    const testing::Linearization lin = testing::Evaluate(*MakeFactor(PriorError<TypeParam>(x0)), {x});
    EXPECT_LT((lin.error - d).norm(), 1e-12) << lin.error.transpose() << " vs " << d.transpose();
  }
}

TYPED_TEST(PriorErrorTest, JacobiansMatchCentralDifferences) {
  std::mt19937 rng(43);
  const Manifold manifold = TypeParam::manifold();
  for (int trial = 0; trial < 5; ++trial) {
    SCOPED_TRACE(trial);
    const Eigen::VectorXd x0 = RandomPoint(manifold, &rng, 10.0);
    // Near the prior and anywhere.
    for (const Eigen::VectorXd& x : {testing::Perturb(manifold, x0, 0.3, &rng), RandomPoint(manifold, &rng, 10.0)}) {
      const PriorError<TypeParam> model(x0);
      testing::ExpectModelJacobiansMatchNumeric(model, {x});
    }
  }
}

TEST(PriorErrorTest, QuaternionSignDoesNotMatter) {
  std::mt19937 rng(44);
  const Eigen::VectorXd q0 = RandomPoint(Manifold::UnitQuaternion(), &rng);
  const Eigen::VectorXd minus_q0 = -q0;
  EXPECT_LT(testing::Evaluate(*MakeFactor(PriorError<QuaternionBlock>(q0)), {minus_q0}).error.norm(), 1e-12);
}

TEST(PriorErrorTest, PoseErrorSplitsPositionAndBodyRotation) {
  // Position difference in W, rotation difference in the prior's body frame: a 0.1 rad turn about the prior's own z.
  Eigen::VectorXd pose0(7), pose(7);
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond q = q0 * Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()));
  pose0 << 1.0, 2.0, 3.0, q0.w(), q0.x(), q0.y(), q0.z();
  pose << 1.5, 2.0, 2.0, q.w(), q.x(), q.y(), q.z();
  Eigen::Matrix<double, 6, 1> expected;
  expected << 0.5, 0.0, -1.0, 0.0, 0.0, 0.1;
  const testing::Linearization lin = testing::Evaluate(*MakeFactor(PriorError<PoseBlock>(pose0)), {pose});
  EXPECT_LT((lin.error - expected).norm(), 1e-12) << lin.error.transpose();
}

TEST(PriorErrorDeathTest, RejectsWrongSizeAndNonUnitQuaternion) {
  EXPECT_DEATH(PriorError<PoseBlock>(Eigen::VectorXd::Zero(6)), "ambient size 7");
  EXPECT_DEATH(PriorError<QuaternionBlock>(Eigen::Vector4d(1.0, 0.1, 0.0, 0.0)), "unit-norm");
}

}  // namespace
}  // namespace roamlab::estimator
