// calibration.json: the file `roamlab calibrate` writes and tracking (track, montecarlo, the regression suite, the
// benchmark) reads.
//
//   {"parameters": {NAME: {"estimate": [...], "std": [...], "observability": "...",
//                          "component_observability": [...], "manifold": "..."}},
//    "information": {"parameters": [NAME, ...], "matrix": [[...], ...]},
//    "correlations": [{"a", "b", "rho"}], "solver": {...}, "measurements": {STREAM: {...}},
//    "recording": PATH, "config": PATH}
//
// estimate is ambient (quaternions [w, x, y, z]), std and the information matrix are tangent; a non-finite number is
// written as null. Tracking reads only parameters.NAME.estimate and information.
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

// Writes only what tracking reads: parameters.NAME.estimate for `values` and the information of `prior`.
Status WriteCalibrationValues(const std::map<std::string, Eigen::VectorXd>& values, const CalibrationPrior& prior,
                              const std::string& path);

// Parameter values (ambient, by name): parameters.NAME.estimate.
Result<std::map<std::string, Eigen::VectorXd>> ReadCalibrationValues(const std::string& path);

// The joint marginal information of the calibrated parameters, for tracking with tracking.calibration_prior.
Result<CalibrationPrior> ReadCalibrationPrior(const std::string& path);

// TrackingOptions for `config`: with tracking.calibration_prior, the prior read from `calibration_path` (an error
// when the configuration asks for it and no calibration file is given).
Result<TrackingOptions> TrackingOptionsFor(const EstimatorConfig& config, const std::string& calibration_path);

}  // namespace roamlab::estimator
