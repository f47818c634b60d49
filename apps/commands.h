// The `roamlab` subcommands. Each returns the process exit code; bad input is reported on stderr as one line
// "roamlab <command>: <problem>" and gives exit code 2, a failure at run time exit code 1.
#pragma once

#include <iosfwd>
#include <map>
#include <string>

#include <Eigen/Core>

#include "common/status.h"
#include "estimator/config.h"
#include "estimator/tracking.h"

namespace roamlab::apps {

struct CalibrateArgs {
  std::string recording;
  std::string config;
  std::string out;
  bool quiet = false;            // no progress and no summary
  std::ostream* err = nullptr;   // receives the one-line error; nullptr: stderr
};
// Offline self-calibration: writes OUT/calibration.json and OUT/trajectory.tum.
int RunCalibrate(const CalibrateArgs& args);

struct TrackArgs {
  std::string recording;
  std::string config;
  std::string calibration;  // optional calibration.json
  std::string out;
  bool no_time_budget = false;   // ignore tracking.time_budget_s: results that do not depend on the machine's speed
  bool quiet = false;            // no progress and no summary
  std::ostream* err = nullptr;   // receives the one-line error; nullptr: stderr
};
// Online fixed-lag tracking: writes OUT/trajectory.tum, OUT/covariance.csv and OUT/summary.json.
int RunTrack(const TrackArgs& args);

// Parameter values (ambient, by name) from a calibration.json written by `roamlab calibrate`.
Result<std::map<std::string, Eigen::VectorXd>> ReadCalibrationValues(const std::string& path);

// The joint marginal information of the calibrated parameters from the same file ("information": {"parameters":
// [...], "matrix": [[...]]}), for tracking with tracking.calibration_prior.
Result<estimator::CalibrationPrior> ReadCalibrationPrior(const std::string& path);

// TrackingOptions for `config`: with tracking.calibration_prior, the prior read from `calibration_path` (an error
// when the configuration asks for it and no calibration file is given).
Result<estimator::TrackingOptions> TrackingOptionsFor(const estimator::EstimatorConfig& config,
                                                      const std::string& calibration_path);

}  // namespace roamlab::apps
