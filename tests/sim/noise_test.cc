// The seeded noise streams (sim/noise.h): white and first-order Gauss-Markov.
#include "sim/noise.h"

#include <cmath>

#include <gtest/gtest.h>

namespace roamlab::sim {
namespace {

TEST(GaussMarkovNoiseTest, WithoutCorrelationItDrawsTheWhiteNumbers) {
  NoiseStream white(11, NoiseSource::kGyro);
  GaussMarkovNoise coloured(11, NoiseSource::kGyro);
  coloured.SetCorrelation(0.0, 0.01);
  for (int k = 0; k < 100; ++k) {
    const Eigen::Vector3d w = white.Draw3(0.3);
    EXPECT_EQ(coloured.Draw3(0.3), w);
  }
}

// Stationary std sigma and lag-one correlation a = exp(-period / tau), within about 4 standard errors of the sample
// moments of an AR(1) series of 2e5 samples (effective sample size n (1 - a) / (1 + a)).
TEST(GaussMarkovNoiseTest, KeepsTheStationarySigmaWithTheGivenCorrelation) {
  constexpr double kSigma = 0.5, kPeriod = 0.01, kTau = 0.2;
  const double a = std::exp(-kPeriod / kTau);
  GaussMarkovNoise noise(3, NoiseSource::kGps);
  noise.SetCorrelation(kTau, kPeriod);
  constexpr int kN = 200000;
  double sum2 = 0.0, lag1 = 0.0, previous = noise.Draw(kSigma);
  sum2 += previous * previous;
  for (int k = 1; k < kN; ++k) {
    const double e = noise.Draw(kSigma);
    sum2 += e * e;
    lag1 += e * previous;
    previous = e;
  }
  const double variance = sum2 / kN;
  const double effective = kN * (1.0 - a) / (1.0 + a);
  EXPECT_NEAR(std::sqrt(variance), kSigma, 4.0 * kSigma / std::sqrt(2.0 * effective));
  EXPECT_NEAR(lag1 / sum2, a, 4.0 / std::sqrt(effective));
}

}  // namespace
}  // namespace roamlab::sim
