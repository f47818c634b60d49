// `roamlab calibrate` and `roamlab track` (experiment/steps.h). Each returns the process exit code; bad input is
// reported on stderr as one line "roamlab <command>: <problem>" and gives exit code 2, a failure at run time exit
// code 1 (apps/cli.h).
#pragma once

#include <iosfwd>

#include "experiment/steps.h"

namespace roamlab::apps {

// The step's request (without progress, which the command sets).
struct CalibrateArgs : experiment::CalibrateRequest {
  bool quiet = false;           // no progress and no summary
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
// Offline self-calibration: writes OUT/calibration.json and OUT/trajectory.tum.
int RunCalibrate(const CalibrateArgs& args);

// The step's request (without progress, which the command sets; no_time_budget is not an option of the command).
struct TrackArgs : experiment::TrackRequest {
  bool quiet = false;           // no progress and no summary
  std::ostream* err = nullptr;  // receives the one-line error; nullptr: stderr
};
// Online fixed-lag tracking: writes OUT/trajectory.tum, OUT/covariance.csv and OUT/summary.json.
int RunTrack(const TrackArgs& args);

}  // namespace roamlab::apps
