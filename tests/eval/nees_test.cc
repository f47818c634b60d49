#include "eval/nees.h"

#include <cmath>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/recording/temp_dir.h"

namespace roamlab::eval {
namespace {

using ::roamlab::testing::TempDir;
using ::roamlab::testing::WriteFile;
using ::testing::HasSubstr;

// A full (correlated) position covariance [m^2].
Eigen::Matrix3d KnownCovariance() {
  Eigen::Matrix3d c;
  c << 0.09, 0.03, -0.01,  //
      0.03, 0.04, 0.005,   //
      -0.01, 0.005, 0.0225;
  return c;
}

// Zero-mean Gaussian errors with covariance c, from one seeded stream.
class GaussianErrors {
 public:
  GaussianErrors(const Eigen::Matrix3d& c, unsigned seed) : l_(c.llt().matrixL()), random_(seed) {}
  Eigen::Vector3d Draw() {
    const Eigen::Vector3d z(normal_(random_), normal_(random_), normal_(random_));
    return l_ * z;
  }

 private:
  Eigen::Matrix3d l_;
  std::mt19937_64 random_;
  std::normal_distribution<double> normal_;
};

// Binomial(n, p) quantile: the smallest k with P(X <= k) >= q.
int BinomialQuantile(int n, double p, double q) {
  double cdf = 0.0;
  for (int k = 0; k <= n; ++k) {
    cdf += std::exp(std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) + k * std::log(p) +
                    (n - k) * std::log1p(-p));
    if (cdf >= q) return k;
  }
  return n;
}

std::vector<Time> Grid(int steps, double dt) {
  std::vector<Time> t;
  for (int k = 0; k < steps; ++k) t.push_back(Time::FromSeconds(k * dt));
  return t;
}

TEST(NeesTest, PositionNeesOfAHandComputedCase) {
  // Each axis one standard deviation off: 1 + 1 + 1.
  EXPECT_NEAR(PositionNees(Eigen::Vector3d(2.0, 1.0, 0.5), Eigen::Vector3d(4.0, 1.0, 0.25).asDiagonal()), 3.0, 1e-12);
  // The error along the first eigenvector of a correlated covariance.
  const Eigen::Matrix3d c = KnownCovariance();
  const Eigen::Vector3d e(0.1, -0.2, 0.05);
  EXPECT_NEAR(PositionNees(e, c), e.dot(c.inverse() * e), 1e-10);
  EXPECT_TRUE(std::isnan(PositionNees(e, Eigen::Vector3d(1.0, 0.0, 1.0).asDiagonal())));
  EXPECT_TRUE(std::isnan(PositionNees(e, Eigen::Vector3d(1.0, -1.0, 1.0).asDiagonal())));
}

TEST(NeesTest, GaussianErrorsAverageToTheDimension) {
  // M draws: the sum of their NEES is chi-square(3 M); the mean lies in its two-sided 99.9 % interval / M.
  const int draws = 20000;
  GaussianErrors errors(KnownCovariance(), 42);
  double sum = 0.0;
  for (int i = 0; i < draws; ++i) sum += PositionNees(errors.Draw(), KnownCovariance());
  const double mean = sum / draws;
  EXPECT_GT(mean, ChiSquareQuantile(0.0005, 3.0 * draws) / draws);
  EXPECT_LT(mean, ChiSquareQuantile(0.9995, 3.0 * draws) / draws);
}

TEST(NeesTest, MonteCarloBandAndFractionForFiftyConsistentRuns) {
  // 50 runs of 400 steps with consistent covariances: the band is the seed's, and each step's mean falls in it with
  // probability 0.95 independently, so the fraction lies in the binomial(400, 0.95) 99.9 % interval.
  const int runs = 50;
  const int steps = 400;
  GaussianErrors errors(KnownCovariance(), 7);
  std::vector<std::vector<double>> series(runs, std::vector<double>(steps));
  for (auto& run : series)
    for (double& v : run) v = PositionNees(errors.Draw(), KnownCovariance());
  const MonteCarloNees nees = AggregateNees(Grid(steps, 0.1), series, 3);
  EXPECT_EQ(nees.runs, 50);
  EXPECT_NEAR(nees.band.lo, 2.3597, 1e-3);
  EXPECT_NEAR(nees.band.hi, 3.7160, 1e-3);
  ASSERT_EQ(nees.mean_nees.size(), static_cast<std::size_t>(steps));
  double manual = 0.0;
  for (int j = 0; j < runs; ++j) manual += series[j][123];
  EXPECT_NEAR(nees.mean_nees[123], manual / runs, 1e-12);
  EXPECT_GE(nees.fraction_in_band, BinomialQuantile(steps, 0.95, 0.0005) / static_cast<double>(steps));
  EXPECT_LE(nees.fraction_in_band, BinomialQuantile(steps, 0.95, 0.9995) / static_cast<double>(steps));

  // An optimistic estimator (covariance half the true one) leaves the band.
  std::vector<std::vector<double>> optimistic = series;
  for (auto& run : optimistic)
    for (double& v : run) v *= 2.0;
  EXPECT_LT(AggregateNees(Grid(steps, 0.1), optimistic, 3).fraction_in_band, 0.05);
}

TEST(NeesTest, FractionInBandCountsStepsAfterT0) {
  const Interval band{2.3597, 3.7160};
  const std::vector<double> values = {0.0, 2.5, 3.0, 5.0, 3.7, 2.36, 3.72, 1.0, 3.0, 3.0};
  const std::vector<Time> t = Grid(10, 1.0);
  // From t = 2 s: 3.0 in, 5.0 out, 3.7 in, 2.36 in, 3.72 out, 1.0 out, 3.0 in, 3.0 in.
  EXPECT_DOUBLE_EQ(FractionInBand(t, values, band, 2.0), 5.0 / 8.0);
  EXPECT_DOUBLE_EQ(FractionInBand(t, values, band, 0.0), 6.0 / 10.0);
  EXPECT_TRUE(std::isnan(FractionInBand(t, values, band, 100.0)));
  // Band edges count as inside.
  EXPECT_DOUBLE_EQ(FractionInBand(Grid(2, 1.0), {band.lo, band.hi}, band, 0.0), 1.0);

  const MonteCarloNees nees = AggregateNees(t, {values}, 3, 2.0);
  EXPECT_EQ(nees.runs, 1);
  EXPECT_NEAR(nees.band.lo, ChiSquareQuantile(0.025, 3.0), 1e-12);
  EXPECT_NEAR(nees.band.hi, ChiSquareQuantile(0.975, 3.0), 1e-12);
}

TEST(NeesTest, JsonHasTheNeesFileKeys) {
  const MonteCarloNees nees = AggregateNees(Grid(3, 0.5), {{1.0, 2.0, 3.0}, {3.0, 4.0, 5.0}}, 3, 0.5);
  const nlohmann::json j = NeesJson(nees);
  EXPECT_EQ(j["runs"], 2);
  EXPECT_EQ(j["dof"], 3);
  ASSERT_EQ(j["band"].size(), 2u);
  EXPECT_DOUBLE_EQ(j["band"][0].get<double>(), nees.band.lo);
  EXPECT_EQ(j["t"], nlohmann::json({0.0, 0.5, 1.0}));
  EXPECT_EQ(j["mean_nees"], nlohmann::json({2.0, 3.0, 4.0}));
  // 2 runs, 3 dof: band [0.61, 7.22] holds 3.0 and 4.0 (from t0 = 0.5 s).
  EXPECT_DOUBLE_EQ(j["fraction_in_band"].get<double>(), 1.0);
}

TEST(NeesTest, ReadsCovarianceCsv) {
  TempDir dir;
  WriteFile(dir.File("covariance.csv"),
            "t,xx,xy,xz,yx,yy,yz,zx,zy,zz\n"
            "0.000000000,1,0.5,0,0.5,2,0,0,0,3\n"
            "0.010000000,4,0,0,0,4,0,0,0,4\n");
  const Result<std::vector<StampedCovariance>> rows = ReadPositionCovariances(dir.File("covariance.csv"));
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows.value().size(), 2u);
  EXPECT_EQ(rows.value()[1].t, Time::FromNanoseconds(10'000'000));
  EXPECT_EQ(rows.value()[0].covariance_world(0, 1), 0.5);
  EXPECT_EQ(rows.value()[0].covariance_world(2, 2), 3.0);
}

TEST(NeesTest, CovarianceCsvErrorsNameFileAndLine) {
  TempDir dir;
  const std::string path = dir.File("covariance.csv");
  const auto error = [&](const std::string& content) {
    WriteFile(path, content);
    const Result<std::vector<StampedCovariance>> rows = ReadPositionCovariances(path);
    EXPECT_FALSE(rows.ok());
    return rows.ok() ? std::string() : rows.status().message();
  };
  const std::string header = "t,xx,xy,xz,yx,yy,yz,zx,zy,zz\n";
  EXPECT_THAT(error("t,a,b\n"), HasSubstr(path + ":1: header"));
  EXPECT_THAT(error(header + "0,1,0,0,0,1,0,0,0,1\n0,1,0,0,0,1,0,0,0,1\n"), HasSubstr(path + ":3: timestamp"));
  EXPECT_THAT(error(header + "0,1,0.5,0,0,1,0,0,0,1\n"), HasSubstr(path + ":2: covariance is not symmetric"));
  EXPECT_THAT(error(header + "0,1,0,0,0,nan,0,0,0,1\n"), HasSubstr(path + ":2: field 'yy'"));
  EXPECT_THAT(error(header + "0,1,0,0,0,1\n"), HasSubstr(path + ":2: expected 10 fields"));
  EXPECT_FALSE(ReadPositionCovariances(dir.File("missing.csv")).ok());
}

}  // namespace
}  // namespace roamlab::eval
