#include "eval/calibration_consistency.h"

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <gtest/gtest.h>

namespace roamlab::eval {
namespace {

// A 3x3 covariance with strong correlations and stds of different scales.
Eigen::MatrixXd CorrelatedCovariance() {
  Eigen::MatrixXd correlation(3, 3);
  correlation << 1.0, 0.6, -0.3,  //
      0.6, 1.0, 0.2,              //
      -0.3, 0.2, 1.0;
  const Eigen::Vector3d std(0.02, 0.5, 3.0);
  return std.asDiagonal() * correlation * std.asDiagonal();
}

// `runs` draws of errors ~ N(bias, true_covariance), each reporting `reported` as its covariance.
std::vector<ParameterDraw> Draws(int runs, const Eigen::MatrixXd& true_covariance, const Eigen::MatrixXd& reported,
                                 const Eigen::VectorXd& bias, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::MatrixXd l = true_covariance.llt().matrixL();
  std::vector<ParameterDraw> draws;
  for (int j = 0; j < runs; ++j) {
    Eigen::VectorXd z(bias.size());
    for (Eigen::Index i = 0; i < z.size(); ++i) z[i] = normal(rng);
    draws.push_back({bias + l * z, reported.diagonal().cwiseSqrt(), reported});
  }
  return draws;
}

// The binomial standard deviation of a share p over n trials.
double BinomialSd(double p, int n) { return std::sqrt(p * (1.0 - p) / n); }

// The Wilson interval's ends are the shares p0 whose normal test just accepts the observed share:
// (p - p0)^2 = z^2 p0 (1 - p0) / n with z the normal's 97.5 % quantile.
TEST(WilsonIntervalTest, EndsAreWhereTheScoreTestAccepts) {
  const double z = 1.959963984540054;
  const Interval i = WilsonInterval(95, 100);
  for (const double p0 : {i.lo, i.hi})
    EXPECT_NEAR((0.95 - p0) * (0.95 - p0), z * z * p0 * (1.0 - p0) / 100.0, 1e-12) << p0;
  EXPECT_NEAR(i.lo, 0.8882, 1e-4);
  EXPECT_NEAR(i.hi, 0.9785, 1e-4);
  // All successes: the upper end is 1, the lower one n / (n + z^2).
  const Interval all = WilsonInterval(20, 20);
  EXPECT_DOUBLE_EQ(all.hi, 1.0);
  EXPECT_NEAR(all.lo, 20.0 / (20.0 + z * z), 1e-12);
}

// Errors drawn from the reported covariance: coverage near 68.3 / 95.4 / 99.7 % within the binomial spread, spread /
// std near 1 within the sample std's own spread, no bias, the block NEES near its dimension (4 standard deviations of
// each statistic: a seed that fails them is a one in 10^4 event).
TEST(BlockStatisticsTest, ConsistentDrawsPassEveryTest) {
  const int runs = 2000;
  const Eigen::MatrixXd covariance = CorrelatedCovariance();
  const std::vector<ParameterDraw> draws = Draws(runs, covariance, covariance, Eigen::Vector3d::Zero(), 44);
  const Eigen::VectorXd crb = covariance.diagonal().cwiseSqrt();
  const BlockConsistency block = BlockStatistics("lever", draws, crb);
  EXPECT_EQ(block.runs, runs);
  EXPECT_EQ(block.dimension, 3);
  ASSERT_EQ(block.components.size(), 3u);
  const double nominal[3] = {0.6827, 0.9545, 0.9973};
  for (int i = 0; i < 3; ++i) {
    const ComponentConsistency& c = block.components[i];
    EXPECT_LT(std::abs(c.bias), 4.0 * c.bias_standard_error) << i;
    EXPECT_NEAR(c.bias_standard_error, c.spread / std::sqrt(runs), 1e-15);
    EXPECT_NEAR(c.spread_over_std, 1.0, 4.0 / std::sqrt(2.0 * (runs - 1))) << i;
    EXPECT_NEAR(c.mean_std, crb[i], 1e-12 * crb[i]);
    EXPECT_NEAR(c.efficiency, 1.0, 1e-12);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(c.coverage[k].sigmas, k + 1);
      EXPECT_NEAR(c.coverage[k].nominal, nominal[k], 5e-5);
      EXPECT_NEAR(c.coverage[k].fraction, nominal[k], 4.0 * BinomialSd(nominal[k], runs)) << i << " " << k;
      EXPECT_LE(c.coverage[k].confidence.lo, c.coverage[k].fraction);
      EXPECT_GE(c.coverage[k].confidence.hi, c.coverage[k].fraction);
    }
  }
  // N times the mean NEES is chi-square(3 N): mean 3, standard deviation sqrt(6 / N).
  EXPECT_EQ(block.nees_runs, runs);
  EXPECT_NEAR(block.mean_nees, 3.0, 4.0 * std::sqrt(6.0 / runs));
  const Interval band = AverageNeesBand(runs, 3, 0.05);
  EXPECT_DOUBLE_EQ(block.band.lo, band.lo);
  EXPECT_DOUBLE_EQ(block.band.hi, band.hi);
}

// The NEES uses the whole block covariance: errors with the right stds but the wrong correlations are not consistent
// although every component alone is.
TEST(BlockStatisticsTest, NeesSeesWrongCorrelations) {
  const int runs = 2000;
  const Eigen::MatrixXd covariance = CorrelatedCovariance();
  const Eigen::MatrixXd uncorrelated = Eigen::MatrixXd(covariance.diagonal().asDiagonal());
  const BlockConsistency block =
      BlockStatistics("lever", Draws(runs, uncorrelated, covariance, Eigen::Vector3d::Zero(), 45));
  for (const ComponentConsistency& c : block.components)
    EXPECT_NEAR(c.spread_over_std, 1.0, 4.0 / std::sqrt(2.0 * (runs - 1)));
  // E[e^T C^-1 e] = trace(C^-1 D) with D the true (diagonal) covariance.
  const double expected = (covariance.inverse() * uncorrelated).trace();
  ASSERT_GT(expected, 3.5);
  EXPECT_GT(block.mean_nees, block.band.hi);
}

// A bias of half a std on one component is found (7 standard errors of the mean over 200 runs); the others are not.
TEST(BlockStatisticsTest, BiasIsDetected) {
  const int runs = 200;
  const Eigen::MatrixXd covariance = CorrelatedCovariance();
  const Eigen::Vector3d bias(0.0, 0.25, 0.0);  // half of component 1's std
  const BlockConsistency block = BlockStatistics("lever", Draws(runs, covariance, covariance, bias, 46));
  EXPECT_TRUE(block.components[1].biased);
  EXPECT_NEAR(block.components[1].bias, 0.25, 4.0 * block.components[1].bias_standard_error);
  EXPECT_FALSE(block.components[0].biased);
  EXPECT_FALSE(block.components[2].biased);
  // The bias adds |bias|^2 / std^2 = 0.25 to the expected NEES (3 + 0.25 with the correlation; over 200 runs the
  // band's upper end is 3.6): the coverage and NEES barely see what the mean shows.
  EXPECT_GT(block.mean_nees, 3.0);
}

// An over-confident std (a third of the true one): coverage far too low, spread / std near 3, NEES near 9 d, above
// the band. An under-confident one (three times the true one): NEES below the band, every error within 2 sigma.
TEST(BlockStatisticsTest, OverAndUnderConfidentStdsAreCaught) {
  const int runs = 500;
  const Eigen::MatrixXd covariance = CorrelatedCovariance();
  const BlockConsistency over =
      BlockStatistics("lever", Draws(runs, covariance, covariance / 9.0, Eigen::Vector3d::Zero(), 47));
  const double within_two_thirds = std::erf(2.0 / 3.0 / std::sqrt(2.0));  // P(|x| <= 2/3): 0.495
  for (const ComponentConsistency& c : over.components) {
    EXPECT_NEAR(c.coverage[1].fraction, within_two_thirds, 4.0 * BinomialSd(within_two_thirds, runs));
    EXPECT_FALSE(c.coverage[1].consistent());
    EXPECT_NEAR(c.spread_over_std, 3.0, 3.0 * 4.0 / std::sqrt(2.0 * (runs - 1)));
  }
  EXPECT_NEAR(over.mean_nees, 27.0, 4.0 * 9.0 * std::sqrt(6.0 / runs));
  EXPECT_GT(over.mean_nees, over.band.hi);
  EXPECT_FALSE(over.nees_in_band());

  const BlockConsistency under =
      BlockStatistics("lever", Draws(runs, covariance, covariance * 9.0, Eigen::Vector3d::Zero(), 48));
  EXPECT_LT(under.mean_nees, under.band.lo);
  for (const ComponentConsistency& c : under.components) {
    EXPECT_GT(c.coverage[0].fraction, c.coverage[0].confidence.lo);
    EXPECT_FALSE(c.coverage[0].consistent());  // P(|x| <= 3) = 0.997 for the 1-sigma interval
  }
}

// A run whose std is unknown (an unobservable direction) leaves the coverage of that component and the block's NEES
// to the other runs.
TEST(BlockStatisticsTest, UnknownStdsAreLeftOut) {
  const Eigen::MatrixXd covariance = CorrelatedCovariance();
  std::vector<ParameterDraw> draws = Draws(10, covariance, covariance, Eigen::Vector3d::Zero(), 49);
  draws[3].std[2] = std::numeric_limits<double>::quiet_NaN();
  draws[3].covariance(2, 2) = std::numeric_limits<double>::quiet_NaN();
  const BlockConsistency block = BlockStatistics("lever", draws);
  EXPECT_TRUE(std::isnan(block.nees[3]));
  EXPECT_EQ(block.nees_runs, 9);
  EXPECT_TRUE(std::isfinite(block.mean_nees));
  const Interval band = AverageNeesBand(9, 3, 0.05);
  EXPECT_DOUBLE_EQ(block.band.hi, band.hi);
  EXPECT_TRUE(std::isnan(block.components[2].cramer_rao_std));
  EXPECT_TRUE(std::isnan(block.components[2].efficiency));
  // Component 2's 3-sigma coverage counts 9 trials: a share in ninths.
  const double ninths = block.components[2].coverage[2].fraction * 9.0;
  EXPECT_NEAR(ninths, std::round(ninths), 1e-12);
}

TEST(BlockStatisticsTest, OneRunHasNoSpread) {
  const Eigen::MatrixXd covariance = CorrelatedCovariance();
  const BlockConsistency block =
      BlockStatistics("lever", Draws(1, covariance, covariance, Eigen::Vector3d::Zero(), 50));
  EXPECT_TRUE(std::isnan(block.components[0].spread));
  EXPECT_FALSE(block.components[0].biased);
  EXPECT_TRUE(std::isfinite(block.mean_nees));
}

TEST(ConsistencyJsonTest, HoldsEveryStatistic) {
  const Eigen::MatrixXd covariance = CorrelatedCovariance();
  const BlockConsistency block = BlockStatistics(
      "gps.lever_arm", Draws(20, covariance, covariance, Eigen::Vector3d::Zero(), 51), covariance.diagonal().cwiseSqrt());
  const nlohmann::json j = ConsistencyJson({block});
  ASSERT_EQ(j.size(), 1u);
  EXPECT_EQ(j[0]["name"], "gps.lever_arm");
  EXPECT_EQ(j[0]["runs"], 20);
  EXPECT_EQ(j[0]["dimension"], 3);
  EXPECT_DOUBLE_EQ(j[0]["nees"]["mean"].get<double>(), block.mean_nees);
  EXPECT_EQ(j[0]["nees"]["per_run"].size(), 20u);
  EXPECT_EQ(j[0]["nees"]["in_band"], block.nees_in_band());
  ASSERT_EQ(j[0]["components"].size(), 3u);
  const nlohmann::json& c = j[0]["components"][2];
  EXPECT_EQ(c["index"], 2);
  EXPECT_DOUBLE_EQ(c["bias"].get<double>(), block.components[2].bias);
  EXPECT_DOUBLE_EQ(c["spread_over_std"].get<double>(), block.components[2].spread_over_std);
  EXPECT_NEAR(c["efficiency"].get<double>(), 1.0, 1e-12);
  ASSERT_EQ(c["coverage"].size(), 3u);
  EXPECT_EQ(c["coverage"][1]["sigmas"], 2);
  EXPECT_DOUBLE_EQ(c["coverage"][1]["fraction"].get<double>(), block.components[2].coverage[1].fraction);
  EXPECT_EQ(c["coverage"][1]["confidence"].size(), 2u);
  const std::string table = ConsistencyTable({block});
  EXPECT_NE(table.find("gps.lever_arm[2]"), std::string::npos) << table;
  EXPECT_NE(table.find("mean NEES"), std::string::npos) << table;
}

}  // namespace
}  // namespace roamlab::eval
