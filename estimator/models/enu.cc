#include "estimator/models/enu.h"

#include <GeographicLib/LocalCartesian.hpp>

#include "common/check.h"

namespace roamlab::estimator {

struct EnuConverter::Impl {
  GeographicLib::LocalCartesian local;
};

EnuConverter::EnuConverter(const recording::GeodeticOrigin& origin)
    : origin_(origin),
      impl_(std::make_unique<Impl>(
          Impl{GeographicLib::LocalCartesian(origin.latitude_deg, origin.longitude_deg, origin.altitude_m)})) {
  ROAMLAB_CHECK(origin.latitude_deg >= -90.0 && origin.latitude_deg <= 90.0,
                "ENU origin latitude " << origin.latitude_deg << " deg is outside [-90, 90]");
}

EnuConverter::EnuConverter(const EnuConverter& other)
    : origin_(other.origin_), impl_(std::make_unique<Impl>(*other.impl_)) {}

EnuConverter& EnuConverter::operator=(const EnuConverter& other) {
  if (this != &other) {
    origin_ = other.origin_;
    impl_ = std::make_unique<Impl>(*other.impl_);
  }
  return *this;
}

EnuConverter::EnuConverter(EnuConverter&&) noexcept = default;
EnuConverter& EnuConverter::operator=(EnuConverter&&) noexcept = default;
EnuConverter::~EnuConverter() = default;

Eigen::Vector3d EnuConverter::ToEnu(double latitude_deg, double longitude_deg, double altitude_m) const {
  Eigen::Vector3d enu;
  impl_->local.Forward(latitude_deg, longitude_deg, altitude_m, enu.x(), enu.y(), enu.z());
  return enu;
}

void EnuConverter::ToGeodetic(const Eigen::Vector3d& enu, double* latitude_deg, double* longitude_deg,
                              double* altitude_m) const {
  ROAMLAB_CHECK(latitude_deg != nullptr && longitude_deg != nullptr && altitude_m != nullptr,
                "ToGeodetic: null output");
  impl_->local.Reverse(enu.x(), enu.y(), enu.z(), *latitude_deg, *longitude_deg, *altitude_m);
}

}  // namespace roamlab::estimator
