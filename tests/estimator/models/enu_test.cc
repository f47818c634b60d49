#include "estimator/models/enu.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace roamlab::estimator {
namespace {

// WGS84 ellipsoid.
constexpr double kSemiMajorAxis = 6378137.0;  // [m]
constexpr double kFlattening = 1.0 / 298.257223563;
constexpr double kEccentricitySq = kFlattening * (2.0 - kFlattening);
constexpr double kDegToRad = M_PI / 180.0;

// Radii of curvature at geodetic latitude phi [rad]: meridian M and prime vertical N.
double MeridianRadius(double phi) {
  const double s = std::sin(phi);
  return kSemiMajorAxis * (1.0 - kEccentricitySq) / std::pow(1.0 - kEccentricitySq * s * s, 1.5);
}
double PrimeVerticalRadius(double phi) {
  const double s = std::sin(phi);
  return kSemiMajorAxis / std::sqrt(1.0 - kEccentricitySq * s * s);
}

// Politecnico di Milano, 120 m above the ellipsoid.
recording::GeodeticOrigin Origin() {
  recording::GeodeticOrigin origin;
  origin.latitude_deg = 45.4781;
  origin.longitude_deg = 9.2274;
  origin.altitude_m = 120.0;
  return origin;
}

TEST(EnuConverterTest, OriginMapsToZero) {
  const recording::GeodeticOrigin o = Origin();
  const EnuConverter enu(o);
  EXPECT_LT(enu.ToEnu(o.latitude_deg, o.longitude_deg, o.altitude_m).norm(), 1e-9);
}

TEST(EnuConverterTest, NorthStepFollowsTheMeridianArc) {
  // 0.001 deg north at the same altitude: the arc (M + h) dphi along y, no east component, and the tangent plane
  // leaves the point below it by y^2 / (2 (M + h)) (about 1 mm).
  const recording::GeodeticOrigin o = Origin();
  const EnuConverter enu(o);
  const Eigen::Vector3d p = enu.ToEnu(o.latitude_deg + 0.001, o.longitude_deg, o.altitude_m);
  const double radius = MeridianRadius(o.latitude_deg * kDegToRad) + o.altitude_m;
  const double arc = radius * 0.001 * kDegToRad;
  EXPECT_NEAR(p.y(), 111.1, 0.5);
  EXPECT_NEAR(p.y(), arc, 1e-3);
  EXPECT_NEAR(p.x(), 0.0, 1e-6);
  EXPECT_NEAR(p.z(), -arc * arc / (2.0 * radius), 1e-5);
}

TEST(EnuConverterTest, EastStepFollowsTheParallel) {
  const recording::GeodeticOrigin o = Origin();
  const EnuConverter enu(o);
  const Eigen::Vector3d p = enu.ToEnu(o.latitude_deg, o.longitude_deg + 0.001, o.altitude_m);
  const double phi = o.latitude_deg * kDegToRad;
  const double arc = (PrimeVerticalRadius(phi) + o.altitude_m) * std::cos(phi) * 0.001 * kDegToRad;
  EXPECT_NEAR(p.x(), arc, 1e-3);
  EXPECT_LT(std::abs(p.y()), 1e-3);
  EXPECT_NEAR(EnuConverter(o).ToEnu(o.latitude_deg, o.longitude_deg, o.altitude_m + 5.0).z(), 5.0, 1e-9);
}

TEST(EnuConverterTest, ToGeodeticInvertsToEnu) {
  const recording::GeodeticOrigin o = Origin();
  const EnuConverter enu(o);
  std::mt19937 rng(51);
  std::uniform_real_distribution<double> horizontal(-5000.0, 5000.0), vertical(-200.0, 200.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d point(horizontal(rng), horizontal(rng), vertical(rng));
    double lat = 0.0, lon = 0.0, alt = 0.0;
    enu.ToGeodetic(point, &lat, &lon, &alt);
    EXPECT_LT((enu.ToEnu(lat, lon, alt) - point).norm(), 1e-6);

    const double lat_in = o.latitude_deg + 0.05 * horizontal(rng) / 5000.0;
    const double lon_in = o.longitude_deg + 0.05 * horizontal(rng) / 5000.0;
    const double alt_in = o.altitude_m + vertical(rng);
    enu.ToGeodetic(enu.ToEnu(lat_in, lon_in, alt_in), &lat, &lon, &alt);
    EXPECT_NEAR(lat, lat_in, 1e-9);
    EXPECT_NEAR(lon, lon_in, 1e-9);
    EXPECT_NEAR(alt, alt_in, 1e-6);
  }
}

TEST(EnuConverterTest, CopiesConvertTheSame) {
  const EnuConverter enu(Origin());
  EnuConverter other(recording::GeodeticOrigin{});
  other = enu;
  const EnuConverter copy(enu);
  const Eigen::Vector3d expected = enu.ToEnu(45.48, 9.23, 150.0);
  EXPECT_GT(expected.norm(), 100.0);
  EXPECT_EQ(copy.ToEnu(45.48, 9.23, 150.0), expected);
  EXPECT_EQ(other.ToEnu(45.48, 9.23, 150.0), expected);
  EXPECT_EQ(other.origin().latitude_deg, Origin().latitude_deg);
}

}  // namespace
}  // namespace roamlab::estimator
