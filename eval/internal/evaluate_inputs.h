// Private to eval/evaluate.cc: what an evaluation reads (eval/evaluate.h describes the sources and their order).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/status.h"
#include "eval/evaluate.h"
#include "eval/nees.h"
#include "eval/parameters.h"
#include "recording/recording.h"
#include "recording/truth.h"

namespace roamlab::eval::internal {

struct Inputs {
  std::optional<recording::Recording> recording;
  std::string recording_dir;
  Trajectory reference;
  bool reference_timed = true;
  bool reference_has_orientation = true;
  bool reference_is_ground_truth = false;  // REC/ground_truth.tum
  std::string reference_path;              // file read, or the stream's CSV
  std::string reference_stream;            // name when the reference is a stream, else ""
  std::string reference_label;             // legend text
  nlohmann::json reference_json;           // metrics.json "reference"

  Trajectory estimate;  // stamps shifted by the time offset; moved to the sensor of a stream reference
  bool estimate_timed = true;
  std::string estimate_name;    // directory or file name
  std::string estimate_format;  // "directory" or the file's format
  std::optional<std::vector<StampedCovariance>> covariances;
  std::optional<std::map<std::string, ParameterEstimate>> calibration;
  std::optional<recording::Truth> true_values;
  std::string trajectory_path, covariance_path, calibration_path;
};

// gps, position and pose streams: the sensors that measure where the platform is in W.
bool IsAbsoluteSensor(recording::StreamType type);

// Reads the reference, the estimate and the optional files. Errors are bad input: one line naming the file.
Result<Inputs> ReadInputs(const EvaluateOptions& options);

}  // namespace roamlab::eval::internal
