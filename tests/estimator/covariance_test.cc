#include "estimator/covariance.h"

#include <cmath>

#include <gtest/gtest.h>

#include "estimator/solver.h"
#include "tests/estimator/solver_testing.h"

namespace roamlab::estimator {
namespace {

using testing::MultiAntennaProblem;

TEST(SolverTest, NoisyErrorIsConsistentWithMarginalCovariance) {
  // Over many seeds, the squared Mahalanobis error of the pose against its marginal covariance averages to 6 (the
  // tangent dimension); with 40 trials the average of chi-square(6) lies in [4.6, 7.6] with probability ~0.999.
  double sum = 0.0;
  const int trials = 40;
  for (int seed = 0; seed < trials; ++seed) {
    MultiAntennaProblem problem(0.05, 100 + seed);
    ASSERT_TRUE(Solve(SolverOptions{}, &problem.graph).usable());
    const auto info = ComputeMarginalInformation(problem.graph, {problem.pose});
    ASSERT_TRUE(info.ok()) << info.status().message();
    const Eigen::VectorXd e = problem.Error();
    sum += e.dot(info.value().information * e);
  }
  EXPECT_GT(sum / trials, 4.6);
  EXPECT_LT(sum / trials, 7.6);
}

TEST(ObservabilityTest, ClassifiesNullAndWeakDirections) {
  // Component 0 well determined; components 1 and 2 only through their sum (a null direction); component 3 nearly
  // collinear with component 0.
  Eigen::MatrixXd J(4, 4);
  J << 1, 0, 0, 0, 0, 1, 1, 0, 0, 2, 2, 0, 1, 0, 0, 1.001;
  Eigen::MatrixXd H = J.transpose() * J;
  H(0, 0) += 1.0;
  const ObservabilityAnalysis a = AnalyzeObservability(H, H.diagonal());
  EXPECT_EQ(a.observability[0], Observability::kObservable);
  EXPECT_EQ(a.observability[1], Observability::kUnobservable);
  EXPECT_EQ(a.observability[2], Observability::kUnobservable);
  EXPECT_TRUE(std::isnan(a.std[1]));
  EXPECT_NEAR(std::abs(a.correlation(1, 2)), 1.0, 1e-3);
  EXPECT_EQ(a.observability[3], Observability::kObservable);
}

TEST(ObservabilityTest, ComponentWhoseInformationIsAlmostAllSharedIsUnobservable) {
  // One component known only 1e-3 as well once the other variables are marginalized as it would be on its own: its
  // variance is inflated 1e6 times (std 1000 times): unobservable. At 30 times (std ~5.5x) it is weak.
  Eigen::MatrixXd marginal = Eigen::MatrixXd::Identity(2, 2);
  marginal(1, 1) = 1e-3 * 1e-3;
  Eigen::VectorXd conditional(2);
  conditional << 1.0, 1.0;
  ObservabilityAnalysis a = AnalyzeObservability(marginal, conditional);
  EXPECT_EQ(a.observability[0], Observability::kObservable);
  EXPECT_EQ(a.observability[1], Observability::kUnobservable);
  EXPECT_TRUE(std::isnan(a.std[1]));
  marginal(1, 1) = 1.0 / 300.0;
  a = AnalyzeObservability(marginal, conditional);
  EXPECT_EQ(a.observability[1], Observability::kWeak);
  EXPECT_NEAR(a.std[1], std::sqrt(300.0), 1e-9);
}

}  // namespace
}  // namespace roamlab::estimator
