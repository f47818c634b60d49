#include "estimator/odometry/robust_linear.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

namespace roamlab::estimator::odometry {
namespace {

// 20 % of the pairs are gross outliers (about 50 noise standard deviations, random sign): eq. 9's Huber fit still
// recovers W within a few standard errors of a least-squares fit on clean data, while plain least squares on the same
// data misses by far more (so the assertion can fail).
TEST(RobustLinearTest, HuberRecoversWWithTwentyPercentGrossOutliers) {
  const int n = 1000;
  Eigen::MatrixXd W_true(3, 3);
  W_true << 0.04, -0.02, 0.01, -0.01, 0.05, 0.02, 0.3, 0.25, -0.28;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double sigma = 0.002;
  Eigen::MatrixXd X(n, 3), Y(n, 3);
  for (int k = 0; k < n; ++k) {
    for (int d = 0; d < 3; ++d) X(k, d) = 3.0 * normal(rng);
    Y.row(k) = (W_true * X.row(k).transpose()).transpose();
    for (int i = 0; i < 3; ++i) Y(k, i) += sigma * normal(rng);
    if (k % 5 == 0) {
      for (int i = 0; i < 3; ++i) Y(k, i) += (uniform(rng) < 0.5 ? -1.0 : 1.0) * sigma * (30.0 + 40.0 * uniform(rng));
    }
  }
  const Eigen::MatrixXd S = Eigen::MatrixXd::Constant(n, 3, sigma);
  Result<HuberFit> fit = FitHuberLinear(X, Y, S);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  // Standard error of one coefficient of a clean least-squares fit: sigma / sqrt(n var(x)).
  const double standard_error = sigma / std::sqrt(static_cast<double>(n) * 9.0);
  const double huber_error = (fit.value().W - W_true).cwiseAbs().maxCoeff();
  EXPECT_LT(huber_error, 5.0 * standard_error);
  const Eigen::MatrixXd W_ls = (X.transpose() * X).ldlt().solve(X.transpose() * Y).transpose();
  EXPECT_GT((W_ls - W_true).cwiseAbs().maxCoeff(), 10.0 * standard_error);
}

TEST(RobustLinearTest, RejectsSizeMismatchAndTooFewPairs) {
  EXPECT_FALSE(
      FitHuberLinear(Eigen::MatrixXd::Ones(5, 2), Eigen::MatrixXd::Ones(4, 3), Eigen::MatrixXd::Ones(5, 3)).ok());
  EXPECT_FALSE(
      FitHuberLinear(Eigen::MatrixXd::Ones(2, 2), Eigen::MatrixXd::Ones(2, 3), Eigen::MatrixXd::Ones(2, 3)).ok());
}

}  // namespace
}  // namespace roamlab::estimator::odometry
