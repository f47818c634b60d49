#include <cmath>
#include <filesystem>

#include "eval/internal/evaluate_inputs.h"

namespace roamlab::eval::internal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string Join(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

bool IsFile(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

bool IsDirectory(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

// The last component of a path, trailing separators ignored; "estimate" when there is none usable as a directory name
// ("/", ".", "..").
std::string BaseName(const std::string& path) {
  fs::path p = fs::path(path).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  const std::string name = p.filename().string();
  return name.empty() || name == "." || name == ".." || name == "/" ? "estimate" : name;
}

// Reads one optional input: absent is fine, present but broken is an error.
template <typename T, typename Reader>
Status ReadOptional(const std::string& path, Reader reader, std::optional<T>* out) {
  if (!IsFile(path)) return Status::Ok();
  Result<T> result = reader(path);
  if (!result.ok()) return result.status();
  *out = std::move(result).value();
  return Status::Ok();
}

Status ReadReferenceFile(const EvaluateOptions& options, Inputs* in) {
  Result<TrajectoryFile> file = ReadTrajectoryFile(options.reference_file, options.reference_format);
  if (!file.ok()) return file.status();
  in->reference = std::move(file.value().poses);
  in->reference_timed = file.value().timed;
  in->reference_path = options.reference_file;
  in->reference_label = "reference (" + BaseName(options.reference_file) + ")";
  in->reference_json = {
      {"kind", "file"}, {"path", options.reference_file}, {"format", TrajectoryFormatName(file.value().format)}};
  return Status::Ok();
}

// The stream as a trajectory: positions in W (gps through ENU at the origin), orientations of pose streams.
Status ReadReferenceStream(const recording::Stream& stream, Inputs* in) {
  in->reference_stream = stream.info.name;
  in->reference_path = Join(in->recording_dir, stream.info.name + ".csv");
  for (const PositionFixes& f : AbsoluteFixes(*in->recording)) {
    if (f.name != stream.info.name) continue;
    in->reference_label = f.label;
    for (std::size_t i = 0; i < f.t.size(); ++i) {
      StampedPose pose;
      pose.t = f.t[i];
      pose.p_world_body = f.p_world[i];
      if (stream.info.type == recording::StreamType::kPose) {
        const auto row = stream.values.row(static_cast<Eigen::Index>(i));
        pose.q_world_body = Eigen::Quaterniond(row(6), row(3), row(4), row(5)).normalized();
      }
      in->reference.push_back(pose);
    }
  }
  in->reference_has_orientation = stream.info.type == recording::StreamType::kPose;
  in->reference_json = {{"kind", "stream"},
                        {"stream", stream.info.name},
                        {"type", recording::StreamTypeName(stream.info.type)},
                        {"path", in->reference_path}};
  return Status::Ok();
}

// The reference stream: the one named, else the recording's first gps, position or pose stream.
Status ChooseReferenceStream(const EvaluateOptions& options, Inputs* in) {
  const std::string yaml = Join(options.recording_dir, "recording.yaml");
  for (const recording::Stream& stream : in->recording->streams) {
    if (!options.reference_stream.empty() && stream.info.name != options.reference_stream) continue;
    if (!IsAbsoluteSensor(stream.info.type)) {
      if (options.reference_stream.empty()) continue;
      return Status::Error(yaml + ": stream '" + stream.info.name + "' is of type " +
                           recording::StreamTypeName(stream.info.type) +
                           "; a reference stream must be gps, position or pose");
    }
    return ReadReferenceStream(stream, in);
  }
  if (!options.reference_stream.empty()) return Status::Error(yaml + ": no stream '" + options.reference_stream + "'");
  return Status::Error(Join(options.recording_dir, "ground_truth.tum") +
                       ": missing, and the recording has no gps, position or pose stream to compare with");
}

Status ReadReference(const EvaluateOptions& options, Inputs* in) {
  if (!options.recording_dir.empty()) {
    recording::ReadOptions read;
    read.load_ground_truth = true;
    Result<recording::Recording> rec = recording::ReadRecording(options.recording_dir, read);
    if (!rec.ok()) return rec.status();
    in->recording = std::move(rec).value();
    in->recording_dir = options.recording_dir;
  }
  Status status = Status::Ok();
  if (!options.reference_file.empty()) {
    status = ReadReferenceFile(options, in);
  } else if (options.reference_stream.empty() && in->recording->ground_truth) {
    in->reference = *in->recording->ground_truth;
    in->reference_is_ground_truth = true;
    in->reference_path = Join(options.recording_dir, "ground_truth.tum");
    in->reference_label = "ground truth";
    in->reference_json = {{"kind", "ground_truth"}, {"path", in->reference_path}};
  } else {
    status = ChooseReferenceStream(options, in);
  }
  if (!status.ok()) return status;
  if (in->reference.empty()) return Status::Error(in->reference_path + ": no poses");
  in->reference_json["poses"] = in->reference.size();
  in->reference_json["orientation"] = in->reference_has_orientation;
  return Status::Ok();
}

Status ReadEstimate(const EvaluateOptions& options, Inputs* in) {
  in->estimate_name = BaseName(options.estimate_dir);
  if (IsDirectory(options.estimate_dir)) {
    in->estimate_format = "directory";
    in->trajectory_path = Join(options.estimate_dir, "trajectory.tum");
    if (!IsFile(in->trajectory_path))
      return Status::Error(in->trajectory_path + ": missing; the estimate needs a trajectory");
    Result<Trajectory> estimate = ReadTum(in->trajectory_path);
    if (!estimate.ok()) return estimate.status();
    in->estimate = std::move(estimate).value();
    in->covariance_path = Join(options.estimate_dir, "covariance.csv");
    if (Status s = ReadOptional(in->covariance_path, ReadPositionCovariances, &in->covariances); !s.ok()) return s;
    in->calibration_path = Join(options.estimate_dir, "calibration.json");
  } else {
    in->trajectory_path = options.estimate_dir;
    if (!IsFile(in->trajectory_path))
      return Status::Error(in->trajectory_path + ": missing; the estimate is a trajectory file or a directory with " +
                           "trajectory.tum");
    Result<TrajectoryFile> file = ReadTrajectoryFile(in->trajectory_path, options.estimate_format);
    if (!file.ok()) return file.status();
    in->estimate = std::move(file.value().poses);
    in->estimate_timed = file.value().timed;
    in->estimate_format = TrajectoryFormatName(file.value().format);
  }
  if (in->estimate.empty()) return Status::Error(in->trajectory_path + ": no poses");
  if (!options.covariance_file.empty()) {
    if (!in->estimate_timed)
      return Status::Error(options.covariance_file + ": covariances pair with poses by stamp; " +
                           in->trajectory_path + " has no time stamps");
    in->covariance_path = options.covariance_file;
    Result<std::vector<StampedCovariance>> rows = ReadPositionCovariances(options.covariance_file);
    if (!rows.ok()) return rows.status();
    in->covariances = std::move(rows).value();
  }
  // The time offset, on the covariance rows too (they are matched to the poses by stamp).
  const std::int64_t offset_ns = std::llround(options.time_offset_s * 1e9);
  for (StampedPose& pose : in->estimate) pose.t = Time::FromNanoseconds(pose.t.nanoseconds() + offset_ns);
  if (in->covariances)
    for (StampedCovariance& row : *in->covariances) row.t = Time::FromNanoseconds(row.t.nanoseconds() + offset_ns);
  return Status::Ok();
}

// A stream measures its sensor: the estimate is moved there (see eval/evaluate.h).
void MoveEstimateToSensor(Inputs* in) {
  const recording::Stream* stream = nullptr;
  for (const recording::Stream& s : in->recording->streams)
    if (s.info.name == in->reference_stream) stream = &s;
  Eigen::Vector3d p_body_sensor = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_body_sensor = Eigen::Quaterniond::Identity();
  std::string source = "none: ignored";
  if (stream && stream->info.mounting) {
    p_body_sensor = stream->info.mounting->p_body_sensor;
    q_body_sensor = stream->info.mounting->q_body_sensor;
    source = "mounting in recording.yaml";
  }
  if (in->calibration) {
    const auto it = in->calibration->find(in->reference_stream + ".lever_arm");
    if (it != in->calibration->end() && it->second.estimate.size() == 3) {
      p_body_sensor = Eigen::Vector3d(it->second.estimate[0], it->second.estimate[1], it->second.estimate[2]);
      source = "calibration (" + in->calibration_path + ")";
    }
  }
  const bool pose = stream && stream->info.type == recording::StreamType::kPose;
  for (StampedPose& p : in->estimate) {
    p.p_world_body += p.q_world_body * p_body_sensor;
    if (pose) p.q_world_body = (p.q_world_body * q_body_sensor).normalized();
  }
  in->reference_json["lever_arm_m"] = {p_body_sensor.x(), p_body_sensor.y(), p_body_sensor.z()};
  in->reference_json["lever_arm_source"] = source;
}

}  // namespace

bool IsAbsoluteSensor(recording::StreamType type) {
  return type == recording::StreamType::kGps || type == recording::StreamType::kPosition ||
         type == recording::StreamType::kPose;
}

Result<Inputs> ReadInputs(const EvaluateOptions& options) {
  Inputs in;
  if (Status s = ReadReference(options, &in); !s.ok()) return s;
  if (Status s = ReadEstimate(options, &in); !s.ok()) return s;
  if (!options.calibration_file.empty()) {
    if (!IsFile(options.calibration_file)) return Status::Error(options.calibration_file + ": missing");
    in.calibration_path = options.calibration_file;
  }
  if (!in.calibration_path.empty())
    if (Status s = ReadOptional(in.calibration_path, ReadCalibrationEstimates, &in.calibration); !s.ok()) return s;
  if (in.calibration && in.recording && IsFile(Join(options.recording_dir, "truth.yaml"))) {
    Result<recording::Truth> t = recording::ReadTruth(options.recording_dir);
    if (!t.ok()) return t.status();
    in.true_values = std::move(t).value();
  }
  if (!in.reference_stream.empty()) MoveEstimateToSensor(&in);
  return in;
}

}  // namespace roamlab::eval::internal
