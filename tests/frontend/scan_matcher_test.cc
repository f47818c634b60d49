#include "frontend/scan_matcher.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace roamlab::frontend {
namespace {

// A synthetic room: the walls of a 7 m x 5 m rectangle and two boxes, as segments in the world frame.
struct Segment {
  Eigen::Vector2d a, b;
};

std::vector<Segment> Room() {
  std::vector<Segment> s;
  const auto box = [&s](double x0, double y0, double x1, double y1) {
    s.push_back({{x0, y0}, {x1, y0}});
    s.push_back({{x1, y0}, {x1, y1}});
    s.push_back({{x1, y1}, {x0, y1}});
    s.push_back({{x0, y1}, {x0, y0}});
  };
  box(-3.5, -2.5, 3.5, 2.5);
  box(1.0, 0.8, 1.6, 1.3);
  box(-2.0, -1.9, -1.5, -1.2);
  return s;
}

// Ranges seen from the laser pose (x, y, theta) in the world, with Gaussian noise.
std::vector<double> Scan(const ScanGeometry& g, const Eigen::Vector3d& pose, double sigma_m, std::mt19937* rng) {
  std::normal_distribution<double> noise(0.0, sigma_m);
  std::vector<double> ranges(static_cast<std::size_t>(g.beams), std::numeric_limits<double>::quiet_NaN());
  for (int k = 0; k < g.beams; ++k) {
    const double a = pose[2] + g.Angle(k);
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    double best = std::numeric_limits<double>::infinity();
    for (const Segment& s : Room()) {
      // Solve origin + r d = a + u (b - a).
      const Eigen::Vector2d e = s.b - s.a;
      const double det = d.x() * (-e.y()) - d.y() * (-e.x());
      if (std::abs(det) < 1e-12) continue;
      const Eigen::Vector2d rhs = s.a - pose.head<2>();
      const double r = (rhs.x() * (-e.y()) - rhs.y() * (-e.x())) / det;
      const double u = (d.x() * rhs.y() - d.y() * rhs.x()) / det;
      if (r > 0.0 && u >= 0.0 && u <= 1.0) best = std::min(best, r);
    }
    const double measured = best + noise(*rng);
    if (best <= g.max_range_m) ranges[static_cast<std::size_t>(k)] = measured;
  }
  return ranges;
}

// The pose of b in a's frame.
Eigen::Vector3d Relative(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector2d d = Eigen::Rotation2Dd(-a[2]) * (b.head<2>() - a.head<2>());
  return Eigen::Vector3d(d.x(), d.y(), std::remainder(b[2] - a[2], 2.0 * M_PI));
}

TEST(ScanMatcherTest, RecoversTrueDisplacementsWithinReportedCovariance) {
  const ScanGeometry g;
  std::mt19937 rng(3);
  const Eigen::Vector3d start(-0.4, 0.2, 0.3);
  // Displacements of a robot between two 10 Hz scans: forward, sideways, turning, backwards while turning.
  const std::vector<Eigen::Vector3d> steps = {
      {0.08, 0.0, 0.0}, {0.0, 0.03, 0.05}, {0.05, 0.01, 0.15}, {-0.07, 0.0, -0.12}, {0.1, -0.02, 0.2}};
  for (const Eigen::Vector3d& step : steps) {
    const Eigen::Vector2d p = start.head<2>() + Eigen::Rotation2Dd(start[2]) * step.head<2>();
    const Eigen::Vector3d end(p.x(), p.y(), start[2] + step[2]);
    const Eigen::Vector3d truth = Relative(start, end);
    const ScanMatch m = MatchScans(g, Scan(g, start, 0.01, &rng), Scan(g, end, 0.01, &rng), Eigen::Vector3d::Zero());
    ASSERT_TRUE(m.ok) << step.transpose();
    const Eigen::Vector3d error = m.pose - truth;
    // Accurate in absolute terms (a few mm, a tenth of a degree) ...
    EXPECT_LT(error.head<2>().norm(), 0.01) << "step " << step.transpose() << " error " << error.transpose();
    EXPECT_LT(std::abs(error[2]), 0.002) << "step " << step.transpose() << " error " << error.transpose();
    // ... and the covariance is of the right order: the error within 6 reported standard deviations per axis (the
    // covariance ignores correlated residuals, see scan_matcher.h), and not hugely pessimistic.
    for (int i = 0; i < 3; ++i) {
      const double sigma = std::sqrt(m.covariance(i, i));
      EXPECT_LT(std::abs(error[i]), 6.0 * sigma) << "axis " << i << " step " << step.transpose();
      EXPECT_LT(sigma, 0.005) << "axis " << i;
    }
    EXPECT_NEAR(m.rms_m, 0.01, 0.004);
  }
}

// The displacement scale: over many independent scan pairs with 1 cm range noise, the least-squares slope of the
// matched displacement on the true one is 1 within 4 of its standard errors per axis (the standard error from the
// scatter of the errors: se = rms(error) / sqrt(sum d^2)). A two-point reference line would under-read these steps by
// a few percent (scan_matcher.h says why).
TEST(ScanMatcherTest, DisplacementScaleIsUnbiasedUnderRangeNoise) {
  const ScanGeometry g;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  constexpr int kPairs = 200;
  // Per axis: sum of matched x true, sum of true^2, sum of squared errors.
  Eigen::Vector3d cross = Eigen::Vector3d::Zero(), truth2 = Eigen::Vector3d::Zero(), error2 = Eigen::Vector3d::Zero();
  for (int pair = 0; pair < kPairs; ++pair) {
    const Eigen::Vector3d start(0.8 * uniform(rng), 0.6 * uniform(rng), M_PI * uniform(rng));
    // A 10 Hz step of the mecanum robot at full speed on every axis (0.2 m/s, 0.25 rad/s), random signs.
    const auto sign = [&]() { return uniform(rng) < 0.0 ? -1.0 : 1.0; };
    const Eigen::Vector3d step(0.02 * sign(), 0.02 * sign(), 0.025 * sign());
    const Eigen::Vector2d p = start.head<2>() + Eigen::Rotation2Dd(start[2]) * step.head<2>();
    const Eigen::Vector3d end(p.x(), p.y(), start[2] + step[2]);
    const Eigen::Vector3d truth = Relative(start, end);
    const ScanMatch m = MatchScans(g, Scan(g, start, 0.01, &rng), Scan(g, end, 0.01, &rng), Eigen::Vector3d::Zero());
    ASSERT_TRUE(m.ok) << "pair " << pair;
    cross += m.pose.cwiseProduct(truth);
    truth2 += truth.cwiseAbs2();
    error2 += (m.pose - truth).cwiseAbs2();
  }
  for (int i = 0; i < 3; ++i) {
    const double slope = cross[i] / truth2[i];
    const double se = std::sqrt(error2[i] / kPairs) / std::sqrt(truth2[i]);
    EXPECT_NEAR(slope, 1.0, 4.0 * se) << "axis " << i << " slope " << slope << " se " << se;
    EXPECT_LT(se, 0.01) << "axis " << i;  // the test can tell a 1-3 % bias
  }
}

TEST(ScanMatcherTest, FailsWithoutStructure) {
  ScanGeometry g;
  std::vector<double> empty(static_cast<std::size_t>(g.beams), std::numeric_limits<double>::quiet_NaN());
  EXPECT_FALSE(MatchScans(g, empty, empty, Eigen::Vector3d::Zero()).ok);
}

TEST(ScanMatcherTest, BestOfSeveralGuessesHandlesLargeRotation) {
  const ScanGeometry g;
  std::mt19937 rng(4);
  const Eigen::Vector3d a(0.3, -0.1, 1.0), b(0.33, -0.08, 1.45);  // 0.45 rad: beyond the search window from zero
  const ScanMatch m = MatchScansFrom(g, Scan(g, a, 0.01, &rng), Scan(g, b, 0.01, &rng),
                                     {Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, 0.4)});
  ASSERT_TRUE(m.ok);
  EXPECT_LT((m.pose - Relative(a, b)).norm(), 0.01);
}

}  // namespace
}  // namespace roamlab::frontend
