// The twin against the real recording on constructed tracks (gap/twin.h, CompareTwin): the whitened residuals and the
// drift over windows, which a rigid motion of the whole twin does not change and a velocity error grows linearly.
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "gap/internal/twin_fit.h"
#include "gap/twin.h"

namespace roamlab::gap {
namespace {

using recording::Stream;
using recording::StreamType;

constexpr double kRateHz = 10.0;
constexpr double kDurationS = 30.0;

// A pose (or position) stream along a circle of speed 1 m/s and yaw rate 0.2 rad/s, moved by `yaw` about the vertical
// and `offset`, with `velocity_error_mps` added along x over time.
Stream Track(StreamType type, double yaw, const Eigen::Vector3d& offset, double velocity_error_mps) {
  Stream s;
  s.info.name = "mocap";
  s.info.type = type;
  s.info.rate_hz = kRateHz;
  s.info.columns = type == StreamType::kPose ? std::vector<std::string>{"x", "y", "z", "qx", "qy", "qz", "qw"}
                                             : std::vector<std::string>{"x", "y", "z"};
  s.info.noise = {{"sigma_m", 0.01}};
  const int n = static_cast<int>(kDurationS * kRateHz) + 1;
  s.values.resize(n, static_cast<Eigen::Index>(s.info.columns.size()));
  const Eigen::AngleAxisd R(yaw, Eigen::Vector3d::UnitZ());
  for (int i = 0; i < n; ++i) {
    const double t = i / kRateHz;
    s.t.push_back(Time::FromSeconds(t));
    const double heading = 0.2 * t;
    const Eigen::Vector3d p(5.0 * std::sin(heading) + velocity_error_mps * t, 5.0 * (1.0 - std::cos(heading)), 0.0);
    s.values.row(i).head(3) = (R * p + offset).transpose();
    if (type != StreamType::kPose) continue;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw + heading, Eigen::Vector3d::UnitZ()));
    s.values.row(i).tail(4) << q.x(), q.y(), q.z(), q.w();
  }
  return s;
}

recording::Recording With(Stream s) {
  recording::Recording r;
  r.platform.kind = "differential_drive";
  r.streams.push_back(std::move(s));
  return r;
}

TEST(TwinCompareTest, ARigidlyMovedTwinHasNoDrift) {
  for (const StreamType type : {StreamType::kPose, StreamType::kPosition}) {
    const recording::Recording real = With(Track(type, 0.0, Eigen::Vector3d::Zero(), 0.0));
    const recording::Recording twin = With(Track(type, 0.7, Eigen::Vector3d(3.0, -2.0, 0.5), 0.0));
    const TwinComparison c = CompareTwin(real, twin, 0.0, kDurationS);
    ASSERT_TRUE(c.drift.count("mocap"));
    const TwinDrift& d = c.drift.at("mocap");
    EXPECT_EQ(d.windows, 21);  // starts every second from 0 to 20 s
    EXPECT_LT(d.max_position_m, 1e-9);
    EXPECT_EQ(d.heading_measured, type == StreamType::kPose);
    EXPECT_LT(d.max_heading_rad, 1e-9);
    // The residuals are not aligned: the offset shows in the whitened RMS.
    EXPECT_GT(c.streams.at("mocap").rms, 100.0);
  }
}

TEST(TwinCompareTest, AVelocityErrorDriftsByItsSizeTimesTheWindow) {
  // Headings stated exact: the alignment takes the yaw from them, and the translation matches the centroids of the
  // first 2 s, whose mean stamp is 1 s into the window.
  Stream moving = Track(StreamType::kPose, 0.0, Eigen::Vector3d::Zero(), 0.01);
  moving.info.noise["orientation_rad"] = 1e-9;
  Stream still = Track(StreamType::kPose, 0.0, Eigen::Vector3d::Zero(), 0.0);
  still.info.noise = moving.info.noise;
  const recording::Recording real = With(still), twin = With(moving);
  const TwinComparison c = CompareTwin(real, twin, 0.0, kDurationS);
  const TwinDrift& d = c.drift.at("mocap");
  EXPECT_NEAR(d.mean_position_m, 0.09, 1e-6);  // 0.01 m/s over the 9 s after that, whatever the heading
  EXPECT_NEAR(d.max_position_m, 0.09, 1e-6);
  EXPECT_LT(d.max_heading_rad, 1e-9);
  // The residual grows as 0.01 t m in units of 0.01 m: RMS of t over [0, 30] s is 30 / sqrt(3), on x alone.
  const SimulatedStreamFit& fit = c.streams.at("mocap");
  EXPECT_NEAR(fit.component_rms[0], 30.0 / std::sqrt(3.0), 0.2);
  EXPECT_LT(fit.component_rms[1], 1e-6);
  EXPECT_EQ(fit.samples, 301);
}

// The real track's headings carry the motion-capture's noise (5 mrad, stated): aligned on one sample, a window that
// travels 9.7 m (its chord) would end E|n| 9.7 m = 39 mm off on average; the fit over the first 2 s (21 samples,
// exact positions stated at 1 mm) takes the yaw mostly from the positions and keeps that noise out.
TEST(TwinCompareTest, TheAlignmentOverTheWindowsStartKeepsTheHeadingNoiseOut) {
  constexpr double kHeadingSigmaRad = 0.005;
  Stream real = Track(StreamType::kPose, 0.0, Eigen::Vector3d::Zero(), 0.0);
  real.info.noise = {{"position_m", 0.001}, {"orientation_rad", kHeadingSigmaRad}};
  const Stream twin = real;
  std::mt19937_64 draws(5);
  std::normal_distribution<double> normal(0.0, kHeadingSigmaRad);
  for (Eigen::Index i = 0; i < real.values.rows(); ++i) {
    const Eigen::Vector4d v = real.values.row(i).tail(4).transpose();
    const Eigen::Quaterniond q =
        Eigen::AngleAxisd(normal(draws), Eigen::Vector3d::UnitZ()) * Eigen::Quaterniond(v[3], v[0], v[1], v[2]);
    real.values.row(i).tail(4) << q.x(), q.y(), q.z(), q.w();
  }
  const TwinComparison c = CompareTwin(With(real), With(twin), 0.0, kDurationS);
  const double chord_m = 2.0 * 5.0 * std::sin(0.5 * 0.2 * 10.0);
  const double one_sample_m = kHeadingSigmaRad * std::sqrt(2.0 / M_PI) * chord_m;
  EXPECT_LT(c.drift.at("mocap").mean_position_m, 0.1 * one_sample_m);
  // The heading error at the window's end is that sample's own noise: E|n| = 4 mrad.
  EXPECT_NEAR(c.drift.at("mocap").mean_heading_rad, kHeadingSigmaRad * std::sqrt(2.0 / M_PI), 0.0015);
}

// Compared over 10 s windows: a pose track moved rigidly (yaw and translation) leaves no residual in the 21 windows of
// 30 s starting every second (the twin aligned over each window's first 2 s), where the absolute values are far apart;
// a position track (no heading) leaves none in its three consecutive increments when translated, and some when turned.
TEST(TwinCompareTest, ARigidlyMovedTwinHasNoWindowedIncrementResidual) {
  TwinResidualOptions increments;
  increments.increment_window_s = 10.0;
  for (const StreamType type : {StreamType::kPose, StreamType::kPosition}) {
    const recording::Recording real = With(Track(type, 0.0, Eigen::Vector3d::Zero(), 0.0));
    const Eigen::Vector3d offset(3.0, -2.0, 0.5);
    const recording::Recording moved = With(Track(type, type == StreamType::kPose ? 0.7 : 0.0, offset, 0.0));
    const TwinComparison c = CompareTwin(real, moved, 0.0, kDurationS, {}, increments);
    EXPECT_EQ(c.increment_window_s, 10.0);
    EXPECT_EQ(c.residuals, type == StreamType::kPose ? 21 * 2 : 3 * 3);
    EXPECT_LT(c.chi2, 1e-12);
    EXPECT_GT(CompareTwin(real, moved, 0.0, kDurationS).chi2, 1e4);
    if (type == StreamType::kPose) continue;
    const recording::Recording turned = With(Track(type, 0.7, offset, 0.0));
    EXPECT_GT(CompareTwin(real, turned, 0.0, kDurationS, {}, increments).chi2, 1e4);
  }
}

// A twin 0.01 m/s faster along x. A position stream's 10 s increments are 0.1 m off, whitened by two samples' noise
// (sqrt(2) sigma, sigma 1 cm): chi2 = 3 x 0.1^2 / (2 sigma^2) = 150 over the three windows. A pose stream with its
// headings stated exact is aligned by them (no yaw) and by the centroids of each window's first 2 s (21 samples, mean
// stamp 1 s in): its end is 0.09 m off (as its drift), whitened by sigma sqrt(1 + 1/21) each way, in 21 windows, each
// weighted sqrt(1 s / 10 s).
TEST(TwinCompareTest, TheWindowedResidualIsTheDriftWhitenedByTheRecordedNoise) {
  constexpr double kSigmaM = 0.01;
  TwinResidualOptions increments;
  increments.increment_window_s = 10.0;
  const recording::Recording real = With(Track(StreamType::kPosition, 0.0, Eigen::Vector3d::Zero(), 0.0));
  const recording::Recording faster = With(Track(StreamType::kPosition, 0.0, Eigen::Vector3d::Zero(), 0.01));
  EXPECT_NEAR(CompareTwin(real, faster, 0.0, kDurationS, {}, increments).chi2, 3.0 * 0.01 / (2.0 * kSigmaM * kSigmaM),
              1e-6);
  Stream still = Track(StreamType::kPose, 0.0, Eigen::Vector3d::Zero(), 0.0);
  Stream moving = Track(StreamType::kPose, 0.0, Eigen::Vector3d::Zero(), 0.01);
  still.info.noise["orientation_rad"] = moving.info.noise["orientation_rad"] = 1e-9;
  const TwinComparison c = CompareTwin(With(still), With(moving), 0.0, kDurationS, {}, increments);
  EXPECT_EQ(c.residuals, 21 * 2);
  EXPECT_NEAR(c.chi2, 21 * 0.1 * 0.09 * 0.09 / (kSigmaM * kSigmaM * (1.0 + 1.0 / 21.0)), 1e-6);
}

// The recorded poses carry their stated noise (1 mm, 5 mrad), the twin none: the pose windows' whitened residuals have
// unit variance (over 40 draws; without the alignment yaw's share, l^2 / I, the across component's would be about 7:
// a lever of 7-8 m turned by about 0.4 mrad against 1 mm).
TEST(TwinCompareTest, ThePoseWindowsResidualIsWhitenedByTheAlignmentsNoise) {
  constexpr double kSigmaM = 0.001, kHeadingSigmaRad = 0.005;
  TwinResidualOptions increments;
  increments.increment_window_s = 10.0;
  Stream twin = Track(StreamType::kPose, 0.0, Eigen::Vector3d::Zero(), 0.0);
  twin.info.noise = {{"position_m", kSigmaM}, {"orientation_rad", kHeadingSigmaRad}};
  std::mt19937_64 draws(11);
  std::normal_distribution<double> normal;
  Eigen::Vector2d sum_squares = Eigen::Vector2d::Zero();
  int windows = 0;
  for (int draw = 0; draw < 40; ++draw) {
    Stream real = twin;
    for (Eigen::Index i = 0; i < real.values.rows(); ++i) {
      real.values(i, 0) += kSigmaM * normal(draws);
      real.values(i, 1) += kSigmaM * normal(draws);
      const Eigen::Vector4d v = real.values.row(i).tail(4).transpose();
      const Eigen::Quaterniond q = Eigen::AngleAxisd(kHeadingSigmaRad * normal(draws), Eigen::Vector3d::UnitZ()) *
                                   Eigen::Quaterniond(v[3], v[0], v[1], v[2]);
      real.values.row(i).tail(4) << q.x(), q.y(), q.z(), q.w();
    }
    const SimulatedStreamFit fit =
        CompareTwin(With(real), With(twin), 0.0, kDurationS, {}, increments).streams.at("mocap");
    for (int k = 0; k < 2; ++k)
      sum_squares[k] += fit.samples * std::pow(fit.component_rms[static_cast<std::size_t>(k)], 2);
    windows += fit.samples;
  }
  const Eigen::Vector2d variance = sum_squares / (0.1 * windows);  // each entry weighted sqrt(0.1)
  std::printf("pose windows' whitened variance: along %.3f, across %.3f (%d windows)\n", variance[0], variance[1],
              windows);
  EXPECT_NEAR(variance[0], 1.0, 0.25);
  EXPECT_NEAR(variance[1], 1.0, 0.25);
}

TEST(TwinCompareTest, TheWhiteNoiseCovarianceIsTheInverseCurvature) {
  TwinFitRows rows;
  rows.jacobian = Eigen::MatrixXd::Zero(4, 2);
  rows.jacobian.col(0) << 1, 1, 1, 1;  // four residuals see the first parameter with unit weight
  rows.residuals = Eigen::VectorXd::Zero(4);
  for (int i = 0; i < 4; ++i) {
    rows.t.push_back(Time::FromSeconds(i));
    rows.series.push_back("s");
  }
  const Eigen::MatrixXd cov = ComputeTwinCovariance(rows).white;
  EXPECT_NEAR(cov(0, 0), 0.25, 1e-12);
  EXPECT_NEAR(cov(1, 1), 0.0, 1e-12);  // unseen: no information, and no variance claimed either
}

// Rows scaled by sqrt(w) (a run's residuals weighted in the fit, TwinDiagnoseOptions::train_weight): three unit rows
// and one scaled by 2 (w = 4) of the first parameter give the weighted fit's variance (J^T J)^-1 J^T W J (J^T J)^-1 =
// (3 + 4 * 4) / 7^2, not the 1/7 of unit-variance rows.
TEST(TwinCompareTest, TheWhiteCovarianceOfWeightedRowsIsTheWeightedFits) {
  TwinFitRows rows;
  rows.jacobian = Eigen::MatrixXd::Zero(4, 1);
  rows.jacobian.col(0) << 1, 1, 1, 2;
  rows.residuals = Eigen::VectorXd::Zero(4);
  for (int i = 0; i < 4; ++i) {
    rows.t.push_back(Time::FromSeconds(i));
    rows.series.push_back("s");
  }
  EXPECT_NEAR(ComputeTwinCovariance(rows).white(0, 0), 1.0 / 7.0, 1e-12);
  rows.weight = {1.0, 1.0, 1.0, 4.0};
  EXPECT_NEAR(ComputeTwinCovariance(rows).white(0, 0), 19.0 / 49.0, 1e-12);
}

// The mean of a first-order Gauss-Markov series e(k+1) = a e(k) + sqrt(1 - a^2) n fitted as one parameter (the
// residuals at the fit: the series less its mean; two components per stamp, one series): the HAC variance over the
// white one is the long-run factor (1 + a) / (1 - a) (the scores prewhitened by their AR(1) and recoloured, so without
// the Bartlett weights' bias), within 4 of the estimate's relative standard deviations: sqrt(4 L / (3 n)) of the
// Bartlett sum over the prewhitened scores and 2 sqrt((1 - a^2) / n) / (1 - a) of the recolouring (1 - rho)^-2;
// white residuals (a = 0) leave it at 1.
TEST(TwinCompareTest, TheHacCovarianceCountsTheResidualsAutocorrelation) {
  constexpr int kStamps = 20000;
  for (const double a : {0.0, 0.9}) {
    std::mt19937_64 draws(17);
    std::normal_distribution<double> normal;
    TwinFitRows rows;
    rows.jacobian = Eigen::MatrixXd::Ones(2 * kStamps, 1);
    rows.residuals.resize(2 * kStamps);
    Eigen::Vector2d e(normal(draws), normal(draws));
    for (int k = 0; k < kStamps; ++k) {
      rows.residuals.segment<2>(2 * k) = e;
      e = a * e + std::sqrt(1.0 - a * a) * Eigen::Vector2d(normal(draws), normal(draws));
      for (int c = 0; c < 2; ++c) {
        rows.t.push_back(Time::FromSeconds(0.01 * k));
        rows.series.push_back("gyroscope");
      }
    }
    rows.residuals.array() -= rows.residuals.mean();
    const TwinCovariance cov = ComputeTwinCovariance(rows);
    const int lag = cov.lags.at("gyroscope");
    const double expected = (1.0 + a) / (1.0 - a);
    const double ratio = cov.hac(0, 0) / cov.white(0, 0);
    const double recolouring = 2.0 * std::sqrt((1.0 - a * a) / kStamps) / (1.0 - a);
    const double spread = std::sqrt(4.0 * std::max(lag, 1) / (3.0 * kStamps) + recolouring * recolouring);
    std::printf("a %.1f: lag %d, HAC / white variance %.3f, expected (long-run) %.3f +- %.3f\n", a, lag, ratio,
                expected, spread * expected);
    EXPECT_NEAR(ratio / expected, 1.0, 4.0 * spread) << "a = " << a;
    if (a > 0.0) {
      EXPECT_GT(lag, 20);  // several correlation times (1 / -ln a = 9.5 stamps)
    }
  }
}

// The fixed-b widening: 1 at b = 0, Kiefer and Vogelsang's cv(1/4) / 1.96 at the lag's cap, growing in between.
TEST(TwinCompareTest, TheFixedBFactorIsTheBartlettKernelsCriticalValueOverTheNormals) {
  EXPECT_DOUBLE_EQ(FixedBFactor(0.0), 1.0);
  EXPECT_NEAR(FixedBFactor(0.25), (1.96 + 2.9694 / 4 + 0.4160 / 16 - 0.5324 / 64) / 1.96, 1e-12);
  for (double b = 0.0; b < 0.25; b += 0.01) EXPECT_LT(FixedBFactor(b), FixedBFactor(b + 0.01)) << b;
}

// Fits with the lag near its cap: the mean of 925 samples (a square run's training part) of a persistent AR(1) series
// (coefficient 0.98, correlated over the whole series as a twin's drift is), the lag a fifth of the series or more on
// average. The 2-std interval of the widened HAC std covers the true mean (0) in 95 % of 400 seeded replications,
// within four of the binomial std (1.1 %); the unwidened std (the HAC over the factor) covers less, by more than two.
TEST(TwinCompareTest, TheWidenedHacStdCoversNearTheLagsCap) {
  constexpr int kStamps = 925, kReplications = 400;
  constexpr double kPhi = 0.98;
  std::mt19937_64 draws(23);
  std::normal_distribution<double> normal;
  int covered = 0, covered_unwidened = 0;
  double share = 0.0;
  for (int r = 0; r < kReplications; ++r) {
    TwinFitRows rows;
    rows.jacobian = Eigen::MatrixXd::Ones(kStamps, 1);
    rows.residuals.resize(kStamps);
    double x = normal(draws) / std::sqrt(1.0 - kPhi * kPhi);
    for (int k = 0; k < kStamps; ++k) {
      rows.residuals[k] = x;
      x = kPhi * x + normal(draws);
      rows.t.push_back(Time::FromSeconds(0.05 * k));
      rows.series.push_back("mocap");
    }
    const double mean = rows.residuals.mean();
    rows.residuals.array() -= mean;
    const TwinCovariance cov = ComputeTwinCovariance(rows);
    const double b = static_cast<double>(cov.lags.at("mocap") + 1) / kStamps;
    share += b / kReplications;
    const double std = std::sqrt(cov.hac(0, 0));
    if (std::abs(mean) <= 2.0 * std) ++covered;
    if (std::abs(mean) <= 2.0 * std / FixedBFactor(b)) ++covered_unwidened;
  }
  const double coverage = static_cast<double>(covered) / kReplications;
  const double unwidened = static_cast<double>(covered_unwidened) / kReplications;
  const double binomial = std::sqrt(0.95 * 0.05 / kReplications);
  std::printf("mean lag share %.3f; 2-std coverage %.3f widened, %.3f unwidened (%d replications)\n", share, coverage,
              unwidened, kReplications);
  EXPECT_GT(share, 0.2);
  EXPECT_NEAR(coverage, 0.95, 4.0 * binomial);
  EXPECT_LT(unwidened, 0.95 - 2.0 * binomial);
}

// A time shift's batch-means std (internal/twin_fit.h BatchShiftStd) on a constructed fit: one series of 800 samples
// at 10 Hz, each entry's residual at shift s a (s - theta_k) + noise, theta_k the best shift of its 10 s span k, so
// that each span's chi-square is a parabola with its vertex at its own best shift (the noise's mean moves it).
struct ShiftFit {
  internal::Layout layout;
  std::map<long, Eigen::VectorXd> residuals_at_step;
  Eigen::VectorXd jacobian;
};
constexpr double kShiftStepS = 0.01;
constexpr int kShiftSamples = 800, kShiftSpans = 8;

ShiftFit Shifted(const std::vector<double>& span_shift_s, const std::vector<double>& span_slope,
                 const Eigen::VectorXd& noise) {
  ShiftFit fit;
  internal::Series series;
  series.name = series.stream = "gps";
  series.sigma = {1.0};
  for (int i = 0; i < kShiftSamples; ++i) {
    series.rows.push_back(static_cast<std::size_t>(i));
    series.t.push_back(Time::FromSeconds(0.1 * i));
  }
  fit.layout.series.push_back(series);
  fit.layout.size = kShiftSamples;
  fit.jacobian.resize(kShiftSamples);
  for (int i = 0; i < kShiftSamples; ++i) fit.jacobian[i] = span_slope[i * kShiftSpans / kShiftSamples];
  for (long s = -20; s <= 20; ++s) {
    Eigen::VectorXd r(kShiftSamples);
    for (int i = 0; i < kShiftSamples; ++i) {
      const int k = i * kShiftSpans / kShiftSamples;
      r[i] = span_slope[k] * (s * kShiftStepS - span_shift_s[k]) + noise[i];
    }
    fit.residuals_at_step[s] = r;
  }
  return fit;
}

// Equal spans: the spans' best shifts' standard error, sd / sqrt(8), times Student's t_0.975(7) / 1.96; a span without
// information (slope 0) is left out, and the rest count as 7 spans.
TEST(TwinCompareTest, TheBatchMeansStdIsTheSpansBestShiftsStandardErrorWidenedByStudentsT) {
  const std::vector<double> shift_s{0.02, -0.05, 0.11, 0.04, -0.01, 0.07, 0.15, -0.03};
  const auto standard_error = [](std::vector<double> x) {
    const double mean = std::accumulate(x.begin(), x.end(), 0.0) / x.size();
    double sum = 0.0;
    for (double v : x) sum += (v - mean) * (v - mean);
    return std::sqrt(sum / (x.size() - 1.0) / x.size());
  };
  const Eigen::VectorXd quiet = Eigen::VectorXd::Zero(kShiftSamples);
  ShiftFit fit = Shifted(shift_s, std::vector<double>(kShiftSpans, 3.0), quiet);
  EXPECT_NEAR(internal::BatchShiftStd(fit.layout, fit.residuals_at_step, kShiftStepS, fit.jacobian, kShiftSpans),
              standard_error(shift_s) * 2.364624 / 1.959964, 2e-3 * standard_error(shift_s));
  std::vector<double> slope(kShiftSpans, 3.0);
  slope[6] = 0.0;  // the span of the outlying 0.15 s says nothing
  fit = Shifted(shift_s, slope, quiet);
  std::vector<double> informed = shift_s;
  informed.erase(informed.begin() + 6);
  EXPECT_NEAR(internal::BatchShiftStd(fit.layout, fit.residuals_at_step, kShiftStepS, fit.jacobian, kShiftSpans),
              standard_error(informed) * 2.446912 / 1.959964, 5e-3 * standard_error(informed));
}

// One true shift, white noise of unit variance, spans of unequal information (slopes 10 to 45 per s: the spans' best
// shifts scatter by 10 to 2 ms, well within the evaluated +-0.2 s): the 2-std interval of
// the batch-means std about the fit's shift (the least-squares one over every entry) covers the truth in 95 % of 2000
// seeded replications, within four of the binomial std (0.5 %).
TEST(TwinCompareTest, TheBatchMeansStdCoversAWhiteNoiseShift) {
  constexpr int kReplications = 2000;
  constexpr double kTruthS = 0.03;
  std::vector<double> slope;
  for (int k = 0; k < kShiftSpans; ++k) slope.push_back(10.0 + 5.0 * k);
  std::mt19937_64 draws(29);
  std::normal_distribution<double> normal;
  int covered = 0;
  for (int r = 0; r < kReplications; ++r) {
    Eigen::VectorXd noise(kShiftSamples);
    for (int i = 0; i < kShiftSamples; ++i) noise[i] = normal(draws);
    const ShiftFit fit = Shifted(std::vector<double>(kShiftSpans, kTruthS), slope, noise);
    // The least-squares shift: residual a (s - truth) + n is zero in the mean at s = truth - sum(a n) / sum(a^2).
    const double estimate = kTruthS - fit.jacobian.dot(noise) / fit.jacobian.squaredNorm();
    const double std =
        internal::BatchShiftStd(fit.layout, fit.residuals_at_step, kShiftStepS, fit.jacobian, kShiftSpans);
    if (std::abs(estimate - kTruthS) <= 2.0 * std) ++covered;
  }
  const double coverage = static_cast<double>(covered) / kReplications;
  std::printf("batch-means 2-std coverage %.3f (%d replications)\n", coverage, kReplications);
  EXPECT_NEAR(coverage, 0.95, 4.0 * std::sqrt(0.95 * 0.05 / kReplications));
}

}  // namespace
}  // namespace roamlab::gap
