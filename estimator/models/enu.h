// Geodetic <-> local East-North-Up coordinates: the world frame W of the estimator (geometry.h) is the ENU frame
// tangent to the WGS84 ellipsoid at the recording's origin (seed 000, Section III-A: x east, y north, z up). GPS
// readings are converted with ToEnu before they enter the GPS error model (gps.h); the simulator goes the other way
// with ToGeodetic.
//
// Latitude and longitude are in degrees, altitude is the height above the WGS84 ellipsoid [m], ENU coordinates are in
// meters. The conversion is exact (through Earth-centered coordinates, GeographicLib::LocalCartesian), not a flat-earth
// approximation. GeographicLib stays an implementation detail: this header does not include it.
#pragma once

#include <memory>

#include <Eigen/Core>

#include "recording/recording.h"

namespace roamlab::estimator {

class EnuConverter {
 public:
  explicit EnuConverter(const recording::GeodeticOrigin& origin);
  EnuConverter(const EnuConverter& other);
  EnuConverter& operator=(const EnuConverter& other);
  // A moved-from converter may only be assigned to or destroyed.
  EnuConverter(EnuConverter&&) noexcept;
  EnuConverter& operator=(EnuConverter&&) noexcept;
  ~EnuConverter();

  const recording::GeodeticOrigin& origin() const { return origin_; }

  // ENU coordinates [m] of a geodetic point (latitude in [-90, 90] deg).
  Eigen::Vector3d ToEnu(double latitude_deg, double longitude_deg, double altitude_m) const;
  // Inverse of ToEnu: latitude, longitude [deg] and altitude [m] of an ENU point. Outputs must not be null.
  void ToGeodetic(const Eigen::Vector3d& enu, double* latitude_deg, double* longitude_deg, double* altitude_m) const;

 private:
  struct Impl;
  recording::GeodeticOrigin origin_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace roamlab::estimator
