// `roamlab calibrate` and `roamlab track` (experiment/steps.h). Each returns the process exit code; bad input is
// reported on stderr as one line "roamlab <command>: <problem>" and gives exit code 2, a failure at run time exit
// code 1 (apps/cli.h).
#pragma once

#include <iosfwd>
#include <string>

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
  bool quiet = false;            // no progress and no summary
  std::ostream* err = nullptr;   // receives the one-line error; nullptr: stderr
};
// Online fixed-lag tracking: writes OUT/trajectory.tum, OUT/covariance.csv and OUT/summary.json.
int RunTrack(const TrackArgs& args);

}  // namespace roamlab::apps
