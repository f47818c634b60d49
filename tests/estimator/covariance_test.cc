#include "estimator/covariance.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "estimator/marginalization.h"
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

// A scalar x read n times as z_t = 1 + e_t, e a first-order Gauss-Markov series of unit variance and lag-one
// correlation a, each reading believed white with unit variance (stream "z", stamped 10 ms apart): the white variance
// of the estimate is 1 / n, its actual one about (1 + a) / (n (1 - a)).
struct ScalarSeries {
  Graph graph;
  VariableId x;
  ScalarSeries(int n, double a, std::uint32_t seed) {
    x = graph.AddVariable({"x", Manifold::Euclidean(1), Eigen::VectorXd::Zero(1), false, std::nullopt});
    std::mt19937 rng(seed);
    std::normal_distribution<double> normal;
    double e = normal(rng);
    for (int t = 0; t < n; ++t) {
      graph.AddFactor(
          std::make_unique<LinearPriorFactor>(std::vector<Manifold>{Manifold::Euclidean(1)},
                                              std::vector<Eigen::VectorXd>{Eigen::VectorXd::Constant(1, 1.0 + e)},
                                              Eigen::MatrixXd::Identity(1, 1), Eigen::VectorXd::Zero(1)),
          {x}, Eigen::MatrixXd::Identity(1, 1), Loss::Trivial(), "z", Time::FromNanoseconds(10000000LL * t));
      e = a * e + std::sqrt(1.0 - a * a) * normal(rng);
    }
  }
  // The HAC variance over the white one at the least-squares estimate.
  double HacOverWhite() {
    EXPECT_TRUE(Solve(SolverOptions{}, &graph).usable());
    const auto info = ComputeMarginalInformation(graph, {x});
    EXPECT_TRUE(info.ok());
    const Eigen::MatrixXd white = info.value().information.inverse();
    const auto hac = ComputeHacCovariance(graph, {x}, white);
    EXPECT_TRUE(hac.ok()) << hac.status().message();
    return hac.value().covariance(0, 0) / white(0, 0);
  }
};

// With correlation a = 0.9 the actual variance is 19 times the white one. The last window of lags whose mean
// autocorrelation reaches 2 / sqrt(n) = 0.014 is [16, 32) (mean 0.094; [32, 64) has 0.010, near enough to the
// threshold that noise may admit it), so L = 93 (or 189): the Bartlett sum keeps 0.90 (0.95) of the long-run variance,
// with a relative spread of about sqrt(4 L / (3 n)) = 0.08 (0.11). Within 3 of those of either.
TEST(HacCovarianceTest, InflatesTheWhiteVarianceByTheLongRunVarianceOfCorrelatedResiduals) {
  constexpr double kA = 0.9;
  ScalarSeries series(20000, kA, 5);
  const double ratio = series.HacOverWhite() / ((1.0 + kA) / (1.0 - kA));
  EXPECT_GT(ratio, 0.90 - 3.0 * 0.08);
  EXPECT_LT(ratio, 0.95 + 3.0 * 0.11);
}

// With white residuals of the believed variance the HAC variance is the white one, within the spread of a variance
// estimate over n = 20000 rows and a lag of a few rows (about sqrt(2 / n) = 0.01 each; 5 of those).
TEST(HacCovarianceTest, MatchesTheWhiteVarianceOnWhiteResiduals) {
  ScalarSeries series(20000, 0.0, 6);
  EXPECT_NEAR(series.HacOverWhite(), 1.0, 0.05);
}

// AR(1) residuals of correlation a: the integrated autocorrelation time (1 + a) / (1 - a) = 19 for a = 0.9, kept as
// above.
TEST(HacCovarianceTest, IntegratedAutocorrelationTimeOfAGaussMarkovSeries) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  std::vector<Eigen::VectorXd> series;
  double e = normal(rng);
  for (int t = 0; t < 20000; ++t) {
    series.push_back(Eigen::VectorXd::Constant(1, e));
    e = 0.9 * e + std::sqrt(1.0 - 0.81) * normal(rng);
  }
  const ResidualAutocorrelation r = AnalyzeAutocorrelation(series);
  EXPECT_TRUE(r.lag == 93 || r.lag == 189) << r.lag;
  EXPECT_GT(r.integrated_time / 19.0, 0.90 - 3.0 * 0.08);
  EXPECT_LT(r.integrated_time / 19.0, 0.95 + 3.0 * 0.11);
}

// BartlettSum's running boxes give the weighted sum of lagged products itself, the products of the last L rows with
// each other included, at a lag that is a large share of the rows (as the twin's motion capture reaches) and beyond.
TEST(HacCovarianceTest, BartlettSumIsTheWeightedSumOfLaggedProducts) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd a(2, 40);
  for (Eigen::Index t = 0; t < a.cols(); ++t) a.col(t) = Eigen::Vector2d(normal(rng), normal(rng));
  for (const int lag : {0, 1, 10, 39, 60}) {
    Eigen::MatrixXd direct = a * a.transpose();
    for (int l = 1; l <= lag && l < a.cols(); ++l) {
      const Eigen::MatrixXd c = a.leftCols(a.cols() - l) * a.rightCols(a.cols() - l).transpose();
      direct += (1.0 - static_cast<double>(l) / (lag + 1)) * (c + c.transpose());
    }
    EXPECT_LT((BartlettSum(a, lag) - direct).norm(), 1e-12 * direct.norm()) << "lag " << lag;
  }
}

// Sums of `series` first-order Gauss-Markov series of `n` rows, correlation a, unit variance, each demeaned as the
// scores at a fit sum to zero, over lag L, as shares of the long-run sum n (1 + a) / (1 - a): their mean and standard
// error, of the plain and of the prewhitened Bartlett sum.
struct LongRunShares {
  double plain = 0.0, plain_error = 0.0, prewhitened = 0.0, prewhitened_error = 0.0;
};
LongRunShares ShareOfLongRunSum(int series, int n, double a, int lag, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const double long_run = n * (1.0 + a) / (1.0 - a);
  double sum[2] = {0.0, 0.0}, sum2[2] = {0.0, 0.0};
  for (int s = 0; s < series; ++s) {
    Eigen::MatrixXd x(1, n);
    double e = normal(rng);
    for (int t = 0; t < n; ++t, e = a * e + std::sqrt(1.0 - a * a) * normal(rng)) x(0, t) = e;
    x.array() -= x.mean();
    const double share[2] = {BartlettSum(x, lag)(0, 0) / long_run, PrewhitenedBartlettSum(x, lag)(0, 0) / long_run};
    for (int k = 0; k < 2; ++k) {
      sum[k] += share[k];
      sum2[k] += share[k] * share[k];
    }
  }
  const auto error = [&](int k) { return std::sqrt((sum2[k] / series - std::pow(sum[k] / series, 2)) / series); };
  return {sum[0] / series, error(0), sum[1] / series, error(1)};
}

// The twin's gyroscope under IMU noise correlated over 0.05 s at 100 Hz (a = exp(-0.2) = 0.82), 667 rows, L = 21:
// the plain Bartlett sum keeps 1 + 2 sum_{l=1..21} (1 - l / 22) a^l = 78 % of the long-run sum before the zero sum
// takes its share. Prewhitened, the mean is the long-run sum up to the recolouring's first-order
// biases, each about 5 % (the demeaned AR(1) coefficient's downward bias (1 + 3a) / n, times 2 / (1 - a); the
// convexity of (1 - rho)^-2, 3 (1 - a^2) / (n (1 - a)^2), upward), so within their sum 0.10 and 3 standard errors.
TEST(HacCovarianceTest, PrewhiteningRemovesTheBartlettSumsBiasOnAGaussMarkovSeries) {
  const LongRunShares s = ShareOfLongRunSum(300, 667, std::exp(-0.2), 21, 11);
  std::printf("share of the long-run sum: plain %.3f +- %.3f, prewhitened %.3f +- %.3f\n", s.plain, s.plain_error,
              s.prewhitened, s.prewhitened_error);
  EXPECT_LT(s.plain, 0.78);
  EXPECT_NEAR(s.prewhitened, 1.0, 0.10 + 3.0 * s.prewhitened_error);
}

// White rows: the AR(1) coefficients are near 0 and the prewhitened sum is the plain one, within the spread of the
// coefficient (about 1 / sqrt(n) = 0.014, a recolouring of 1 +- 0.03; 4 of those). A component that is zero throughout
// (a parameter the stream does not inform) stays zero.
TEST(HacCovarianceTest, PrewhiteningLeavesWhiteRowsAndZeroComponentsAlone) {
  std::mt19937 rng(12);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(2, 5000);
  for (int t = 0; t < x.cols(); ++t) x(0, t) = normal(rng);
  const Eigen::MatrixXd plain = BartlettSum(x, 2), prewhitened = PrewhitenedBartlettSum(x, 2);
  EXPECT_NEAR(prewhitened(0, 0) / plain(0, 0), 1.0, 4.0 * 2.0 / std::sqrt(5000.0));
  EXPECT_EQ(prewhitened(1, 1), 0.0);
  EXPECT_EQ(prewhitened(0, 1), 0.0);
}

}  // namespace
}  // namespace roamlab::estimator
