// truth.yaml: what only a simulator knows and only evaluation may read. The estimator and the gap diagnosis never call
// ReadTruth (tests make the file unreadable to prove it).
//
//   calibration:            true values of calibration parameters, named "<stream>.<parameter>" as in calibration.json
//     gps.lever_arm: [0.57, -0.46, 0.32]
//     imu.misalignment: [w, x, y, z]          # quaternions w first, matrices row-major
//   effects:                hidden physical effects, each with its parameters
//     - name: gps_latency
//       parameters: {latency_s: 0.12}
//   replay:                 a replay's twin (sim/replay.h) only: noise-free, driven by a recording's inputs
//     noise_free: true
//     drive: wheel_encoders stream 'wheel_encoders' (differentiated)
//     start: pose stream 'mocap'
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/status.h"

namespace roamlab::recording {

struct Effect {
  std::string name;
  std::map<std::string, double> parameters;
};

// A replay's twin: every sensor-noise source off; the drive and the start taken from the recording.
struct ReplayNote {
  std::string drive;  // the recorded streams the inputs came from
  std::string start;  // where the start pose came from
};

struct Truth {
  std::map<std::string, std::vector<double>> calibration;
  std::vector<Effect> effects;
  std::optional<ReplayNote> replay;
};

Result<Truth> ReadTruth(const std::string& directory);
Status WriteTruth(const Truth& truth, const std::string& directory);

}  // namespace roamlab::recording
