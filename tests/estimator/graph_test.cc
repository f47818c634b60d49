#include "estimator/graph.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "estimator/models/gps.h"

namespace roamlab::estimator {
namespace {

// Factors added with the same noise covariance share one model, factored once; one that differs in any entry gets its
// own model.
TEST(GraphTest, FactorsWithTheSameNoiseCovarianceShareOneModel) {
  Graph graph;
  const VariableId pose =
      graph.AddVariable({"pose", Manifold::Pose(), Manifold::Pose().Identity(), false, Time::FromSeconds(0.0)});
  const VariableId lever = graph.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), true, {}});
  const VariableId bias = graph.AddVariable({"bias", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), true, {}});
  const auto add = [&](const Eigen::Matrix3d& covariance) {
    const FactorId id = graph.AddFactor(MakeFactor(GpsError(Eigen::Vector3d::Zero())), {pose, lever, bias}, covariance,
                                        Loss::Trivial(), "gps", Time::FromSeconds(0.0));
    return graph.factor(id).noise;
  };
  Eigen::Matrix3d a;
  a << 4.0, 1.0, 0.0, 1.0, 3.0, 0.5, 0.0, 0.5, 2.0;
  const Eigen::Matrix3d b = Eigen::Vector3d(1.0, 2.0, 3.0).asDiagonal();
  const auto first = add(a);
  EXPECT_EQ(add(a), first);
  const auto other = add(b);
  EXPECT_NE(other, first);
  EXPECT_EQ(add(a), first);
  Eigen::Matrix3d nearly = a;
  nearly(2, 2) = std::nextafter(2.0, 3.0);
  EXPECT_NE(add(nearly), first);
  // The factor and its diagonal flag, as computed for each factor before.
  EXPECT_EQ(first->covariance, a);
  EXPECT_TRUE(first->sqrt_covariance.isApprox(Eigen::LLT<Eigen::MatrixXd>(a).matrixL().toDenseMatrix(), 0.0));
  EXPECT_FALSE(first->sqrt_diagonal);
  EXPECT_TRUE(other->sqrt_diagonal);
  EXPECT_TRUE(other->sqrt_covariance.isApprox(Eigen::LLT<Eigen::MatrixXd>(b).matrixL().toDenseMatrix(), 0.0));
}

TEST(GraphDeathTest, NoiseCovarianceThatIsNotPositiveDefiniteIsRefused) {
  Graph graph;
  const VariableId pose =
      graph.AddVariable({"pose", Manifold::Pose(), Manifold::Pose().Identity(), false, Time::FromSeconds(0.0)});
  const VariableId lever = graph.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), true, {}});
  const VariableId bias = graph.AddVariable({"bias", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), true, {}});
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  graph.AddFactor(MakeFactor(GpsError(Eigen::Vector3d::Zero())), {pose, lever, bias}, covariance, Loss::Trivial(),
                  "gps", Time::FromSeconds(0.0));
  covariance(0, 0) = -1.0;
  EXPECT_DEATH(graph.AddFactor(MakeFactor(GpsError(Eigen::Vector3d::Zero())), {pose, lever, bias}, covariance,
                               Loss::Trivial(), "gps", Time::FromSeconds(0.0)),
               "factor from 'gps': noise covariance is not symmetric positive definite");
}

// A small graph: a pose, a fixed lever arm and a fixed GPS bias, each GPS factor on all three.
struct PoseAndLever {
  Graph graph;
  VariableId pose =
      graph.AddVariable({"pose", Manifold::Pose(), Manifold::Pose().Identity(), false, Time::FromSeconds(0.0)});
  VariableId lever = graph.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), true, {}});
  VariableId bias = graph.AddVariable({"bias", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), true, {}});

  FactorId AddGps(const std::string& stream = "gps") {
    return graph.AddFactor(MakeFactor(GpsError(Eigen::Vector3d::Zero())), {pose, lever, bias},
                           Eigen::Matrix3d::Identity(), Loss::Trivial(), stream, Time::FromSeconds(0.0));
  }
};

// Ids are handed out in increasing order and never reused; lookups return what was added; iteration is in id order;
// FactorsOf lists a variable's factors in id order and follows removals.
TEST(GraphTest, AddRemoveAndLookUpVariablesAndFactors) {
  PoseAndLever g;
  Graph& graph = g.graph;
  EXPECT_LT(g.pose, g.lever);
  EXPECT_TRUE(graph.HasVariable(g.pose));
  EXPECT_EQ(graph.variable(g.lever).name, "lever");
  EXPECT_TRUE(graph.variable(g.lever).fixed);
  EXPECT_TRUE(graph.variable(g.pose).stamp == Time::FromSeconds(0.0));
  graph.mutable_variable(g.lever).value = Eigen::Vector3d(1.0, 2.0, 3.0);
  EXPECT_EQ(graph.variable(g.lever).value, Eigen::Vector3d(1.0, 2.0, 3.0));

  const FactorId a = g.AddGps("a");
  const FactorId b = g.AddGps("b");
  const FactorId c = g.AddGps("c");
  EXPECT_LT(a, b);
  EXPECT_LT(b, c);
  EXPECT_EQ(graph.factor(b).stream, "b");
  EXPECT_EQ(graph.factor(b).variables, (std::vector<VariableId>{g.pose, g.lever, g.bias}));
  EXPECT_TRUE(graph.factor(b).active);
  graph.mutable_factor(b).active = false;
  EXPECT_FALSE(graph.factor(b).active);
  EXPECT_EQ(graph.FactorsOf(g.pose), (std::vector<FactorId>{a, b, c}));
  EXPECT_EQ(graph.FactorsOf(g.lever), (std::vector<FactorId>{a, b, c}));

  graph.RemoveFactor(b);
  EXPECT_EQ(graph.factors().size(), 2u);
  EXPECT_EQ(graph.FactorsOf(g.pose), (std::vector<FactorId>{a, c}));
  std::vector<FactorId> in_order;
  for (const auto& [id, entry] : graph.factors()) in_order.push_back(id);
  EXPECT_EQ(in_order, (std::vector<FactorId>{a, c}));
  const FactorId d = g.AddGps("d");
  EXPECT_GT(d, c);  // not b again

  for (FactorId f : {a, c, d}) graph.RemoveFactor(f);
  EXPECT_TRUE(graph.FactorsOf(g.lever).empty());
  graph.RemoveVariable(g.lever);
  EXPECT_FALSE(graph.HasVariable(g.lever));
  EXPECT_EQ(graph.variables().size(), 2u);
  const VariableId e = graph.AddVariable({"e", Manifold::Euclidean(1), Eigen::VectorXd::Zero(1), false, {}});
  EXPECT_GT(e, g.lever);
}

TEST(GraphDeathTest, BrokenPreconditionsAbortWithAMessage) {
  PoseAndLever g;
  g.AddGps();
  EXPECT_DEATH(g.graph.RemoveVariable(g.lever), "variable 'lever' still has 1 factors");
  EXPECT_DEATH(g.graph.variable(99), "no variable 99");
  EXPECT_DEATH(g.graph.factor(99), "no factor 99");
  EXPECT_DEATH(g.graph.AddVariable({"short", Manifold::Pose(), Eigen::VectorXd::Zero(3), false, {}}),
               "variable 'short' has 3 values for manifold SE3");
  // The GPS model takes (pose, lever arm, bias): swapped, the manifolds do not match.
  EXPECT_DEATH(g.graph.AddFactor(MakeFactor(GpsError(Eigen::Vector3d::Zero())), {g.lever, g.pose, g.bias},
                                 Eigen::Matrix3d::Identity(), Loss::Trivial(), "gps", Time()),
               "factor from 'gps': variable 0 \\('lever'\\) is R3, expected SE3");
  EXPECT_DEATH(g.graph.AddFactor(MakeFactor(GpsError(Eigen::Vector3d::Zero())), {g.pose, g.lever, g.bias},
                                 Eigen::Matrix2d::Identity(), Loss::Trivial(), "gps", Time()),
               "noise covariance is 2x2, expected 3");
}

}  // namespace
}  // namespace roamlab::estimator
