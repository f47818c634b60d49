// calibration.json (its format: recording/calibration_file.h): written by `roamlab calibrate`, read for tracking.
#pragma once

#include <map>
#include <string>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/calibration.h"
#include "estimator/config.h"
#include "estimator/tracking.h"

namespace roamlab::estimator {

// Writes `result` as calibration.json to `path`; `recording` and `config` are the input paths it records.
Status WriteCalibrationFile(const CalibrationResult& result, const std::string& recording, const std::string& config,
                            const std::string& path);

// Parameter values (ambient, by name): parameters.NAME.estimate (recording::ReadCalibrationFile).
Result<std::map<std::string, Eigen::VectorXd>> ReadCalibrationValues(const std::string& path);

// The joint marginal information of the calibrated parameters, for tracking with tracking.calibration_prior.
Result<CalibrationPrior> ReadCalibrationPrior(const std::string& path);

// TrackingOptions for `config`: with tracking.calibration_prior, the prior read from `calibration_path` (an error
// when the configuration asks for it and no calibration file is given).
Result<TrackingOptions> TrackingOptionsFor(const EstimatorConfig& config, const std::string& calibration_path);

}  // namespace roamlab::estimator
