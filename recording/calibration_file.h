// calibration.json: the file `roamlab calibrate` writes (estimator/calibration_io.h), read by tracking (track,
// montecarlo, the regression suite, the benchmark) and by evaluation (the parameter table). One reader for all.
//
//   {"parameters": {NAME: {"estimate": [...], "std": [...], "std_white": [...], "std_hac": [...],
//                          "observability": "...", "component_observability": [...], "manifold": "..."}},
//    "std_method": "white|hac", "hac_lags": {STREAM: L},
//    "information": {"parameters": [NAME, ...], "matrix": [[...], ...]},
//    "correlations": [{"a", "b", "rho"}], "solver": {...}, "measurements": {STREAM: {...}},
//    "recording": PATH, "config": PATH}
//
// estimate is ambient (quaternions [w, x, y, z]; SE3 [x, y, z, w, x, y, z]), std and the information matrix are
// tangent; a non-finite number is written as null. Only parameters.NAME.estimate is required; the reader ignores the
// keys it does not use (correlations, solver, measurements, paths, component_observability, std_white, std_hac:
// `std` is the chosen one of the two, std_method says which).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace roamlab::recording {

struct CalibratedParameter {
  std::vector<double> estimate;    // ambient values
  std::vector<double> std;         // tangent standard deviations; NaN where null; empty when absent
  std::string manifold;            // "R<n>", "S3" or "SE3" as written; "" when absent
  std::string observability = "";  // "observable", "weak" or "unobservable" as written; "" when absent
};

// The parameters' joint marginal information, tangent coordinates stacked in the order of `parameters`.
struct CalibrationInformation {
  std::vector<std::string> parameters;
  Eigen::MatrixXd matrix;  // NaN where null
};

struct CalibrationFile {
  std::map<std::string, CalibratedParameter> parameters;
  std::optional<CalibrationInformation> information;  // absent when the file has no "information" object with
                                                      // "parameters" and "matrix" arrays
};

// Reads calibration.json. Errors (one line naming the file): it cannot be opened or is not JSON, no object
// "parameters", a parameter without an array of numbers "estimate", a "std" that is not numbers or nulls, a
// "manifold" that is not a string, information names that are not strings or a matrix that is not square numbers.
Result<CalibrationFile> ReadCalibrationFile(const std::string& path);

}  // namespace roamlab::recording
