#include "common/chi_square.h"

#include <gtest/gtest.h>

namespace roamlab {
namespace {

TEST(ChiSquareTest, KnownQuantiles) {
  // Tabulated values of the chi-square distribution.
  EXPECT_NEAR(ChiSquareQuantile(0.95, 1), 3.841459, 1e-5);
  EXPECT_NEAR(ChiSquareQuantile(0.95, 3), 7.814728, 1e-5);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 2), 9.210340, 1e-5);
  EXPECT_NEAR(ChiSquareQuantile(0.05, 10), 3.940299, 1e-5);
}

TEST(ChiSquareTest, CdfInvertsQuantile) {
  for (double dof : {1.0, 2.5, 6.0, 150.0}) {
    for (double p : {0.001, 0.3, 0.5, 0.975}) {
      EXPECT_NEAR(ChiSquareCdf(ChiSquareQuantile(p, dof), dof), p, 1e-9);
    }
  }
}

TEST(ChiSquareTest, SeedNeesBandForFiftyRunsOfThreeDimensions) {
  // Seed 000, Section V: 95% region of the average NEES over 50 runs is [2.359, 3.716] (the seed truncates;
  // chi2inv(0.025, 150) / 50 = 2.35969, chi2inv(0.975, 150) / 50 = 3.71598).
  const Interval band = AverageNeesBand(50, 3);
  EXPECT_NEAR(band.lo, 2.35969, 1e-4);
  EXPECT_NEAR(band.hi, 3.71598, 1e-4);
}

}  // namespace
}  // namespace roamlab
