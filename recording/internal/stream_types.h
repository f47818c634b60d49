// The stream types of the recording format, the units each accepts and the checks the reader and the writer share
// (recording.h has the tables; recording.cc the reader, recording_writer.cc the writer).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "recording/recording.h"

namespace roamlab::recording::internal {

inline constexpr const char* kYamlFile = "recording.yaml";
inline constexpr const char* kGroundTruthFile = "ground_truth.tum";
inline constexpr const char* kTruthYamlFile = "truth.yaml";
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegree = kPi / 180.0;       // rad per degree
inline constexpr double kStandardGravity = 9.80665;  // m/s^2 per g

struct TypeRow {
  StreamType type;
  const char* name;
  std::vector<std::string> columns;  // empty: named in the stream entry
};

// One row per StreamType: its name in recording.yaml and its fixed columns.
const std::vector<TypeRow>& TypeTable();

// The type's row of TypeTable().
const TypeRow& RowOf(StreamType type);

// The types whose fixed columns may be followed by the covariance columns: the velocity types (6x6) and gps (3x3).
bool HasCovarianceColumns(StreamType type);

// Fixed columns followed by the covariance columns (HasCovarianceColumns types only).
std::vector<std::string> ColumnsWithCovariance(StreamType type);

// " (optionally followed by the N covariance columns)" for the types that may carry them, else "".
std::string CovarianceNote(StreamType type);

// Whether the stream's columns include the covariance columns of its type.
bool CarriesCovariance(const StreamInfo& info);

// Camera intrinsics in the attributes of camera and visual_odometry streams: all six or none; "" when fine.
std::string IntrinsicsProblem(const StreamInfo& info);

// Entries of a covariance column are at most this in magnitude [m^2, (m/s)^2, (rad/s)^2, ...].
inline constexpr double kMaxCovarianceEntry = 1e12;

// Problem with the covariance columns of a stream's values (a negative diagonal entry, an entry beyond
// kMaxCovarianceEntry, a matrix that is not positive semi-definite to rounding) as "<line>: <problem>" for the
// first bad row, or "" when fine. Row i is on line i + 2 of its file (after the header).
std::string CovarianceProblem(const Stream& stream);

// Types whose `units:` is free text, kept as given.
bool HasFreeUnits(StreamType type);

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

// The accepted `units:` row of the type, or nullptr.
const UnitRow* FindUnitRow(StreamType type, const std::string& declared);

// "deg/s, rad/s" for messages.
std::string AcceptedUnits(StreamType type);

// How to bring a stream file to canonical units: multiply the first three columns by `first`, the others by `rest`.
struct UnitConversion {
  double first = 1.0;
  double rest = 1.0;
};

void ApplyConversion(const UnitConversion& conversion, Eigen::MatrixXd* values);

// [A-Za-z0-9_]+
bool IsIdentifier(const std::string& name);

bool AllFinite(const std::map<std::string, double>& values);

// "a, b, c" for messages.
std::string JoinColumns(const std::vector<std::string>& columns);

// Problem with the columns named for a wheel_encoders or inputs stream, or "" when they are fine.
std::string FreeColumnsProblem(const std::vector<std::string>& columns);

// Problem with the columns named in the entry of a stream whose type fixes none, or "" when they are fine.
std::string NamedColumnsProblem(StreamType type, const std::vector<std::string>& columns);

// Problem with an origin, or "" when it is fine.
std::string OriginProblem(const GeodeticOrigin& origin);

}  // namespace roamlab::recording::internal
