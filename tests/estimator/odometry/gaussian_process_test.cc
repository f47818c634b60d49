#include "estimator/odometry/gaussian_process.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace roamlab::estimator::odometry {
namespace {

// Wheel rotations of a differential drive over short intervals and a smooth nonlinear target.
void MakeData(int n, std::uint64_t seed, Eigen::MatrixXd* X, Eigen::VectorXd* y) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  X->resize(n, 2);
  y->resize(n);
  for (int k = 0; k < n; ++k) {
    (*X)(k, 0) = 2.0 + normal(rng);
    (*X)(k, 1) = 2.0 + normal(rng);
    (*y)[k] = 0.04 * (*X)(k, 0) + 0.03 * (*X)(k, 1) + 0.01 * std::sin((*X)(k, 0)) + 0.002 * normal(rng);
  }
}

class GpGradientTest : public ::testing::TestWithParam<std::pair<GpMean, GpKernel>> {};

// The analytic gradient of the log marginal likelihood against central differences, at a point away from the
// optimum (so that the gradient is not zero), for every mean/kernel combination.
TEST_P(GpGradientTest, LogMarginalLikelihoodGradientMatchesCentralDifferences) {
  const auto [mean, kernel] = GetParam();
  Eigen::MatrixXd X;
  Eigen::VectorXd y;
  MakeData(40, 3, &X, &y);
  const Eigen::VectorXd noise = Eigen::VectorXd::Constant(40, 1e-6);
  const GpLayout layout(2, mean, kernel);
  Eigen::VectorXd p = GpInitialParameters(layout, X, y);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> shift(-0.3, 0.3);
  for (int i = 0; i < p.size(); ++i) p[i] += (i >= layout.log_sn() + 1 ? 0.01 : 1.0) * shift(rng);
  Eigen::VectorXd gradient;
  const double value = GpLogMarginalLikelihood(layout, X, y, noise, p, &gradient);
  ASSERT_TRUE(std::isfinite(value));
  ASSERT_EQ(gradient.size(), layout.size());
  for (int i = 0; i < p.size(); ++i) {
    const double h = 1e-6 * std::max(1.0, std::abs(p[i]));
    Eigen::VectorXd plus = p, minus = p;
    plus[i] += h;
    minus[i] -= h;
    const double numeric = (GpLogMarginalLikelihood(layout, X, y, noise, plus, nullptr) -
                            GpLogMarginalLikelihood(layout, X, y, noise, minus, nullptr)) /
                           (2.0 * h);
    EXPECT_NEAR(gradient[i], numeric, 1e-5 * std::max(1.0, std::abs(numeric))) << "parameter " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(AllMeansAndKernels, GpGradientTest,
                         ::testing::Values(std::make_pair(GpMean::kZero, GpKernel::kRbf),
                                           std::make_pair(GpMean::kLinear, GpKernel::kRbf),
                                           std::make_pair(GpMean::kZero, GpKernel::kLinear),
                                           std::make_pair(GpMean::kLinear, GpKernel::kLinear),
                                           std::make_pair(GpMean::kZero, GpKernel::kRbfPlusLinear),
                                           std::make_pair(GpMean::kLinear, GpKernel::kRbfPlusLinear)));

// Linear kernel, zero mean, one input: Bayesian linear regression y = w x + e, w ~ N(0, sl^2), e ~ N(0, sn^2 + v_n).
// Posterior of w: precision P = 1/sl^2 + sum x_n^2 / s_n^2, mean P^-1 sum x_n y_n / s_n^2; f(x*) = w x*.
TEST(GaussianProcessTest, LinearKernelPredictionIsBayesianLinearRegression) {
  Eigen::MatrixXd X(5, 1);
  X << 0.5, 1.0, -0.7, 2.0, 1.5;
  Eigen::MatrixXd Y(5, 3);
  Y.col(0) << 0.2, 0.45, -0.3, 0.85, 0.6;
  Y.col(1) = -Y.col(0);
  Y.col(2) = 2.0 * Y.col(0);
  Eigen::MatrixXd noise(5, 3);
  noise.setConstant(0.01);
  noise(2, 0) = 0.05;  // unequal known noise
  const double sl = 0.8, sn = 0.1;
  const GpLayout layout(1, GpMean::kZero, GpKernel::kLinear);
  Eigen::VectorXd p(layout.size());
  p[layout.log_sl()] = std::log(sl);
  p[layout.log_sn()] = std::log(sn);
  GpOptions options;
  options.mean = GpMean::kZero;
  options.kernel = GpKernel::kLinear;
  Result<GaussianProcess> gp = GaussianProcess::Train(X, Y, noise, options, {p, p, p});
  ASSERT_TRUE(gp.ok()) << gp.status().message();
  Eigen::VectorXd x_star(1);
  x_star << 1.2;
  const Eigen::Vector3d mean = gp.value().PredictMean(x_star);
  const Eigen::Matrix3d cov = gp.value().PredictCovariance(x_star);
  for (int i = 0; i < 3; ++i) {
    double precision = 1.0 / (sl * sl);
    double b = 0.0;
    for (int k = 0; k < 5; ++k) {
      const double var = noise(k, i) + sn * sn;
      precision += X(k, 0) * X(k, 0) / var;
      b += X(k, 0) * Y(k, i) / var;
    }
    EXPECT_NEAR(mean[i], x_star[0] * b / precision, 1e-12);
    EXPECT_NEAR(cov(i, i), x_star[0] * x_star[0] / precision, 1e-12);
  }
}

// RBF kernel, linear mean, one training pair: mean = c x* + k*/(k + s^2) (y - c x), var = sf^2 - k*^2 / (sf^2 + s^2).
TEST(GaussianProcessTest, RbfPredictionWithOnePairMatchesClosedForm) {
  Eigen::MatrixXd X(2, 2);
  X << 1.0, 2.0, 50.0, 50.0;  // the second pair is far away: its kernel value is exp(-1e3), i.e. 0
  Eigen::MatrixXd Y(2, 3);
  Y << 0.3, -0.1, 0.05, 0.0, 0.0, 0.0;
  const Eigen::MatrixXd noise = Eigen::MatrixXd::Zero(2, 3);
  const GpLayout layout(2, GpMean::kLinear, GpKernel::kRbf);
  Eigen::VectorXd p(layout.size());
  const double l0 = 0.7, l1 = 1.3, sf = 0.2, sn = 0.05;
  p[layout.log_length(0)] = std::log(l0);
  p[layout.log_length(1)] = std::log(l1);
  p[layout.log_sf()] = std::log(sf);
  p[layout.log_sn()] = std::log(sn);
  p[layout.c(0)] = 0.01;
  p[layout.c(1)] = 0.02;
  GpOptions options;  // linear mean, rbf
  Result<GaussianProcess> gp = GaussianProcess::Train(X, Y, noise, options, {p, p, p});
  ASSERT_TRUE(gp.ok()) << gp.status().message();
  Eigen::VectorXd x_star(2);
  x_star << 1.5, 1.4;
  const double d2 = std::pow((1.5 - 1.0) / l0, 2) + std::pow((1.4 - 2.0) / l1, 2);
  const double k_star = sf * sf * std::exp(-0.5 * d2);
  const Eigen::Vector3d mean = gp.value().PredictMean(x_star);
  const Eigen::Matrix3d cov = gp.value().PredictCovariance(x_star);
  for (int i = 0; i < 3; ++i) {
    const double mu_train = 0.01 * 1.0 + 0.02 * 2.0;
    const double mu_star = 0.01 * 1.5 + 0.02 * 1.4;
    EXPECT_NEAR(mean[i], mu_star + k_star / (sf * sf + sn * sn) * (Y(0, i) - mu_train), 1e-12);
    EXPECT_NEAR(cov(i, i), sf * sf - k_star * k_star / (sf * sf + sn * sn), 1e-12);
  }
}

// Optimization raises the likelihood above the initial guess, and the trained linear-mean model predicts held-out
// data of the smooth function better than its own linear mean alone.
TEST(GaussianProcessTest, TrainingImprovesLikelihoodAndHeldOutFit) {
  Eigen::MatrixXd X;
  Eigen::VectorXd y;
  MakeData(300, 11, &X, &y);
  Eigen::MatrixXd Y(300, 3);
  Y << y, 0.5 * y, -y;
  const Eigen::MatrixXd noise = Eigen::MatrixXd::Constant(300, 3, 1e-8);
  GpOptions options;
  options.hyperparameter_subset = 0;  // all 200: the likelihoods below are comparable
  Result<GaussianProcess> gp = GaussianProcess::Train(X.topRows(200), Y.topRows(200), noise.topRows(200), options);
  ASSERT_TRUE(gp.ok()) << gp.status().message();
  const GpLayout layout(2, options.mean, options.kernel);
  const double initial = GpLogMarginalLikelihood(layout, X.topRows(200), y.head(200), noise.col(0).head(200),
                                                 GpInitialParameters(layout, X.topRows(200), y.head(200)), nullptr);
  EXPECT_GT(gp.value().log_likelihoods()[0], initial);
  double gp_sq = 0.0, mean_sq = 0.0;
  const Eigen::VectorXd& p = gp.value().parameters()[0];
  for (int k = 200; k < 300; ++k) {
    const Eigen::VectorXd x = X.row(k).transpose();
    gp_sq += std::pow(gp.value().PredictMean(x)[0] - y[k], 2);
    mean_sq += std::pow(p.segment(layout.c(0), 2).dot(x) - y[k], 2);
  }
  EXPECT_LT(gp_sq, 0.5 * mean_sq);
}

}  // namespace
}  // namespace roamlab::estimator::odometry
