// Reading and writing the recording directory (recording.h).
//
// recording.yaml, format_version 1:
//
//   format_version: 1                               # required; other versions are refused
//   platform:                                       # required
//     kind: ackermann                               # required, free string
//     geometry: {wheelbase_m: 1.25, track_m: 1.1}   # optional, name -> number (names carry the unit)
//   origin: {latitude_deg: 45.47, longitude_deg: 9.23, altitude_m: 120.0}
//                                                   # all three keys; required when a stream has type gps
//   provenance:                                     # optional; when present, source is required
//     source: simulated                             # "simulated" or "imported"
//     scenario: scenarios/atv_hills.yaml            # optional
//     seed: 1                                       # optional, unsigned 64-bit integer
//     description: "..."                            # optional
//   streams:                                        # required, may be empty
//     - name: gps                                   # required, unique, [A-Za-z0-9_]+; the data file is gps.csv
//       type: gps                                   # required, a StreamTypeName
//       rate_hz: 5                                  # required, nominal rate, > 0
//       units: deg                                  # optional, see the table below; absent = canonical
//       columns: [latitude, longitude, altitude]    # optional for fixed-column types (must then match exactly, or
//                                                   # for velocity types be followed by the 21 covariance columns);
//                                                   # required for wheel_encoders and inputs ([A-Za-z0-9_]+, unique)
//                                                   # and laser_scan (LaserScanColumns)
//       mounting: {p_body_sensor_m: [0.57, -0.46, 0.32], q_body_sensor_wxyz: [1, 0, 0, 0]}
//                                                   # optional, each key optional (zero, identity); |q| within 1e-3
//       noise: {sigma_m: 0.33}                      # optional, name -> number
//       attributes: {ticks_per_revolution: 2048}    # optional, name -> number; camera and visual_odometry: the
//                                                   # six intrinsics (recording.h), all or none
//
// Accepted `units:` per type, and what they become after reading (values are converted, info.units is replaced):
//   imu              rad/s,m/s^2 (canonical) | deg/s,m/s^2 | rad/s,g | deg/s,g        g = 9.80665 m/s^2
//   gyroscope        rad/s | deg/s                     accelerometer   m/s^2 | g
//   magnetometer     normalized | uT | nT | gauss      kept as given, no conversion (absent stays empty)
//   gps              deg                               position, pose  m
//   steering         rad | deg                         odometry, visual_odometry, scan_matching   m/s,rad/s
//   wheel_encoders   rad (default) | rad/s | m/s | ticks: ticks -> rad with attributes.ticks_per_revolution (required)
//   laser_scan       rad,m
//   inputs, camera   anything, kept as given
//
// Reading is strict: unknown or duplicate keys, missing required keys, wrong types, non-finite numbers are errors
// "<dir>/recording.yaml:<line>: <problem>". Writing emits the keys in the order above (origin only when set,
// provenance only when it has a source, units only when not empty, columns always), numbers as their shortest
// round-trip text, so that the same Recording always gives the same bytes.
#include "recording/recording.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <system_error>

#include <yaml-cpp/yaml.h>

#include "recording/internal/laser_scan.h"
#include "recording/internal/stream_csv.h"
#include "recording/internal/text_io.h"
#include "recording/internal/yaml_util.h"

namespace roamlab::recording {
namespace {

namespace fs = std::filesystem;
using internal::CheckKeys;
using internal::ReadNumber;
using internal::ReadNumberList;
using internal::ReadNumberMap;
using internal::ReadString;
using internal::ReadStringList;
using internal::RequireKey;
using internal::Where;

constexpr const char* kYamlFile = "recording.yaml";
constexpr const char* kGroundTruthFile = "ground_truth.tum";
constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;       // rad per degree
constexpr double kStandardGravity = 9.80665;  // m/s^2 per g

// Stream types and units.

struct TypeRow {
  StreamType type;
  const char* name;
  std::vector<std::string> columns;  // empty: named in the stream entry
};

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
  for (Eigen::Index row = 0; row < stream.values.rows(); ++row) {
    // The diagonal of an n x n upper triangle stored row by row: 6x6 entries 0, 6, 11, 15, 18, 20; 3x3: 0, 3, 5.
    const Eigen::Index n = stream.info.type == StreamType::kGps ? 3 : 6;
    Eigen::Index index = 0;
    for (Eigen::Index k = 0; k < n; index += n - k, ++k) {
      if (stream.values(row, fixed + index) < 0.0) {
        return std::to_string(row + 2) + ": " + names[static_cast<std::size_t>(index)] + " is negative";
      }
    }
  }
  return "";
}

// Types whose `units:` is free text, kept as given.
bool HasFreeUnits(StreamType type) { return type == StreamType::kInputs || type == StreamType::kCamera; }

// One accepted `units:` value of a type: what info.units becomes after reading, and the factors to canonical units
// for the first three columns and for the others (they differ for imu only). `ticks` takes its factor from
// attributes.ticks_per_revolution instead.
struct UnitRow {
  StreamType type;
  const char* declared;
  const char* canonical;
  double first;
  double rest;
  bool ticks;
};

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

// How to bring a stream file to canonical units: multiply the first three columns by `first`, the others by `rest`.
struct UnitConversion {
  double first = 1.0;
  double rest = 1.0;
};

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

// Reading recording.yaml.

// A stream entry of recording.yaml and the conversion its file needs.
struct StreamEntry {
  StreamInfo info;
  UnitConversion conversion;
};

// "<path>:<line>: <problem>" at `node`.
Status ErrorAt(const std::string& path, const YAML::Node& node, const std::string& problem) {
  return Status::Error(Where(path, node) + ": " + problem);
}

Status ParsePlatform(const YAML::Node& node, const std::string& path, Platform* platform) {
  if (Status s = CheckKeys(node, path, "platform", {"kind", "geometry"}); !s.ok()) return s;
  if (Status s = RequireKey(node, "kind", path, "platform"); !s.ok()) return s;
  if (Status s = ReadString(node["kind"], path, "platform.kind", &platform->kind); !s.ok()) return s;
  if (platform->kind.empty()) return ErrorAt(path, node["kind"], "platform.kind is empty");
  if (!node["geometry"]) return Status::Ok();
  return ReadNumberMap(node["geometry"], path, "platform.geometry", &platform->geometry);
}

Status ParseOrigin(const YAML::Node& node, const std::string& path, GeodeticOrigin* origin) {
  if (Status s = CheckKeys(node, path, "origin", {"latitude_deg", "longitude_deg", "altitude_m"}); !s.ok()) return s;
  const std::pair<const char*, double*> fields[] = {{"latitude_deg", &origin->latitude_deg},
                                                    {"longitude_deg", &origin->longitude_deg},
                                                    {"altitude_m", &origin->altitude_m}};
  for (const auto& [key, value] : fields) {
    if (Status s = RequireKey(node, key, path, "origin"); !s.ok()) return s;
    if (Status s = ReadNumber(node[key], path, std::string("origin.") + key, value); !s.ok()) return s;
  }
  const std::string problem = OriginProblem(*origin);
  return problem.empty() ? Status::Ok() : ErrorAt(path, node, "origin: " + problem);
}

Status ParseSeed(const YAML::Node& node, const std::string& path, std::uint64_t* seed) {
  std::string text;
  if (Status s = ReadString(node, path, "provenance.seed", &text); !s.ok()) return s;
  const bool digits = !text.empty() && text.size() <= 20 &&
                      std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  errno = 0;
  const unsigned long long value = digits ? std::strtoull(text.c_str(), nullptr, 10) : 0;
  if (!digits || errno == ERANGE) return ErrorAt(path, node, "provenance.seed: not an unsigned integer '" + text + "'");
  *seed = static_cast<std::uint64_t>(value);
  return Status::Ok();
}

Status ParseProvenance(const YAML::Node& node, const std::string& path, Provenance* provenance) {
  if (Status s = CheckKeys(node, path, "provenance", {"source", "scenario", "seed", "description"}); !s.ok()) return s;
  if (Status s = RequireKey(node, "source", path, "provenance"); !s.ok()) return s;
  if (Status s = ReadString(node["source"], path, "provenance.source", &provenance->source); !s.ok()) return s;
  if (node["scenario"]) {
    if (Status s = ReadString(node["scenario"], path, "provenance.scenario", &provenance->scenario); !s.ok()) return s;
  }
  if (node["description"]) {
    const YAML::Node description = node["description"];
    if (Status s = ReadString(description, path, "provenance.description", &provenance->description); !s.ok()) {
      return s;
    }
  }
  if (!node["seed"]) return Status::Ok();
  std::uint64_t seed = 0;
  if (Status s = ParseSeed(node["seed"], path, &seed); !s.ok()) return s;
  provenance->seed = seed;
  return Status::Ok();
}

// Fills info->columns: the fixed columns of the type (a `columns:` key must repeat them exactly), or the named ones.
Status ParseColumns(const YAML::Node& entry, const std::string& path, const std::string& context, StreamInfo* info) {
  std::vector<std::string> declared;
  const YAML::Node node = entry["columns"];
  if (node) {
    if (Status s = ReadStringList(node, path, "columns of " + context, &declared); !s.ok()) return s;
  }
  // Fixed-column types; the velocity types may add the covariance columns.
  const std::vector<std::string>& fixed = FixedColumns(info->type);
  if (!fixed.empty()) {
    const bool covariance = HasCovarianceColumns(info->type) && declared == ColumnsWithCovariance(info->type);
    if (node && declared != fixed && !covariance) {
      return ErrorAt(path, node,
                     "columns " + JoinColumns(declared) + " of " + context + " do not match type " +
                         StreamTypeName(info->type) + ": expected " + JoinColumns(fixed) +
                         CovarianceNote(info->type));
    }
    info->columns = covariance ? declared : fixed;
    return Status::Ok();
  }
  // wheel_encoders, inputs and laser_scan name their own columns.
  if (!node) {
    return ErrorAt(path, entry,
                   "missing required key 'columns' in " + context + " (type " + StreamTypeName(info->type) + ")");
  }
  const std::string problem = NamedColumnsProblem(info->type, declared);
  if (!problem.empty()) return ErrorAt(path, node, context + ": " + problem);
  info->columns = std::move(declared);
  return Status::Ok();
}

Status ParseMounting(const YAML::Node& node, const std::string& path, const std::string& context, Mounting* mounting) {
  const std::string where = "mounting of " + context;
  if (Status s = CheckKeys(node, path, where, {"p_body_sensor_m", "q_body_sensor_wxyz"}); !s.ok()) return s;
  std::vector<double> values;
  if (node["p_body_sensor_m"]) {
    if (Status s = ReadNumberList(node["p_body_sensor_m"], path, "p_body_sensor_m of " + context, 3, &values);
        !s.ok()) {
      return s;
    }
    mounting->p_body_sensor = Eigen::Vector3d(values[0], values[1], values[2]);
  }
  if (node["q_body_sensor_wxyz"]) {
    const YAML::Node q = node["q_body_sensor_wxyz"];
    if (Status s = ReadNumberList(q, path, "q_body_sensor_wxyz of " + context, 4, &values); !s.ok()) return s;
    mounting->q_body_sensor = Eigen::Quaterniond(values[0], values[1], values[2], values[3]);
    if (!internal::NormalizeNearUnit(&mounting->q_body_sensor)) {
      return ErrorAt(path, q, "q_body_sensor_wxyz of " + context + " is not a unit quaternion");
    }
  }
  return Status::Ok();
}

// Resolves `units:` (already in info->units) into the canonical unit string and the conversion of the file's values.
Status ResolveUnits(const YAML::Node& entry, const std::string& path, const std::string& context, StreamInfo* info,
                    UnitConversion* conversion) {
  if (HasFreeUnits(info->type)) return Status::Ok();
  const YAML::Node where = entry["units"] ? entry["units"] : entry;
  const UnitRow* row = FindUnitRow(info->type, info->units);
  if (row == nullptr) {
    return ErrorAt(path, where,
                   "unknown units '" + info->units + "' for " + context + " of type " + StreamTypeName(info->type) +
                       " (accepted: " + AcceptedUnits(info->type) + ")");
  }
  info->units = row->canonical;
  conversion->first = row->first;
  conversion->rest = row->rest;
  if (!row->ticks) return Status::Ok();
  // Ticks -> rad needs the encoder resolution.
  const auto ticks = info->attributes.find("ticks_per_revolution");
  if (ticks == info->attributes.end() || !(ticks->second > 0.0)) {
    return ErrorAt(path, where, context + " has units ticks but no positive attributes.ticks_per_revolution");
  }
  conversion->first = conversion->rest = 2.0 * kPi / ticks->second;
  return Status::Ok();
}

Status ParseStreamEntry(const YAML::Node& node, const std::string& path, std::size_t index, StreamEntry* entry) {
  // Name the stream in every later message, once its name is known.
  std::string context = "streams[" + std::to_string(index) + "]";
  if (node.IsMap() && node["name"] && node["name"].IsScalar()) context = "stream '" + node["name"].Scalar() + "'";
  if (Status s = CheckKeys(node, path, context,
                           {"name", "type", "rate_hz", "units", "columns", "mounting", "noise", "attributes"});
      !s.ok()) {
    return s;
  }
  for (const char* key : {"name", "type", "rate_hz"}) {
    if (Status s = RequireKey(node, key, path, context); !s.ok()) return s;
  }
  // Name, type and rate.
  StreamInfo& info = entry->info;
  if (Status s = ReadString(node["name"], path, "name of " + context, &info.name); !s.ok()) return s;
  if (!IsIdentifier(info.name)) return ErrorAt(path, node["name"], "invalid stream name '" + info.name + "'");
  std::string type_name;
  if (Status s = ReadString(node["type"], path, "type of " + context, &type_name); !s.ok()) return s;
  const std::optional<StreamType> type = ParseStreamType(type_name);
  if (!type) return ErrorAt(path, node["type"], "unknown stream type '" + type_name + "' for " + context);
  info.type = *type;
  if (Status s = ReadNumber(node["rate_hz"], path, "rate_hz of " + context, &info.rate_hz); !s.ok()) return s;
  if (!(info.rate_hz > 0.0)) return ErrorAt(path, node["rate_hz"], "rate_hz of " + context + " must be positive");
  // Columns, mounting, noise, attributes.
  if (Status s = ParseColumns(node, path, context, &info); !s.ok()) return s;
  if (node["mounting"]) {
    info.mounting.emplace();
    if (Status s = ParseMounting(node["mounting"], path, context, &*info.mounting); !s.ok()) return s;
  }
  if (node["noise"]) {
    if (Status s = ReadNumberMap(node["noise"], path, "noise of " + context, &info.noise); !s.ok()) return s;
  }
  if (node["attributes"]) {
    const YAML::Node attributes = node["attributes"];
    if (Status s = ReadNumberMap(attributes, path, "attributes of " + context, &info.attributes); !s.ok()) return s;
    const std::string problem = IntrinsicsProblem(info);
    if (!problem.empty()) return ErrorAt(path, attributes, context + ": " + problem);
  }
  // Units last: ticks need the attributes.
  if (node["units"]) {
    if (Status s = ReadString(node["units"], path, "units of " + context, &info.units); !s.ok()) return s;
  }
  return ResolveUnits(node, path, context, &info, &entry->conversion);
}

Status ParseStreams(const YAML::Node& node, const std::string& path, std::vector<StreamEntry>* entries) {
  if (!node.IsSequence()) return ErrorAt(path, node, "streams must be a list");
  std::set<std::string> names;
  for (std::size_t i = 0; i < node.size(); ++i) {
    StreamEntry entry;
    if (Status s = ParseStreamEntry(node[i], path, i, &entry); !s.ok()) return s;
    if (!names.insert(entry.info.name).second) {
      return ErrorAt(path, node[i], "duplicate stream name '" + entry.info.name + "'");
    }
    entries->push_back(std::move(entry));
  }
  return Status::Ok();
}

Status ParseFormatVersion(const YAML::Node& node, const std::string& path, int* version) {
  double value = 0.0;
  if (Status s = ReadNumber(node, path, "format_version", &value); !s.ok()) return s;
  if (value != kFormatVersion) {
    return ErrorAt(
        path, node,
        "unsupported format_version " + node.Scalar() + " (this reader knows " + std::to_string(kFormatVersion) + ")");
  }
  *version = kFormatVersion;
  return Status::Ok();
}

// Parses the whole of recording.yaml: metadata into `recording` (streams without data), one entry per stream.
Status ParseRecordingYaml(const YAML::Node& root, const std::string& path, Recording* recording,
                          std::vector<StreamEntry>* entries) {
  // Top level: known keys, required ones present.
  const std::string context = "the top level";
  if (Status s = CheckKeys(root, path, context, {"format_version", "platform", "origin", "provenance", "streams"});
      !s.ok()) {
    return s;
  }
  for (const char* key : {"format_version", "platform", "streams"}) {
    if (Status s = RequireKey(root, key, path, context); !s.ok()) return s;
  }
  // Sections in schema order.
  if (Status s = ParseFormatVersion(root["format_version"], path, &recording->format_version); !s.ok()) return s;
  if (Status s = ParsePlatform(root["platform"], path, &recording->platform); !s.ok()) return s;
  if (root["origin"]) {
    recording->origin.emplace();
    if (Status s = ParseOrigin(root["origin"], path, &*recording->origin); !s.ok()) return s;
  }
  if (root["provenance"]) {
    if (Status s = ParseProvenance(root["provenance"], path, &recording->provenance); !s.ok()) return s;
  }
  if (Status s = ParseStreams(root["streams"], path, entries); !s.ok()) return s;
  // A gps stream is only meaningful with the origin of the local frame.
  for (const StreamEntry& entry : *entries) {
    if (entry.info.type == StreamType::kGps && !recording->origin) {
      return Status::Error(path + ": stream '" + entry.info.name +
                           "' has type gps but there is no origin (latitude_deg, longitude_deg, altitude_m)");
    }
  }
  return Status::Ok();
}

// Reading stream files.

Status ReadStreamFile(const fs::path& directory, const UnitConversion& conversion, Stream* stream) {
  const StreamInfo& info = stream->info;
  const std::string path = (directory / (info.name + ".csv")).string();
  std::string content;
  if (Status s = internal::ReadTextFile(path, &content); !s.ok()) {
    return Status::Error(s.message() + " (stream '" + info.name + "' listed in " + kYamlFile + ")");
  }
  internal::CsvColumns data;
  const bool text_column = info.type == StreamType::kCamera;
  if (Status s = internal::ParseStreamCsv(content, path, info.columns, text_column, &data); !s.ok()) return s;
  stream->t = std::move(data.t);
  stream->values = std::move(data.values);
  stream->text = std::move(data.text);
  ApplyConversion(conversion, &stream->values);
  std::string problem = CovarianceProblem(*stream);
  if (problem.empty()) problem = internal::LaserScanRowsProblem(*stream);
  return problem.empty() ? Status::Ok() : Status::Error(path + ":" + problem);
}

// Validation before writing: refuse what the reader would refuse, so that every written recording reads back.

// Units the writer may write for a type: empty, or a canonical (non-converting) value.
bool WritableUnits(StreamType type, const std::string& units) {
  if (units.empty() || HasFreeUnits(type)) return true;
  const UnitRow* row = FindUnitRow(type, units);
  return row != nullptr && units == row->canonical;
}

// Columns written for a stream: the fixed ones of its type (with the covariance columns when it carries them), or
// the named ones.
const std::vector<std::string>& WrittenColumns(const StreamInfo& info) {
  const std::vector<std::string>& fixed = FixedColumns(info.type);
  return fixed.empty() || CarriesCovariance(info) ? info.columns : fixed;
}

Status ValidateInfoForWrite(const StreamInfo& info, const std::string& prefix) {
  if (!IsIdentifier(info.name)) return Status::Error(prefix + "invalid stream name (use [A-Za-z0-9_]+)");
  if (!(info.rate_hz > 0.0) || !std::isfinite(info.rate_hz)) return Status::Error(prefix + "rate_hz must be positive");
  // Columns: as fixed by the type (or left empty), or named validly.
  const std::vector<std::string>& fixed = FixedColumns(info.type);
  if (!fixed.empty() && !info.columns.empty() && info.columns != fixed && !CarriesCovariance(info)) {
    return Status::Error(prefix + "columns " + JoinColumns(info.columns) + " do not match type " +
                         StreamTypeName(info.type) + ": expected " + JoinColumns(fixed) +
                         CovarianceNote(info.type));
  }
  if (fixed.empty()) {
    const std::string problem = NamedColumnsProblem(info.type, info.columns);
    if (!problem.empty()) return Status::Error(prefix + problem);
  }
  // Units, mounting, noise and attributes.
  if (!WritableUnits(info.type, info.units)) {
    return Status::Error(prefix + "units '" + info.units + "' are not canonical for type " + StreamTypeName(info.type) +
                         " (values are held in canonical units)");
  }
  if (info.mounting && (!info.mounting->p_body_sensor.allFinite() ||
                        !(std::abs(info.mounting->q_body_sensor.norm() - 1.0) < internal::kQuaternionNormTolerance))) {
    return Status::Error(prefix + "mounting has a non-finite lever arm or a non-unit quaternion");
  }
  if (!AllFinite(info.noise) || !AllFinite(info.attributes)) {
    return Status::Error(prefix + "noise and attributes must be finite");
  }
  const std::string problem = IntrinsicsProblem(info);
  return problem.empty() ? Status::Ok() : Status::Error(prefix + problem);
}

// Camera frame names must survive the CSV: non-empty, no comma or line break, no surrounding blanks.
bool IsWritableText(const std::string& text) {
  return !text.empty() && text.find_first_of(",\n\r") == std::string::npos && internal::Trim(text) == text;
}

Status ValidateDataForWrite(const Stream& stream, const std::string& prefix) {
  const std::size_t n = stream.t.size();
  const Eigen::Index rows = stream.values.rows();
  // Sizes: a numeric stream has one value per column and sample, a camera stream one text per sample.
  if (stream.info.type == StreamType::kCamera) {
    if (stream.values.cols() != 0 || (rows != 0 && static_cast<std::size_t>(rows) != n) || stream.text.size() != n) {
      return Status::Error(prefix + "a camera stream needs one text per sample and no values");
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!IsWritableText(stream.text[i])) {
        return Status::Error(prefix + "sample " + std::to_string(i) + ": frame name '" + stream.text[i] +
                             "' is empty or holds a comma, line break or surrounding blank");
      }
    }
  } else {
    const std::size_t cols = WrittenColumns(stream.info).size();
    if (static_cast<std::size_t>(stream.values.cols()) != cols) {
      return Status::Error(prefix + "values have " + std::to_string(stream.values.cols()) + " columns, expected " +
                           std::to_string(cols) + " " + JoinColumns(WrittenColumns(stream.info)));
    }
    if (static_cast<std::size_t>(rows) != n) {
      return Status::Error(prefix + "values have " + std::to_string(rows) + " rows for " + std::to_string(n) +
                           " timestamps");
    }
    if (!stream.text.empty()) return Status::Error(prefix + "text is only for camera streams");
    if (!stream.values.allFinite()) return Status::Error(prefix + "values contain NaN or Inf");
    std::string problem = CovarianceProblem(stream);
    if (problem.empty()) problem = internal::LaserScanRowsProblem(stream);
    if (!problem.empty()) return Status::Error(prefix + "row " + problem);
  }
  // Time strictly increasing.
  for (std::size_t i = 1; i < n; ++i) {
    if (stream.t[i] <= stream.t[i - 1]) {
      return Status::Error(prefix + "sample " + std::to_string(i) + ": " +
                           internal::TimeOrderProblem(stream.t[i - 1], stream.t[i]));
    }
  }
  return Status::Ok();
}

Status ValidateForWrite(const Recording& recording, const std::string& directory) {
  const std::string prefix = directory + ": ";
  // Metadata.
  if (recording.format_version != kFormatVersion) return Status::Error(prefix + "format_version must be 1");
  if (recording.platform.kind.empty()) return Status::Error(prefix + "platform.kind is empty");
  if (!AllFinite(recording.platform.geometry)) return Status::Error(prefix + "platform.geometry must be finite");
  if (recording.origin) {
    const std::string problem = OriginProblem(*recording.origin);
    if (!problem.empty()) return Status::Error(prefix + "origin: " + problem);
  }
  const Provenance& provenance = recording.provenance;
  if (provenance.source.empty() &&
      (!provenance.scenario.empty() || provenance.seed || !provenance.description.empty())) {
    return Status::Error(prefix + "provenance.source is empty");
  }
  // Streams: unique names, valid metadata and data, an origin for gps.
  std::set<std::string> names;
  for (const Stream& stream : recording.streams) {
    const std::string stream_prefix = prefix + "stream '" + stream.info.name + "': ";
    if (!names.insert(stream.info.name).second) {
      return Status::Error(prefix + "duplicate stream name '" + stream.info.name + "'");
    }
    if (Status s = ValidateInfoForWrite(stream.info, stream_prefix); !s.ok()) return s;
    if (Status s = ValidateDataForWrite(stream, stream_prefix); !s.ok()) return s;
    if (stream.info.type == StreamType::kGps && !recording.origin) {
      return Status::Error(stream_prefix + "type gps needs an origin");
    }
  }
  return Status::Ok();
}

// Writing recording.yaml.

void EmitStreamInfo(const StreamInfo& info, YAML::Emitter* out) {
  *out << YAML::BeginMap;
  *out << YAML::Key << "name" << YAML::Value << info.name;
  *out << YAML::Key << "type" << YAML::Value << StreamTypeName(info.type);
  *out << YAML::Key << "rate_hz" << YAML::Value;
  internal::EmitNumber(info.rate_hz, out);
  if (!info.units.empty()) *out << YAML::Key << "units" << YAML::Value << info.units;
  *out << YAML::Key << "columns" << YAML::Value;
  internal::EmitStringList(WrittenColumns(info), out);
  if (info.mounting) {
    const Eigen::Vector3d& p = info.mounting->p_body_sensor;
    const Eigen::Quaterniond& q = info.mounting->q_body_sensor;
    *out << YAML::Key << "mounting" << YAML::Value << YAML::Flow << YAML::BeginMap;
    *out << YAML::Key << "p_body_sensor_m" << YAML::Value;
    internal::EmitNumberList({p.x(), p.y(), p.z()}, out);
    *out << YAML::Key << "q_body_sensor_wxyz" << YAML::Value;
    internal::EmitNumberList({q.w(), q.x(), q.y(), q.z()}, out);
    *out << YAML::EndMap;
  }
  if (!info.noise.empty()) {
    *out << YAML::Key << "noise" << YAML::Value;
    internal::EmitNumberMap(info.noise, out);
  }
  if (!info.attributes.empty()) {
    *out << YAML::Key << "attributes" << YAML::Value;
    internal::EmitNumberMap(info.attributes, out);
  }
  *out << YAML::EndMap;
}

std::string EmitRecordingYaml(const Recording& recording) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "format_version" << YAML::Value << recording.format_version;
  // Platform.
  out << YAML::Key << "platform" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "kind" << YAML::Value << recording.platform.kind;
  if (!recording.platform.geometry.empty()) {
    out << YAML::Key << "geometry" << YAML::Value;
    internal::EmitNumberMap(recording.platform.geometry, &out);
  }
  out << YAML::EndMap;
  // Origin.
  if (recording.origin) {
    out << YAML::Key << "origin" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "latitude_deg" << YAML::Value;
    internal::EmitNumber(recording.origin->latitude_deg, &out);
    out << YAML::Key << "longitude_deg" << YAML::Value;
    internal::EmitNumber(recording.origin->longitude_deg, &out);
    out << YAML::Key << "altitude_m" << YAML::Value;
    internal::EmitNumber(recording.origin->altitude_m, &out);
    out << YAML::EndMap;
  }
  // Provenance.
  const Provenance& provenance = recording.provenance;
  if (!provenance.source.empty()) {
    out << YAML::Key << "provenance" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "source" << YAML::Value << provenance.source;
    if (!provenance.scenario.empty()) out << YAML::Key << "scenario" << YAML::Value << provenance.scenario;
    if (provenance.seed) out << YAML::Key << "seed" << YAML::Value << std::to_string(*provenance.seed);
    if (!provenance.description.empty()) out << YAML::Key << "description" << YAML::Value << provenance.description;
    out << YAML::EndMap;
  }
  // Streams.
  out << YAML::Key << "streams" << YAML::Value;
  if (recording.streams.empty()) out << YAML::Flow;  // "[]" on the same line
  out << YAML::BeginSeq;
  for (const Stream& stream : recording.streams) EmitStreamInfo(stream.info, &out);
  out << YAML::EndSeq;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace

// Public interface.

const char* StreamTypeName(StreamType type) { return RowOf(type).name; }

std::optional<StreamType> ParseStreamType(const std::string& name) {
  for (const TypeRow& row : TypeTable()) {
    if (name == row.name) return row.type;
  }
  return std::nullopt;
}

const std::vector<std::string>& FixedColumns(StreamType type) { return RowOf(type).columns; }

std::vector<std::string> LaserScanColumns(int beams) {
  std::vector<std::string> columns = {"angle_min_rad", "angle_increment_rad", "range_min_m", "range_max_m"};
  for (int k = 0; k < beams; ++k) columns.push_back("range_" + std::to_string(k));
  return columns;
}

const std::vector<std::string>& CovarianceColumns(StreamType type) {
  static const std::vector<std::string> none;
  static const std::vector<std::string> gps = {"cov_e_e", "cov_e_n", "cov_e_u", "cov_n_n", "cov_n_u", "cov_u_u"};
  if (type == StreamType::kGps) return gps;
  static const std::vector<std::string> covariance = [] {
    const char* const names[] = {"vx", "vy", "vz", "wx", "wy", "wz"};
    std::vector<std::string> columns;
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j) columns.push_back(std::string("cov_") + names[i] + "_" + names[j]);
    return columns;
  }();
  return HasCovarianceColumns(type) ? covariance : none;
}

const Stream* Recording::Find(const std::string& name) const {
  for (const Stream& stream : streams) {
    if (stream.info.name == name) return &stream;
  }
  return nullptr;
}

Result<Recording> ReadRecording(const std::string& directory, const ReadOptions& options) {
  const fs::path dir(directory);
  const std::string yaml_path = (dir / kYamlFile).string();
  // Metadata.
  YAML::Node root;
  if (Status s = internal::LoadYamlFile(yaml_path, &root); !s.ok()) return s;
  Recording recording;
  std::vector<StreamEntry> entries;
  if (Status s = ParseRecordingYaml(root, yaml_path, &recording, &entries); !s.ok()) return s;
  // Required streams, before any data is read.
  for (const std::string& name : options.required_streams) {
    const bool present = std::any_of(entries.begin(), entries.end(),
                                     [&name](const StreamEntry& entry) { return entry.info.name == name; });
    if (!present) return Status::Error(yaml_path + ": required stream '" + name + "' missing");
  }
  // Stream files, converted to canonical units.
  recording.streams.resize(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    recording.streams[i].info = std::move(entries[i].info);
    if (Status s = ReadStreamFile(dir, entries[i].conversion, &recording.streams[i]); !s.ok()) return s;
  }
  // Ground truth, when present and wanted. truth.yaml is never opened here.
  const fs::path ground_truth_path = dir / kGroundTruthFile;
  std::error_code error;
  if (options.load_ground_truth && fs::exists(ground_truth_path, error)) {
    Result<Trajectory> ground_truth = ReadTum(ground_truth_path.string());
    if (!ground_truth.ok()) return ground_truth.status();
    recording.ground_truth = std::move(ground_truth).value();
  }
  return recording;
}

Status WriteRecording(const Recording& recording, const std::string& directory) {
  // Validate everything first: nothing is written for a recording that would not read back.
  if (Status s = ValidateForWrite(recording, directory); !s.ok()) return s;
  const fs::path dir(directory);
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) return Status::Error(directory + ": cannot create directory: " + error.message());
  // Stream files.
  for (const Stream& stream : recording.streams) {
    const std::string path = (dir / (stream.info.name + ".csv")).string();
    const bool camera = stream.info.type == StreamType::kCamera;
    const Eigen::MatrixXd no_values(static_cast<Eigen::Index>(stream.t.size()), 0);
    const std::string text = internal::FormatStreamCsv(
        WrittenColumns(stream.info), stream.t, camera ? no_values : stream.values, camera ? &stream.text : nullptr);
    if (Status s = internal::WriteTextFile(path, text); !s.ok()) return s;
  }
  // Ground truth; a stale file from an earlier recording in the same directory is removed.
  const fs::path ground_truth_path = dir / kGroundTruthFile;
  if (recording.ground_truth) {
    if (Status s = WriteTum(*recording.ground_truth, ground_truth_path.string()); !s.ok()) return s;
  } else {
    fs::remove(ground_truth_path, error);
    if (error) return Status::Error(ground_truth_path.string() + ": cannot remove stale file: " + error.message());
  }
  // recording.yaml last: an interrupted write leaves a directory that does not read as a recording.
  return internal::WriteTextFile((dir / kYamlFile).string(), EmitRecordingYaml(recording));
}

}  // namespace roamlab::recording
