// Writing the recording directory (recording.h): the writer refuses what the reader would refuse, so that every
// written recording reads back, and emits recording.yaml in a fixed key order (recording.cc describes the format).
#include "recording/recording.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <system_error>

#include <yaml-cpp/yaml.h>

#include "common/atomic_file.h"
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
                         StreamTypeName(info.type) + ": expected " + JoinColumns(fixed) + CovarianceNote(info.type));
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
  // Time strictly increasing, but for a row identical to the one before it (a duplicated message; see Stream).
  for (std::size_t i = 1; i < n; ++i) {
    const Eigen::Index row = static_cast<Eigen::Index>(i);
    const bool identical = stream.t[i] == stream.t[i - 1] && stream.values.row(row) == stream.values.row(row - 1) &&
                           (stream.text.empty() || stream.text[i] == stream.text[i - 1]);
    if (stream.t[i] <= stream.t[i - 1] && !identical) {
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

// The stream CSVs named by the recording.yaml that DIR holds, read leniently: a missing or unreadable file names none.
// Only plain names count (no path separator, not starting with a dot).
std::vector<std::string> EarlierStreamFiles(const fs::path& dir) {
  std::vector<std::string> files;
  try {
    const YAML::Node root = YAML::LoadFile((dir / kYamlFile).string());
    if (!root.IsMap() || !root["streams"] || !root["streams"].IsSequence()) return files;
    for (const YAML::Node& stream : root["streams"]) {
      if (!stream.IsMap() || !stream["name"] || !stream["name"].IsScalar()) continue;
      const std::string name = stream["name"].Scalar();
      if (!name.empty() && name[0] != '.' && name.find('/') == std::string::npos) files.push_back(name + ".csv");
    }
  } catch (const YAML::Exception&) {
    files.clear();
  }
  return files;
}

// An earlier recording in DIR: its recording.yaml is removed first (until the new one is written last, the directory
// does not read as a recording), then its stream CSVs that the new recording does not write, and its truth.yaml
// (WriteTruth writes the new recording's after this). Other files are left alone.
Status RemoveEarlierRecording(const Recording& recording, const fs::path& dir) {
  const std::vector<std::string> earlier = EarlierStreamFiles(dir);
  std::set<std::string> written;
  for (const Stream& stream : recording.streams) written.insert(stream.info.name + ".csv");
  std::vector<std::string> stale = {kYamlFile, kTruthYamlFile};
  for (const std::string& file : earlier)
    if (!written.count(file)) stale.push_back(file);
  for (const std::string& file : stale)
    if (Status s = RemoveStaleFile((dir / file).string()); !s.ok()) return s;
  return Status::Ok();
}

}  // namespace

Status WriteRecording(const Recording& recording, const std::string& directory) {
  // Validate everything first: nothing is written for a recording that would not read back.
  if (Status s = ValidateForWrite(recording, directory); !s.ok()) return s;
  const fs::path dir(directory);
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) return Status::Error(directory + ": cannot create directory: " + error.message());
  if (Status s = RemoveEarlierRecording(recording, dir); !s.ok()) return s;
  // Stream files.
  for (const Stream& stream : recording.streams) {
    const std::string path = (dir / (stream.info.name + ".csv")).string();
    const bool camera = stream.info.type == StreamType::kCamera;
    const Eigen::MatrixXd no_values(static_cast<Eigen::Index>(stream.t.size()), 0);
    const std::string text = internal::FormatStreamCsv(
        WrittenColumns(stream.info), stream.t, camera ? no_values : stream.values, camera ? &stream.text : nullptr);
    if (Status s = WriteFileAtomic(path, text); !s.ok()) return s;
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
  return WriteFileAtomic((dir / kYamlFile).string(), EmitRecordingYaml(recording));
}

}  // namespace roamlab::recording
