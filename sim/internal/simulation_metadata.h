// Private helpers of the simulator: what it writes besides the streams, the recording's provenance and the true
// calibration written to truth.yaml (recording/truth.h).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "recording/recording.h"
#include "sim/scenario.h"
#include "sim/sensors.h"

namespace roamlab::sim::internal {

// The provenance of a simulated recording: source "simulated", the scenario file, the seed and a description naming
// the scenario, the MuJoCo version, the robot model (`model_where`), the terrain and whether the noise is off.
recording::Provenance SimulatedProvenance(const Scenario& scenario, std::uint64_t seed, const std::string& model_where,
                                          bool noise);

// What the simulator measured or applied that the scenario does not state directly.
struct TrueSensorFrames {
  ImuCalibration imu;
  MagnetometerCalibration magnetometer;
  std::map<std::string, std::vector<double>> wheels;  // the wheeled robot's true odometer geometry
  recording::Mounting laser;                          // the laser site in O
  std::optional<recording::Mounting> camera;          // the camera in O, when it ran
  double rear_rolling_over_radius = 1.0;  // the Ackermann rear tires' travel per radian over their geometric radius
};

// The true calibration, named as calibration.json names the estimated parameters; quaternions w first, matrices
// row-major.
std::map<std::string, std::vector<double>> TrueCalibration(const SensorOptions& sensors,
                                                           const TrueSensorFrames& frames);

}  // namespace roamlab::sim::internal
