// What a replay (sim/replay.h) hands the simulator in place of the scenario's driver and sensor rates: the drive inputs
// taken from a recording and the recording's own sample stamps. The simulator keeps one loop; with a schedule
// (SimulateOptions::replay) its simulation time 0 is the recording time `t0`:
//   - Drive. From t = 0 on the set-points are the inputs at t0 + t (DriveInputs::At); during the lead-in the robot
//     rests and then ramps to the first input, as it ramps to the profiles' first values without a schedule.
//   - Samples. A scheduled stream's sample stamped s is taken at the physics step nearest s - t0 (half a step at most
//     away: 1 ms on models/diffdrive.xml, 0.5 ms on models/atv.xml), minus the time shift of an effect
//     (gps_latency, imu_time_offset); two stamps nearest the same step read the same state. The stream keeps the
//     exact stamps s. The ground truth keeps the scenario's rate, stamped t0 + k / ground_truth_rate_hz.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/time.h"

namespace roamlab::sim {

struct DriveInputs {
  enum class Kind {
    kBodyVelocity,  // per row v_x [m/s], v_y [m/s], omega_z [rad/s] of O: the wheeled robots' body-velocity driver
    kWheelRates,    // per row one rate [rad/s] per wheel of the model (WheeledRobot::EncoderColumns order): each
                    // wheel's velocity servo set to it
    kAckermann,     // per row rear-wheel speed [m/s] (the speed controller's set-point) and handlebar angle [rad]
  };
  Kind kind = Kind::kBodyVelocity;
  std::vector<Time> t;     // recording time, strictly increasing, at least one row
  Eigen::MatrixXd values;  // one row per t
  bool hold = false;       // true: each row holds until the next (recorded commands); false: linear between rows
  std::string source;      // what the inputs were taken from (stream names), for messages and truth.yaml

  // The inputs at recording time `t`: the first row before the first stamp, the last after the last.
  Eigen::VectorXd At(Time t) const;
};

struct ReplaySchedule {
  Time t0;             // the recording time of simulation time 0
  DriveInputs drive;
  // Per simulated stream (its name in the simulator: imu, magnetometer, gps, wheel_encoders, rear_wheel, steering):
  // the stamps to sample it at (recording time, strictly increasing, >= t0). A stream of the scenario without an
  // entry here is not scheduled and keeps its rate (stamps from t0).
  std::map<std::string, std::vector<Time>> stamps;
};

}  // namespace roamlab::sim
