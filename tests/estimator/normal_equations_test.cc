#include "estimator/internal/normal_equations.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <deque>
#include <map>
#include <random>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>

#include "common/interrupt.h"
#include "estimator/covariance.h"
#include "estimator/internal/linearization.h"
#include "estimator/marginalization.h"
#include "estimator/solver.h"
#include "tests/estimator/factor_testing.h"
#include "tests/estimator/solver_testing.h"

namespace roamlab::estimator {
namespace {

using testing::TieWithRandomPrior;

// `count` poses one second apart at random points, then a free constant parameter ("lever", 3 components).
std::pair<std::vector<VariableId>, VariableId> AddPosesAndLever(int count, std::mt19937* rng, Graph* graph) {
  std::vector<VariableId> poses;
  for (int k = 0; k < count; ++k)
    poses.push_back(graph->AddVariable(
        {"pose", Manifold::Pose(), testing::RandomPoint(Manifold::Pose(), rng, 5.0), false, Time::FromSeconds(k)}));
  const VariableId lever =
      graph->AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d(0.1, 0.2, 0.3), false, std::nullopt});
  return {poses, lever};
}

// A sliding window of poses with a constant parameter ("lever") and a time-varying one whose instance changes every
// `instance_period` poses, tied by linear priors with random Jacobians: instance to instance, pose to its instance
// (and to the lever when `pose_with_lever`), pose to pose with the lever.
class SlidingWindowWithInstances {
 public:
  SlidingWindowWithInstances(unsigned seed, int instance_period, bool pose_with_lever)
      : rng_(seed), instance_period_(instance_period), pose_with_lever_(pose_with_lever) {
    lever_ = graph_.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d(0.1, 0.2, 0.3), false, std::nullopt});
  }
  Graph& graph() { return graph_; }
  VariableId oldest_pose() const { return nodes_.front().pose; }
  VariableId pose(int k) const { return nodes_[static_cast<std::size_t>(k)].pose; }

  void AddPose() {
    const Time t = Time::FromSeconds(static_cast<double>(stamp_));
    const VariableId pose =
        graph_.AddVariable({"pose", Manifold::Pose(), testing::RandomPoint(Manifold::Pose(), &rng_, 5.0), false, t});
    VariableId instance = nodes_.empty() ? -1 : nodes_.back().instance;
    if (stamp_ % instance_period_ == 0) {
      instance = graph_.AddVariable({"drift", Manifold::Euclidean(3), Eigen::Vector3d::Zero(), false, t});
      if (!nodes_.empty()) Tie({nodes_.back().instance, instance});
    }
    ++stamp_;
    if (pose_with_lever_) {
      Tie({pose, instance, lever_});
    } else {
      Tie({pose, instance});
    }
    if (!nodes_.empty()) Tie({nodes_.back().pose, pose, lever_});
    nodes_.push_back({pose, instance});
  }
  // The oldest pose leaves (marginalized), with its instance when the next pose has another one; a new pose comes.
  bool Slide() {
    std::vector<VariableId> leaving = {nodes_.front().pose};
    if (nodes_[1].instance != nodes_.front().instance) leaving.push_back(nodes_.front().instance);
    if (!Marginalize(leaving, &graph_)) return false;
    nodes_.pop_front();
    AddPose();
    return true;
  }

 private:
  struct Node {
    VariableId pose;
    VariableId instance;
  };
  void Tie(const std::vector<VariableId>& ids) { TieWithRandomPrior(ids, &rng_, &graph_); }

  std::mt19937 rng_;
  int instance_period_;
  bool pose_with_lever_;
  Graph graph_;
  VariableId lever_ = -1;
  std::deque<Node> nodes_;
  int stamp_ = 0;
};

// An interruption stops a linearization part way (it fails, naming no stream), and a solve before its first
// iteration; both run whole again once it is cleared.
TEST(NormalEquationsTest, AnInterruptionStopsALinearizationPartWay) {
  std::mt19937 rng(7);
  Graph graph;
  const auto [poses, lever] = AddPosesAndLever(5000, &rng, &graph);
  for (const VariableId pose : poses) TieWithRandomPrior({pose, lever}, &rng, &graph);
  internal::NormalEquations system(graph, FreeVariableOrder(graph));
  RequestInterrupt(SIGTERM);
  std::string failed = "not cleared";
  const bool interrupted_linearization = system.Linearize(graph, &failed);
  const long evaluated = system.evaluations();
  const SolverSummary interrupted_solve = Solve(SolverOptions(), &graph);
  ClearInterrupt();
  EXPECT_FALSE(interrupted_linearization);
  EXPECT_EQ(failed, "");
  EXPECT_GT(evaluated, 0);
  EXPECT_LT(evaluated, 5000);
  EXPECT_FALSE(interrupted_solve.usable());
  EXPECT_EQ(interrupted_solve.iterations, 0);
  EXPECT_EQ(interrupted_solve.message, "interrupted by SIGTERM at iteration 0");

  EXPECT_TRUE(system.Linearize(graph, &failed));
  EXPECT_TRUE(Solve(SolverOptions(), &graph).usable());
}

// A tracking window in the solver's natural order: poses in time order, each tied to the next and to the one after
// (which skips a pose: fill inside the envelope), and a free constant parameter tied to two poses (the dense border),
// by linear priors with random Jacobians. The envelope factorization must give the step and the covariances of a dense
// Cholesky of the same H: a few columns by forward substitution, many by the full solve.
TEST(NormalEquationsTest, EnvelopeFactorizationOfABandWithABorderMatchesADenseCholesky) {
  std::mt19937 rng(11);
  Graph graph;
  const auto [poses, lever] = AddPosesAndLever(12, &rng, &graph);
  const auto tie = [&](const std::vector<VariableId>& ids) { TieWithRandomPrior(ids, &rng, &graph); };
  for (std::size_t k = 0; k < poses.size(); ++k) {
    tie({poses[k]});
    if (k + 1 < poses.size()) tie({poses[k], poses[k + 1]});
    if (k + 2 < poses.size()) tie({poses[k], poses[k + 2]});
  }
  tie({poses[0], lever});
  tie({poses[7], lever});

  internal::NormalEquations system(graph, FreeVariableOrder(graph));
  ASSERT_TRUE(system.Linearize(graph));
  const int n = system.dimension();
  ASSERT_EQ(n, 75);
  const Eigen::SparseMatrix<double> H_sparse = system.hessian_upper().selfadjointView<Eigen::Upper>();
  const Eigen::MatrixXd H(H_sparse);
  const Eigen::LLT<Eigen::MatrixXd> dense(H);
  ASSERT_EQ(dense.info(), Eigen::Success);
  const Eigen::MatrixXd H_inv = dense.solve(Eigen::MatrixXd::Identity(n, n));

  Eigen::VectorXd dx;
  ASSERT_TRUE(system.Solve(0.0, &dx));
  const Eigen::VectorXd expected = dense.solve(-system.gradient());
  EXPECT_LT((dx - expected).norm(), 1e-9 * expected.norm());

  // The oldest pose and the parameter (9 columns), then every pose (72).
  Eigen::MatrixXd few;
  ASSERT_TRUE(system.Covariance({poses[0], lever}, &few));
  Eigen::MatrixXd few_expected(9, 9);
  const std::vector<int> rows = {0, 1, 2, 3, 4, 5, n - 3, n - 2, n - 1};
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) few_expected(i, j) = H_inv(rows[i], rows[j]);
  EXPECT_LT((few - few_expected).norm(), 1e-9 * few_expected.norm());
  Eigen::MatrixXd many;
  ASSERT_TRUE(system.Covariance(poses, &many));
  EXPECT_LT((many - H_inv.topLeftCorner(72, 72)).norm(), 1e-9 * H_inv.norm());
  // Positions only (a pose's first three tangent components; tracking's output): the oldest pose, then two poses and
  // the parameter (its three components are all it has).
  Eigen::MatrixXd position;
  ASSERT_TRUE(system.Covariance({poses[0]}, &position, 3));
  EXPECT_LT((position - H_inv.topLeftCorner(3, 3)).norm(), 1e-9 * H_inv.topLeftCorner(3, 3).norm());
  Eigen::MatrixXd leading;
  ASSERT_TRUE(system.Covariance({poses[0], poses[5], lever}, &leading, 3));
  const std::vector<int> leading_rows = {0, 1, 2, 30, 31, 32, n - 3, n - 2, n - 1};
  ASSERT_EQ(leading.rows(), 9);
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j)
      EXPECT_NEAR(leading(i, j), H_inv(leading_rows[i], leading_rows[j]), 1e-9 * H_inv.norm()) << i << ", " << j;
  // Requests whose first block lies further down the band (the forward substitution starts there), or in the border.
  const auto expect_covariance = [&](const std::vector<VariableId>& ids, const std::vector<int>& expected_rows) {
    Eigen::MatrixXd covariance;
    ASSERT_TRUE(system.Covariance(ids, &covariance, 3));
    ASSERT_EQ(covariance.rows(), static_cast<int>(expected_rows.size()));
    for (std::size_t i = 0; i < expected_rows.size(); ++i)
      for (std::size_t j = 0; j < expected_rows.size(); ++j)
        EXPECT_NEAR(covariance(i, j), H_inv(expected_rows[i], expected_rows[j]), 1e-9 * H_inv.norm()) << i << ", " << j;
  };
  expect_covariance({poses[7]}, {42, 43, 44});
  expect_covariance({poses[11], poses[4], lever}, {66, 67, 68, 24, 25, 26, n - 3, n - 2, n - 1});
  expect_covariance({lever}, {n - 3, n - 2, n - 1});

  // A damped solve factors H + lambda diag(H).
  const double lambda = 0.3;
  Eigen::MatrixXd damped = H;
  damped.diagonal() += lambda * H.diagonal();
  ASSERT_TRUE(system.Solve(lambda, &dx));
  const Eigen::VectorXd damped_expected = damped.llt().solve(-system.gradient());
  EXPECT_LT((dx - damped_expected).norm(), 1e-9 * damped_expected.norm());
}

// The envelope is scattered, factored and its border substituted block column by block column in one sweep: a
// factorization that fails partway (a pose without any factor: a zero diagonal block) must stop cleanly, and the
// damped one after it must be the dense Cholesky's.
TEST(NormalEquationsTest, EnvelopeFactorizationThatFailsPartwayIsFollowedByAGoodDampedOne) {
  std::mt19937 rng(12);
  Graph graph;
  const auto [poses, lever] = AddPosesAndLever(12, &rng, &graph);
  const auto tie = [&](const std::vector<VariableId>& ids) { TieWithRandomPrior(ids, &rng, &graph); };
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (k == 5) continue;
    tie({poses[k]});
    if (k + 1 < poses.size() && k + 1 != 5) tie({poses[k], poses[k + 1]});
  }
  tie({poses[0], lever});
  tie({poses[9], lever});
  internal::NormalEquations system(graph, FreeVariableOrder(graph));
  ASSERT_TRUE(system.Linearize(graph));
  ASSERT_TRUE(system.factored_in_envelope());
  Eigen::VectorXd dx;
  EXPECT_FALSE(system.Solve(0.0, &dx));
  // Damping the constant parameter alone leaves the pose's block singular.
  EXPECT_FALSE(system.Solve(0.3, &dx, internal::NormalEquations::Damping::kConstantsOnly));
  const Eigen::MatrixXd H = Eigen::SparseMatrix<double>(system.hessian_upper().selfadjointView<Eigen::Upper>());
  const double lambda = 0.3;
  Eigen::MatrixXd damped = H;
  for (int i = 0; i < H.rows(); ++i) damped(i, i) += lambda * std::max(H(i, i), 1e-12);
  const Eigen::LLT<Eigen::MatrixXd> dense(damped);
  ASSERT_EQ(dense.info(), Eigen::Success);
  ASSERT_TRUE(system.Solve(lambda, &dx));
  const Eigen::VectorXd expected = dense.solve(-system.gradient());
  EXPECT_LT((dx - expected).norm(), 1e-9 * expected.norm());
  EXPECT_TRUE(dx.segment<6>(30).isZero(0.0));  // (pose 5: no gradient)
}

// A whole recording's system (beyond the size of a tracking window) in natural order: 400 poses tied to their next
// and to the one after, and a constant parameter tied to a few poses (none of them the first). It is factored in its
// envelope while the poses are tied to their neighbours in time only, by CHOLMOD once every pose is also tied to the
// one 100 poses later (a route driven twice: each block column's envelope would reach 100 poses back, 25 times H's
// pattern); either way the undamped and the damped steps must be those of a sparse Cholesky of the same H, and the
// parameter's marginal information the Schur complement of H onto it.
TEST(NormalEquationsTest, LargeBandIsFactoredInItsEnvelopeUnlessManyPosesFarApartAreTied) {
  for (const bool loop : {false, true}) {
    SCOPED_TRACE(loop ? "each pose tied to the one 100 poses later" : "neighbours only");
    std::mt19937 rng(17);
    Graph graph;
    const auto [poses, lever] = AddPosesAndLever(400, &rng, &graph);
    const auto tie = [&](const std::vector<VariableId>& ids) { TieWithRandomPrior(ids, &rng, &graph); };
    for (std::size_t k = 0; k < poses.size(); ++k) {
      if (k + 1 < poses.size()) tie({poses[k], poses[k + 1]});
      if (k + 2 < poses.size()) tie({poses[k], poses[k + 2]});
      if (k % 50 == 7) tie({poses[k], lever});
      if (loop && k + 100 < poses.size()) tie({poses[k], poses[k + 100]});
    }
    tie({poses[0]});

    internal::NormalEquations system(graph, FreeVariableOrder(graph));
    ASSERT_TRUE(system.Linearize(graph));
    ASSERT_EQ(system.dimension(), 2403);
    EXPECT_EQ(system.factored_in_envelope(), !loop);
    const Eigen::SparseMatrix<double> H = system.hessian_upper().selfadjointView<Eigen::Upper>();
    // Undamped, damped, and damped on the constant parameter only (its 3 trailing rows; the poses undamped).
    using Damping = internal::NormalEquations::Damping;
    for (const auto& [lambda, damping] : {std::pair(0.0, Damping::kAll), std::pair(0.3, Damping::kAll),
                                          std::pair(0.3, Damping::kConstantsOnly)}) {
      const int first_damped = damping == Damping::kAll ? 0 : system.dimension() - 3;
      Eigen::SparseMatrix<double> A = H;
      for (int i = first_damped; i < A.rows(); ++i) A.coeffRef(i, i) += lambda * std::max(H.coeff(i, i), 1e-12);
      const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> reference(A);
      ASSERT_EQ(reference.info(), Eigen::Success);
      const Eigen::VectorXd expected = reference.solve(-system.gradient());
      Eigen::VectorXd dx;
      ASSERT_TRUE(system.Solve(lambda, &dx, damping));
      EXPECT_LT((dx - expected).norm(), 1e-9 * expected.norm()) << "lambda " << lambda << ", from " << first_damped;
    }

    // The parameter's information with the poses marginalized out, Hpp - Hxp^T Hxx^-1 Hxp: from the envelope
    // factorization (its border), or from CHOLMOD on Hxx.
    const int nx = system.dimension() - 3;
    const Eigen::SparseMatrix<double> Hxx = H.topLeftCorner(nx, nx);
    const Eigen::MatrixXd Hxp = Eigen::MatrixXd(H.topRightCorner(nx, 3));
    const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> xx(Hxx);
    ASSERT_EQ(xx.info(), Eigen::Success);
    const Eigen::MatrixXd schur = Eigen::MatrixXd(H.bottomRightCorner(3, 3)) - Hxp.transpose() * xx.solve(Hxp);
    Eigen::MatrixXd border;
    ASSERT_EQ(system.BorderInformation(3, &border), !loop);
    if (!loop) {
      EXPECT_LT((border - schur).norm(), 1e-9 * schur.norm());
    }
    const auto marginal = ComputeMarginalInformation(graph, {lever});
    ASSERT_TRUE(marginal.ok()) << marginal.status().message();
    EXPECT_LT((marginal.value().information - schur).norm(), 1e-9 * schur.norm());

    // In the buffers of a solver workspace whose last solve kept its factorization and carried linearizations to
    // first order (a relinearization threshold): the same information bit for bit, and the workspace's next solve is
    // the same as a fresh one's.
    SolverOptions carrying;
    carrying.method = SolverOptions::Method::kGaussNewton;
    carrying.relinearize_threshold = 1e-2;
    carrying.max_iterations = 3;
    SolverWorkspace workspace;
    ASSERT_TRUE(Solve(carrying, &graph, nullptr, &workspace).usable());
    ASSERT_GT(workspace.carries(), 0);
    const auto fresh = ComputeMarginalInformation(graph, {lever});
    const auto reused = ComputeMarginalInformation(graph, {lever}, &workspace);
    ASSERT_TRUE(fresh.ok() && reused.ok());
    EXPECT_EQ(reused.value().information, fresh.value().information);
    EXPECT_EQ(reused.value().conditional, fresh.value().conditional);
    std::vector<std::pair<VariableId, Eigen::VectorXd>> start;
    for (const auto& [id, v] : graph.variables()) start.emplace_back(id, v.value);
    const SolverOptions options;
    const SolverSummary after = Solve(options, &graph, nullptr, &workspace);
    const Eigen::VectorXd lever_after = graph.variable(lever).value;
    for (const auto& [id, value] : start) graph.mutable_variable(id).value = value;
    const SolverSummary alone = Solve(options, &graph, nullptr);
    EXPECT_EQ(after.final_cost, alone.final_cost);
    EXPECT_EQ(lever_after, graph.variable(lever).value);
  }
}

// Reset of one NormalEquations object to a window that slides (the oldest pose marginalized, a new one added, a
// factor gated off and on again, a held-constant parameter freed) is incremental; it must give the same system as a
// fresh object built from scratch: the same factors, H's pattern and values, gradient, cost and step, bit for bit.
TEST(NormalEquationsTest, IncrementalResetOfASlidingWindowMatchesAFreshBuild) {
  std::mt19937 rng(5);
  Graph graph;
  const VariableId lever =
      graph.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d(0.1, 0.2, 0.3), false, std::nullopt});
  const VariableId held =
      graph.AddVariable({"held", Manifold::UnitQuaternion(), Eigen::Vector4d(1.0, 0.0, 0.0, 0.0), true, std::nullopt});
  std::deque<VariableId> poses;
  const auto tie = [&](const std::vector<VariableId>& ids) { TieWithRandomPrior(ids, &rng, &graph); };
  const auto add_pose = [&] {
    poses.push_back(graph.AddVariable({"pose", Manifold::Pose(), testing::RandomPoint(Manifold::Pose(), &rng, 5.0),
                                       false, Time::FromSeconds(static_cast<double>(poses.size()))}));
    tie({poses.back()});
    if (poses.size() > 1) tie({poses[poses.size() - 2], poses.back(), lever});
    if (poses.size() % 3 == 0) tie({poses.back(), held});
  };
  tie({held});  // on a held-constant variable only: never in the system
  for (int k = 0; k < 8; ++k) add_pose();

  internal::NormalEquations incremental;
  FactorId gated = -1;
  for (int step = 0; step < 12; ++step) {
    // Slide: marginalize the oldest pose, add a new one; gate a factor off at step 3, on again at step 5; free the
    // held parameter at step 8 (a variable that was constant becomes free: the tables are rebuilt).
    if (step > 0) {
      ASSERT_TRUE(Marginalize({poses.front()}, &graph));
      poses.pop_front();
      add_pose();
    }
    if (step == 3) {
      gated = graph.FactorsOf(poses[4]).back();
      graph.mutable_factor(gated).active = false;
    }
    if (step == 5) graph.mutable_factor(gated).active = true;
    if (step == 8) graph.mutable_variable(held).fixed = false;

    incremental.Reset(graph, FreeVariableOrder(graph));
    internal::NormalEquations fresh(graph, FreeVariableOrder(graph));
    ASSERT_TRUE(incremental.Linearize(graph));
    ASSERT_TRUE(fresh.Linearize(graph));
    ASSERT_EQ(incremental.factor_ids(), fresh.factor_ids()) << "step " << step;
    const Eigen::SparseMatrix<double>& a = incremental.hessian_upper();
    const Eigen::SparseMatrix<double>& b = fresh.hessian_upper();
    ASSERT_EQ(a.rows(), b.rows()) << "step " << step;
    ASSERT_EQ(a.nonZeros(), b.nonZeros()) << "step " << step;
    EXPECT_TRUE(std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1, b.outerIndexPtr()));
    EXPECT_TRUE(std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr()));
    EXPECT_TRUE(std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), b.valuePtr())) << "step " << step;
    EXPECT_EQ(incremental.gradient(), fresh.gradient()) << "step " << step;
    EXPECT_EQ(incremental.cost(), fresh.cost()) << "step " << step;
    Eigen::VectorXd dx_incremental, dx_fresh;
    ASSERT_TRUE(incremental.Solve(0.0, &dx_incremental));
    ASSERT_TRUE(fresh.Solve(0.0, &dx_fresh));
    EXPECT_EQ(dx_incremental, dx_fresh) << "step " << step;
    // Move the free variables (as a solver step would) so that the next linearization point differs.
    incremental.Update(0.1 * dx_incremental, &graph);
  }
  // Every Reset after the first was incremental but the one after the parameter was freed.
  EXPECT_EQ(incremental.incremental_resets(), 10);
}

// A window with a time-varying parameter's instance per three poses (process.interval_s): its block pattern changes
// as the window slides and comes back every three slides. The patterns kept from before (BuildPattern) must give the
// same system as a fresh object built from scratch, bit for bit (H's pattern and values, gradient, step, the oldest
// pose's covariance); fewer patterns are built than there are slides.
TEST(NormalEquationsTest, PatternsThatComeBackAsTheWindowSlidesMatchAFreshBuild) {
  SlidingWindowWithInstances window(29, 3, false);
  Graph& graph = window.graph();
  for (int k = 0; k < 8; ++k) window.AddPose();

  internal::NormalEquations incremental;
  const int slides = 15;
  for (int step = 0; step <= slides; ++step) {
    if (step > 0) {
      ASSERT_TRUE(window.Slide());
    }
    incremental.Reset(graph, FreeVariableOrder(graph));
    internal::NormalEquations fresh(graph, FreeVariableOrder(graph));
    ASSERT_TRUE(incremental.Linearize(graph));
    ASSERT_TRUE(fresh.Linearize(graph));
    const Eigen::SparseMatrix<double>& a = incremental.hessian_upper();
    const Eigen::SparseMatrix<double>& b = fresh.hessian_upper();
    ASSERT_EQ(a.rows(), b.rows()) << "step " << step;
    ASSERT_EQ(a.nonZeros(), b.nonZeros()) << "step " << step;
    EXPECT_TRUE(std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1, b.outerIndexPtr()))
        << "step " << step;
    EXPECT_TRUE(std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr())) << "step " << step;
    EXPECT_TRUE(std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), b.valuePtr())) << "step " << step;
    EXPECT_EQ(incremental.gradient(), fresh.gradient()) << "step " << step;
    Eigen::VectorXd dx_incremental, dx_fresh;
    ASSERT_TRUE(incremental.Solve(0.0, &dx_incremental));
    ASSERT_TRUE(fresh.Solve(0.0, &dx_fresh));
    EXPECT_EQ(dx_incremental, dx_fresh) << "step " << step;
    Eigen::MatrixXd cov_incremental, cov_fresh;
    ASSERT_TRUE(incremental.Covariance({window.oldest_pose()}, &cov_incremental));
    ASSERT_TRUE(fresh.Covariance({window.oldest_pose()}, &cov_fresh));
    EXPECT_EQ(cov_incremental, cov_fresh) << "step " << step;
  }
  // The first patterns are built; from then on most come back from the kept ones (the marginalization prior on the
  // leaving instance's successor may add a pattern or two before the cycle settles).
  EXPECT_LE(incremental.patterns_built(), 8);
  EXPECT_GT(slides + 1 - incremental.patterns_built(), 7);
}

// Incremental factorization (with a relinearization threshold): the leading block columns of the factor whose rows of
// H did not change since the last factorization are taken over. Against a fresh object on the same graph at every
// slide (the same H bit for bit: variables either stay or move beyond the threshold, so every factor is evaluated at
// the same values in both): before the first marginalization the step and the oldest pose's covariance are the same
// bit for bit; after it (the prior stands for the Schur complement that the kept rows hold) to 1e-12 relative. A
// moved pose, a factor gated off or on again, and a leaving pose whose factors were evaluated again after the last
// factorization limit what is taken over.
TEST(NormalEquationsTest, IncrementalFactorizationOfASlidingWindowMatchesAFreshOne) {
  std::mt19937 rng(17);
  Graph graph;
  const VariableId lever =
      graph.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d(0.1, 0.2, 0.3), false, std::nullopt});
  std::deque<VariableId> poses;
  int stamp = 0;
  const auto tie = [&](const std::vector<VariableId>& ids) { TieWithRandomPrior(ids, &rng, &graph); };
  const auto add_pose = [&] {
    poses.push_back(graph.AddVariable({"pose", Manifold::Pose(), testing::RandomPoint(Manifold::Pose(), &rng, 5.0),
                                       false, Time::FromSeconds(static_cast<double>(stamp++))}));
    tie({poses.back()});
    if (poses.size() > 1) tie({poses[poses.size() - 2], poses.back(), lever});
  };
  for (int k = 0; k < 10; ++k) add_pose();
  const double threshold = 1e-3;
  const auto move = [&](VariableId id) {  // beyond the threshold
    Variable& v = graph.mutable_variable(id);
    const Eigen::VectorXd d = Eigen::VectorXd::Constant(v.manifold.tangent_dim(), 10.0 * threshold);
    v.manifold.Plus(v.value.data(), d.data(), v.value.data());
  };

  internal::NormalEquations incremental;
  incremental.set_relinearize_threshold(threshold);
  FactorId gated = -1;
  long reused_before = 0;
  bool marginalized = false;
  for (int step = 0; step < 14; ++step) {
    int reusable = 1 << 20;  // bound on the columns taken over at this step
    if (step > 0 && step % 2 == 0) {
      ASSERT_TRUE(Marginalize({poses.front()}, &graph));
      poses.pop_front();
      marginalized = true;
    }
    if (step > 0) {
      add_pose();
      reusable = static_cast<int>(poses.size()) - 2;  // the pose before the new one has a new factor
    }
    if (step == 5) {
      move(poses[4]);  // its factors are evaluated again from pose 3 on
      reusable = 3;
    }
    if (step == 7) {
      gated = graph.FactorsOf(poses[6]).back();  // (pose 6, pose 7, lever)
      graph.mutable_factor(gated).active = false;
      reusable = 6;
    }
    if (step == 9) {
      graph.mutable_factor(gated).active = true;
      reusable = 5;  // pose 6 of step 7, one pose marginalized since
    }
    if (step == 12) reusable = 0;  // the leaving pose's factors were evaluated again after the last factorization

    incremental.Reset(graph, FreeVariableOrder(graph));
    internal::NormalEquations fresh(graph, FreeVariableOrder(graph));
    fresh.set_relinearize_threshold(threshold);
    ASSERT_TRUE(incremental.Linearize(graph));
    ASSERT_TRUE(fresh.Linearize(graph));
    const Eigen::SparseMatrix<double>& a = incremental.hessian_upper();
    const Eigen::SparseMatrix<double>& b = fresh.hessian_upper();
    ASSERT_EQ(a.nonZeros(), b.nonZeros()) << "step " << step;
    ASSERT_TRUE(std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), b.valuePtr())) << "step " << step;
    Eigen::VectorXd dx_incremental, dx_fresh;
    ASSERT_TRUE(incremental.Solve(0.0, &dx_incremental));
    ASSERT_TRUE(fresh.Solve(0.0, &dx_fresh));
    EXPECT_EQ(fresh.reused_blocks(), 0);
    const long reused = incremental.reused_blocks() - reused_before;
    reused_before = incremental.reused_blocks();
    EXPECT_LE(reused, reusable) << "step " << step;
    if (step > 0 && step != 12) {
      EXPECT_GT(reused, 0) << "step " << step;
    }
    Eigen::MatrixXd cov_incremental, cov_fresh;
    ASSERT_TRUE(incremental.Covariance({poses.front()}, &cov_incremental));
    ASSERT_TRUE(fresh.Covariance({poses.front()}, &cov_fresh));
    if (marginalized) {
      EXPECT_LT((dx_incremental - dx_fresh).norm(), 1e-12 * dx_fresh.norm()) << "step " << step;
      EXPECT_LT((cov_incremental - cov_fresh).norm(), 1e-12 * cov_fresh.norm()) << "step " << step;
    } else {
      EXPECT_EQ(dx_incremental, dx_fresh) << "step " << step;
      EXPECT_EQ(cov_incremental, cov_fresh) << "step " << step;
    }
    if (step == 11) {
      // After the factorization the oldest pose moves and its factors are evaluated again (a Gauss-Newton trial point
      // beyond the threshold): the prior that replaces them is not the Schur complement of the kept rows.
      move(poses.front());
      double cost = 0.0;
      ASSERT_TRUE(incremental.LinearizeForCost(&cost));
    }
  }
  EXPECT_GT(incremental.reused_blocks(), 40);
}

// Under a relinearization threshold Linearize leaves out the blocks of H that the kept factorization takes over. A
// window that slides (with a border parameter, an instance per two poses and a pose moved beyond the threshold) is
// solved by two objects with the same history: one completes H after every Linearize (hessian_upper), the other does
// not. Their steps must be the same bit for bit (the factorization reads only blocks that were summed), H completed
// after the solve the same as the other's bit for bit, a damped solve after a fresh Linearize the same (it completes H
// first), and the model decrease from -g.dx / 2 that from H to rounding. Reading H once a factor was evaluated again
// since (a trial point beyond the threshold) is refused.
TEST(NormalEquationsTest, LinearizationWithoutTheTakenOverBlocksSolvesLikeAComplete) {
  SlidingWindowWithInstances window(31, 2, true);
  Graph& graph = window.graph();
  for (int k = 0; k < 10; ++k) window.AddPose();
  const double threshold = 1e-3;

  internal::NormalEquations partial, complete;
  int steps_with_reuse = 0;
  partial.set_relinearize_threshold(threshold);
  complete.set_relinearize_threshold(threshold);
  for (int step = 0; step < 12; ++step) {
    if (step > 0) {
      ASSERT_TRUE(window.Slide());
    }
    if (step == 6) {  // beyond the threshold: its factors are evaluated again
      Variable& v = graph.mutable_variable(window.pose(5));
      const Eigen::VectorXd d = Eigen::VectorXd::Constant(6, 10.0 * threshold);
      v.manifold.Plus(v.value.data(), d.data(), v.value.data());
    }
    const long reused_before = partial.reused_blocks();
    partial.Reset(graph, FreeVariableOrder(graph));
    complete.Reset(graph, FreeVariableOrder(graph));
    ASSERT_TRUE(partial.Linearize(graph));
    ASSERT_TRUE(complete.Linearize(graph));
    complete.hessian_upper();
    Eigen::VectorXd dx_partial, dx_complete;
    ASSERT_TRUE(partial.Solve(0.0, &dx_partial));
    ASSERT_TRUE(complete.Solve(0.0, &dx_complete));
    if (partial.reused_blocks() > reused_before) ++steps_with_reuse;
    EXPECT_EQ(partial.reused_blocks(), complete.reused_blocks()) << "step " << step;
    EXPECT_EQ(dx_partial, dx_complete) << "step " << step;
    // -g.dx - dx.H.dx / 2 and -g.dx / 2 differ by dx.(H dx + g) / 2: the solve's residual (the kept rows are the
    // factor of the exact Schur complement, the prior in H is that complement to rounding).
    const double decrease = complete.ModelDecrease(dx_complete);
    const Eigen::VectorXd residual =
        complete.hessian_upper().selfadjointView<Eigen::Upper>() * dx_complete + complete.gradient();
    EXPECT_NEAR(partial.ModelDecrease(dx_partial), decrease,
                0.5 * dx_complete.norm() * residual.norm() + 1e-12 * std::abs(decrease))
        << "step " << step;
    const Eigen::SparseMatrix<double>& a = partial.hessian_upper();
    const Eigen::SparseMatrix<double>& b = complete.hessian_upper();
    ASSERT_EQ(a.nonZeros(), b.nonZeros()) << "step " << step;
    EXPECT_TRUE(std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), b.valuePtr())) << "step " << step;
    // Both take the step, as a Gauss-Newton iteration would (within the threshold: the factors are carried).
    partial.Update(dx_partial.normalized() * 0.1 * threshold, &graph);
    ASSERT_TRUE(partial.Linearize(graph));
    ASSERT_TRUE(complete.Linearize(graph));
    if (step % 3 == 1) {
      ASSERT_TRUE(partial.Solve(0.3, &dx_partial));
      ASSERT_TRUE(complete.Solve(0.3, &dx_complete));
      EXPECT_EQ(dx_partial, dx_complete) << "step " << step;
    } else {
      ASSERT_TRUE(partial.Solve(0.0, &dx_partial));
      ASSERT_TRUE(complete.Solve(0.0, &dx_complete));
      EXPECT_EQ(dx_partial, dx_complete) << "step " << step;
    }
  }
  EXPECT_GE(steps_with_reuse, 6);
  EXPECT_DEATH(
      {
        partial.Update(Eigen::VectorXd::Constant(partial.dimension(), 10.0 * threshold), &graph);
        double cost = 0.0;
        partial.LinearizeForCost(&cost);
        partial.hessian_upper();
      },
      "evaluated again");
}

// Relinearization threshold (iSAM2's): a factor whose variables all moved by at most the threshold since its
// linearization keeps its Jacobians (H is the same, bit for bit) and its whitened error is carried to first order,
// r_lin + sum_i J_i (x_i [-] x_lin_i), which differs from a fresh evaluation by second order only. Once a variable has
// moved beyond it, its factors are evaluated again and the system equals a fresh one's; with threshold 0 every move
// re-evaluates.
TEST(NormalEquationsTest, RelinearizationThresholdCarriesTheErrorToFirstOrderAndRelinearizesBeyondIt) {
  std::mt19937 rng(23);
  Graph graph;
  std::vector<VariableId> poses;
  for (int k = 0; k < 5; ++k)
    poses.push_back(graph.AddVariable(
        {"pose", Manifold::Pose(), testing::RandomPoint(Manifold::Pose(), &rng, 5.0), false, Time::FromSeconds(k)}));
  const VariableId lever =
      graph.AddVariable({"lever", Manifold::Euclidean(3), Eigen::Vector3d(0.1, 0.2, 0.3), false, std::nullopt});
  for (std::size_t k = 0; k < poses.size(); ++k) {
    TieWithRandomPrior({poses[k]}, &rng, &graph);
    if (k + 1 < poses.size()) TieWithRandomPrior({poses[k], poses[k + 1], lever}, &rng, &graph);
  }
  const double threshold = 1e-3;
  internal::NormalEquations system(graph, FreeVariableOrder(graph));
  system.set_relinearize_threshold(threshold);
  ASSERT_TRUE(system.Linearize(graph));
  const long factors = static_cast<long>(system.factor_ids().size());
  EXPECT_EQ(system.evaluations(), factors);
  const Eigen::SparseMatrix<double> H0 = system.hessian_upper();
  std::map<FactorId, internal::WhitenedFactor> at_start;
  const auto full_mask = [&](FactorId id) {
    return (std::uint64_t{1} << graph.factor(id).variables.size()) - 1;  // every variable is free
  };
  for (FactorId id : system.factor_ids()) at_start[id] = *system.LinearizationAt(id, full_mask(id));
  std::map<VariableId, Eigen::VectorXd> start;
  for (const auto& [id, v] : graph.variables()) start[id] = v.value;

  // Every tangent component moved by up to 0.8 of the threshold: carried, the same H.
  std::uniform_real_distribution<double> within(-0.8 * threshold, 0.8 * threshold);
  const Eigen::VectorXd small = Eigen::VectorXd::NullaryExpr(system.dimension(), [&] { return within(rng); });
  system.Update(small, &graph);
  ASSERT_TRUE(system.Linearize(graph));
  EXPECT_EQ(system.evaluations(), factors);
  EXPECT_EQ(system.carries(), factors);
  EXPECT_TRUE(std::equal(H0.valuePtr(), H0.valuePtr() + H0.nonZeros(), system.hessian_upper().valuePtr()));
  double cost = 0.0;
  for (FactorId id : system.factor_ids()) {
    const FactorEntry& entry = graph.factor(id);
    const internal::WhitenedFactor* kept = system.LinearizationAt(id, full_mask(id));
    ASSERT_NE(kept, nullptr);
    const internal::WhitenedFactor& lin = at_start[id];
    Eigen::VectorXd expected = lin.residual;
    for (std::size_t i = 0; i < entry.variables.size(); ++i) {
      const Manifold& m = graph.variable(entry.variables[i]).manifold;
      Eigen::VectorXd d(m.tangent_dim());
      m.Minus(graph.variable(entry.variables[i]).value.data(), start.at(entry.variables[i]).data(), d.data());
      expected += lin.jacobians[i] * d;
      EXPECT_EQ(kept->jacobians[i], lin.jacobians[i]);
    }
    EXPECT_LT((kept->residual - expected).norm(), 1e-12 * (1.0 + expected.norm())) << "factor " << id;
    internal::WhitenedFactor fresh;
    ASSERT_TRUE(internal::LinearizeFactor(graph, entry, std::vector<bool>(entry.variables.size(), true), &fresh));
    // Second order against the first-order change.
    EXPECT_LT((kept->residual - fresh.residual).norm(), 0.01 * (fresh.residual - lin.residual).norm())
        << "factor " << id;
    cost += 0.5 * kept->residual.squaredNorm();
  }
  EXPECT_NEAR(system.cost(), cost, 1e-12 * cost);

  // Then every component moved by 2 thresholds more: beyond it from the start, every factor is evaluated again.
  system.Update(Eigen::VectorXd::Constant(system.dimension(), 2.0 * threshold), &graph);
  ASSERT_TRUE(system.Linearize(graph));
  EXPECT_EQ(system.evaluations(), 2 * factors);
  EXPECT_EQ(system.carries(), factors);
  internal::NormalEquations fresh(graph, FreeVariableOrder(graph));
  ASSERT_TRUE(fresh.Linearize(graph));
  const Eigen::SparseMatrix<double>& a = system.hessian_upper();
  const Eigen::SparseMatrix<double>& b = fresh.hessian_upper();
  ASSERT_EQ(a.nonZeros(), b.nonZeros());
  EXPECT_TRUE(std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), b.valuePtr()));
  EXPECT_EQ(system.gradient(), fresh.gradient());

  // Threshold 0: the smallest move re-evaluates every factor.
  fresh.Update(Eigen::VectorXd::Constant(fresh.dimension(), 1e-9), &graph);
  ASSERT_TRUE(fresh.Linearize(graph));
  EXPECT_EQ(fresh.evaluations(), 2 * factors);
  EXPECT_EQ(fresh.carries(), 0);
}

// Two factors on one pose, linearized at different points of it (the second one evaluated again after its other pose
// moved beyond the threshold): carried to the same values, each takes the pose's offset from its own point (the
// box-minus of a pose is kept per block for the factors that share both points).
TEST(NormalEquationsTest, CarriesOfFactorsLinearizedAtDifferentPointsOfAPoseUseTheirOwnPoint) {
  std::mt19937 rng(31);
  Graph graph;
  const VariableId p = graph.AddVariable(
      {"pose", Manifold::Pose(), testing::RandomPoint(Manifold::Pose(), &rng, 5.0), false, Time::FromSeconds(0)});
  const VariableId q = graph.AddVariable(
      {"pose", Manifold::Pose(), testing::RandomPoint(Manifold::Pose(), &rng, 5.0), false, Time::FromSeconds(1)});
  TieWithRandomPrior({p}, &rng, &graph);
  TieWithRandomPrior({p, q}, &rng, &graph);
  const double threshold = 1e-2;
  internal::NormalEquations system(graph, FreeVariableOrder(graph));
  system.set_relinearize_threshold(threshold);
  const auto move = [&](VariableId id, double by) {
    Variable& v = graph.mutable_variable(id);
    Eigen::VectorXd d(6);
    d << by, -by, 0.5 * by, -0.7 * by, by, 0.3 * by;
    v.manifold.Plus(v.value.data(), d.data(), v.value.data());
  };
  const std::vector<FactorId> ids = system.factor_ids();
  ASSERT_EQ(ids.size(), 2u);
  ASSERT_TRUE(system.Linearize(graph));
  const internal::WhitenedFactor prior_lin = *system.LinearizationAt(ids[0], 1);
  const Eigen::VectorXd p0 = graph.variable(p).value;
  // p within the threshold, q beyond it: the prior on p is carried from p0, the tie evaluated again at p1.
  move(p, 0.3 * threshold);
  move(q, 3.0 * threshold);
  ASSERT_TRUE(system.Linearize(graph));
  EXPECT_EQ(system.evaluations(), 3);
  const internal::WhitenedFactor tie_lin = *system.LinearizationAt(ids[1], 3);
  const Eigen::VectorXd p1 = graph.variable(p).value, q1 = graph.variable(q).value;
  // Both within the threshold of their points: both carried to p2.
  move(p, 0.3 * threshold);
  move(q, 0.1 * threshold);
  ASSERT_TRUE(system.Linearize(graph));
  EXPECT_EQ(system.evaluations(), 3);
  const auto minus = [&](VariableId id, const Eigen::VectorXd& from) {
    Eigen::VectorXd d(6);
    Manifold::Pose().Minus(graph.variable(id).value.data(), from.data(), d.data());
    return d;
  };
  const Eigen::VectorXd prior_expected = prior_lin.residual + prior_lin.jacobians[0] * minus(p, p0);
  const Eigen::VectorXd tie_expected =
      tie_lin.residual + tie_lin.jacobians[0] * minus(p, p1) + tie_lin.jacobians[1] * minus(q, q1);
  EXPECT_LT((system.LinearizationAt(ids[0], 1)->residual - prior_expected).norm(), 1e-12 * prior_expected.norm());
  EXPECT_LT((system.LinearizationAt(ids[1], 3)->residual - tie_expected).norm(), 1e-12 * tie_expected.norm());
}

}  // namespace
}  // namespace roamlab::estimator
