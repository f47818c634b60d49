// The files `roamlab track` writes into its output directory:
//   trajectory.tum   the tracked poses (recording/trajectory.h)
//   covariance.csv   t,xx,xy,xz,yx,yy,yz,zx,zy,zz: each pose's world-frame position covariance [m^2]
//   summary.json     {"poses", "updates", "mean_update_s", "max_update_s", "p99_update_s", "mean_iterations",
//                     "factor_evaluations", "factor_carries", "seconds", "realtime_factor", "window",
//                     "rejected_measurements", "measurements": {STREAM: {"attached", "rejected", "too_late",
//                     "outside"}}}
#pragma once

#include <string>

#include "common/status.h"
#include "estimator/tracking.h"

namespace roamlab::estimator {

// Measurements rejected by the gate, over all streams.
int RejectedMeasurements(const TrackingResult& result);

// Seconds of data tracked per second of run time (0 when the run took no time).
double RealtimeFactor(const TrackingResult& result);

// Writes the three files into `dir` (which exists); `window` is the configuration's tracking.window.
Status WriteTrackingFiles(const TrackingResult& result, int window, const std::string& dir);

}  // namespace roamlab::estimator
