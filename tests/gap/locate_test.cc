// Locating (gap/locate.h) on constructed residuals with a known structure: white noise stays consistent, a burst is
// found in its interval, a residual that follows a lagged copy of the motion is traced to that condition and lag.
#include "gap/locate.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace roamlab::gap {
namespace {

// A 20 s circle-and-speed-change drive at 100 Hz: speed 4 + sin(2 pi t / 7), yaw rate 0.3 sin(2 pi t / 5).
Trajectory Drive() {
  Trajectory out;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  for (int k = 0; k <= 2000; ++k) {
    const double t = 0.01 * k;
    out.push_back({Time::FromSeconds(t), p, Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))});
    const double v = 4.0 + std::sin(2.0 * M_PI * t / 7.0);
    p += 0.01 * v * Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
    yaw += 0.01 * 0.3 * std::sin(2.0 * M_PI * t / 5.0);
  }
  return out;
}

TEST(LocateTest, ConditionsFollowTheMotion) {
  const Conditions c = ComputeConditions(Drive(), recording::Recording{});
  ASSERT_EQ(c.names.size(), 8u);  // no steering stream
  EXPECT_EQ(c.names[0], "speed_mps");
  for (double t : {3.0, 9.5, 16.0}) {
    EXPECT_NEAR(c.At(0, Time::FromSeconds(t)), 4.0 + std::sin(2.0 * M_PI * t / 7.0), 0.01) << t;
    EXPECT_NEAR(c.At(3, Time::FromSeconds(t)), 0.3 * std::sin(2.0 * M_PI * t / 5.0), 0.01) << t;
  }
}

TEST(LocateTest, WhiteNoiseIsConsistentABurstIsLocatedALagIsFound) {
  const Trajectory drive = Drive();
  const Conditions conditions = ComputeConditions(drive, recording::Recording{});
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01;
  std::vector<estimator::MeasurementResidual> residuals;
  for (int k = 10; k < 1990; ++k) {
    const Time t = Time::FromSeconds(0.01 * k);
    // "white": N(0, 1). "burst": N(0, 1), times 3 in [8, 11] s. "lagged": yaw rate 0.1 s later, plus N(0, 0.5).
    const double burst = (0.01 * k >= 8.0 && 0.01 * k <= 11.0) ? 3.0 : 1.0;
    const double yaw_rate_later = conditions.At(3, Time::FromSeconds(0.01 * k + 0.1));
    residuals.push_back({"white", t, Eigen::VectorXd::Constant(1, n01(rng)), true});
    residuals.push_back({"burst", t, Eigen::VectorXd::Constant(1, burst * n01(rng)), true});
    residuals.push_back({"lagged", t, Eigen::VectorXd::Constant(1, 10.0 * yaw_rate_later + 0.5 * n01(rng)), true});
  }
  const std::vector<LocatedComponent> located = Locate(residuals, conditions, {});
  ASSERT_EQ(located.size(), 3u);
  std::map<std::string, LocatedComponent> by_stream;
  for (const LocatedComponent& lc : located) by_stream[lc.stream] = lc;

  EXPECT_FALSE(by_stream["white"].inconsistent) << by_stream["white"].chi2_per_dof;
  EXPECT_TRUE(by_stream["white"].intervals.empty());

  const LocatedComponent& burst = by_stream["burst"];
  EXPECT_TRUE(burst.inconsistent) << burst.chi2_per_dof;  // (1 * 16.8 + 9 * 3) / 19.8 = 2.2
  ASSERT_EQ(burst.intervals.size(), 1u) << burst.intervals[0].first << " " << burst.intervals[0].second;
  EXPECT_LE(burst.intervals[0].first, 8.5);
  EXPECT_GE(burst.intervals[0].first, 6.0);
  EXPECT_GE(burst.intervals[0].second, 10.5);
  EXPECT_LE(burst.intervals[0].second, 13.0);

  const LocatedComponent& lagged = by_stream["lagged"];
  ASSERT_FALSE(lagged.correlates.empty());
  EXPECT_EQ(lagged.correlates[0].condition, "yaw_rate_radps");
  EXPECT_NEAR(lagged.correlates[0].lag_s, 0.1, 0.021);
  EXPECT_GT(lagged.correlates[0].rho, 0.9);

  // Against a higher expected level (as a nominal simulation would give), the burst is no longer inconsistent.
  const auto relaxed = Locate(residuals, conditions, {{ComponentKey("burst", 0), 2.5}});
  for (const LocatedComponent& lc : relaxed)
    if (lc.stream == "burst") {
      EXPECT_FALSE(lc.inconsistent);
    }
}

TEST(LocateTest, StreamFitsCountActiveMeasurementsOnly) {
  std::vector<estimator::MeasurementResidual> r = {{"a", Time::FromSeconds(0.0), Eigen::Vector2d(1.0, 2.0), true},
                                                   {"a", Time::FromSeconds(0.1), Eigen::Vector2d(3.0, 0.0), true},
                                                   {"a", Time::FromSeconds(0.2), Eigen::Vector2d(100.0, 0.0), false}};
  const auto fits = StreamFits(r);
  EXPECT_EQ(fits.at("a").measurements, 2);
  EXPECT_EQ(fits.at("a").dof, 4);
  EXPECT_DOUBLE_EQ(fits.at("a").chi2_per_dof, 14.0 / 4.0);
  EXPECT_DOUBLE_EQ(fits.at("a").rms, std::sqrt(3.5));
  EXPECT_DOUBLE_EQ(ComponentLevels(r).at("a/0"), 5.0);
}

// The 1 s RMS keeps a bias and averages white noise out: unit noise at 100 Hz plus a 0.3 bias on one of two
// components gives a per-sample RMS near sqrt((1 + 0.09 + 1) / 2) = 1.02 but a 1 s RMS near
// sqrt((0.09 + 2 / 100) / 2) = 0.235 (the noise's window means have variance 1 / 100).
TEST(LocateTest, SystematicRmsAveragesWhiteNoiseOutAndKeepsABias) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<estimator::MeasurementResidual> biased, white;
  for (int k = 0; k < 20000; ++k) {
    const Time t = Time::FromSeconds(5.0 + 0.01 * k);
    const Eigen::Vector2d noise(n(rng), n(rng));
    white.push_back({"s", t, noise, true});
    biased.push_back({"s", t, noise + Eigen::Vector2d(0.3, 0.0), true});
  }
  const StreamFit w = StreamFits(white).at("s"), b = StreamFits(biased).at("s");
  EXPECT_NEAR(w.rms, 1.0, 0.02);
  EXPECT_NEAR(b.rms, std::sqrt(2.09 / 2.0), 0.02);
  // 200 windows x 2 components: the noise's squared window mean has relative std sqrt(2 / 400) = 7 %.
  EXPECT_NEAR(w.rms_1s, 0.1, 0.1 * 0.15);
  EXPECT_NEAR(b.rms_1s, std::sqrt(0.11 / 2.0), 0.235 * 0.1);
}

// A component whose level is far below 1 (the fit absorbs most of the noise, as the poses absorb the IMU's) spreads
// as the few dimensions of noise the fit leaves: at level 0.03 over 2900 residuals, with the projection's eigenvalues 0
// or 1, its chi-square is chi2(87), whose 99.9 % quantile is 1.54 times its mean (chi2(2900) scaled: 1.08).
TEST(LocateTest, ALevelBelowOneSpreadsAsTheNoiseTheFitLeaves) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  int flagged = 0;
  for (int r = 0; r < 400; ++r) {
    double chi2 = 0.0;
    for (int i = 0; i < 87; ++i) chi2 += std::pow(n(rng), 2);
    flagged += Inconsistent({chi2 / 2900.0, 2900}, 0.03, 1.3) ? 1 : 0;
  }
  EXPECT_LE(flagged, 3);  // 0.4 expected of 400
  EXPECT_FALSE(Inconsistent({0.0435, 2900}, 0.03, 1.3));
  EXPECT_TRUE(Inconsistent({0.06, 2900}, 0.03, 1.3));
  // At level 1 and above: the level times chi2(count), as before.
  EXPECT_TRUE(Inconsistent({1.2, 2900}, 1.0, 1.1));
  EXPECT_FALSE(Inconsistent({1.07, 2900}, 1.0, 1.0));
  EXPECT_TRUE(Inconsistent({2.2, 2900}, 2.0, 1.0));
}

}  // namespace
}  // namespace roamlab::gap
