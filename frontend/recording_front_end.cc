#include "frontend/recording_front_end.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/atomic_file.h"
#include "frontend/laser_scan.h"
#include "frontend/scan_matching_stream.h"
#include "frontend/visual_odometry_stream.h"

namespace roamlab::frontend {
namespace {

namespace fs = std::filesystem;

std::string YamlPath(const std::string& directory) { return (fs::path(directory) / "recording.yaml").string(); }

// The input stream: the one named, which must have `type`, or the recording's only stream of `type`.
Result<const recording::Stream*> FindInput(const recording::Recording& recording, const std::string& directory,
                                           const std::string& name, recording::StreamType type) {
  const std::string where = YamlPath(directory) + ": ";
  const std::string type_name = recording::StreamTypeName(type);
  if (!name.empty()) {
    const recording::Stream* stream = recording.Find(name);
    if (stream == nullptr) return Status::Error(where + "no stream '" + name + "'");
    if (stream->info.type != type) return Status::Error(where + "stream '" + name + "' is not of type " + type_name);
    return stream;
  }
  const recording::Stream* found = nullptr;
  for (const recording::Stream& stream : recording.streams) {
    if (stream.info.type != type) continue;
    if (found != nullptr) {
      return Status::Error(where + "several " + type_name + " streams ('" + found->info.name + "', '" +
                           stream.info.name + "'): name one");
    }
    found = &stream;
  }
  if (found == nullptr) return Status::Error(where + "no " + type_name + " stream");
  return found;
}

// The camera's intrinsics and the VO options (defaults with the stream's floor reference), checked.
Status CameraModel(const recording::Stream& camera, const std::string& directory, PinholeIntrinsics* intrinsics,
                   VisualOdometryOptions* options) {
  const std::string where = YamlPath(directory) + ": stream '" + camera.info.name + "': ";
  Result<PinholeIntrinsics> k = IntrinsicsOfAttributes(camera.info.attributes);
  if (!k.ok()) return Status::Error(where + k.status().message() + " (camera intrinsics)");
  *intrinsics = k.value();
  if (Status s = ReadFloorAttributes(camera.info.attributes, options); !s.ok()) {
    return Status::Error(where + s.message() + " (the visual odometry's floor reference)");
  }
  const std::string problem = options->Validate();
  return problem.empty() ? Status::Ok() : Status::Error(where + problem);
}

// Runs the visual odometry over the frames of `camera`.
Result<FrontEndResult> VisualOdometryOfFrames(const recording::Stream& camera, const std::string& directory,
                                              const std::string& output_stream,
                                              const std::function<void(double)>& progress) {
  PinholeIntrinsics intrinsics;
  VisualOdometryOptions options;
  if (Status s = CameraModel(camera, directory, &intrinsics, &options); !s.ok()) return s;
  VisualOdometryStream vo(intrinsics, options, output_stream, camera.info.rate_hz);
  cv::Mat gray;
  for (std::size_t i = 0; i < camera.t.size(); ++i) {
    const std::string path = (fs::path(directory) / camera.text[i]).string();
    cv::Mat bgr;
    try {
      bgr = cv::imread(path, cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
      bgr.release();
    }
    if (bgr.empty()) return Status::Error(path + ": cannot read the image");
    if (bgr.cols != intrinsics.width_px || bgr.rows != intrinsics.height_px) {
      return Status::Error(path + ": the image is " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) +
                           ", the intrinsics of stream '" + camera.info.name + "' say " +
                           std::to_string(intrinsics.width_px) + "x" + std::to_string(intrinsics.height_px));
    }
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    vo.ProcessFrame(camera.t[i], gray);
    if (progress) progress(static_cast<double>(i + 1) / static_cast<double>(camera.t.size()));
  }
  FrontEndResult result;
  result.stream = vo.TakeStream();
  result.stream.info.mounting = camera.info.mounting;
  result.input_stream = camera.info.name;
  result.visual_odometry = vo.counters();
  return result;
}

// Runs the scan matcher over the scans of `laser`.
Result<FrontEndResult> ScanMatchingOfScans(const recording::Stream& laser, const std::string& directory,
                                           const std::string& output_stream,
                                           const std::function<void(double)>& progress) {
  ScanMatchingStream matching(output_stream, laser.info.rate_hz);
  for (Eigen::Index row = 0; row < laser.values.rows(); ++row) {
    const ScanGeometry geometry = LaserScanGeometry(laser, row);
    if (laser.values.row(row).head<4>() != laser.values.row(0).head<4>()) {
      return Status::Error((fs::path(directory) / (laser.info.name + ".csv")).string() + ":" + std::to_string(row + 2) +
                           ": the scan geometry differs from the first scan's");
    }
    matching.AddScan(laser.t[static_cast<std::size_t>(row)], geometry, LaserScanRanges(laser, row));
    if (progress) progress(static_cast<double>(row + 1) / static_cast<double>(laser.values.rows()));
  }
  FrontEndResult result;
  result.stream = matching.TakeStream();
  result.stream.info.mounting = laser.info.mounting;
  result.input_stream = laser.info.name;
  result.failed_scan_matches = matching.failed_matches();
  return result;
}

// Copies `relative` from one recording directory to the other (written atomically).
Status CopyFile(const std::string& from_directory, const std::string& to_directory, const std::string& relative) {
  const fs::path from = fs::path(from_directory) / relative;
  const fs::path to = fs::path(to_directory) / relative;
  std::error_code error;
  fs::create_directories(to.parent_path(), error);
  if (error) return Status::Error(to.string() + ": cannot create its directory: " + error.message());
  std::ifstream in(from, std::ios::binary);
  const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) return Status::Error(from.string() + ": cannot read (copying it to " + to.string() + ")");
  return WriteFileAtomic(to.string(), content);
}

// The camera frames of the input recording, which WriteRecording does not write.
Status CopyFrames(const recording::Recording& recording, const std::string& input_directory,
                  const std::string& output_directory) {
  for (const recording::Stream& stream : recording.streams) {
    for (const std::string& frame : stream.text) {
      if (Status s = CopyFile(input_directory, output_directory, frame); !s.ok()) return s;
    }
  }
  return Status::Ok();
}

// truth.yaml, after WriteRecording (which removes an earlier recording's).
Status CopyTruth(const std::string& input_directory, const std::string& output_directory) {
  std::error_code error;
  if (!fs::exists(fs::path(input_directory) / "truth.yaml", error)) return Status::Ok();
  return CopyFile(input_directory, output_directory, "truth.yaml");
}

}  // namespace

Result<FrontEndResult> DeriveStream(const recording::Recording& recording, const std::string& directory,
                                    const FrontEndOptions& options) {
  const bool vo = options.front_end == FrontEnd::kVisualOdometry;
  const std::string output_stream = !options.output_stream.empty() ? options.output_stream
                                    : vo                           ? "visual_odometry"
                                                                   : "scan_matching";
  const recording::StreamType type = vo ? recording::StreamType::kCamera : recording::StreamType::kLaserScan;
  Result<const recording::Stream*> input = FindInput(recording, directory, options.input_stream, type);
  if (!input.ok()) return input.status();
  if (output_stream == input.value()->info.name) {
    return Status::Error(YamlPath(directory) + ": the derived stream would replace its input '" + output_stream + "'");
  }
  return vo ? VisualOdometryOfFrames(*input.value(), directory, output_stream, options.progress)
            : ScanMatchingOfScans(*input.value(), directory, output_stream, options.progress);
}

Result<FrontEndResult> RunFrontEnd(const std::string& input_directory, const std::string& output_directory,
                                   const FrontEndOptions& options, bool* bad_input) {
  if (bad_input != nullptr) *bad_input = true;
  Result<recording::Recording> read = recording::ReadRecording(input_directory);
  if (!read.ok()) return read.status();
  recording::Recording recording = std::move(read).value();
  Result<FrontEndResult> derived = DeriveStream(recording, input_directory, options);
  if (!derived.ok()) return derived.status();
  if (bad_input != nullptr) *bad_input = false;
  // The derived stream in place of one of the same name, else last.
  const recording::Stream& stream = derived.value().stream;
  bool replaced = false;
  for (recording::Stream& existing : recording.streams) {
    if (existing.info.name != stream.info.name) continue;
    existing = stream;
    replaced = true;
  }
  if (!replaced) recording.streams.push_back(stream);
  if (Status s = CopyFrames(recording, input_directory, output_directory); !s.ok()) return s;
  if (Status s = recording::WriteRecording(recording, output_directory); !s.ok()) return s;
  if (Status s = CopyTruth(input_directory, output_directory); !s.ok()) return s;
  return derived;
}

}  // namespace roamlab::frontend
