// JSON file helpers of the estimator's result files (calibration_io.cc, tracking_io.cc).
#pragma once

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "common/status.h"
#include "estimator/problem.h"

namespace roamlab::estimator::internal {

// `j` written to `path` with two-space indentation and a final newline.
Status WriteJson(const nlohmann::json& j, const std::string& path);

// Measurement counts by stream: {STREAM: {"attached", "rejected", "too_late", "outside"}}.
nlohmann::json CountsJson(const std::map<std::string, StreamCounts>& counts);

}  // namespace roamlab::estimator::internal
