#include "recording/internal/stream_types.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <Eigen/Eigenvalues>

#include "recording/internal/laser_scan.h"
#include "recording/internal/text_io.h"

namespace roamlab::recording::internal {

const std::vector<TypeRow>& TypeTable() {
  static const std::vector<TypeRow> table = {
      {StreamType::kImu, "imu", {"wx", "wy", "wz", "ax", "ay", "az"}},
      {StreamType::kGyroscope, "gyroscope", {"wx", "wy", "wz"}},
      {StreamType::kAccelerometer, "accelerometer", {"ax", "ay", "az"}},
      {StreamType::kMagnetometer, "magnetometer", {"mx", "my", "mz"}},
      {StreamType::kGps, "gps", {"latitude", "longitude", "altitude"}},
      {StreamType::kPosition, "position", {"x", "y", "z"}},
      {StreamType::kPose, "pose", {"x", "y", "z", "qx", "qy", "qz", "qw"}},
      {StreamType::kWheelEncoders, "wheel_encoders", {}},
      {StreamType::kSteering, "steering", {"angle"}},
      {StreamType::kOdometry, "odometry", {"vx", "vy", "vz", "wx", "wy", "wz"}},
      {StreamType::kVisualOdometry, "visual_odometry", {"vx", "vy", "vz", "wx", "wy", "wz"}},
      {StreamType::kScanMatching, "scan_matching", {"vx", "vy", "vz", "wx", "wy", "wz"}},
      {StreamType::kCamera, "camera", {"frame"}},
      {StreamType::kInputs, "inputs", {}},
      {StreamType::kLaserScan, "laser_scan", {}},
  };
  return table;
}

const TypeRow& RowOf(StreamType type) {
  for (const TypeRow& row : TypeTable()) {
    if (row.type == type) return row;
  }
  ROAMLAB_CHECK(false, "stream type " << static_cast<int>(type) << " missing from the type table");
}

// The types whose fixed columns may be followed by the covariance columns: the velocity types (6x6) and gps (3x3).
bool HasCovarianceColumns(StreamType type) {
  return type == StreamType::kOdometry || type == StreamType::kVisualOdometry || type == StreamType::kScanMatching ||
         type == StreamType::kGps;
}

// Fixed columns followed by the covariance columns (HasCovarianceColumns types only).
std::vector<std::string> ColumnsWithCovariance(StreamType type) {
  std::vector<std::string> columns = FixedColumns(type);
  const std::vector<std::string>& covariance = CovarianceColumns(type);
  columns.insert(columns.end(), covariance.begin(), covariance.end());
  return columns;
}

// " (optionally followed by the N covariance columns)" for the types that may carry them, else "".
std::string CovarianceNote(StreamType type) {
  if (!HasCovarianceColumns(type)) return "";
  return " (optionally followed by the " + std::to_string(CovarianceColumns(type).size()) + " covariance columns)";
}

bool CarriesCovariance(const StreamInfo& info) {
  return HasCovarianceColumns(info.type) && info.columns == ColumnsWithCovariance(info.type);
}

// Camera intrinsics in the attributes of camera and visual_odometry streams: all six or none; "" when fine.
std::string IntrinsicsProblem(const StreamInfo& info) {
  if (info.type != StreamType::kCamera && info.type != StreamType::kVisualOdometry) return "";
  static const char* const kKeys[] = {"width_px", "height_px", "fx_px", "fy_px", "cx_px", "cy_px"};
  int present = 0;
  for (const char* key : kKeys) present += static_cast<int>(info.attributes.count(key));
  if (present == 0) return "";
  for (const char* key : kKeys) {
    if (!info.attributes.count(key)) {
      return std::string("camera intrinsics need all of width_px, height_px, fx_px, fy_px, cx_px, cy_px (") + key +
             " is missing)";
    }
  }
  const auto& a = info.attributes;
  const double width = a.at("width_px");
  const double height = a.at("height_px");
  if (!(width >= 1.0 && height >= 1.0) || width != std::floor(width) || height != std::floor(height)) {
    return "camera intrinsics: width_px and height_px must be positive integers";
  }
  if (!(a.at("fx_px") > 0.0 && a.at("fy_px") > 0.0)) return "camera intrinsics: fx_px and fy_px must be positive";
  if (!(a.at("cx_px") >= 0.0 && a.at("cx_px") < width && a.at("cy_px") >= 0.0 && a.at("cy_px") < height)) {
    return "camera intrinsics: the principal point (cx_px, cy_px) must lie inside the image";
  }
  return "";
}

// Problem with the covariance columns of a stream's values (a negative diagonal entry) as "<line>: <problem>" for the
// first bad row, or "" when fine. Row i is on line i + 2 of its file (after the header).
std::string CovarianceProblem(const Stream& stream) {
  if (!CarriesCovariance(stream.info)) return "";
  const Eigen::Index fixed = static_cast<Eigen::Index>(FixedColumns(stream.info.type).size());
  const std::vector<std::string>& names = CovarianceColumns(stream.info.type);
  const Eigen::Index n = stream.info.type == StreamType::kGps ? 3 : 6;
  Eigen::MatrixXd covariance(n, n);
  for (Eigen::Index row = 0; row < stream.values.rows(); ++row) {
    // The upper triangle stored row by row: 6x6 diagonal entries 0, 6, 11, 15, 18, 20; 3x3: 0, 3, 5.
    Eigen::Index index = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index j = i; j < n; ++j, ++index) {
        const double value = stream.values(row, fixed + index);
        const std::string& name = names[static_cast<std::size_t>(index)];
        if (i == j && value < 0.0) return std::to_string(row + 2) + ": " + name + " is negative";
        if (std::abs(value) > kMaxCovarianceEntry) {
          return std::to_string(row + 2) + ": " + name + " " + FormatShortest(value) +
                 " is beyond the physical range (|entry| <= 1e12)";
        }
        covariance(i, j) = covariance(j, i) = value;
      }
    }
    // Positive semi-definite to rounding (an all-zero covariance, "unknown", is allowed).
    const double scale = std::max(1.0, covariance.diagonal().maxCoeff());
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(covariance, Eigen::EigenvaluesOnly);
    if (eigen.eigenvalues().minCoeff() < -1e-9 * scale) {
      return std::to_string(row + 2) + ": the covariance is not positive semi-definite (smallest eigenvalue " +
             FormatShortest(eigen.eigenvalues().minCoeff()) + ")";
    }
  }
  return "";
}

// Types whose `units:` is free text, kept as given.
bool HasFreeUnits(StreamType type) { return type == StreamType::kInputs || type == StreamType::kCamera; }

namespace {

constexpr UnitRow kUnitTable[] = {
    {StreamType::kImu, "", "rad/s,m/s^2", 1.0, 1.0, false},
    {StreamType::kImu, "rad/s,m/s^2", "rad/s,m/s^2", 1.0, 1.0, false},
    {StreamType::kImu, "deg/s,m/s^2", "rad/s,m/s^2", kDegree, 1.0, false},
    {StreamType::kImu, "rad/s,g", "rad/s,m/s^2", 1.0, kStandardGravity, false},
    {StreamType::kImu, "deg/s,g", "rad/s,m/s^2", kDegree, kStandardGravity, false},
    {StreamType::kGyroscope, "", "rad/s", 1.0, 1.0, false},
    {StreamType::kGyroscope, "rad/s", "rad/s", 1.0, 1.0, false},
    {StreamType::kGyroscope, "deg/s", "rad/s", kDegree, kDegree, false},
    {StreamType::kAccelerometer, "", "m/s^2", 1.0, 1.0, false},
    {StreamType::kAccelerometer, "m/s^2", "m/s^2", 1.0, 1.0, false},
    {StreamType::kAccelerometer, "g", "m/s^2", kStandardGravity, kStandardGravity, false},
    {StreamType::kMagnetometer, "", "", 1.0, 1.0, false},
    {StreamType::kMagnetometer, "normalized", "normalized", 1.0, 1.0, false},
    {StreamType::kMagnetometer, "uT", "uT", 1.0, 1.0, false},
    {StreamType::kMagnetometer, "nT", "nT", 1.0, 1.0, false},
    {StreamType::kMagnetometer, "gauss", "gauss", 1.0, 1.0, false},
    {StreamType::kGps, "", "deg", 1.0, 1.0, false},
    {StreamType::kGps, "deg", "deg", 1.0, 1.0, false},
    {StreamType::kPosition, "", "m", 1.0, 1.0, false},
    {StreamType::kPosition, "m", "m", 1.0, 1.0, false},
    {StreamType::kPose, "", "m", 1.0, 1.0, false},
    {StreamType::kPose, "m", "m", 1.0, 1.0, false},
    {StreamType::kWheelEncoders, "", "rad", 1.0, 1.0, false},
    {StreamType::kWheelEncoders, "rad", "rad", 1.0, 1.0, false},
    {StreamType::kWheelEncoders, "rad/s", "rad/s", 1.0, 1.0, false},
    {StreamType::kWheelEncoders, "m/s", "m/s", 1.0, 1.0, false},
    {StreamType::kWheelEncoders, "ticks", "rad", 1.0, 1.0, true},
    {StreamType::kSteering, "", "rad", 1.0, 1.0, false},
    {StreamType::kSteering, "rad", "rad", 1.0, 1.0, false},
    {StreamType::kSteering, "deg", "rad", kDegree, kDegree, false},
    {StreamType::kOdometry, "", "m/s,rad/s", 1.0, 1.0, false},
    {StreamType::kOdometry, "m/s,rad/s", "m/s,rad/s", 1.0, 1.0, false},
    {StreamType::kVisualOdometry, "", "m/s,rad/s", 1.0, 1.0, false},
    {StreamType::kVisualOdometry, "m/s,rad/s", "m/s,rad/s", 1.0, 1.0, false},
    {StreamType::kScanMatching, "", "m/s,rad/s", 1.0, 1.0, false},
    {StreamType::kScanMatching, "m/s,rad/s", "m/s,rad/s", 1.0, 1.0, false},
    {StreamType::kLaserScan, "", "rad,m", 1.0, 1.0, false},
    {StreamType::kLaserScan, "rad,m", "rad,m", 1.0, 1.0, false},
};

}  // namespace

const UnitRow* FindUnitRow(StreamType type, const std::string& declared) {
  for (const UnitRow& row : kUnitTable) {
    if (row.type == type && declared == row.declared) return &row;
  }
  return nullptr;
}

// "deg/s, rad/s" for messages.
std::string AcceptedUnits(StreamType type) {
  std::string list;
  for (const UnitRow& row : kUnitTable) {
    if (row.type != type || *row.declared == '\0') continue;
    list += (list.empty() ? "" : " | ") + std::string(row.declared);
  }
  return list;
}

void ApplyConversion(const UnitConversion& conversion, Eigen::MatrixXd* values) {
  const Eigen::Index split = std::min<Eigen::Index>(3, values->cols());
  if (conversion.first != 1.0) values->leftCols(split) *= conversion.first;
  if (conversion.rest != 1.0) values->rightCols(values->cols() - split) *= conversion.rest;
}

// Small checks shared by the reader and the writer.

bool IsIdentifier(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

bool AllFinite(const std::map<std::string, double>& values) {
  return std::all_of(values.begin(), values.end(), [](const auto& item) { return std::isfinite(item.second); });
}

std::string JoinColumns(const std::vector<std::string>& columns) {
  std::string text = "[";
  for (std::size_t i = 0; i < columns.size(); ++i) text += (i > 0 ? ", " : "") + columns[i];
  return text + "]";
}

// Problem with the columns named for a wheel_encoders or inputs stream, or "" when they are fine.
std::string FreeColumnsProblem(const std::vector<std::string>& columns) {
  if (columns.empty()) return "needs at least one column";
  std::set<std::string> seen;
  for (const std::string& column : columns) {
    if (!IsIdentifier(column) || column == "t") return "invalid column name '" + column + "'";
    if (!seen.insert(column).second) return "duplicate column '" + column + "'";
  }
  return "";
}

// Problem with the columns named in the entry of a stream whose type fixes none, or "" when they are fine.
std::string NamedColumnsProblem(StreamType type, const std::vector<std::string>& columns) {
  if (type == StreamType::kLaserScan) return internal::LaserScanColumnsProblem(columns);
  return FreeColumnsProblem(columns);
}

// Problem with an origin, or "" when it is fine.
std::string OriginProblem(const GeodeticOrigin& origin) {
  if (!std::isfinite(origin.latitude_deg) || std::abs(origin.latitude_deg) > 90.0) return "latitude_deg out of range";
  if (!std::isfinite(origin.longitude_deg) || std::abs(origin.longitude_deg) > 180.0) {
    return "longitude_deg out of range";
  }
  if (!std::isfinite(origin.altitude_m)) return "altitude_m is not finite";
  return "";
}

}  // namespace roamlab::recording::internal
