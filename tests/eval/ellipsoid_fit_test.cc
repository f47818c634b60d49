// The ellipsoid fit (eval/ellipsoid_fit.h) on synthetic magnetometer samples: a known soft-iron matrix and hard-iron
// offset, the field turned through random orientations.
#include "eval/ellipsoid_fit.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace roamlab::eval {
namespace {

struct Synthetic {
  Eigen::Matrix3d distortion;  // z = distortion h + centre, |h| = radius; symmetric, det 1
  Eigen::Vector3d centre{4.7, 0.1, -1.8};
  double radius = 45.0;
  std::vector<Eigen::Vector3d> samples;
};

Synthetic Make(int n, double sigma, std::uint32_t seed) {
  Synthetic s;
  Eigen::Matrix3d D;
  D << 1.08, 0.05, -0.03, 0.05, 0.95, 0.02, -0.03, 0.02, 1.0;
  s.distortion = D / std::cbrt(D.determinant());
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d direction, noise;
    for (int k = 0; k < 3; ++k) direction[k] = normal(rng);
    for (int k = 0; k < 3; ++k) noise[k] = sigma * normal(rng);
    const Eigen::Vector3d h = s.radius * direction.normalized();
    s.samples.push_back(s.distortion * h + s.centre + noise);
  }
  return s;
}

TEST(EllipsoidFitTest, ExactOnNoiseFreeSamples) {
  const Synthetic s = Make(200, 0.0, 1);
  const auto fit = FitEllipsoid(s.samples);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_LT((fit.value().centre - s.centre).norm(), 1e-8);
  EXPECT_NEAR(fit.value().radius, s.radius, 1e-8);
  EXPECT_LT((fit.value().correction - s.distortion.inverse()).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_NEAR(fit.value().correction.determinant(), 1.0, 1e-12);
  EXPECT_LT(fit.value().rms_residual, 1e-8);
}

// Linearized about a near-sphere (W = I + E, trace E = 0 as det W = 1), sample i with unit direction u_i has the radial
// error r u_i^T E u_i + u_i^T delta_centre + delta_r + n_i, n_i ~ N(0, sigma^2). Least squares over N samples spread
// uniformly over the sphere (E[u_x^2] = 1/3, E[u_x^4] = 1/5, E[u_x^2 u_y^2] = 1/15) gives: centre components std
// sqrt(3 / N) sigma; off-diagonal E std sqrt(15 / 4 / N) sigma / r (regressor 2 u_x u_y); diagonal E, on the
// trace-zero subspace where the regressors' covariance is (2/15) I, std sqrt(15/2 * 2/3 / N) = sqrt(5 / N) sigma / r;
// radius std sigma / sqrt(N). The distortion's largest gain scales the noise as seen on the sphere. The algebraic
// fit's bias is of order (sigma / r)^2 (1e-4 here), below these. Tolerances: 4 stds.
TEST(EllipsoidFitTest, RecoversCentreAndShapeWithinDerivedTolerance) {
  const int n = 2000;
  const double sigma = 0.5;
  const Synthetic s = Make(n, sigma, 7);
  const auto fit = FitEllipsoid(s.samples);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  const double gain = s.distortion.operatorNorm();
  const double centre_std = std::sqrt(3.0 / n) * sigma * gain;
  const double shape_std = std::sqrt(5.0 / n) * sigma * gain / s.radius;
  const Eigen::Vector3d centre_error = fit.value().centre - s.centre;
  const Eigen::Matrix3d shape_error = fit.value().correction - s.distortion.inverse();
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::abs(centre_error[i]), 4.0 * centre_std) << i;
  EXPECT_LT(shape_error.cwiseAbs().maxCoeff(), 4.0 * shape_std);
  EXPECT_NEAR(fit.value().radius, s.radius, 4.0 * sigma / std::sqrt(n));
  EXPECT_NEAR(fit.value().rms_residual, sigma, 0.1 * sigma);
  // The polar factor: a rotated distortion has the same symmetric factor.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_LT((SymmetricFactor(s.distortion * R) - s.distortion).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(EllipsoidFitTest, EllipsoidSpecificFitIsExactOnNoiseFreeSamples) {
  // A quarter of the sphere only (h_z < -0.3 r and h_x > 0), as a device kept roughly level covers.
  Synthetic s = Make(2000, 0.0, 3);
  std::vector<Eigen::Vector3d> cap;
  for (const Eigen::Vector3d& z : s.samples) {
    const Eigen::Vector3d h = s.distortion.inverse() * (z - s.centre);
    if (h.z() < -0.3 * s.radius && h.x() > 0.0) cap.push_back(z);
  }
  ASSERT_GT(cap.size(), 100u);
  const auto fit = FitEllipsoid(cap, EllipsoidFitMethod::kEllipsoidSpecific);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_TRUE(fit.value().constrained);
  EXPECT_LT((fit.value().centre - s.centre).norm(), 1e-6);
  EXPECT_LT((fit.value().correction - s.distortion.inverse()).cwiseAbs().maxCoeff(), 1e-8);
}

// The Cramer-Rao covariance of the centre against the spread of the fit's centre over K seeded sample sets: the
// sample std of K draws has a relative standard error of 1 / sqrt(2 (K - 1)), the tolerance 3 of them. On a cap of
// the same number of samples the bound is many times wider (the centre trades off against the shape).
TEST(EllipsoidFitTest, CentreCovarianceMatchesTheSpreadOfFitsAndGrowsOnACap) {
  const int n = 500, k = 40;
  const double sigma = 0.5;
  const Synthetic first = Make(n, sigma, 100);
  const auto reference = FitEllipsoid(first.samples);
  ASSERT_TRUE(reference.ok());
  const Eigen::Vector3d bound =
      EllipsoidCentreCovariance(reference.value(), first.samples, sigma).diagonal().cwiseSqrt();
  EXPECT_NEAR(bound.mean(), std::sqrt(3.0 / n) * sigma, 0.2 * std::sqrt(3.0 / n) * sigma);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum_squared = Eigen::Vector3d::Zero();
  for (int seed = 0; seed < k; ++seed) {
    const auto fit = FitEllipsoid(Make(n, sigma, 200 + static_cast<std::uint32_t>(seed)).samples);
    ASSERT_TRUE(fit.ok());
    sum += fit.value().centre;
    sum_squared += fit.value().centre.cwiseProduct(fit.value().centre);
  }
  const Eigen::Vector3d spread = ((sum_squared - sum.cwiseProduct(sum) / k) / (k - 1)).cwiseSqrt();
  const double tolerance = 3.0 / std::sqrt(2.0 * (k - 1));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(spread[i] / bound[i], 1.0, tolerance) << i;

  // A cap: the directions within 50 degrees of the distorted field's -z.
  const Synthetic dense = Make(20 * n, sigma, 300);
  std::vector<Eigen::Vector3d> cap;
  for (const Eigen::Vector3d& z : dense.samples)
    if ((dense.distortion.inverse() * (z - dense.centre)).normalized().z() < -std::cos(50.0 * M_PI / 180.0) &&
        static_cast<int>(cap.size()) < n)
      cap.push_back(z);
  ASSERT_EQ(static_cast<int>(cap.size()), n);
  EllipsoidFit truth;
  truth.centre = dense.centre;
  truth.radius = dense.radius;
  truth.correction = dense.distortion.inverse();
  const Eigen::Vector3d cap_bound = EllipsoidCentreCovariance(truth, cap, sigma).diagonal().cwiseSqrt();
  EXPECT_GT(cap_bound.maxCoeff(), 10.0 * bound.maxCoeff());
}

TEST(EllipsoidFitTest, RefusesTooFewOrFlatSamples) {
  EXPECT_FALSE(FitEllipsoid(std::vector<Eigen::Vector3d>(5, Eigen::Vector3d::Ones())).ok());
  EXPECT_FALSE(FitEllipsoid(std::vector<Eigen::Vector3d>(20, Eigen::Vector3d::Ones())).ok());
  // A ring in one plane: no ellipsoid.
  std::vector<Eigen::Vector3d> ring;
  for (int i = 0; i < 50; ++i) ring.emplace_back(std::cos(0.1 * i), std::sin(0.1 * i), 0.0);
  EXPECT_FALSE(FitEllipsoid(ring).ok());
  std::vector<Eigen::Vector3d> bad = Make(50, 0.1, 2).samples;
  bad[3].x() = std::nan("");
  EXPECT_FALSE(FitEllipsoid(bad).ok());
}

}  // namespace
}  // namespace roamlab::eval
