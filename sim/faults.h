// Sensor faults injected into a simulated recording: the scenario's `faults:` list, applied in order to the streams
// once the drive is simulated (Simulator::Run), before the recording is written. The ground truth and truth.yaml are
// untouched: a fault is what the recording gets wrong about the world, never the world.
//
//   faults:
//     - {type: outliers, stream: gps, fraction: 0.1, size: 5.0}         # gross errors
//     - {type: outage, stream: gps, start_s: 5.0, duration_s: 20.0}    # no samples
//     - {type: clock_jump, stream: gps, at_s: 15.0, jump_s: 1.0}        # the stream's clock leaps ahead
//     - {type: duplicates, stream: imu, fraction: 0.05}                 # messages delivered twice
//     - {type: freeze, stream: imu, start_s: 10.0, duration_s: 5.0}     # the sensor repeats one reading
//
//   outliers    each row independently with probability `fraction` (in (0, 1]) is moved by `size` (> 0): a gps row
//               by `size` metres in a uniformly random direction (east, north, up; converted to degrees on the
//               WGS84 ellipsoid at the row's latitude), any other row by +-size (random sign) on every column, in the
//               column's unit (m/s, rad, rad/s, m/s^2, ...).
//   outage      the rows stamped in [start_s, start_s + duration_s) are removed (a dropout).
//   clock_jump  the rows stamped at or after at_s are stamped jump_s later (jump_s in (0, 3600]): the stream's own
//               clock stepped forward. A backward step would make the stamps go backwards, which the recording format
//               refuses (the reader's error names the file, the row and "goes backwards"), so it is not offered.
//   duplicates  each row independently with probability `fraction` is written twice (the same stamp and values, as a
//               message delivered twice); the recording reader drops the copies and counts them.
//   freeze      the rows stamped in [start_s, start_s + duration_s) repeat the values of the first of them (a sensor
//               stuck at one reading, its stamps still advancing).
// `stream` names a stream the scenario writes (sensors: imu, magnetometer, gps, mocap, rear_wheel and steering for the
// odometer, the wheel encoders' name, scan_matching and laser_scan for the laser, visual_odometry for the camera);
// start_s, at_s within [0, duration_s], duration_s > 0. Each fault draws from its own seeded generator (the scenario's
// noise seed and the fault's index in the list), so the same scenario and seed give the same faults.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/status.h"
#include "recording/recording.h"

namespace roamlab::sim {

struct FaultOptions {
  std::string type;    // outliers | outage | clock_jump | duplicates | freeze
  std::string stream;  // the stream it applies to
  double fraction = 0.0;
  double size = 0.0;
  double start_s = 0.0;
  double duration_s = 0.0;
  double at_s = 0.0;
  double jump_s = 0.0;
};

// The keys each fault type takes besides `type` and `stream` (all required).
const std::vector<std::string>& FaultKeys(const std::string& type);

// What is wrong with one fault given the scenario's duration and the names of the streams it writes: the offending
// key ("type", "stream", "fraction", ...) and the problem; nullopt when it is valid.
struct FaultProblem {
  std::string key;
  std::string message;
};
std::optional<FaultProblem> CheckFault(const FaultOptions& fault, double duration_s,
                                       const std::vector<std::string>& stream_names);

// Applies `faults` in order to `recording`'s streams (which must exist: checked by CheckFault). `seed` is the noise
// seed. Returns one line per fault saying what it changed ("gps: outliers on 31 of 151 rows").
std::vector<std::string> ApplyFaults(const std::vector<FaultOptions>& faults, std::uint64_t seed,
                                     recording::Recording* recording);

}  // namespace roamlab::sim
