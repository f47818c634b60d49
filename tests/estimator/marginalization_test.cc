#include "estimator/marginalization.h"

#include <algorithm>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <Eigen/QR>

#include "estimator/internal/linearization.h"
#include "estimator/solver.h"
#include "tests/estimator/solver_testing.h"

namespace roamlab::estimator {
namespace {

using testing::TieWithRandomPrior;

// A leaving variable whose own information (1e10) dwarfs the blanket's (1e3), as a pose between 100 Hz odometry and IMU
// factors does: the stiff factor on (x, y) is absorbed by x entirely, so it must leave no prior on y, whose information
// stays the weak factor's, rank 2 (y's direction (1, 1, 1) unobserved). The computed Schur complement has an error of
// about n eps 1e10 ~ 1e-5 in that direction (either sign); a floor of 1e-12 of the blanket's largest eigenvalue
// (1e-9) alone would keep it when positive, with a mean of rounding / rounding along it. Several stiff couplings
// (different rounding) must all give the exact rank and the weak factor's minimizer to rounding-level accuracy.
TEST(MarginalizationTest, StiffLeavingVariableLeavesNoRoundingInThePrior) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  const std::vector<Manifold> xy = {Manifold::Euclidean(3), Manifold::Euclidean(3)};
  Eigen::MatrixXd J_weak(2, 3);  // information ~1e3, y's direction (1, 1, 1) unobserved
  J_weak << 30.0, -20.0, -10.0, 5.0, 25.0, -30.0;
  const Eigen::Vector2d r_weak(0.7, -1.1);
  // The weak factor's minimum-norm step: what the prior must propose for y.
  const Eigen::Vector3d expected_step = -J_weak.completeOrthogonalDecomposition().solve(r_weak);
  for (int trial = 0; trial < 20; ++trial) {
    Graph graph;
    const VariableId x = graph.AddVariable({"x", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), false, std::nullopt});
    const VariableId y = graph.AddVariable({"y", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), false, std::nullopt});
    Eigen::MatrixXd J_stiff(3, 6);
    J_stiff.leftCols(3) = 1e5 * Eigen::Matrix3d::Identity();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) J_stiff(i, 3 + j) = 1e5 * normal(rng);
    const Eigen::Vector3d r_stiff = 1e2 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    graph.AddFactor(
        std::make_unique<LinearPriorFactor>(
            xy, std::vector<Eigen::VectorXd>{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}, J_stiff, r_stiff),
        {x, y}, Eigen::Matrix3d::Identity(), Loss::Trivial(), "stiff", Time());
    graph.AddFactor(
        std::make_unique<LinearPriorFactor>(std::vector<Manifold>{Manifold::Euclidean(3)},
                                            std::vector<Eigen::VectorXd>{Eigen::Vector3d::Zero()}, J_weak, r_weak),
        {y}, Eigen::Matrix2d::Identity(), Loss::Trivial(), "weak", Time());
    ASSERT_TRUE(Marginalize({x}, &graph));
    // What y's factors now say (the weak one, and a prior if any): stacked, their minimum-norm step.
    Eigen::MatrixXd J(0, 3);
    Eigen::VectorXd r0(0);
    for (const auto& [id, entry] : graph.factors()) {
      const int m = entry.factor->residual_dim();
      Eigen::VectorXd r(m);
      Eigen::MatrixXd Jf(m, 3);
      const double* values[] = {graph.variable(y).value.data()};
      double* jacobians[] = {Jf.data()};
      ASSERT_TRUE(entry.factor->Evaluate(values, r.data(), jacobians, nullptr));
      J.conservativeResize(J.rows() + m, 3);
      J.bottomRows(m) = Jf;
      r0.conservativeResize(r0.size() + m);
      r0.tail(m) = r;
    }
    EXPECT_EQ(J.rows(), 2) << "trial " << trial << ": the stiff factor left a prior of rounding";
    const Eigen::Vector3d step = -J.completeOrthogonalDecomposition().solve(r0);
    // Tolerance: the Schur complement's rounding (~1e-5 against information ~1e3) relative, with a margin of 10.
    EXPECT_LT((step - expected_step).norm(), 1e-7 * expected_step.norm()) << "trial " << trial;
  }
}

// Marginalizing x out of linear factors on (x, y) leaves a prior on y with J^T J and J^T r0 equal to the Schur
// complement of the information and the gradient, also when that information is rank-deficient (y's third
// coordinate is never observed; its second well, or weakly: information 1e-8 of the largest).
TEST(MarginalizationTest, PriorHoldsTheSchurComplementAlsoWhenRankDeficient) {
  for (const double weak : {1.0, 1e-4}) {
    Graph graph;
    const VariableId x =
        graph.AddVariable({"x", Manifold::Euclidean(2), Eigen::Vector2d(0.3, -0.2), false, std::nullopt});
    const VariableId y =
        graph.AddVariable({"y", Manifold::Euclidean(3), Eigen::Vector3d(1.0, 2.0, -1.0), false, std::nullopt});
    const std::vector<Manifold> xy = {Manifold::Euclidean(2), Manifold::Euclidean(3)};
    Eigen::MatrixXd J1(3, 5);  // on (x, y): y's third column zero, its second scaled by `weak`
    J1 << 1.0, 0.5, -1.0, 0.2 * weak, 0.0, 0.0, 2.0, 0.3, -1.0 * weak, 0.0, 0.4, 0.0, 0.0, 0.7 * weak, 0.0;
    const Eigen::Vector3d r1(0.1, -0.4, 0.25);
    graph.AddFactor(
        std::make_unique<LinearPriorFactor>(
            xy, std::vector<Eigen::VectorXd>{Eigen::Vector2d(0.3, -0.2), Eigen::Vector3d(1.0, 2.0, -1.0)}, J1, r1),
        {x, y}, Eigen::Matrix3d::Identity(), Loss::Trivial(), "test", Time());
    Eigen::MatrixXd J2(2, 2);
    J2 << 3.0, 0.0, 1.0, 1.0;
    const Eigen::Vector2d r2(-0.3, 0.2);
    graph.AddFactor(
        std::make_unique<LinearPriorFactor>(std::vector<Manifold>{Manifold::Euclidean(2)},
                                            std::vector<Eigen::VectorXd>{Eigen::Vector2d(0.3, -0.2)}, J2, r2),
        {x}, Eigen::Matrix2d::Identity(), Loss::Trivial(), "test", Time());
    // Expected: H and g of both factors at the current values, Schur complement onto y.
    Eigen::MatrixXd H = J1.transpose() * J1;
    Eigen::VectorXd g = J1.transpose() * r1;
    H.topLeftCorner(2, 2) += J2.transpose() * J2;
    g.head(2) += J2.transpose() * r2;
    const Eigen::MatrixXd Hmm_inv = H.topLeftCorner(2, 2).inverse();
    const Eigen::MatrixXd expected_H =
        H.bottomRightCorner(3, 3) - H.bottomLeftCorner(3, 2) * Hmm_inv * H.topRightCorner(2, 3);
    const Eigen::VectorXd expected_g = g.tail(3) - H.bottomLeftCorner(3, 2) * Hmm_inv * g.head(2);

    ASSERT_TRUE(Marginalize({x}, &graph));
    ASSERT_EQ(graph.factors().size(), 1u);
    const FactorEntry& prior = graph.factors().begin()->second;
    ASSERT_EQ(prior.variables, std::vector<VariableId>{y});
    const int m = prior.factor->residual_dim();
    EXPECT_EQ(m, 2);  // the null direction is dropped
    Eigen::VectorXd r0(m);
    Eigen::MatrixXd J(m, 3);
    const double* values[] = {graph.variable(y).value.data()};
    double* jacobians[] = {J.data()};
    ASSERT_TRUE(prior.factor->Evaluate(values, r0.data(), jacobians, nullptr));
    EXPECT_LT((J.transpose() * J - expected_H).norm(), 1e-9 * expected_H.norm()) << "weak = " << weak;
    EXPECT_LT((J.transpose() * r0 - expected_g).norm(), 1e-9 * expected_g.norm()) << "weak = " << weak;
  }
}

// Marginalize after a Gauss-Newton solve under a relinearization threshold adds the solve's kept J_a^T J_b products
// instead of computing them again (one factor takes its variables in the opposite order to the blanket's: its
// products go in transposed). The prior must hold the Schur complement of the information of those Jacobians.
TEST(MarginalizationTest, PriorFromTheSolvesKeptProductsHoldsTheSchurComplement) {
  std::mt19937 rng(37);
  Graph graph;
  const VariableId lever =
      graph.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d(0.1, 0.2, 0.3), false, std::nullopt});
  std::vector<VariableId> x;
  for (int k = 0; k < 4; ++k)
    x.push_back(graph.AddVariable({"x", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), false, Time::FromSeconds(k)}));
  const auto tie = [&](const std::vector<VariableId>& ids) { TieWithRandomPrior(ids, &rng, &graph); };
  tie({x[0]});
  tie({x[1], x[0], lever});
  tie({x[0], x[2]});
  for (int k = 1; k < 4; ++k) tie({x[k]});
  tie({x[2], x[3], lever});
  SolverOptions options;
  options.method = SolverOptions::Method::kGaussNewton;
  options.relinearize_threshold = 1e-3;
  SolverWorkspace workspace;
  // The first solve's trial point is evaluated again (it moved beyond the threshold); the second keeps the products of
  // its linearization (its step is within the threshold: carried).
  ASSERT_TRUE(Solve(options, &graph, nullptr, &workspace).usable());
  ASSERT_TRUE(Solve(options, &graph, nullptr, &workspace).usable());

  // Expected: the information of the kept Jacobians over [x0, x1, x2, lever], Schur complement onto the blanket.
  const std::vector<VariableId> order = {x[0], x[1], x[2], lever};
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(12, 12);
  int with_products = 0;
  for (FactorId f : graph.FactorsOf(x[0])) {
    const FactorEntry& e = graph.factor(f);
    const std::uint64_t mask = (std::uint64_t{1} << e.variables.size()) - 1;
    const internal::WhitenedFactor* lf = workspace.Linearization(f, mask);
    ASSERT_NE(lf, nullptr);
    if (workspace.Products(f, mask) != nullptr) ++with_products;
    for (std::size_t a = 0; a < e.variables.size(); ++a)
      for (std::size_t b = 0; b < e.variables.size(); ++b) {
        const int oa = 3 * static_cast<int>(std::find(order.begin(), order.end(), e.variables[a]) - order.begin());
        const int ob = 3 * static_cast<int>(std::find(order.begin(), order.end(), e.variables[b]) - order.begin());
        H.block(oa, ob, 3, 3) += lf->jacobians[a].transpose() * lf->jacobians[b];
      }
  }
  EXPECT_EQ(with_products, 3);
  const Eigen::MatrixXd expected =
      H.bottomRightCorner(9, 9) - H.bottomLeftCorner(9, 3) * H.topLeftCorner(3, 3).inverse() * H.topRightCorner(3, 9);

  ASSERT_TRUE(Marginalize({x[0]}, &graph, &workspace));
  const FactorEntry& prior = graph.factor(graph.FactorsOf(x[1]).back());
  ASSERT_EQ(prior.stream, "marginalization");
  ASSERT_EQ(prior.variables, (std::vector<VariableId>{x[1], lever, x[2]}));
  const int m = prior.factor->residual_dim();
  Eigen::VectorXd r0(m);
  Eigen::MatrixXd J(m, 9);
  const double* values[] = {graph.variable(x[1]).value.data(), graph.variable(lever).value.data(),
                            graph.variable(x[2]).value.data()};
  double* jacobians[] = {J.data(), J.data() + 3 * m, J.data() + 6 * m};
  ASSERT_TRUE(prior.factor->Evaluate(values, r0.data(), jacobians, nullptr));
  // The prior's variables are in the blanket's order (x1, lever, x2): the expected one's rows and columns permuted.
  Eigen::MatrixXd permuted(9, 9);
  const int from[] = {0, 6, 3};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) permuted.block(3 * i, 3 * j, 3, 3) = expected.block(from[i], from[j], 3, 3);
  EXPECT_LT((J.transpose() * J - permuted).norm(), 1e-9 * permuted.norm());
}

}  // namespace
}  // namespace roamlab::estimator
