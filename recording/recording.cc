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
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <system_error>

#include <yaml-cpp/yaml.h>

#include "recording/internal/laser_scan.h"
#include "recording/internal/stream_csv.h"
#include "recording/internal/stream_types.h"
#include "recording/internal/text_io.h"
#include "recording/internal/yaml_util.h"

namespace roamlab::recording {
namespace {

namespace fs = std::filesystem;
// The format's tables and the parsing helpers (recording/internal/).
using namespace internal;

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

// The physical ranges of recording.yaml's numbers (documented in docs/recording-format.md).
constexpr double kMaxRateHz = 1e6;
constexpr double kMaxLeverArmM = 1e3;
constexpr double kMaxGeometry = 1e6;
constexpr double kMaxNoiseOrAttribute = 1e9;

// "<path>:<line>: <what>: <key> <value> is beyond the physical range (|value| <= <limit>)" for the first value of
// `values` beyond `limit`; ok otherwise.
Status CheckMagnitudes(const std::map<std::string, double>& values, double limit, const std::string& path,
                       const YAML::Node& node, const std::string& what) {
  for (const auto& [key, value] : values) {
    if (std::abs(value) > limit) {
      char bound[16];
      std::snprintf(bound, sizeof(bound), "%g", limit);
      return ErrorAt(
          path, node,
          what + ": " + key + " " + FormatShortest(value) + " is beyond the physical range (|value| <= " + bound + ")");
    }
  }
  return Status::Ok();
}

Status ParsePlatform(const YAML::Node& node, const std::string& path, Platform* platform) {
  if (Status s = CheckKeys(node, path, "platform", {"kind", "geometry"}); !s.ok()) return s;
  if (Status s = RequireKey(node, "kind", path, "platform"); !s.ok()) return s;
  if (Status s = ReadString(node["kind"], path, "platform.kind", &platform->kind); !s.ok()) return s;
  if (platform->kind.empty()) return ErrorAt(path, node["kind"], "platform.kind is empty");
  if (!node["geometry"]) return Status::Ok();
  if (Status s = ReadNumberMap(node["geometry"], path, "platform.geometry", &platform->geometry); !s.ok()) return s;
  return CheckMagnitudes(platform->geometry, kMaxGeometry, path, node["geometry"], "platform.geometry");
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
                         StreamTypeName(info->type) + ": expected " + JoinColumns(fixed) + CovarianceNote(info->type));
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
    if (!(mounting->p_body_sensor.cwiseAbs().maxCoeff() <= kMaxLeverArmM)) {
      return ErrorAt(path, node["p_body_sensor_m"],
                     "p_body_sensor_m of " + context + " is beyond the physical range (|component| <= 1000 m)");
    }
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
  if (!(info.rate_hz > 0.0 && info.rate_hz <= kMaxRateHz)) {
    return ErrorAt(path, node["rate_hz"], "rate_hz of " + context + " must be positive and at most 1e6");
  }
  // Columns, mounting, noise, attributes.
  if (Status s = ParseColumns(node, path, context, &info); !s.ok()) return s;
  if (node["mounting"]) {
    info.mounting.emplace();
    if (Status s = ParseMounting(node["mounting"], path, context, &*info.mounting); !s.ok()) return s;
  }
  if (node["noise"]) {
    if (Status s = ReadNumberMap(node["noise"], path, "noise of " + context, &info.noise); !s.ok()) return s;
    const std::string what = "noise of " + context;
    if (Status s = CheckMagnitudes(info.noise, kMaxNoiseOrAttribute, path, node["noise"], what); !s.ok()) return s;
  }
  if (node["attributes"]) {
    const YAML::Node attributes = node["attributes"];
    if (Status s = ReadNumberMap(attributes, path, "attributes of " + context, &info.attributes); !s.ok()) return s;
    const std::string what = "attributes of " + context;
    if (Status s = CheckMagnitudes(info.attributes, kMaxNoiseOrAttribute, path, attributes, what); !s.ok()) return s;
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
  stream->duplicate_rows_dropped = data.duplicate_rows;
  ApplyConversion(conversion, &stream->values);
  std::string problem = CovarianceProblem(*stream);
  if (problem.empty()) problem = internal::LaserScanRowsProblem(*stream);
  return problem.empty() ? Status::Ok() : Status::Error(path + ":" + problem);
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

}  // namespace roamlab::recording
