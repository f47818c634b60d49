// What a replay (sim/replay.h) hands the simulator in place of the scenario's driver and sensor rates: the drive inputs
// taken from a recording and the recording's own sample stamps. The simulator keeps one loop; with a schedule
// (SimulateOptions::replay) its simulation time 0 is the recording time `t0`:
//   - Drive. During the lead-in the robot settles at rest on the ground; from t = 0 on the set-points are the inputs
//     at t0 + t (DriveInputs::At; at t0 + t + offset_s + drift_ppm 1e-6 t with the effect drive_time_offset, its
//     rates then scaled by 1 + drift_ppm 1e-6). A recording that starts in motion therefore starts the twin with a
//     step. Measured wheel angles (DriveInputs::angles_rad) are tracked: each wheel's servo target is its measured rate
//     plus (measured - twin angle increment since t = 0) / kAngleTrackingS, which removes the velocity servo's
//     steady-state error (the load torque over its gain: the twin's wheel would otherwise lag the recorded one, which
//     had already lagged its own command by as much). Likewise an Ackermann vehicle's measured travel
//     (DriveInputs::travel_m): the speed set-point is the measured speed plus (measured - twin travel since t = 0) /
//     kAngleTrackingS, the twin's travel being its rear-wheel speed integrated. Both are in the speed sensor's terms:
//     with longitudinal_slip or slope_slip the twin's rear-wheel speed is read as the sensor would, times the slip
//     factor at the last odometer sample (1 + s_f f_x + s_p g sin(pitch) of that state), and the controller's target is
//     divided by it, so that the twin's speed readings follow the recorded ones.
//   - Samples. A scheduled stream's sample stamped s is taken at the physics step nearest s - t0 (half a step at most
//     away: 1 ms on models/diffdrive.xml, 0.5 ms on models/atv.xml), minus the time shift of an effect
//     (gps_latency, imu_time_offset, pose_time_offset); two stamps nearest the same step read the same state. The
//     stream keeps the exact stamps s. The ground truth keeps the scenario's rate, stamped t0 + k /
//     ground_truth_rate_hz.
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
    kWheelRates,    // per row one rate [rad/s] per wheel of the model (wheel index order, sim/replay.h): each
                    // wheel's velocity servo set to it
    kAckermann,     // per row rear-wheel speed [m/s] (the speed controller's set-point) and handlebar angle [rad]
  };
  Kind kind = Kind::kBodyVelocity;
  std::vector<Time> t;         // recording time, strictly increasing, at least one row
  Eigen::MatrixXd values;      // one row per t
  bool hold = false;           // true: each row holds until the next (recorded commands); false: linear between rows
  std::string source;          // what the inputs were taken from (stream names), for messages and truth.yaml
  Eigen::MatrixXd angles_rad;  // kWheelRates from cumulative angles: per row the angle [rad] of each model wheel;
                               // empty otherwise
  Eigen::VectorXd travel_m;    // kAckermann from measured speeds: per row the rear wheels' travel since the first
                               // row [m] (the speeds integrated); empty otherwise
  // The recorded streams the inputs were taken from (DriveInputsFrom).
  std::vector<std::string> streams;

  // The inputs at recording time `t`: the first row before the first stamp, the last after the last.
  Eigen::VectorXd At(Time t) const;
  // The wheel angles at `t`, linear between rows (angles_rad must not be empty).
  Eigen::VectorXd AnglesAt(Time t) const;
  // The travel at `t`, linear between rows (travel_m must not be empty).
  double TravelAt(Time t) const;
};

// The time constant with which a replay's wheels track the measured wheel angles [s] (well above the velocity
// servos' own few milliseconds, so the two loops do not fight).
inline constexpr double kAngleTrackingS = 0.1;

struct ReplaySchedule {
  Time t0;  // the recording time of simulation time 0
  DriveInputs drive;
  // Per simulated stream (its role in the simulator: imu, magnetometer, gps, wheel_encoders (the scenario's encoder
  // stream, whatever its name), rear_wheel, steering, mocap, odometry):
  // the stamps to sample it at (recording time, strictly increasing, >= t0). A stream of the scenario without an
  // entry here is not scheduled and keeps its rate (stamps from t0).
  std::map<std::string, std::vector<Time>> stamps;
};

}  // namespace roamlab::sim
