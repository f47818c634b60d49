#include "estimator/solver.h"

#include <cmath>
#include <cstdint>
#include <deque>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/factor.h"
#include "estimator/internal/linearization.h"
#include "estimator/marginalization.h"
#include "estimator/models/ackermann_odometer.h"
#include "tests/estimator/factor_testing.h"
#include "tests/estimator/solver_testing.h"

namespace roamlab::estimator {
namespace {

using testing::MultiAntennaProblem;
using testing::TieWithRandomPrior;

TEST(SolverTest, LevenbergMarquardtRecoversNoiseFreePose) {
  MultiAntennaProblem problem(0.0, 3);
  const SolverSummary summary = Solve(SolverOptions{}, &problem.graph);
  ASSERT_TRUE(summary.usable()) << summary.message;
  EXPECT_LT(problem.Error().norm(), 1e-8);
  EXPECT_LT(summary.final_cost, 1e-12);
  EXPECT_GT(summary.initial_cost, 1.0);
  EXPECT_EQ(summary.free_dimension, 6);
}

TEST(SolverTest, GaussNewtonRecoversNoiseFreePose) {
  MultiAntennaProblem problem(0.0, 4);
  SolverOptions options;
  options.method = SolverOptions::Method::kGaussNewton;
  const SolverSummary summary = Solve(options, &problem.graph);
  ASSERT_TRUE(summary.usable()) << summary.message;
  EXPECT_LT(problem.Error().norm(), 1e-8);
  for (std::size_t i = 1; i < summary.cost_history.size(); ++i)
    EXPECT_LE(summary.cost_history[i], summary.cost_history[i - 1] * (1 + 1e-12) + 1e-20);
}

TEST(SolverTest, WorkspaceGivesTheSameSolutionAndKeepsTheAnalysisOfAnUnchangedPattern) {
  MultiAntennaProblem plain(0.05, 7), reused(0.05, 7);
  const SolverSummary a = Solve(SolverOptions{}, &plain.graph);
  SolverWorkspace workspace;
  const SolverSummary b = Solve(SolverOptions{}, &reused.graph, nullptr, &workspace);
  ASSERT_TRUE(a.usable() && b.usable());
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.final_cost, b.final_cost);
  EXPECT_EQ(plain.graph.variable(plain.pose).value, reused.graph.variable(reused.pose).value);
  EXPECT_EQ(workspace.analyses(), 1);
  // A second solve of the same structure keeps the analysis; switching a factor off changes nothing in the pattern
  // of a single pose, so it is kept too.
  reused.graph.mutable_variable(reused.pose).value = plain.graph.variable(plain.pose).value;
  ASSERT_TRUE(Solve(SolverOptions{}, &reused.graph, nullptr, &workspace).usable());
  reused.graph.mutable_factor(reused.graph.factors().begin()->first).active = false;
  ASSERT_TRUE(Solve(SolverOptions{}, &reused.graph, nullptr, &workspace).usable());
  EXPECT_EQ(workspace.analyses(), 1);
}

TEST(SolverTest, WorkspaceThatKeepsNoLinearizationsSolvesTheSame) {
  // Factors of several shapes (pose priors, Ackermann rows with two poses and three parameters) and an error
  // covariance that depends on the estimate (the odometer's noise through eq. 15): Levenberg-Marquardt judges its
  // trial points with the last whitening, which a factor linearized without keeping must still keep.
  testing::SmallProblem kept = testing::AckermannProblem<AckermannOdometerError>(true, 41);
  testing::SmallProblem lean = testing::AckermannProblem<AckermannOdometerError>(true, 41);
  for (testing::SmallProblem* problem : {&kept, &lean}) {  // (far from the minimum: several iterations)
    std::mt19937 rng(5);
    for (VariableId pose : problem->poses) {
      Eigen::VectorXd& x = problem->graph.mutable_variable(pose).value;
      x = testing::Perturb(Manifold::Pose(), x, 0.7, &rng);
    }
  }
  SolverWorkspace keeping, not_keeping;
  not_keeping.set_keep_linearizations(false);
  const SolverOptions options;
  for (int solve = 0; solve < 2; ++solve) {
    const SolverSummary a = Solve(options, &kept.graph, nullptr, &keeping);
    const SolverSummary b = Solve(options, &lean.graph, nullptr, &not_keeping);
    ASSERT_TRUE(a.usable() && b.usable()) << a.message << b.message;
    EXPECT_EQ(a.iterations, b.iterations);
    EXPECT_EQ(a.cost_history, b.cost_history);
    for (const auto& [id, v] : kept.graph.variables()) ASSERT_EQ(v.value, lean.graph.variable(id).value) << id;
    // A solve that only linearizes (no iteration) leaves a linearization at the current values with the keeping
    // workspace only.
    SolverOptions none = options;
    none.max_iterations = 0;
    ASSERT_TRUE(Solve(none, &kept.graph, nullptr, &keeping).usable());
    ASSERT_TRUE(Solve(none, &lean.graph, nullptr, &not_keeping).usable());
    const auto& [id, entry] = *kept.graph.factors().rbegin();
    std::uint64_t free_mask = 0;
    for (std::size_t i = 0; i < entry.variables.size(); ++i)
      if (!kept.graph.variable(entry.variables[i]).fixed) free_mask |= std::uint64_t{1} << i;
    EXPECT_NE(keeping.Linearization(id, free_mask), nullptr);
    EXPECT_EQ(not_keeping.Linearization(id, free_mask), nullptr);
    // The next solve starts elsewhere, with one factor switched off.
    for (testing::SmallProblem* problem : {&kept, &lean}) {
      problem->graph.mutable_factor(problem->graph.factors().begin()->first).active = false;
      problem->graph.mutable_variable(problem->parameters[0]).value *= 1.1;
    }
  }
}

TEST(SolverTest, ModelToleranceStopsWhenTheQuadraticModelPredictedTheDecrease) {
  // GPS errors are linear in the position: after the first Gauss-Newton step from a pose with the right orientation
  // the model's prediction is exact, so the model tolerance stops there; without it a second step is taken.
  MultiAntennaProblem problem(0.05, 9);
  problem.graph.mutable_variable(problem.pose).value.tail<4>() = problem.truth.tail<4>();
  MultiAntennaProblem again(0.05, 9);
  again.graph.mutable_variable(again.pose).value = problem.graph.variable(problem.pose).value;
  SolverOptions options;
  options.method = SolverOptions::Method::kGaussNewton;
  options.function_tolerance = 1e-12;
  const SolverSummary without = Solve(options, &problem.graph);
  options.model_tolerance = 1e-3;
  const SolverSummary with = Solve(options, &again.graph);
  ASSERT_TRUE(without.usable() && with.usable());
  EXPECT_EQ(with.termination, Termination::kModelTolerance);
  EXPECT_EQ(with.iterations, 1);
  EXPECT_GT(without.iterations, 1);
  EXPECT_NEAR(with.final_cost, without.final_cost, 1e-3 * without.final_cost);
}

TEST(SolverTest, LevenbergMarquardtStartedAtItsMinimumConvergesThere) {
  // Two priors either side of x = 0 with equal weights: their gradients cancel exactly there, so every step is zero
  // and neither the model nor the cost changes. That is a minimum (the function tolerance), not a failure of the
  // damping: rejecting such steps until the damping passed its limit would fail a warm-started fit whose cost changes
  // only in the round-off.
  Graph graph;
  const VariableId x = graph.AddVariable({"x", Manifold::Euclidean(1), Eigen::VectorXd::Zero(1), false, std::nullopt});
  const Eigen::MatrixXd one = Eigen::MatrixXd::Identity(1, 1);
  for (const double r0 : {1.0, -1.0})
    graph.AddFactor(std::make_unique<LinearPriorFactor>(std::vector<Manifold>{Manifold::Euclidean(1)},
                                                        std::vector<Eigen::VectorXd>{Eigen::VectorXd::Zero(1)}, one,
                                                        Eigen::VectorXd::Constant(1, r0)),
                    {x}, one, Loss::Trivial(), "prior", Time());
  SolverOptions options;
  options.initial_lambda = 1e-11;  // as the diagnosis's warm fits
  const SolverSummary summary = Solve(options, &graph);
  ASSERT_TRUE(summary.usable()) << summary.message;
  EXPECT_EQ(summary.termination, Termination::kFunctionTolerance);
  EXPECT_EQ(summary.initial_cost, 1.0);
  EXPECT_EQ(summary.final_cost, 1.0);
  EXPECT_EQ(graph.variable(x).value[0], 0.0);
}

// e = sin(x) + eta: along a step from x = 1.2 the cost bends far more than the Gauss-Newton model of its slope there.
struct SineError {
  using Blocks = std::tuple<ScalarBlock>;
  static constexpr int kResidualDim = 1;
  static constexpr int kNoiseDim = 1;
  template <typename T>
  bool operator()(const T* const* x, const T* noise, T* error) const {
    using std::sin;
    error[0] = sin(x[0][0]) + noise[0];
    return true;
  }
};

TEST(SolverTest, LevenbergMarquardtShortensARejectedStepToTheMinimumAlongIt) {
  // From x = 1.2 the first step (-r / J = -tan(1.2) = -2.57) lands at x = -1.37, where sin is -0.98: rejected. The
  // parabola through the cost at 0 and 1 along it and the slope at 0 has its minimum at t = 0.47 (x = -0.02), which
  // lowers the cost; the solver takes it instead of re-solving with more damping until a step passes, so no iteration
  // is rejected.
  Graph graph;
  const VariableId x =
      graph.AddVariable({"x", Manifold::Euclidean(1), Eigen::VectorXd::Constant(1, 1.2), false, std::nullopt});
  graph.AddFactor(MakeFactor(SineError()), {x}, Eigen::MatrixXd::Identity(1, 1), Loss::Trivial(), "sine", Time());
  SolverOptions options;
  options.initial_lambda = 1e-8;
  const SolverSummary summary = Solve(options, &graph);
  ASSERT_TRUE(summary.usable()) << summary.message;
  EXPECT_NE(summary.termination, Termination::kMaxIterations);
  EXPECT_EQ(summary.cost_history.size(), static_cast<std::size_t>(summary.iterations) + 1);  // all accepted
  EXPECT_LT(std::abs(summary.cost_history[1] - 0.5 * std::pow(std::sin(-0.02), 2)), 2e-3);
  EXPECT_LT(std::abs(graph.variable(x).value[0]), 1e-6);
}

// A stretch dead-reckoned between two absolute fixes: N stamped states tied by x_{k+1} - x_k = c (c a constant
// parameter, such as a wheel radius), the first and the last pinned by priors, started from the chain integrated with
// a wrong c. The error is a ramp, the chain's longest mode, whose curvature is about (pi / N)^2 of the diagonal: a
// damping of 1e-2 on the states would shorten the step along it a thousand times. Damping only c (the states
// undamped), the problem being linear, the first step takes the chain to its minimum given c.
TEST(SolverTest, LevenbergMarquardtDampsTheConstantParametersNotTheStates) {
  constexpr int kStates = 1000;
  constexpr double kStep = 0.01, kStartStep = 0.012;
  Graph graph;
  const VariableId c =
      graph.AddVariable({"c", Manifold::Euclidean(1), Eigen::VectorXd::Constant(1, kStartStep), false, std::nullopt});
  std::vector<VariableId> x;
  for (int k = 0; k < kStates; ++k)
    x.push_back(graph.AddVariable({"x" + std::to_string(k), Manifold::Euclidean(1),
                                   Eigen::VectorXd::Constant(1, k * kStartStep), false, Time::FromSeconds(0.01 * k)}));
  const std::vector<Manifold> one(1, Manifold::Euclidean(1)), three(3, Manifold::Euclidean(1));
  const Eigen::MatrixXd unit = Eigen::MatrixXd::Identity(1, 1);
  const auto zeros = [](int n) { return std::vector<Eigen::VectorXd>(n, Eigen::VectorXd::Zero(1)); };
  // e = (x_{k+1} - x_k - c) / 0.01 and e = (x - fix) / 0.001, linear in the values (linearized at zero).
  for (int k = 0; k + 1 < kStates; ++k)
    graph.AddFactor(std::make_unique<LinearPriorFactor>(three, zeros(3), Eigen::RowVector3d(-100.0, 100.0, -100.0),
                                                        Eigen::VectorXd::Zero(1)),
                    {x[k], x[k + 1], c}, unit, Loss::Trivial(), "chain", Time::FromSeconds(0.01 * k));
  for (const int k : {0, kStates - 1})
    graph.AddFactor(std::make_unique<LinearPriorFactor>(one, zeros(1), Eigen::MatrixXd::Constant(1, 1, 1000.0),
                                                        Eigen::VectorXd::Constant(1, -1000.0 * k * kStep)),
                    {x[k]}, unit, Loss::Trivial(), "fix", Time::FromSeconds(0.01 * k));
  std::vector<std::pair<VariableId, Eigen::VectorXd>> start;
  for (const auto& [id, v] : graph.variables()) start.emplace_back(id, v.value);
  SolverOptions options;
  options.initial_lambda = 1e-2;
  options.max_iterations = 2;
  const int middle = kStates / 2;
  const double c_error = kStartStep - kStep;

  // Damping every variable, the middle of the chain (1 m off at the start) barely moves in two steps.
  const SolverSummary all = Solve(options, &graph);
  ASSERT_TRUE(all.usable()) << all.message;
  EXPECT_GT(std::abs(graph.variable(x[middle]).value[0] - middle * kStep), 0.5);

  // Damping c alone: its step is held back by 1e-2 of its curvature (1 % of its error left), and the chain moves to
  // its minimum given c.
  for (const auto& [id, value] : start) graph.mutable_variable(id).value = value;
  options.damping = SolverOptions::Damping::kParameters;
  const SolverSummary parameters = Solve(options, &graph);
  ASSERT_TRUE(parameters.usable()) << parameters.message;
  EXPECT_LT(std::abs(graph.variable(c).value[0] - kStep), 0.02 * c_error);
  EXPECT_LT(std::abs(graph.variable(x[middle]).value[0] - middle * kStep), 1e-6);
  EXPECT_LT(parameters.final_cost, 1e-8 * parameters.initial_cost);
}

// The solver's order: poses in time; each time-varying instance after the last pose it serves (just before the pose
// that starts the next instance of its parameter), the newest after every pose; fixed variables left out; constant
// parameters last. Here instance "a" every 3 poses (one fixed), "b" per pose, created out of id order with the poses.
TEST(SolverTest, FreeVariableOrderPutsEachInstanceAfterTheLastPoseItServes) {
  Graph graph;
  const VariableId lever =
      graph.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), false, std::nullopt});
  std::vector<VariableId> poses, a, b;
  for (int k = 0; k < 8; ++k) {
    const Time t = Time::FromSeconds(0.1 * k);
    poses.push_back(graph.AddVariable({"pose", Manifold::Pose(), Manifold::Pose().Identity(), false, t}));
    if (k % 3 == 0) a.push_back(graph.AddVariable({"a", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), k == 3, t}));
    b.push_back(graph.AddVariable({"b", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), false, t}));
  }
  const std::vector<VariableId> expected = {poses[0], b[0], poses[1], b[1], poses[2], a[0], b[2],
                                            poses[3], b[3], poses[4], b[4], poses[5], b[5], /* a[1] fixed */
                                            poses[6], b[6], poses[7], a[2], b[7],     lever};
  EXPECT_EQ(FreeVariableOrder(graph), expected);
}

TEST(SolverTest, RelinearizationThresholdNeedsGaussNewton) {
  SolverOptions options;
  options.relinearize_threshold = 0.01;
  EXPECT_EQ(options.Validate(), "relinearize_threshold needs method gauss_newton");
  options.method = SolverOptions::Method::kGaussNewton;
  EXPECT_EQ(options.Validate(), "");
  options.relinearize_threshold = -1.0;
  EXPECT_EQ(options.Validate(), "relinearize_threshold must be >= 0");
}

// A Gauss-Newton solve with a workspace ends with every factor linearized at its final point (its trial point), and
// Marginalize, GateOutliers and the next solve take those linearizations instead of evaluating the factors again. On a
// sliding window, solving and marginalizing with the workspace must give the same values, bit for bit, as without;
// a kept linearization must equal a fresh one, and must not be handed out once a variable moved.
TEST(SolverTest, GaussNewtonWorkspaceKeepsTheFinalLinearizationForMarginalizeAndTheNextSolve) {
  struct Window {
    std::mt19937 rng{17};
    Graph graph;
    VariableId lever;
    std::deque<VariableId> poses;
    Window() {
      lever = graph.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d(0.1, 0.2, 0.3), false, std::nullopt});
      for (int k = 0; k < 6; ++k) AddPose();
    }
    void AddPose() {
      poses.push_back(graph.AddVariable({"pose", Manifold::Pose(), testing::RandomPoint(Manifold::Pose(), &rng, 5.0),
                                         false, Time::FromSeconds(static_cast<double>(poses.size()))}));
      TieWithRandomPrior({poses.back()}, &rng, &graph);
      if (poses.size() > 1) TieWithRandomPrior({poses[poses.size() - 2], poses.back(), lever}, &rng, &graph);
    }
  };
  Window reused, plain;
  SolverOptions options;
  options.method = SolverOptions::Method::kGaussNewton;
  options.max_iterations = 3;
  SolverWorkspace workspace;
  for (int step = 0; step < 6; ++step) {
    ASSERT_TRUE(Solve(options, &reused.graph, nullptr, &workspace).usable());
    ASSERT_TRUE(Solve(options, &plain.graph, nullptr, nullptr).usable());
    for (const auto& [id, v] : reused.graph.variables())
      ASSERT_EQ(v.value, plain.graph.variable(id).value) << "step " << step << ", variable " << id;
    // Every factor's kept linearization is a fresh one at the final point.
    for (const auto& [id, entry] : reused.graph.factors()) {
      const std::uint64_t mask = (std::uint64_t{1} << entry.variables.size()) - 1;  // every variable is free
      const internal::WhitenedFactor* kept = workspace.Linearization(id, mask);
      ASSERT_NE(kept, nullptr) << "step " << step << ", factor " << id;
      EXPECT_EQ(workspace.Linearization(id, mask & ~std::uint64_t{1}), nullptr);
      internal::WhitenedFactor fresh;
      ASSERT_TRUE(
          internal::LinearizeFactor(reused.graph, entry, std::vector<bool>(entry.variables.size(), true), &fresh));
      EXPECT_EQ(kept->residual, fresh.residual);
      for (std::size_t i = 0; i < entry.variables.size(); ++i) EXPECT_EQ(kept->jacobians[i], fresh.jacobians[i]);
    }
    // Moved by one unit in the last place, the oldest pose's factors are no longer handed out.
    Eigen::VectorXd& x = reused.graph.mutable_variable(reused.poses.front()).value;
    const double before = x[0];
    x[0] = std::nextafter(before, 1e300);
    for (FactorId f : reused.graph.FactorsOf(reused.poses.front()))
      EXPECT_EQ(workspace.Linearization(f, (std::uint64_t{1} << reused.graph.factor(f).variables.size()) - 1), nullptr);
    x[0] = before;
    ASSERT_TRUE(Marginalize({reused.poses.front()}, &reused.graph, &workspace));
    ASSERT_TRUE(Marginalize({plain.poses.front()}, &plain.graph));
    reused.poses.pop_front();
    plain.poses.pop_front();
    reused.AddPose();
    plain.AddPose();
  }
  ASSERT_TRUE(Solve(options, &reused.graph, nullptr, &workspace).usable());
  ASSERT_TRUE(Solve(options, &plain.graph, nullptr, nullptr).usable());
  for (const auto& [id, v] : reused.graph.variables()) EXPECT_EQ(v.value, plain.graph.variable(id).value);
}

}  // namespace
}  // namespace roamlab::estimator
